//! `kapaint import-set`: a project rebuilt from an exported set.

use std::path::PathBuf;

use super::{CliError, model_error, set_error};
use crate::model::project;

/// Rebuild a project from an exported set.
#[derive(Debug, clap::Args)]
pub struct ImportSetArgs {
    /// The set's material.json.
    manifest: PathBuf,
    /// Project file to write.
    #[arg(long)]
    out: PathBuf,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
}

impl ImportSetArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A set that does not read back, an existing file without `--force`, a failed write.
    pub fn run(self) -> Result<String, CliError> {
        if self.out.exists() && !self.force {
            return Err(CliError::usage(format!(
                "{} exists; pass --force to overwrite it",
                self.out.display()
            )));
        }
        let doc = crate::export::set::import(&self.manifest).map_err(set_error)?;
        project::save(&doc, &self.out).map_err(model_error)?;
        Ok(format!(
            "imported {} into {} ({}x{})\n",
            self.manifest.display(),
            self.out.display(),
            doc.maps().width(),
            doc.maps().height()
        ))
    }
}
