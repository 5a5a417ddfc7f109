//! `kapaint import`: an image (PNG, JPEG, TGA, EXR) into one channel of a project.

use std::path::PathBuf;

use super::{CliError, model_error};
use crate::model::{Channel, project};

/// Import an image (PNG, JPEG, TGA, EXR) into one channel of a project.
#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// Project file (rewritten atomically unless --out is given).
    file: PathBuf,
    /// Channel to replace.
    #[arg(long, value_parser = ["kd", "ks", "n"])]
    channel: String,
    /// Image file.
    #[arg(long)]
    image: PathBuf,
    /// Write the result here instead of over FILE.
    #[arg(long)]
    out: Option<PathBuf>,
}

impl ImportArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project or image that does not load, or a failed write.
    pub fn run(self) -> Result<String, CliError> {
        let channel = Channel::from_name(&self.channel)
            .ok_or_else(|| CliError::usage(format!("unknown channel {:?}", self.channel)))?;
        // The file as read: a save finds out if another run saved over it meanwhile.
        let on_disk = project::OnDisk::of(&self.file);
        let mut doc = super::open_project(&self.file)?;
        doc.import_file(channel, &self.image).map_err(model_error)?;
        let expected = if self.out.is_none() {
            on_disk.as_ref()
        } else {
            None
        };
        let target = self.out.unwrap_or(self.file);
        project::save_checked(&doc, &target, expected).map_err(model_error)?;
        Ok(format!(
            "imported {} into {} of {}\n",
            self.image.display(),
            channel.name(),
            target.display()
        ))
    }
}
