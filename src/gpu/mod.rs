//! The wgpu side: it only mirrors the model (dirty tiles of the maps, the mesh) and shades it
//! with `shaders/preview.wgsl`. Works headless on any adapter wgpu finds (lavapipe in CI).

pub mod check;
pub mod difference;
pub mod headless;
pub mod maps;
pub mod preview;
mod upload;

use std::fmt;

pub use maps::MapTextures;
pub use preview::{Layout, MeshBuffers, Offscreen, Preview, RenderedImage};

/// Why the GPU side could not do something.
#[derive(Debug)]
pub struct GpuError(pub String);

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for GpuError {}

/// A device and its queue, with what the adapter offers that the preview uses.
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, driver and backend, for reports.
    pub info: wgpu::AdapterInfo,
    /// Whether 16-bit normalised textures are available (else `k_d`/`k_s` use half floats).
    pub unorm16: bool,
}

impl fmt::Debug for Gpu {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Gpu")
            .field("adapter", &self.info.name)
            .field("backend", &self.info.backend)
            .field("unorm16", &self.unorm16)
            .finish_non_exhaustive()
    }
}

/// WGSL of a shader in `shaders/` with the files its `// requires:` line names prepended.
pub fn shader_source(main: &str) -> String {
    let ambient = include_str!("../../shaders/ambient.wgsl");
    match main
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("// requires:"))
    {
        Some(list) if list.trim() == "ambient.wgsl" => format!("{ambient}\n{main}"),
        _ => main.to_string(),
    }
}

impl Gpu {
    /// A 2D texture of one mip level and one sample, `size` texels.
    pub fn texture_2d(
        &self,
        label: &str,
        (width, height): (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    }

    /// A device on the first adapter wgpu finds, without any window or display.
    ///
    /// # Errors
    /// When no adapter is found or the device cannot be created.
    pub fn headless() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| {
            GpuError(format!(
                "no GPU adapter found ({e}); install a Vulkan driver (e.g. Mesa's lavapipe, package mesa-vulkan-drivers)"
            ))
        })?;
        Self::from_adapter(&adapter)
    }

    /// A device on `adapter`, with the features and limits the preview uses when offered.
    ///
    /// # Errors
    /// When the device cannot be created.
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        let unorm16 = adapter
            .features()
            .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM);
        let required_features = if unorm16 {
            wgpu::Features::TEXTURE_FORMAT_16BIT_NORM
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("kapaint"),
            required_features,
            // The adapter's own limits: 8192^2 maps need more than the portable defaults.
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError(format!("cannot open the GPU device: {e}")))?;
        Ok(Self {
            device,
            queue,
            info: adapter.get_info(),
            unorm16,
        })
    }

    /// Blocks until the queue's work is done.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}
