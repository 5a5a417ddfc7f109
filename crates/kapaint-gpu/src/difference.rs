//! The difference compare on the GPU: two linear renders of the same frame (Phong and
//! Blinn-Phong, or any two sides) combined by `shaders/difference.wgsl` into a heatmap of
//! `|left - right|`, for the editor's viewport. `kapaint render --model compare-diff` makes the
//! same picture on the CPU from read-backs ([`kapaint_core::render::heat_ramp`] is the one ramp).

use super::{Gpu, GpuError, PipelineCache, RenderedImage};

/// The format of the two renders the pass reads (linear floats, so small differences survive).
pub const SIDE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The pass's uniforms, laid out as `Heat` in `shaders/difference.wgsl` (a test checks the
/// sizes and offsets against naga's layouter).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HeatUniforms {
    /// `1 / max` (0 when `max` is 0 or not finite): the difference shown white.
    pub inv_max: f32,
    /// Padding to 16 bytes.
    pub pad0: f32,
    /// Padding to 16 bytes.
    pub pad1: f32,
    /// Padding to 16 bytes.
    pub pad2: f32,
}

/// The heatmap pass: immutable once made, with one pipeline per target format, cached.
pub struct Difference {
    module: wgpu::ShaderModule,
    bind_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipelines: PipelineCache<wgpu::TextureFormat>,
}

impl std::fmt::Debug for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Difference")
            .field("pipelines", &self.pipelines.len())
            .finish_non_exhaustive()
    }
}

/// The heatmap's uniform buffer and bind group, kept by the caller from frame to frame: the
/// group is made again only when the two sides' views change.
#[derive(Debug, Default)]
pub struct DifferenceBindings {
    slot: Option<(wgpu::Buffer, [wgpu::TextureView; 2], wgpu::BindGroup)>,
    made: u64,
}

impl DifferenceBindings {
    /// How many GPU objects (buffers, bind groups) the bindings have made.
    pub fn made(&self) -> u64 {
        self.made
    }
}

/// One heatmap's draw data: its bind group (the two sides and the uniforms) and pipeline.
#[derive(Debug)]
pub struct DifferenceDrawData {
    bind_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
}

impl Difference {
    /// Compiles the pass.
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let module = super::shader_module(device, "difference.wgsl");
        let texture = |binding| super::texture_entry(binding, false);
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
        Self {
            module,
            bind_layout,
            layout,
            pipelines: PipelineCache::default(),
        }
    }

    /// The pipeline for a target of `format`, compiled on first use.
    fn pipeline(&self, gpu: &Gpu, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.get_or_compile(format, || {
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

    /// The draw data of the heatmap of `|left - right|` (two linear renders of one size) into
    /// a target of `format`: white at `max` and above, black at 0. The uniforms go into the
    /// buffer of `bindings`, whose bind group is reused while the sides are the same views.
    pub fn draw_data(
        &self,
        gpu: &Gpu,
        [left, right]: [&wgpu::TextureView; 2],
        format: wgpu::TextureFormat,
        max: f32,
        bindings: &mut DifferenceBindings,
    ) -> DifferenceDrawData {
        let inv_max = if max.is_finite() && max > 0.0 {
            1.0 / max
        } else {
            0.0
        };
        let sides = [left.clone(), right.clone()];
        let (buffer, sides, bind_group) = match bindings.slot.take() {
            Some(slot) if slot.1 == sides => slot,
            old => {
                let buffer = old.map_or_else(
                    || {
                        bindings.made += 1;
                        gpu.device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some("difference"),
                            size: std::mem::size_of::<HeatUniforms>() as u64,
                            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                            mapped_at_creation: false,
                        })
                    },
                    |(buffer, ..)| buffer,
                );
                bindings.made += 1;
                let group = self.bind_group(gpu, left, right, &buffer);
                (buffer, sides, group)
            }
        };
        gpu.queue.write_buffer(
            &buffer,
            0,
            bytemuck::bytes_of(&HeatUniforms {
                inv_max,
                ..HeatUniforms::default()
            }),
        );
        let data = DifferenceDrawData {
            bind_group: bind_group.clone(),
            pipeline: self.pipeline(gpu, format),
        };
        bindings.slot = Some((buffer, sides, bind_group));
        data
    }

    /// The bind group of the two sides and the uniforms.
    fn bind_group(
        &self,
        gpu: &Gpu,
        left: &wgpu::TextureView,
        right: &wgpu::TextureView,
        uniforms: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
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
                    resource: uniforms.as_entire_binding(),
                },
            ],
        })
    }

    /// Records `data` into `pass` (one triangle over the target).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, data: &DifferenceDrawData) {
        pass.set_pipeline(&data.pipeline);
        pass.set_bind_group(0, &data.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// A render pass over `target`, cleared: what the heatmap is drawn in.
    pub fn begin_pass<'e>(
        encoder: &'e mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
    ) -> wgpu::RenderPass<'e> {
        super::cleared_pass(encoder, "difference", target, None)
    }

    /// The heatmap of two linear images read back from the GPU (tests and diagnostics):
    /// uploads them, runs the pass into an sRGB target and reads it back.
    ///
    /// # Errors
    /// When the images are not linear, differ in size, or the read-back fails.
    pub fn heatmap(
        &self,
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
        let mut bindings = DifferenceBindings::default();
        let data = self.draw_data(gpu, [&a, &b], format, max, &mut bindings);
        {
            let target = out.create_view(&wgpu::TextureViewDescriptor::default());
            let mut pass = Self::begin_pass(&mut encoder, &target);
            self.draw(&mut pass, &data);
        }
        let pixels = super::readback::read_texture(gpu, encoder, &out, 4, 0)?;
        Ok(RenderedImage::Srgb8 {
            width,
            height,
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_uniforms_match_the_shader_struct() {
        let (size, offsets) = crate::shader::struct_layout("difference.wgsl", "Heat");
        assert_eq!(size as usize, std::mem::size_of::<HeatUniforms>());
        let rust = [
            ("inv_max", std::mem::offset_of!(HeatUniforms, inv_max)),
            ("pad0", std::mem::offset_of!(HeatUniforms, pad0)),
            ("pad1", std::mem::offset_of!(HeatUniforms, pad1)),
            ("pad2", std::mem::offset_of!(HeatUniforms, pad2)),
        ]
        .map(|(n, o)| (n.to_string(), o as u32));
        assert_eq!(offsets, rust);
    }
}
