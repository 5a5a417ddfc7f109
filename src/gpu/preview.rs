//! The preview renderer: one shader (`shaders/preview.wgsl`), one pipeline per combination of
//! overridable constants actually used (model, approximation, view, which maps are uniform,
//! whether there is any specular), cached; draws into any colour target, and headless into
//! an offscreen image that is read back.

use std::collections::HashMap;

use glam::Vec3;

use super::maps::{MapTextures, UniformChannels};
use super::{Gpu, GpuError, shader_source};
use crate::mesh::Mesh;
use crate::reflectance::{AmbientApprox, ShadingModel};
use crate::render::{Compare, FrameSettings, ViewMode};

/// Depth buffer format.
/// Depth buffer format of every preview pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The preview's per-frame uniforms, laid out as `Frame` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light: [f32; 4],
    intensity: [f32; 4],
    kd: [f32; 4],
    ks: [f32; 4],
    n: [f32; 4],
}

/// Interleaved vertex: position, normal, UV.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
}

/// A mesh on the GPU.
pub struct MeshBuffers {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    /// Object-space bounds, for framing.
    pub bounds: (Vec3, Vec3),
}

impl std::fmt::Debug for MeshBuffers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshBuffers")
            .field("triangles", &(self.index_count / 3))
            .finish_non_exhaustive()
    }
}

impl MeshBuffers {
    /// Uploads `mesh` (a mesh without UVs gets UV (0, 0): it previews, it cannot be painted).
    ///
    /// # Errors
    /// Buffers beyond the device's limits, or a device out of memory or lost.
    pub fn new(gpu: &Gpu, mesh: &Mesh) -> Result<Self, GpuError> {
        let max = gpu.device.limits().max_buffer_size;
        let bytes = (mesh.positions.len() * std::mem::size_of::<Vertex>()) as u64;
        if bytes > max {
            return Err(GpuError(format!(
                "the mesh's {} vertices need {bytes} bytes, more than this GPU's largest buffer ({max})",
                mesh.positions.len()
            )));
        }
        gpu.checked("uploading the mesh", || Self::upload(gpu, mesh))
    }

    fn upload(gpu: &Gpu, mesh: &Mesh) -> Self {
        use wgpu::util::DeviceExt;
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i].to_array(),
                normal: mesh.normals[i].to_array(),
                uv: mesh.uvs.as_ref().map_or([0.0; 2], |u| u[i].to_array()),
            })
            .collect();
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        Self {
            vertices: gpu
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh vertices"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
            indices: gpu
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh indices"),
                    contents: bytemuck::cast_slice(&indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
            index_count: indices.len() as u32,
            bounds: mesh.bounds(),
        }
    }
}

/// A pixel rectangle `(x, y, width, height)` of the target.
pub type Scissor = (u32, u32, u32, u32);

/// One draw of a frame: a pipeline, the pixels it may shade (scissor) and the rectangle its
/// picture fills (viewport).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawPart {
    /// The pipeline.
    pub key: PipelineKey,
    /// Pixels outside it are not shaded.
    pub scissor: Scissor,
    /// Where the camera's picture goes.
    pub viewport: Scissor,
}

impl DrawPart {
    /// One pipeline over the whole `(width, height)` target.
    pub fn whole(key: PipelineKey, (w, h): (u32, u32)) -> Self {
        Self {
            key,
            scissor: (0, 0, w, h),
            viewport: (0, 0, w, h),
        }
    }
}

/// How one frame shows the two shading models it compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One picture, one model (the left key's).
    Single,
    /// One picture wiped at column `at`: the left key left of it, the right key right of it;
    /// the hidden part of each is never shaded.
    Split(u32),
    /// Two whole pictures, one per half of the target, seen by the one camera.
    SideBySide,
}

impl Layout {
    /// How a `width`-pixel frame draws `compare`, the split's divider at `split_at` (a
    /// fraction of the width); `None` for the difference, which is no one picture.
    pub fn of(compare: Compare, split_at: f32, width: u32) -> Option<Self> {
        match compare {
            Compare::Single => Some(Self::Single),
            Compare::Split => Some(Self::Split(
                ((split_at.clamp(0.0, 1.0) * width as f32) as u32).min(width),
            )),
            Compare::SideBySide => Some(Self::SideBySide),
            Compare::Difference => None,
        }
    }

    /// The parts of a `(width, height)` frame: `left` and `right` are the two sides' pipelines.
    pub fn parts(self, left: PipelineKey, right: PipelineKey, (w, h): (u32, u32)) -> Vec<DrawPart> {
        let whole = (0, 0, w, h);
        match self {
            Self::Single => vec![DrawPart::whole(left, (w, h))],
            Self::Split(at) => {
                let at = at.min(w);
                vec![
                    DrawPart {
                        key: left,
                        scissor: (0, 0, at, h),
                        viewport: whole,
                    },
                    DrawPart {
                        key: right,
                        scissor: (at, 0, w - at, h),
                        viewport: whole,
                    },
                ]
            }
            Self::SideBySide => {
                // Two halves of equal width, so both pictures have one aspect ratio.
                let half = w / 2;
                let (a, b) = ((0, 0, half, h), (w - half, 0, half, h));
                vec![
                    DrawPart {
                        key: left,
                        scissor: a,
                        viewport: a,
                    },
                    DrawPart {
                        key: right,
                        scissor: b,
                        viewport: b,
                    },
                ]
            }
        }
    }
}

