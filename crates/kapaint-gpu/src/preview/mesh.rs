//! A mesh on the GPU: interleaved vertices and a triangle list.

use glam::Vec3;

use crate::{Gpu, GpuError};
use kapaint_mesh::Mesh;

/// Interleaved vertex: position, normal, UV, MikkTSpace tangent.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    tangent: [f32; 4],
}

/// A mesh on the GPU.
pub struct MeshBuffers {
    pub(super) vertices: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) index_count: u32,
    /// Object-space bounds, for framing.
    pub bounds: (Vec3, Vec3),
    /// Whether the vertices carry MikkTSpace tangents (else zero: no normal map is read).
    pub tangents: bool,
}

impl std::fmt::Debug for MeshBuffers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshBuffers")
            .field("triangles", &(self.index_count / 3))
            .finish_non_exhaustive()
    }
}

impl MeshBuffers {
    /// Uploads `mesh` (a mesh without UVs gets UV (0, 0): it previews, it cannot be painted),
    /// without tangents.
    ///
    /// # Errors
    /// Buffers beyond the device's limits, or a device out of memory or lost.
    pub fn new(gpu: &Gpu, mesh: &Mesh) -> Result<Self, GpuError> {
        Self::upload_checked(gpu, mesh, false)
    }

    /// [`Self::new`] with MikkTSpace tangents where the mesh has UVs, for a normal map (its
    /// vertices split where a seam needs two tangents; about 1 ms per 1,000 triangles).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_tangents(gpu: &Gpu, mesh: &Mesh) -> Result<Self, GpuError> {
        Self::upload_checked(gpu, mesh, true)
    }

    fn upload_checked(gpu: &Gpu, mesh: &Mesh, tangents: bool) -> Result<Self, GpuError> {
        let max = gpu.device.limits().max_buffer_size;
        let bytes = (mesh.positions.len() * std::mem::size_of::<Vertex>()) as u64;
        if bytes > max {
            return Err(GpuError(format!(
                "the mesh's {} vertices need {bytes} bytes, more than this GPU's largest buffer ({max})",
                mesh.positions.len()
            )));
        }
        gpu.checked("uploading the mesh", || Self::upload(gpu, mesh, tangents))
    }

    fn upload(gpu: &Gpu, mesh: &Mesh, tangents: bool) -> Self {
        use wgpu::util::DeviceExt;
        let with_tangents = tangents
            .then(|| kapaint_mesh::tangents::generate(mesh))
            .flatten();
        let (mesh, tangents) = match &with_tangents {
            Some(t) => (&t.mesh, Some(&t.tangents)),
            None => (mesh, None),
        };
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i].to_array(),
                normal: mesh.normals[i].to_array(),
                uv: mesh.uvs.as_ref().map_or([0.0; 2], |u| u[i].to_array()),
                tangent: tangents.map_or([0.0; 4], |t| t[i]),
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
            tangents: with_tangents.is_some(),
        }
    }
}
