//! The difference compare on the GPU: two linear renders of the same frame (Phong and
//! Blinn-Phong, or any two sides) combined by `shaders/difference.wgsl` into a heatmap of
//! `|left - right|`, for the editor's viewport. `kapaint render --model compare-diff` makes the
//! same picture on the CPU from read-backs ([`crate::render::heat_ramp`] is the one ramp).

use std::collections::HashMap;

use super::{Gpu, GpuError, RenderedImage};

/// The format of the two renders the pass reads (linear floats, so small differences survive).
pub const SIDE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HeatUniforms {
    inv_max: f32,
    pad: [f32; 3],
}

/// The heatmap pass: one pipeline per target format, cached.
pub struct Difference {
    module: wgpu::ShaderModule,
    bind_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    uniforms: wgpu::Buffer,
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

impl std::fmt::Debug for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Difference")
            .field("pipelines", &self.pipelines.len())
            .finish_non_exhaustive()
    }
}

impl Difference {
    /// Compiles the pass.
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("difference.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/difference.wgsl").into()),
        });
        let texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("difference"),
            entries: &[
                texture(0),
                texture(1),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("difference"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("difference"),
            size: std::mem::size_of::<HeatUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            module,
            bind_layout,
            layout,
            uniforms,
            pipelines: HashMap::new(),
        }
    }

    fn pipeline(&mut self, gpu: &Gpu, format: wgpu::TextureFormat) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.entry(format).or_insert_with(|| {
            gpu.device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("difference"),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some("vs_main"),
                        compilation_options: wgpu::PipelineCompilationOptions::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: None,
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some("fs_main"),
                        compilation_options: wgpu::PipelineCompilationOptions::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        })
    }

    /// Records the heatmap of `|left - right|` into `target` (of `format`, the size of the
    /// two sides): white at `max` and above, black at 0.
    #[expect(clippy::too_many_arguments, reason = "one pass's inputs")]
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        left: &wgpu::TextureView,
        right: &wgpu::TextureView,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        max: f32,
    ) {
        let inv_max = if max.is_finite() && max > 0.0 {
            1.0 / max
        } else {
            0.0
        };
        gpu.queue.write_buffer(
            &self.uniforms,
            0,
            bytemuck::bytes_of(&HeatUniforms {
                inv_max,
                pad: [0.0; 3],
            }),
        );
        self.pipeline(gpu, format);
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("difference"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(left),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(right),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.uniforms.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("difference"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipelines[&format]);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }

    /// The heatmap of two linear images read back from the GPU (tests and diagnostics):
    /// uploads them, runs the pass into an sRGB target and reads it back.
    ///
    /// # Errors
    /// When the images are not linear, differ in size, or the read-back fails.
    pub fn heatmap(
        &mut self,
        gpu: &Gpu,
        left: &RenderedImage,
        right: &RenderedImage,
        max: f32,
    ) -> Result<RenderedImage, GpuError> {
        let (
            RenderedImage::Linear {
                width,
                height,
                pixels: a,
            },
            RenderedImage::Linear {
                width: w2,
                height: h2,
                pixels: b,
            },
        ) = (left, right)
        else {
            return Err(GpuError("the difference needs two linear images".into()));
        };
        if (width, height) != (w2, h2) {
            return Err(GpuError("the two sides differ in size".into()));
        }
        let (width, height) = (*width, *height);
        let extent = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |format, usage| gpu.texture_2d("difference", (width, height), format, usage);
        let side = |pixels: &[f32]| {
            let t = texture(
                SIDE_FORMAT,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            );
            gpu.queue.write_texture(
                t.as_image_copy(),
                bytemuck::cast_slice(pixels),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(width * 16),
                    rows_per_image: Some(height),
                },
                extent,
            );
            t.create_view(&wgpu::TextureViewDescriptor::default())
        };
        let (a, b) = (side(a), side(b));
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let out = texture(
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        self.draw(
            gpu,
            &mut encoder,
            &a,
            &b,
            &out.create_view(&wgpu::TextureViewDescriptor::default()),
            format,
            max,
        );
        let pixels = super::preview::read_texture(gpu, encoder, &out, 4, 0)?;
        Ok(RenderedImage::Srgb8 {
            width,
            height,
            pixels,
        })
    }
}