/// What an offscreen render produces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Offscreen {
    /// Image size.
    pub size: (u32, u32),
    /// Linear floats even for shaded views (data views are always linear).
    pub linear: bool,
    /// Single, or Phong and Blinn-Phong compared (split or side by side); the settings'
    /// model is ignored when comparing.
    pub layout: Layout,
}

/// The overridable constants of one pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[expect(
    clippy::struct_excessive_bools,
    reason = "one bool per overridable constant of the shader"
)]
pub struct PipelineKey {
    /// Shading model.
    pub model: ShadingModel,
    /// Approximation of `chi`.
    pub approx: AmbientApprox,
    /// View.
    pub view: ViewMode,
    /// `k_d` from the uniform value instead of the texture.
    pub kd_uniform: bool,
    /// `k_s` from the uniform value.
    pub ks_uniform: bool,
    /// `n` from the uniform value.
    pub n_uniform: bool,
    /// Any specular at all (false when `k_s` is zero everywhere).
    pub has_specular: bool,
    /// Colour target format.
    pub format: wgpu::TextureFormat,
}

impl PipelineKey {
    /// The cheapest pipeline that draws `settings` on maps whose uniform channels are `u`.
    pub fn for_frame(
        settings: &FrameSettings,
        u: &UniformChannels,
        format: wgpu::TextureFormat,
    ) -> Self {
        Self {
            model: settings.model,
            approx: settings.approx,
            view: settings.view,
            kd_uniform: u.kd.is_some(),
            ks_uniform: u.ks.is_some(),
            n_uniform: u.n.is_some(),
            has_specular: u.ks != Some([0.0; 3]),
            format,
        }
    }

    /// The same pipeline without any of the skips (every fetch and all the lighting): the
    /// baseline the skip variants are measured against.
    #[must_use]
    pub fn full(mut self) -> Self {
        self.kd_uniform = false;
        self.ks_uniform = false;
        self.n_uniform = false;
        self.has_specular = true;
        self
    }
}

fn model_index(m: ShadingModel) -> f64 {
    match m {
        ShadingModel::Phong => 0.0,
        ShadingModel::BlinnPhong => 1.0,
    }
}

fn approx_index(a: AmbientApprox) -> f64 {
    match a {
        AmbientApprox::PaperPrinted => 0.0,
        AmbientApprox::PaperCorrected => 1.0,
        AmbientApprox::Fast => 2.0,
    }
}

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

/// The preview renderer.
pub struct Preview {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    bind_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    uniforms: wgpu::Buffer,
    pipelines: HashMap<PipelineKey, wgpu::RenderPipeline>,
}

impl std::fmt::Debug for Preview {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Preview")
            .field("pipelines", &self.pipelines.len())
            .finish_non_exhaustive()
    }
}

