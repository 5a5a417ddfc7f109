//! AO and thickness rays of a bake from a high mesh on a GPU (`shaders/bake_rays.wgsl`): the
//! high mesh's BVH, the very one the CPU casts through, uploaded once; each batch of queries
//! a dispatch, one invocation a query. The CPU ([`kapaint_mesh::bakes::CpuCaster`]) stays the
//! reference and CI's path: a test holds the two to the rays' Monte Carlo noise on lavapipe.

use wgpu::util::DeviceExt;

use super::{Gpu, GpuError};
use kapaint_mesh::bakes::{RayBatch, RayCaster, RayKind, RayMesh, RayQuery};

/// Queries a workgroup casts.
const WORKGROUP: u32 = 64;

/// Where the rays of a bake run: a hardware GPU when there is one, else the CPU, unless told.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RaysOn {
    /// A hardware adapter if this machine has one (a software one such as lavapipe is slower
    /// than the CPU's own BVH), else the CPU.
    Auto,
    /// The CPU.
    Cpu,
    /// Any adapter, software ones included.
    Gpu,
}

impl RaysOn {
    /// The device this choice opens, if any: `None` for the CPU.
    ///
    /// # Errors
    /// `Gpu` with no adapter at all, or a device that does not open.
    pub fn open(self) -> Result<Option<Gpu>, GpuError> {
        let adapter = match self {
            Self::Cpu => return Ok(None),
            Self::Gpu => Gpu::adapter()?,
            Self::Auto => match Gpu::adapter() {
                Ok(a) if a.get_info().device_type != wgpu::DeviceType::Cpu => a,
                _ => return Ok(None),
            },
        };
        Gpu::from_adapter(&adapter).map(Some)
    }
}

/// The high mesh's BVH on a GPU, and the pipeline that casts through it.
pub struct GpuCaster<'g> {
    gpu: &'g Gpu,
    pipeline: wgpu::ComputePipeline,
    nodes: wgpu::Buffer,
    triangles: wgpu::Buffer,
}

impl<'g> GpuCaster<'g> {
    /// Uploads `rays`' BVH and builds the pipeline.
    ///
    /// # Errors
    /// A BVH larger than the device binds, or what the device said.
    pub fn new(gpu: &'g Gpu, rays: &RayMesh) -> Result<Self, GpuError> {
        let (nodes, triangles) = rays.gpu_layout();
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        for (what, bytes) in [("BVH", nodes.len() * 4), ("triangles", triangles.len() * 4)] {
            if bytes as u64 > limit {
                return Err(GpuError(format!(
                    "the high mesh's {what} ({bytes} bytes) is more than this GPU binds ({limit} bytes)"
                )));
            }
        }
        gpu.checked("upload the high mesh's BVH", || {
            let device = &gpu.device;
            let buffer = |label: &str, contents: &[u8]| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    // A binding is never empty.
                    contents: if contents.is_empty() {
                        &[0; 4]
                    } else {
                        contents
                    },
                    usage: wgpu::BufferUsages::STORAGE,
                })
            };
            let module = super::shader_module(device, "bake_rays.wgsl");
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("bake rays"),
                layout: None,
                module: &module,
                entry_point: Some("cs_main"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            });
            Self {
                gpu,
                pipeline,
                nodes: buffer("bvh nodes", bytemuck::cast_slice(&nodes)),
                triangles: buffer("bvh triangles", bytemuck::cast_slice(&triangles)),
            }
        })
    }

    /// One dispatch of `batch`'s queries (at most a row of 65,535 workgroups times as many
    /// rows).
    fn dispatch(&self, batch: &RayBatch<'_>) -> Result<Vec<f32>, GpuError> {
        let count = batch.queries.len() as u32;
        let groups = count.div_ceil(WORKGROUP);
        let x = groups.min(65_535);
        let y = groups.div_ceil(x);
        let (params, directions, queries) = packed(batch, x * WORKGROUP);
        let gpu = self.gpu;
        let bytes = u64::from(count) * 4;
        let readback = gpu.checked("cast the bake's rays", || {
            let device = &gpu.device;
            let init = |label: &str, contents: &[u8], usage| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
            };
            let storage = wgpu::BufferUsages::STORAGE;
            let uniform = init(
                "params",
                bytemuck::cast_slice(&params),
                wgpu::BufferUsages::UNIFORM,
            );
            let dirs = init("directions", bytemuck::cast_slice(&directions), storage);
            let query = init("queries", bytemuck::cast_slice(&queries), storage);
            let results = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("results"),
                size: bytes,
                usage: storage | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("results readback"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            let entries: Vec<wgpu::BindGroupEntry<'_>> = [
                &uniform,
                &self.nodes,
                &self.triangles,
                &dirs,
                &query,
                &results,
            ]
            .into_iter()
            .enumerate()
            .map(|(k, b)| wgpu::BindGroupEntry {
                binding: k as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("bake rays"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
            encoder.copy_buffer_to_buffer(&results, 0, &readback, 0, bytes);
            gpu.queue.submit([encoder.finish()]);
            readback
        })?;
        let out = super::readback::read_buffer(gpu, &readback)?;
        Ok(bytemuck::pod_collect_to_vec(&out))
    }
}

/// What a dispatch of `batch` uploads: its parameters (`row` queries a row of workgroups), the
/// directions and the queries, four `vec4`s each.
fn packed(batch: &RayBatch<'_>, row: u32) -> ([u32; 8], Vec<f32>, Vec<f32>) {
    let far = if batch.far.is_finite() {
        batch.far
    } else {
        f32::MAX
    };
    let params: [u32; 8] = [
        batch.queries.len() as u32,
        batch.directions.len() as u32,
        u32::from(batch.kind == RayKind::Depth),
        far.to_bits(),
        row,
        0,
        0,
        0,
    ];
    let directions = batch
        .directions
        .iter()
        .flat_map(|d| [d.x, d.y, d.z, 0.0])
        .collect();
    let queries = batch
        .queries
        .iter()
        .flat_map(|q| {
            let [ox, oy, oz] = q.origin.to_array();
            [
                [ox, oy, oz, f32::from_bits(q.group)],
                q.t.extend(0.0).to_array(),
                q.b.extend(0.0).to_array(),
                q.n.extend(0.0).to_array(),
            ]
        })
        .flatten()
        .collect();
    (params, directions, queries)
}

impl RayCaster for GpuCaster<'_> {
    fn cast(&self, batch: &RayBatch<'_>) -> Result<Vec<f32>, String> {
        if let Some(q) = batch
            .queries
            .iter()
            .find(|q| q.group != 0 && q.group != RayQuery::NONE)
        {
            return Err(format!(
                "a query for BVH {} of several: the GPU casts through one (parts matched by name bake on the CPU)",
                q.group
            ));
        }
        if batch.queries.is_empty() || batch.directions.is_empty() {
            return Ok(vec![1.0; batch.queries.len()]);
        }
        self.dispatch(batch).map_err(|e| e.to_string())
    }

    fn batch_size(&self) -> usize {
        1 << 18
    }

    fn name(&self) -> String {
        format!(
            "the GPU {} ({:?})",
            self.gpu.info.name, self.gpu.info.backend
        )
    }
}
