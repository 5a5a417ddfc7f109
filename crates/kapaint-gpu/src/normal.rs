//! The tangent-space normal map on the GPU: RGBA8 unorm (the file's 8 bits, not sRGB), one
//! level; a flat 1x1 texel where the material has none (the shader then skips it altogether).

use std::sync::Arc;

use super::{Gpu, GpuError};
use kapaint_model::normal::NormalMap;

/// The normal map's texture and the map it mirrors.
pub struct NormalTexture {
    /// RGBA8 unorm (A 255).
    pub texture: wgpu::Texture,
    source: Option<Arc<NormalMap>>,
}

impl std::fmt::Debug for NormalTexture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NormalTexture")
            .field("present", &self.source.is_some())
            .finish_non_exhaustive()
    }
}

/// An RGBA8 texture of `(w, h)` holding `rgba`.
fn texture(gpu: &Gpu, (w, h): (u32, u32), rgba: &[u8]) -> wgpu::Texture {
    use wgpu::util::DeviceExt;
    gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("normal map"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        rgba,
    )
}

impl NormalTexture {
    /// No normal map: one flat texel.
    pub fn flat(gpu: &Gpu) -> Self {
        Self {
            texture: texture(gpu, (1, 1), &[128, 128, 255, 255]),
            source: None,
        }
    }

    /// Whether a normal map is bound.
    pub fn present(&self) -> bool {
        self.source.is_some()
    }

    /// Mirrors `normal` (uploaded when it is another map than the one mirrored).
    ///
    /// # Errors
    /// A map larger than the device's largest texture, or a device out of memory or lost.
    pub fn sync(&mut self, gpu: &Gpu, normal: Option<&Arc<NormalMap>>) -> Result<(), GpuError> {
        let same = match (&self.source, normal) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        };
        if same {
            return Ok(());
        }
        let Some(map) = normal else {
            *self = Self::flat(gpu);
            return Ok(());
        };
        let size = (map.width(), map.height());
        gpu.check_texture_size("the normal map", size)?;
        let rgba: Vec<u8> = map
            .image()
            .pixels()
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        let made = gpu.checked("uploading the normal map", || texture(gpu, size, &rgba))?;
        *self = Self {
            texture: made,
            source: Some(Arc::clone(map)),
        };
        Ok(())
    }
}
