//! The wgpu side: it only mirrors the model (dirty tiles of the maps, the mesh) and shades it
//! with `shaders/preview.wgsl`. Works headless on any adapter wgpu finds (lavapipe in CI).

pub mod blocks;
pub mod check;
pub mod difference;
pub mod headless;
pub mod maps;
pub mod normal;
pub mod preview;
pub mod rays;
pub mod readback;
pub mod shader;
mod upload;

use std::collections::HashMap;
use std::fmt;
use std::sync::{Arc, Mutex};

pub use maps::MapTextures;
pub use preview::{Layout, MeshBuffers, Offscreen, Preview, PreviewDrawData, RenderedImage};

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
    /// Errors no scope caught, and the loss of the device: kept here for the next
    /// [`Gpu::checked`] call to report, instead of wgpu's default panic.
    faults: Arc<DeviceFaults>,
}

/// What went wrong on a device outside the error scopes of [`Gpu::checked`].
#[derive(Debug, Default)]
struct DeviceFaults {
    lost: Mutex<Option<String>>,
    uncaptured: Mutex<Option<String>>,
}

/// Open out-of-memory and validation error scopes on a device (see [`Gpu::scope`]).
#[derive(Debug)]
pub struct ErrorScope {
    memory: wgpu::ErrorScopeGuard,
    validation: wgpu::ErrorScopeGuard,
    faults: Arc<DeviceFaults>,
}

impl ErrorScope {
    /// Closes the scopes: an error naming `what` if the work in them failed.
    ///
    /// # Errors
    /// The device ran out of memory, the work broke a rule of the device, or the device was
    /// lost meanwhile.
    pub fn finish(self, what: &str) -> Result<(), GpuError> {
        let invalid = pollster::block_on(self.validation.pop());
        let out_of_memory = pollster::block_on(self.memory.pop());
        if let Some(e) = out_of_memory {
            return Err(GpuError(format!(
                "{what}: the GPU is out of memory ({})",
                one_line(&e.to_string())
            )));
        }
        if let Some(e) = invalid {
            return Err(GpuError(format!("{what}: {}", one_line(&e.to_string()))));
        }
        self.faults.check()
    }
}

impl DeviceFaults {
    /// An error once the device was lost, or once an error escaped every scope (reported
    /// once).
    fn check(&self) -> Result<(), GpuError> {
        if let Some(reason) = self.lost.lock().ok().and_then(|l| l.clone()) {
            return Err(GpuError(format!("the GPU device was lost ({reason})")));
        }
        if let Some(e) = self.uncaptured.lock().ok().and_then(|mut u| u.take()) {
            return Err(GpuError(format!("GPU error: {e}")));
        }
        Ok(())
    }
}

/// `text` on one line.
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

impl fmt::Debug for Gpu {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Gpu")
            .field("adapter", &self.info.name)
            .field("faults", &self.faults)
            .field("backend", &self.info.backend)
            .field("unorm16", &self.unorm16)
            .finish_non_exhaustive()
    }
}

/// The WGSL of a file of `shaders/` with its includes resolved ([`shader::resolve`]). The
/// files are embedded and a test resolves each, so this cannot fail in a build that passed
/// its tests; if it did, the source holds the reason, and the device reports it as a shader
/// error on first use instead of a panic.
pub fn shader_source(name: &str) -> String {
    shader::resolve(name).unwrap_or_else(|e| format!("// {e}\nerror"))
}

/// Compiled render pipelines by key, behind a lock so that the renderer that owns them stays
/// immutable: a draw only reads them, a frame's draw data compiles what it is missing.
pub struct PipelineCache<K> {
    pipelines: Mutex<HashMap<K, wgpu::RenderPipeline>>,
}

impl<K> Default for PipelineCache<K> {
    fn default() -> Self {
        Self {
            pipelines: Mutex::new(HashMap::new()),
        }
    }
}

impl<K: std::hash::Hash + Eq> PipelineCache<K> {
    /// How many pipelines are compiled.
    pub fn len(&self) -> usize {
        self.lock().len()
    }

    /// Whether none is compiled yet.
    pub fn is_empty(&self) -> bool {
        self.lock().is_empty()
    }

