//! Offscreen renders read back to the CPU (the command line, thumbnails, tests).

use super::{DEPTH_FORMAT, Layout, MeshBuffers, PipelineKey, Preview, PreviewDrawData, begin_pass};
use crate::maps::MapTextures;
use crate::readback::read_texture;
use crate::{Gpu, GpuError};
use kapaint_core::render::FrameSettings;
use kapaint_reflectance::ShadingModel;

/// What an offscreen render produces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Offscreen {
    /// Image size.
    pub size: (u32, u32),
    /// Linear floats even for shaded views (data views are always linear).
    pub linear: bool,
    /// Single, or models compared (split, side by side or all three); the settings' model is
    /// ignored when comparing.
    pub layout: Layout,
    /// The compared models from the left: the first two for a split or side by side.
    pub models: [ShadingModel; 3],
}

/// The models a comparison shows unless told otherwise: Phong, Blinn-Phong, Cook-Torrance.
pub const COMPARED_MODELS: [ShadingModel; 3] = [
    ShadingModel::Phong,
    ShadingModel::BlinnPhong,
    ShadingModel::CookTorrance,
];

/// A rendered image read back from the GPU, row-major from the top.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderedImage {
    /// sRGB-encoded RGBA8 (shaded views).
    Srgb8 {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// `width * height * 4` bytes.
        pixels: Vec<u8>,
    },
    /// Linear RGBA floats (data views, and shaded views for comparisons).
    Linear {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// `width * height * 4` floats.
        pixels: Vec<f32>,
    },
}

impl Preview {
    /// Renders a frame offscreen and reads it back: sRGB bytes for shaded views unless
    /// `linear`, linear floats otherwise. A compare layout draws `offscreen.models` from the
    /// left (of the split, or in the left half or third).
    ///
    /// # Errors
    /// When the size is zero or above the device's texture limit, or the read-back fails.
    pub fn render_offscreen(
        &self,
        gpu: &Gpu,
        mesh: &MeshBuffers,
        maps: &MapTextures,
        settings: &FrameSettings,
        offscreen: Offscreen,
    ) -> Result<RenderedImage, GpuError> {
        let scope = gpu.scope()?;
        let image = self.render_offscreen_in_scope(gpu, mesh, maps, settings, offscreen);
        scope.finish("rendering the preview")?;
        image
    }

    /// [`Preview::render_offscreen`], inside its error scope.
    fn render_offscreen_in_scope(
        &self,
        gpu: &Gpu,
        mesh: &MeshBuffers,
        maps: &MapTextures,
        settings: &FrameSettings,
        offscreen: Offscreen,
    ) -> Result<RenderedImage, GpuError> {
        let Offscreen {
            size: (width, height),
            linear,
            layout,
            models,
        } = offscreen;
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GpuError(format!(
                "image size {width}x{height} is outside 1..={max}"
            )));
        }
        let linear = linear || settings.view.is_data();
        let format = if linear {
            wgpu::TextureFormat::Rgba32Float
        } else {
            wgpu::TextureFormat::Rgba8UnormSrgb
        };
        let texture = |format, usage| gpu.texture_2d("offscreen", (width, height), format, usage);
        let color = texture(
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = texture(DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let key = PipelineKey::for_frame(settings, &maps.uniform, format);
        let parts = if layout == Layout::Single {
            layout.parts([key; 3], (width, height))
        } else {
            let settings_of = |model| FrameSettings { model, ..*settings };
            layout.parts(
                models.map(|m| PipelineKey::for_frame(&settings_of(m), &maps.uniform, format)),
                (width, height),
            )
        };
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        // A one-off render: its own bindings.
        let mut bindings = super::FrameBindings::default();
        let data = PreviewDrawData::new(self, gpu, (mesh, maps), settings, &parts, &mut bindings);
        {
            let color = color.create_view(&wgpu::TextureViewDescriptor::default());
            let depth = depth.create_view(&wgpu::TextureViewDescriptor::default());
            let mut pass = begin_pass(&mut encoder, &color, &depth);
            self.draw(&mut pass, &data);
        }
        let texel = if linear { 16 } else { 4 };
        let packed = read_texture(gpu, encoder, &color, texel, 0)?;
        Ok(if linear {
            RenderedImage::Linear {
                width,
                height,
                pixels: bytemuck::pod_collect_to_vec(&packed),
            }
        } else {
            RenderedImage::Srgb8 {
                width,
                height,
                pixels: packed,
            }
        })
    }
}
