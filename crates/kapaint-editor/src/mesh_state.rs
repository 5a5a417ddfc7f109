//! The mesh being painted, as the editor holds it for picking, drawing and the canvas
//! wireframe: rebuilt only when the document's mesh changes.

use std::sync::Arc;

use glam::Vec2;
use kapaint_mesh::Mesh;
use kapaint_mesh::pick::Bvh;

/// The mesh being painted, with what picking and the renderer need.
pub(crate) struct MeshState {
    pub(crate) id: u64,
    /// The document's bake this was made from: when the document's differs (undo of a mesh
    /// import, a resize), the state follows it.
    pub(crate) from: std::sync::Weak<kapaint_model::surface::Surface>,
    pub(crate) mesh: Arc<Mesh>,
    pub(crate) bvh: Bvh,
    /// UV edges in map fractions (u, 1 - v), for the canvas wireframe.
    pub(crate) uv_lines: crate::uv_wire::UvLines,
}

impl MeshState {
    pub(crate) fn new(mesh: Mesh, id: u64) -> Self {
        let bvh = Bvh::build(&mesh);
        let mut uv_lines = Vec::new();
        if let Some(uvs) = &mesh.uvs {
            for tri in &mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                    if a < b || mesh.triangles.len() < 4 {
                        let at = |i: usize| Vec2::new(uvs[i].x, 1.0 - uvs[i].y);
                        uv_lines.push([at(a), at(b)]);
                    }
                }
            }
        }
        Self {
            id,
            from: std::sync::Weak::new(),
            mesh: Arc::new(mesh),
            bvh,
            uv_lines: uv_lines.into(),
        }
    }
}
