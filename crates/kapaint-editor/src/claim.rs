//! The editor's hold on its project file: the file as it was read or last saved (a save over a
//! file another process saved since goes beside it instead), its lock (another editor opening
//! the project is warned first), and opening read-only.

use std::path::{Path, PathBuf};

use crate::desk::{Ask, Desk};
use kapaint_model::project::lock::{self, OnDisk, ProjectLock};
use kapaint_model::recovery::session::Owner;

/// What the editor holds of its project file.
#[derive(Debug, Default)]
pub(super) struct Claim {
    /// The file as this editor read or last saved it: what its next save expects to replace.
    pub(super) on_disk: Option<OnDisk>,
    /// This editor's lock on the project (none read-only, or where it cannot be written).
    lock: Option<ProjectLock>,
    /// Opened read-only: Save asks for another file.
    pub(super) read_only: bool,
    /// A project another kapaint has open, and who: the user is asked how to open it.
    asking: Option<(PathBuf, Owner)>,
    /// The user's answer for a project about to open: read-only or not.
    answered: Option<(PathBuf, bool)>,
}

impl Claim {
    /// Holds `path` (none: untitled) as read or saved as `on_disk`, locking it unless
    /// `read_only`.
    pub(super) fn hold(&mut self, path: Option<&Path>, on_disk: Option<OnDisk>, read_only: bool) {
        // The old lock goes first: a project saved over itself keeps one lock.
        self.lock = None;
        self.on_disk = on_disk;
        self.read_only = read_only && path.is_some();
        if let Some(p) = path.filter(|_| !self.read_only) {
            // A folder that takes no lock file still opens: the lock only warns.
            self.lock = ProjectLock::take(p).ok();
        }
    }

    /// Lets the project go (quitting).
    pub(super) fn release(&mut self) {
        self.lock = None;
    }

    /// Whether `path` may open now: `Some(read_only)` when no other kapaint has it open or the
    /// user answered; `None` when the user is being asked first.
    pub(super) fn may_open(&mut self, path: &Path) -> Option<bool> {
        if let Some((answered, read_only)) = self.answered.take()
            && answered == path
        {
            return Some(read_only);
        }
        match lock::holder(path) {
            Some(owner) => {
                self.asking = Some((path.to_path_buf(), owner));
                None
            }
            None => Some(false),
        }
    }

    /// Asks how to open a project another kapaint has open: read-only, anyway, or not at all.
    pub(super) fn prompt(&mut self, ctx: &egui::Context, desk: &mut Desk) {
        let Some((path, owner)) = self.asking.clone() else {
            return;
        };
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let (mut read_only, mut anyway, mut cancel) = (false, false, false);
        // Modal: until it is answered the document is what was open before (or a placeholder),
        // and a stroke on it would be lost when the project opens.
        egui::Modal::new(egui::Id::new("kapaint-open-in-use")).show(ctx, |ui| {
            ui.heading("Open: in use");
            ui.label(format!(
                "{name} is open in another kapaint (process {} on {}). Two editors saving \
                 one project would each keep only their own work: open it read-only (Save \
                 then asks for another file), or open it anyway (a save that finds the \
                 other's work on disk goes beside it instead of over it).",
                owner.pid, owner.host
            ));
            ui.horizontal(|ui| {
                read_only = ui.button("Open read-only").clicked();
                anyway = ui.button("Open anyway").clicked();
                cancel = ui.button("Cancel").clicked();
            });
        });
        if read_only || anyway {
            self.asking = None;
            self.answered = Some((path.clone(), read_only));
            desk.ask(Ask::OpenNow(path));
        } else if cancel {
            self.asking = None;
        }
    }
}
