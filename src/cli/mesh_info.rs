//! `kapaint mesh-info`: a mesh's vertices, triangles, UV islands and bounds.

use std::path::PathBuf;

use super::{CliError, mesh_error};

/// Print a mesh's vertices, triangles, UV islands, bounds, and whether normals and UVs were
/// present (FILE is an .obj, .gltf or .glb file, or sphere, plane, cube, torus).
#[derive(Debug, clap::Args)]
pub struct MeshInfoArgs {
    /// Mesh file or built-in name.
    file: PathBuf,
}

impl MeshInfoArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A mesh that does not load.
    pub fn run(self) -> Result<String, CliError> {
        let mesh = crate::mesh::open(&self.file).map_err(mesh_error)?;
        Ok(crate::mesh::info_text(&self.file, &mesh))
    }
}
