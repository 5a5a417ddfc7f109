//! `kapaint unwrap`: a mesh with a new UV atlas, written as OBJ or GLB; and the unwrap that
//! `new --unwrap` and `import-pbr --unwrap` keep in the project.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use super::{CliError, mesh_error};
use crate::atomic::write_atomic;
use crate::mesh::unwrap::{UnwrapOptions, Unwrapped, unwrap};
use crate::model::{Document, MeshRef};

/// Give a mesh a new UV atlas (charts packed for a SIZE^2 map, padded, no overlap) and write
/// it as .obj or .glb. The mesh's own UVs, if any, are replaced.
#[derive(Debug, clap::Args)]
pub struct UnwrapArgs {
    /// Mesh file (.obj, .gltf, .glb) or built-in name.
    mesh: PathBuf,
    /// The unwrapped mesh to write: .obj or .glb.
    #[arg(long)]
    out: PathBuf,
    /// The map size the charts are packed and padded for (64 to 16384).
    #[arg(long, default_value_t = 2048)]
    size: u32,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
}

impl UnwrapArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A mesh that does not load or cannot be unwrapped, a bad size or output, an existing
    /// file without `--force`, a failed write. Nothing is written then.
    pub fn run(self) -> Result<String, CliError> {
        let ext = self
            .out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("obj" | "glb")) {
            return Err(CliError::usage(format!(
                "{}: --out must end in .obj or .glb",
                self.out.display()
            )));
        }
        if self.out.exists() && !self.force {
            return Err(CliError::usage(format!(
                "{} exists; pass --force to overwrite it",
                self.out.display()
            )));
        }
        let mesh = crate::mesh::open(&self.mesh).map_err(mesh_error)?;
        let start = Instant::now();
        let done = unwrap_for(&mesh, &self.mesh, self.size)?;
        let seconds = start.elapsed().as_secs_f64();
        let bytes = if ext.as_deref() == Some("glb") {
            crate::export::glb::write_mesh(&done.mesh).map_err(CliError::usage)?
        } else {
            crate::mesh::write_obj(&done.mesh).into_bytes()
        };
        write_atomic(&self.out, &bytes)
            .map_err(|e| CliError::of_io(format!("{}: {e}", self.out.display()), &e))?;
        Ok(format!(
            "{}\nwrote {}\n",
            summary(&self.mesh, &done, self.size, seconds),
            self.out.display()
        ))
    }
}

/// Unwraps `mesh` (read from `path`) for a `size`^2 map.
///
/// # Errors
/// A size outside 64 to 16384 or a mesh the unwrapper cannot chart: exit 2.
pub(super) fn unwrap_for(
    mesh: &crate::mesh::Mesh,
    path: &Path,
    size: u32,
) -> Result<Unwrapped, CliError> {
    if !(64..=16384).contains(&size) {
        return Err(CliError::usage(format!(
            "--size {size} is outside 64 to 16384"
        )));
    }
    let progress = crate::task::Progress::default();
    super::progress::with_bar("unwrap", &progress, || {
        unwrap(mesh, UnwrapOptions::for_size(size), Some(&progress))
    })
    .map_err(|e| CliError::usage(format!("{}: {e}", path.display())))
}

/// One line on what the unwrap made.
pub(super) fn summary(path: &Path, done: &Unwrapped, size: u32, seconds: f64) -> String {
    format!(
        "unwrapped {}: {} triangles, {} charts, {:.1} % of a {size}x{size} map covered, {:.3} s",
        path.display(),
        done.mesh.triangles.len(),
        done.charts,
        100.0 * done.coverage,
        seconds
    )
}

/// Unwraps the mesh `spec` for the document's map and makes it the mesh the project keeps.
/// Returns the document and the line to print.
///
/// # Errors
/// A mesh that does not load or cannot be unwrapped.
pub(super) fn keep_unwrapped(doc: Document, spec: &str) -> Result<(Document, String), CliError> {
    let path = Path::new(spec);
    let mesh = crate::mesh::open(path).map_err(mesh_error)?;
    let (w, h) = (doc.maps().width(), doc.maps().height());
    let size = w.min(h).max(64);
    let start = Instant::now();
    let done = unwrap_for(&mesh, path, size)?;
    let line = summary(path, &done, size, start.elapsed().as_secs_f64());
    let mut mesh = done.mesh;
    mesh.name = format!("{}, unwrapped", mesh.name);
    let mut settings = doc.settings().clone();
    settings.mesh = MeshRef::Embedded(mesh.name.clone());
    let doc = doc
        .with_settings(settings)
        .with_embedded_mesh(Some(Arc::new(mesh)));
    Ok((doc, line))
}
