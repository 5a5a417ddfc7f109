//! The preview renderer, split the way re_renderer splits its renderers:
//! - [`Preview`] is immutable once made: the shader (`shaders/preview.wgsl` and what it
//!   includes), the bind group layout, the sampler and a cache of pipelines, one per
//!   combination of overridable constants a frame uses ([`PipelineKey`]: model,
//!   approximation, view, which maps are uniform, whether there is any specular);
//! - [`PreviewDrawData`] is one frame's data: its uniforms, its bind group, its parts (a
//!   pipeline, a scissor and a viewport each) and the mesh to draw; the uniform buffers and
//!   bind groups are the caller's [`FrameBindings`], reused from frame to frame;
//! - [`Preview::draw`] records a frame's data into a render pass and changes nothing.
//!
//! It draws into any colour target, and headless into an offscreen image that is read back
//! ([`Preview::render_offscreen`]).

pub(crate) mod bindings;
mod draw_data;
mod layout;
mod mesh;
mod offscreen;
mod pipeline;

pub use draw_data::{FrameBindings, FrameUniforms, PreviewDrawData};
pub use layout::{DrawPart, Layout, Scissor};
pub use mesh::MeshBuffers;
pub use offscreen::{COMPARED_MODELS, Offscreen, RenderedImage};
pub use pipeline::PipelineKey;

use super::{Gpu, PipelineCache};

/// Depth buffer format of every preview pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The preview renderer (see the module's doc).
pub struct Preview {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    bind_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    view_table: wgpu::TextureView,
    pipelines: PipelineCache<PipelineKey>,
}

impl std::fmt::Debug for Preview {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Preview")
            .field("pipelines", &self.pipelines.len())
            .finish_non_exhaustive()
    }
}

impl Preview {
    /// Compiles the preview shader and makes the layouts every pipeline shares.
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let module = super::shader_module(device, "preview.wgsl");
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview"),
            entries: &bindings::layout_entries(std::mem::size_of::<FrameUniforms>() as u64),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("maps"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Self {
            module,
            layout,
            bind_layout,
            sampler,
            view_table: view_table(gpu),
            pipelines: PipelineCache::default(),
        }
    }

    /// Number of pipelines compiled so far.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.len()
    }

    /// The pipeline for `key`, compiled on first use.
    pub fn pipeline(&self, gpu: &Gpu, key: PipelineKey) -> wgpu::RenderPipeline {
        self.pipelines.get_or_compile(key, || {
            pipeline::compile(&gpu.device, &self.module, &self.layout, key)
        })
    }

    /// Records `data` into `pass`: each part with its pipeline, scissor and viewport. All
    /// parts share the frame's camera, lights and maps.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, data: &PreviewDrawData) {
        data.record(pass);
    }
}

/// The per-view table's spline coefficients as one `R32Float` texture, the four tables
/// stacked in rows (`shaders/ambient_view.wgsl` reads it): 270 KB, made once per renderer.
fn view_table(gpu: &Gpu) -> wgpu::TextureView {
    use kapaint_reflectance::view::{VIEW_COEFFICIENTS, view_coefficients};
    use wgpu::util::DeviceExt as _;
    let tables = view_coefficients();
    let texels: Vec<f32> = tables.iter().flatten().copied().collect();
    let side = VIEW_COEFFICIENTS as u32;
    let texture = gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("per-view table"),
            size: wgpu::Extent3d {
                width: side,
                height: side * tables.len() as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&texels),
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// A render pass over `target` and `depth`, both cleared: what a preview frame is drawn in.
pub fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    super::cleared_pass(encoder, "preview", target, Some(depth))
}
