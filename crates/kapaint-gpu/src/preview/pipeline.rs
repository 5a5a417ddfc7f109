//! Pipelines: one per combination of the shader's overridable constants a frame uses, keyed
//! by [`PipelineKey`] and compiled on first use into the renderer's cache.

use super::DEPTH_FORMAT;
use super::mesh::Vertex;
use crate::maps::UniformChannels;
use crate::shader::view_id;
use kapaint_core::render::{FrameSettings, ViewMode};
use kapaint_reflectance::wgsl::shader_id;
use kapaint_reflectance::{AmbientApprox, ShadingModel};

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
    /// Any specular at all (false when `k_s` is zero everywhere, but never for Cook-Torrance).
    pub has_specular: bool,
    /// The material has a normal map (the lighting reads it; `k_a` never does).
    pub normal_map: bool,
    /// Colour target format.
    pub format: wgpu::TextureFormat,
}

impl PipelineKey {
    /// The shader's overridable constants for this key, by name: the ids come from the same
    /// functions that generate `ids.wgsl`.
    pub fn constants(&self) -> [(&'static str, f64); 8] {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        [
            (
                "MODEL",
                f64::from(shader_id(&ShadingModel::ALL, &self.model)),
            ),
            (
                "APPROX",
                f64::from(shader_id(&AmbientApprox::ALL, &self.approx)),
            ),
            ("VIEW", f64::from(view_id(self.view))),
            ("KD_UNIFORM", b(self.kd_uniform)),
            ("KS_UNIFORM", b(self.ks_uniform)),
            ("N_UNIFORM", b(self.n_uniform)),
            ("HAS_SPECULAR", b(self.has_specular)),
            ("NORMAL_MAP", b(self.normal_map)),
        ]
    }

    /// The cheapest pipeline that draws `settings` on maps whose uniform channels are `u`.
    pub fn for_frame(
        settings: &FrameSettings,
        u: &UniformChannels,
        format: wgpu::TextureFormat,
    ) -> Self {
        Self {
            model: settings.model,
            approx: settings.approx.for_model(settings.model),
            view: settings.view.untraced(),
            kd_uniform: u.kd.is_some(),
            ks_uniform: u.ks.is_some(),
            n_uniform: u.n.is_some(),
            // Cook-Torrance's Fresnel term reflects even where k_s (its F0) is zero.
            has_specular: u.ks != Some([0.0; 3]) || settings.model.has_second_part(),
            normal_map: u.normal_map,
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

/// Compiles the preview pipeline for `key`.
pub(super) fn compile(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    key: PipelineKey,
) -> wgpu::RenderPipeline {
    let constants = key.constants();
    let options = wgpu::PipelineCompilationOptions {
        constants: &constants,
        zero_initialize_workgroup_memory: false,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
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
                    0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4
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
}