impl Preview {
    /// Compiles the preview shader.
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("preview.wgsl"),
            source: wgpu::ShaderSource::Wgsl(
                shader_source(include_str!("../../shaders/preview.wgsl")).into(),
            ),
        });
        let texture_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(1),
                texture_entry(2),
                texture_entry(3),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
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
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            module,
            layout,
            bind_layout,
            sampler,
            uniforms,
            pipelines: HashMap::new(),
        }
    }

    /// Number of pipelines compiled so far.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.len()
    }

    /// The pipeline for `key`, compiled on first use.
    pub fn pipeline(&mut self, gpu: &Gpu, key: PipelineKey) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.entry(key).or_insert_with(|| {
            let b = |v: bool| if v { 1.0 } else { 0.0 };
            let constants = [
                ("MODEL", model_index(key.model)),
                ("APPROX", approx_index(key.approx)),
                ("VIEW", f64::from(key.view.index())),
                ("KD_UNIFORM", b(key.kd_uniform)),
                ("KS_UNIFORM", b(key.ks_uniform)),
                ("N_UNIFORM", b(key.n_uniform)),
                ("HAS_SPECULAR", b(key.has_specular)),
            ];
            let options = wgpu::PipelineCompilationOptions {
                constants: &constants,
                zero_initialize_workgroup_memory: false,
            };
            gpu.device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("preview"),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some("vs_main"),
                        compilation_options: options.clone(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: std::mem::size_of::<Vertex>() as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &wgpu::vertex_attr_array![
                                0 => Float32x3, 1 => Float32x3, 2 => Float32x2
                            ],
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        cull_mode: Some(wgpu::Face::Back),
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: wgpu::StencilState::default(),
                        bias: wgpu::DepthBiasState::default(),
                    }),
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some("fs_main"),
                        compilation_options: options,
                        targets: &[Some(wgpu::ColorTargetState {
                            format: key.format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        })
    }

    /// Writes the frame uniforms for `settings` at `aspect`.
    fn write_uniforms(
        &self,
        gpu: &Gpu,
        settings: &FrameSettings,
        aspect: f32,
        u: &UniformChannels,
    ) {
        let l = settings.lighting;
        let pad = |v: [f32; 3]| [v[0], v[1], v[2], 0.0];
        let frame = FrameUniforms {
            view_proj: settings.camera.view_proj(aspect).to_cols_array_2d(),
            eye: settings.camera.eye().extend(1.0).to_array(),
            light: l.direction().extend(0.0).to_array(),
            intensity: [l.ia, l.il, 0.0, 0.0],
            kd: pad(u.kd.unwrap_or_default()),
            ks: pad(u.ks.unwrap_or_default()),
            n: [u.n.unwrap_or(0.0), 0.0, 0.0, 0.0],
        };
        gpu.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&frame));
    }

    fn bind_group(&self, gpu: &Gpu, maps: &MapTextures) -> wgpu::BindGroup {
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let (kd, ks, n) = (view(&maps.kd), view(&maps.ks), view(&maps.n));
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&kd),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&ks),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&n),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        })
    }

    /// Draws one or more parts of a frame into `target` (see [`Layout::parts`]): each part is a
    /// pipeline, a scissor rectangle and a viewport. All parts share camera and lights; the
    /// projection's aspect is the first part's viewport's.
    #[expect(clippy::too_many_arguments, reason = "one frame's inputs")]
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        size: (u32, u32),
        mesh: &MeshBuffers,
        maps: &MapTextures,
        settings: &FrameSettings,
        parts: &[DrawPart],
    ) {
        let (_, _, vw, vh) = parts.first().map_or((0, 0, size.0, size.1), |p| p.viewport);
        self.write_uniforms(gpu, settings, vw as f32 / vh.max(1) as f32, &maps.uniform);
        let bind = self.bind_group(gpu, maps);
        for part in parts {
            self.pipeline(gpu, part.key);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("preview"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &bind, &[]);
        pass.set_vertex_buffer(0, mesh.vertices.slice(..));
        pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        for part in parts {
            let (x, y, w, h) = part.scissor;
            let (vx, vy, vw, vh) = part.viewport;
            if w == 0 || h == 0 || vw == 0 || vh == 0 {
                continue;
            }
            pass.set_viewport(vx as f32, vy as f32, vw as f32, vh as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, w, h);
            pass.set_pipeline(&self.pipelines[&part.key]);
            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
        }
    }

    /// Renders a frame offscreen and reads it back: sRGB bytes for shaded views unless
    /// `linear`, linear floats otherwise. A compare layout draws Phong on the left (of the
    /// split, or in the left half) and Blinn-Phong on the right.
    ///
    /// # Errors
    /// When the size is zero or above the device's texture limit, or the read-back fails.
    pub fn render_offscreen(
        &mut self,
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
        &mut self,
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
            layout.parts(key, key, (width, height))
        } else {
            let side = |model| PipelineKey { model, ..key };
            layout.parts(
                side(ShadingModel::Phong),
                side(ShadingModel::BlinnPhong),
                (width, height),
            )
        };
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        self.draw(
            gpu,
            &mut encoder,
            &color.create_view(&wgpu::TextureViewDescriptor::default()),
            &depth.create_view(&wgpu::TextureViewDescriptor::default()),
            (width, height),
            mesh,
            maps,
            settings,
            &parts,
        );
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

/// Copies mip `level` of `texture` (`texel` bytes per texel) out after the work in
/// `encoder`, rows packed.
///
/// # Errors
/// When the read-back fails.
pub fn read_texture(
    gpu: &Gpu,
    mut encoder: wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    texel: u32,
    level: u32,
) -> Result<Vec<u8>, GpuError> {
    let extent = texture
        .size()
        .mip_level_size(level, wgpu::TextureDimension::D2);
    let (width, height) = (extent.width, extent.height);
    let row = (width * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        extent,
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &readback)?;
    let mut packed = Vec::with_capacity((width * height * texel) as usize);
    for y in 0..height as usize {
        let start = y * row as usize;
        packed.extend_from_slice(&bytes[start..start + (width * texel) as usize]);
    }
    Ok(packed)
}

/// Maps a buffer for reading, waits, and copies its bytes out.
///
/// # Errors
/// When mapping fails.
pub fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.wait();
    rx.recv()
        .map_err(|e| GpuError(format!("read-back lost: {e}")))?
        .map_err(|e| GpuError(format!("read-back failed: {e}")))?;
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| GpuError(format!("read-back failed: {e}")))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
