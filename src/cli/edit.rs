//! `kapaint edit [FILE]`: the editor, on a project if one is named (no arguments at all
//! open it too).

use std::path::PathBuf;

/// Open the editor, on the project FILE if one is given (`kapaint` alone opens it too).
#[derive(Debug, clap::Args)]
pub struct EditArgs {
    /// Project file (.kapaint) to open.
    file: Option<PathBuf>,
}

impl EditArgs {
    /// Runs the editor until its window closes; returns the exit code. A worker's panic is a
    /// failed job; only the window's own thread ends the app.
    pub fn run(self) -> i32 {
        crate::crash::install(crate::crash::OnPanic::ExitOnMainThread);
        crate::ui::run(self.file)
    }
}
