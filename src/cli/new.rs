//! `kapaint new`: a project of one material everywhere.

use std::path::PathBuf;

use super::args::parse_size;
use super::{CliError, mesh_error, model_error};
use crate::model::{self, Document, DocumentSettings, project};

/// Create a project of one material everywhere.
#[derive(Debug, clap::Args)]
pub struct NewArgs {
    /// Map size, `W` or `WxH` (each 1 to 8192).
    #[arg(long)]
    size: String,
    /// Material preset (file stem or name), e.g. `brass`.
    #[arg(long, default_value = "default")]
    preset: String,
    /// Project file to write.
    #[arg(long)]
    out: PathBuf,
    /// Mesh the material is painted on: sphere, plane, cube, torus or a mesh file.
    #[arg(long, default_value = "sphere")]
    mesh: String,
    /// Give the mesh a new UV atlas for the map size and keep the unwrapped mesh inside the
    /// project (for a mesh without UVs, or whose UVs overlap).
    #[arg(long)]
    unwrap: bool,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
}

impl NewArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A bad size, preset or mesh, an existing file without `--force`, or a failed write.
    pub fn run(self) -> Result<String, CliError> {
        let (w, h) = parse_size(&self.size)?;
        // A mesh file must exist and load now, not at the first stroke on it.
        crate::mesh::open(std::path::Path::new(&self.mesh)).map_err(mesh_error)?;
        if self.out.exists() && !self.force {
            return Err(CliError::usage(format!(
                "{} exists; pass --force to overwrite it",
                self.out.display()
            )));
        }
        let preset = model::preset::find(&self.preset).map_err(model_error)?;
        let settings = DocumentSettings {
            base: preset.value(),
            secondary: preset.value(),
            preset: Some(preset.name.clone()),
            mesh: model::document::MeshRef::from_spec(&self.mesh),
            ..DocumentSettings::default()
        };
        let doc = Document::new(w, h, settings).map_err(model_error)?;
        let (doc, unwrapped) = if self.unwrap {
            let (doc, line) = super::unwrap::keep_unwrapped(doc, &self.mesh)?;
            (doc, format!("{line}\n"))
        } else {
            (doc, String::new())
        };
        project::save(&doc, &self.out).map_err(model_error)?;
        Ok(format!(
            "{unwrapped}created {} ({w}x{h}, {})\n",
            self.out.display(),
            preset.name
        ))
    }
}
