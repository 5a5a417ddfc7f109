//! Small compute kernels on the GPU: the shader's `chi` (`shaders/chi_check.wgsl`), the
//! models' lobes and the per-view table's coordinates (`shaders/model_check.wgsl`) checked
//! against the Rust core, and any WGSL function over a list of values ([`run_kernel`]).

use kapaint_reflectance::wgsl::shader_id;
use kapaint_reflectance::{AmbientApprox, ShadingModel};

use super::{Gpu, GpuError, shader_source};

/// `chi(model, approx, n)` for every `n`, computed by the WGSL the preview uses.
///
/// # Errors
/// When the read-back fails.
pub fn chi_on_gpu(
    gpu: &Gpu,
    model: ShadingModel,
    approx: AmbientApprox,
    n: &[f32],
) -> Result<Vec<f32>, GpuError> {
    let constants = [
        ("MODEL", f64::from(shader_id(&ShadingModel::ALL, &model))),
        ("APPROX", f64::from(shader_id(&AmbientApprox::ALL, &approx))),
    ];
    let source = shader_source("chi_check.wgsl");
    run_kernel(gpu, &source, &constants, n, n.len())
}

/// One point at which a lobe is evaluated: unit normal, unit direction to the light, unit
/// direction to the eye, and the painted exponent (sanitized by the shader as by the preview).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobePoint {
    /// The unit normal.
    pub normal: [f32; 3],
    /// The unit direction to the light.
    pub l: [f32; 3],
    /// The unit direction to the eye.
    pub v: [f32; 3],
    /// The exponent.
    pub n: f32,
}

/// `specular_lobe(model, ...)` of `shaders/lobes.wgsl` (`[rho_1, rho_0]`) at every point.
///
/// # Errors
/// When the read-back fails.
pub fn lobes_on_gpu(
    gpu: &Gpu,
    model: ShadingModel,
    points: &[LobePoint],
) -> Result<Vec<[f32; 2]>, GpuError> {
    let input: Vec<f32> = points
        .iter()
        .flat_map(|p| p.normal.into_iter().chain(p.l).chain(p.v).chain([p.n]))
        .collect();
    let constants = [
        ("MODEL", f64::from(shader_id(&ShadingModel::ALL, &model))),
        ("CHECK", 0.0),
    ];
    let out = run_kernel(
        gpu,
        &shader_source("model_check.wgsl"),
        &constants,
        &input,
        2 * points.len(),
    )?;
    Ok(out.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
}

/// `view_table_coords(n, phi)` of `shaders/view_coords.wgsl` at every `(n, phi)`.
///
/// # Errors
/// When the read-back fails.
pub fn view_coords_on_gpu(gpu: &Gpu, points: &[[f32; 2]]) -> Result<Vec<[f32; 2]>, GpuError> {
    let input: Vec<f32> = points.iter().flatten().copied().collect();
    let out = run_kernel(
        gpu,
        &shader_source("model_check.wgsl"),
        &[("CHECK", 1.0)],
        &input,
        input.len(),
    )?;
    Ok(out.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
}

/// Runs the compute entry `cs_main` of `source` (binding 0: `array<f32>` input, binding 1:
/// `array<f32>` output of `out_len` values; workgroups of 64 over the input) and returns
/// the output.
///
/// # Errors
/// When the read-back fails.
pub fn run_kernel(
    gpu: &Gpu,
    source: &str,
    constants: &[(&str, f64)],
    input: &[f32],
    out_len: usize,
) -> Result<Vec<f32>, GpuError> {
    use wgpu::util::DeviceExt;
    if input.is_empty() || out_len == 0 {
        return Ok(Vec::new());
    }
    let device = &gpu.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("kernel"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("kernel"),
        layout: None,
        module: &module,
        entry_point: Some("cs_main"),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            zero_initialize_workgroup_memory: false,
        },
        cache: None,
    });
    let input_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("input"),
        contents: bytemuck::cast_slice(input),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (out_len * 4) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("output"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("kernel"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((input.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
    gpu.queue.submit([encoder.finish()]);
    let out = super::readback::read_buffer(gpu, &readback)?;
    Ok(bytemuck::pod_collect_to_vec(&out))
}
