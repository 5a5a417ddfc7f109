//! `kapaint paint`: a paint script (a RON list of commands) replayed on a project.

use std::path::{Path, PathBuf};

use super::{CliError, model_error};
use crate::model::{self, ModelError, project};

/// Largest paint script read (bytes).
const MAX_SCRIPT_BYTES: u64 = 256 << 20;

/// Replay a paint script (RON list of commands) on a project and save it.
#[derive(Debug, clap::Args)]
pub struct PaintArgs {
    /// Project file (rewritten atomically unless --out is given).
    file: PathBuf,
    /// Script of commands (see docs/cli.md).
    #[arg(long)]
    script: PathBuf,
    /// Mesh for strokes on the surface and island/part fills (default: the project's).
    #[arg(long)]
    mesh: Option<String>,
    /// Write the result here instead of over FILE.
    #[arg(long)]
    out: Option<PathBuf>,
}

impl PaintArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project, script or mesh that does not load, a command that cannot apply, or a
    /// failed write; the project is untouched then.
    pub fn run(self) -> Result<String, CliError> {
        let mut commands = read_script(&self.script)?;
        // The images commands paint through, named from the script's folder.
        let folder = self.script.parent().unwrap_or(Path::new("."));
        for (i, command) in commands.iter_mut().enumerate() {
            for image in command.images_mut() {
                image.load(folder).map_err(|e| {
                    CliError::usage(format!("{}: command {}: {e}", self.script.display(), i + 1))
                })?;
            }
        }
        // The file as read: a save finds out if another run saved over it meanwhile.
        let on_disk = project::OnDisk::of(&self.file);
        let mut doc = super::open_project(&self.file)?;
        // The layers are composited on the mesh they are painted on whenever they need it: a
        // stroke on the surface, a fill of an island, or a generator mask (one already in
        // the project, or laid by the script).
        let lays_generator = |c: &model::Command| {
            matches!(
                c,
                model::Command::Mask(
                    model::MaskCommand::SetMaskGenerator(Some(_))
                        | model::MaskCommand::PreviewMaskGenerator(_)
                )
            )
        };
        let needs_mesh = commands
            .iter()
            .any(|c| c.needs_surface() || lays_generator(c));
        if self.mesh.is_some() || (needs_mesh && doc.surface().is_none()) {
            match &self.mesh {
                Some(spec) => project::attach_mesh(&mut doc, Path::new(spec)),
                None => project::attach_own_mesh(&mut doc),
            }
            .map_err(model_error)?;
        }
        let count = commands.len();
        for (i, command) in commands.into_iter().enumerate() {
            doc.apply(command).map_err(|e| {
                CliError::usage(format!("{}: command {}: {e}", self.script.display(), i + 1))
            })?;
        }
        doc.apply(model::StrokeCommand::EndStroke)
            .map_err(model_error)?;
        let expected = if self.out.is_none() {
            on_disk.as_ref()
        } else {
            None
        };
        let target = self.out.unwrap_or(self.file);
        project::save_checked(&doc, &target, expected).map_err(model_error)?;
        Ok(format!(
            "applied {count} commands, saved {}\n",
            target.display()
        ))
    }
}

/// A paint script: `(commands: [ ... ])` in RON.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaintScript {
    /// Commands applied in order.
    pub commands: Vec<model::Command>,
}

fn read_script(path: &Path) -> Result<Vec<model::Command>, CliError> {
    let bytes = crate::file_check::read_limited(path, MAX_SCRIPT_BYTES).map_err(|e| {
        if e.is_io() {
            CliError::io(format!("{}: {e}", path.display()))
        } else {
            CliError::usage(format!("{}: {e}", path.display()))
        }
    })?;
    let script_error = |reason: String| {
        model_error(ModelError::Script {
            path: path.to_path_buf(),
            reason,
        })
    };
    let text = String::from_utf8(bytes).map_err(|_| script_error("not UTF-8 text".into()))?;
    let script: PaintScript = ron::from_str(&text).map_err(|e| script_error(e.to_string()))?;
    Ok(script.commands)
}