    /// The pipeline for `key`, made by `compile` on first use.
    pub fn get_or_compile(
        &self,
        key: K,
        compile: impl FnOnce() -> wgpu::RenderPipeline,
    ) -> wgpu::RenderPipeline {
        self.lock().entry(key).or_insert_with(compile).clone()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<K, wgpu::RenderPipeline>> {
        self.pipelines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// A render pass over `target` (and `depth`, where given), both cleared.
pub fn cleared_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    depth: Option<&wgpu::TextureView>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A layout entry for a 2D float texture read by the fragment stage at `binding`.
pub fn texture_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A shader module of a file of `shaders/`, its includes resolved.
pub fn shader_module(device: &wgpu::Device, name: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(shader_source(name).into()),
    })
}

impl Gpu {
    /// Wraps a device (opened here or by eframe): its uncaptured errors and its loss are
    /// recorded for [`Gpu::checked`] to report, never a panic.
    pub fn on_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let unorm16 = device
            .features()
            .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM);
        let faults = Arc::new(DeviceFaults::default());
        let seen = Arc::clone(&faults);
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut slot) = seen.uncaptured.lock() {
                slot.get_or_insert_with(|| one_line(&e.to_string()));
            }
        }));
        let seen = Arc::clone(&faults);
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut slot) = seen.lost.lock() {
                slot.get_or_insert_with(|| one_line(&format!("{reason:?}: {message}")));
            }
        });
        Self {
            device,
            queue,
            info,
            unorm16,
            faults,
        }
    }

    /// `Ok` while the device works: an error once it was lost, or once an error escaped
    /// every scope (reported once).
    ///
    /// # Errors
    /// The device was lost, or an uncaptured error happened.
    pub fn healthy(&self) -> Result<(), GpuError> {
        self.faults.check()
    }

    /// Runs `work` (allocations, uploads, a frame, a read-back) inside out-of-memory and
    /// validation error scopes: what fails in it is an error naming `what`, never a panic.
    ///
    /// # Errors
    /// The device is lost or out of memory, or `work` broke a rule of the device (a texture
    /// or buffer beyond its limits).
    pub fn checked<T>(&self, what: &str, work: impl FnOnce() -> T) -> Result<T, GpuError> {
        let scope = self.scope()?;
        let value = work();
        scope.finish(what)?;
        Ok(value)
    }

    /// Opens the error scopes of [`Gpu::checked`] for work that needs the `Gpu`'s owner
    /// mutably; [`ErrorScope::finish`] closes them.
    ///
    /// # Errors
    /// The device is already lost or broken.
    pub fn scope(&self) -> Result<ErrorScope, GpuError> {
        self.healthy()?;
        let memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        Ok(ErrorScope {
            memory,
            validation,
            faults: Arc::clone(&self.faults),
        })
    }

    /// `Ok` when a 2D texture of `size` texels fits the device's limits.
    ///
    /// # Errors
    /// A side of zero or beyond the device's largest texture.
    pub fn check_texture_size(
        &self,
        what: &str,
        (width, height): (u32, u32),
    ) -> Result<(), GpuError> {
        let max = self.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GpuError(format!(
                "{what} of {width}x{height} texels does not fit this GPU (its largest texture is {max}x{max})"
            )));
        }
        Ok(())
    }

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
        Self::from_adapter(&Self::adapter()?)
    }

    /// A device on `adapter`, with the features and limits the preview uses when offered.
    ///
    /// # Errors
    /// When the device cannot be created.
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        Self::from_adapter_with_limits(adapter, adapter.limits())
    }

    /// A device on `adapter` with `limits` (at most the adapter's): a smaller GPU, for
    /// tests of what does not fit.
    ///
    /// # Errors
    /// When the device cannot be created.
    pub fn from_adapter_with_limits(
        adapter: &wgpu::Adapter,
        limits: wgpu::Limits,
    ) -> Result<Self, GpuError> {
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
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| GpuError(format!("cannot open the GPU device: {e}")))?;
        Ok(Self::on_device(device, queue, adapter.get_info()))
    }

    /// The first adapter wgpu finds without a display.
    ///
    /// # Errors
    /// When there is none.
    pub fn adapter() -> Result<wgpu::Adapter, GpuError> {
        let request = |desc: wgpu::InstanceDescriptor| {
            let instance = wgpu::Instance::new(desc);
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: None,
                apply_limit_buckets: false,
            }))
        };
        // Without a display, the primary backends first: the GL backend probes for a Wayland
        // display, and libwayland prints an error of its own to stderr where XDG_RUNTIME_DIR
        // is not valid (a headless command's output is its own). GL only where they find none.
        let chosen = std::env::var_os("WGPU_BACKEND").is_some();
        let mut primary = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if !chosen {
            primary.backends &= wgpu::Backends::PRIMARY;
        }
        request(primary)
            .or_else(|e| {
                if chosen {
                    return Err(e);
                }
                request(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
            })
            .map_err(|e| {
                GpuError(format!(
                    "no GPU adapter found ({e}); install a Vulkan driver (e.g. Mesa's lavapipe, package mesa-vulkan-drivers)"
                ))
            })
    }

    /// Blocks until the queue's work is done.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}
