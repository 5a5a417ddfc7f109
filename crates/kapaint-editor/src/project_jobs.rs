//! The jobs that open, recover and save the project, and what the editor does with their
//! results: the recovery copy and the claim on the file follow the work.

use std::path::PathBuf;

use super::files::FilePurpose;
use super::jobs::{OpenedProject, Saved, load_project, with_fallback};
use super::{EditorState, notice};
use kapaint_model::{project, recovery};

/// The project file the document belongs to: where it is saved, what was saved, the claim on
/// the file, the recovery copy, and the projects opened lately.
pub(super) struct Project {
    /// Where it is saved.
    pub(super) path: Option<PathBuf>,
    /// The project named at start, while the recovery offer decides how it opens.
    pub(super) starting: Option<PathBuf>,
    /// The document version last saved.
    pub(super) saved_version: u64,
    /// Recently opened or saved projects, newest first.
    pub(super) recent: Vec<PathBuf>,
    pub(super) autosaver: recovery::Autosaver,
    /// The project file as read or saved, its lock, and whether it opened read-only.
    pub(super) claim: super::claim::Claim,
}

impl EditorState {
    /// A save finished: the document version it holds, and the file as written.
    pub(super) fn saved(&mut self, path: PathBuf, version: u64, on_disk: project::OnDisk) {
        self.project.saved_version = version;
        self.project.claim.hold(Some(&path), Some(on_disk), false);
        self.notices
            .push(notice(format!("saved {}", path.display()), false));
        self.remember(&path);
        if self.project.path.as_deref() != Some(path.as_path()) {
            // Save As (or the first save): the recovery copy follows the work.
            self.project.autosaver.relocate(Some(&path));
        }
        // What was saved needs no recovery copy (unless it changed while saving).
        self.project.autosaver.saved(&self.doc, version);
        self.project.path = Some(path);
        if std::mem::take(&mut self.prompts.quit.after_save) && !self.dirty() {
            // The quit prompt's Save: the work is safe, so the window closes.
            self.prompts.quit.allowed = Some(super::QuitAllowed::Saved);
            self.prompts.quit.asked = true;
        }
        if !self.dirty()
            && let Some(next) = self.prompts.pending_open.take()
        {
            self.open_now(next);
        }
        if !self.dirty()
            && let Some(dialog) = self.dialogs.pending_new.take()
        {
            self.create_project(&dialog);
        }
    }

    /// A save found its project changed on disk: the work went to `written` instead.
    pub(super) fn conflicted(&mut self, message: String, written: PathBuf, version: u64) {
        // The work is safe beside the project: the editor goes on with that file.
        self.project.saved_version = version;
        self.notices.push(notice(message, true));
        self.remember(&written);
        self.project.autosaver.relocate(Some(&written));
        self.project.autosaver.saved(&self.doc, version);
        self.project
            .claim
            .hold(Some(&written), project::OnDisk::of(&written), false);
        self.project.path = Some(written);
        self.prompts.quit.after_save = false;
        self.dialogs.pending_new = None;
    }

    /// Makes `doc` the document, with its mesh shown and framed.
    /// Takes an opened (or recovered) project as the document.
    pub(super) fn opened(&mut self, opened: OpenedProject) {
        let OpenedProject {
            path,
            doc,
            recovered,
            on_disk,
            read_only,
            ..
        } = opened;
        self.project.claim.hold(path.as_deref(), on_disk, read_only);
        self.replace_document(doc);
        // The old document was saved or its changes discarded (asked before).
        self.project.autosaver.discard();
        let interval = self.preferences.autosave_interval();
        // Recovered work is unsaved work, and its copy stays until this editor has its own.
        (self.project.saved_version, self.project.autosaver) = match recovered.clone() {
            Some(from) => (
                u64::MAX,
                recovery::Autosaver::recovering(interval, path.as_deref(), &self.doc, from),
            ),
            None => (
                self.doc.version(),
                recovery::Autosaver::new(interval, path.as_deref(), &self.doc),
            ),
        };
        let recovered = recovered.is_some();
        let name = path
            .as_deref()
            .map_or_else(|| "an untitled project".into(), |p| p.display().to_string());
        let text = if recovered {
            format!("recovered the unsaved work of {name}: save to keep it")
        } else if read_only {
            format!("opened {name} read-only: Save asks for another file")
        } else {
            format!("opened {name}")
        };
        self.notices.push(notice(text, false));
        if let Some(p) = &path {
            self.remember(p);
        }
        self.project.path = path;
    }

    /// Saves to `path` on a worker (a snapshot of the maps, so painting goes on).
    pub fn save_to(&mut self, path: PathBuf) {
        let snapshot = self.doc.snapshot();
        let version = self.doc.version();
        // Over its own file, a save expects the file as this editor last read or wrote it;
        // elsewhere (Save As) the user chose to replace what is there.
        let expected = (self.project.path.as_deref() == Some(path.as_path()))
            .then(|| self.project.claim.on_disk.clone())
            .flatten();
        self.start_job(
            "Save",
            move |progress| {
                progress.start("save", 1);
                match project::save_checked(&snapshot, &path, expected.as_ref()) {
                    Ok(on_disk) => Ok(Saved::Saved(path, version, on_disk)),
                    Err(e @ kapaint_model::ModelError::Conflict { .. }) => {
                        let kapaint_model::ModelError::Conflict { written, .. } = &e else {
                            unreachable!("matched above")
                        };
                        Ok(Saved::Conflicted {
                            written: written.clone(),
                            message: e.to_string(),
                            version,
                        })
                    }
                    Err(e) => Err(format!("could not save: {e}")),
                }
            },
            Self::save_done,
        );
    }

    /// Opens `path` on a worker.
    pub fn open(&mut self, path: PathBuf) {
        if self.dirty() {
            // Unsaved work is never dropped: ask first (see `open_prompt`).
            self.prompts.pending_open = Some(path);
            return;
        }
        self.open_now(path);
    }

    /// Opens `path` on a worker, once the user has answered if another kapaint has it open.
    pub(super) fn open_now(&mut self, path: PathBuf) {
        let Some(read_only) = self.may_open(&path) else {
            return;
        };
        self.start_job_opening(
            "Open",
            path.clone(),
            move |progress| {
                progress.start("open", 1);
                let on_disk = project::OnDisk::of(&path);
                match load_project(&path) {
                    Ok((doc, note)) => Ok(Box::new(OpenedProject {
                        path: Some(path),
                        doc,
                        recovered: None,
                        note,
                        on_disk,
                        read_only,
                    })),
                    Err(e) => Err(format!("could not open {}: {e}", path.display())),
                }
            },
            Self::open_done,
        );
    }

    /// Opens the recovery copy `from` as the project at `path` (unsaved). A copy that cannot
    /// be recovered is removed (it would be offered at every start) and the project opens as
    /// saved, with a notice saying why.
    pub(super) fn recover(&mut self, from: PathBuf, path: Option<PathBuf>) {
        let opens = path.clone().unwrap_or_else(|| from.clone());
        self.start_job_opening(
            "Recover",
            opens,
            move |progress| {
                progress.start("open", 1);
                // Recovered work replaces the project as it is on disk now.
                let on_disk = path.as_deref().and_then(project::OnDisk::of);
                let recovered =
                    recovery::load(&from)
                        .map_err(|e| e.to_string())
                        .and_then(|mut doc| {
                            let failed = project::attach_own_mesh(&mut doc).err();
                            with_fallback(doc, failed)
                        });
                let e = match recovered {
                    Ok((doc, note)) => {
                        return Ok(Box::new(OpenedProject {
                            path,
                            doc,
                            recovered: Some(from),
                            note,
                            on_disk,
                            read_only: false,
                        }));
                    }
                    Err(e) => e,
                };
                recovery::remove(&from);
                let why = format!("could not recover {}: {e}", from.display());
                match path.as_deref().filter(|p| p.exists()).map(load_project) {
                    Some(Ok((doc, _))) => Ok(Box::new(OpenedProject {
                        path,
                        doc,
                        recovered: None,
                        note: Some(format!("{why}; opened the saved project")),
                        on_disk,
                        read_only: false,
                    })),
                    Some(Err(open)) => Err(format!("{why}; {open}")),
                    None => Err(why),
                }
            },
            Self::open_done,
        );
    }

    pub(super) fn save(&mut self) {
        match self.project.path.clone() {
            Some(p) if !self.project.claim.read_only => self.save_to(p),
            _ => self.save_as(),
        }
    }

    pub(super) fn save_as(&mut self) {
        self.choose_file(FilePurpose::SaveProject);
    }

    pub(super) fn open_dialog(&mut self) {
        self.choose_file(FilePurpose::OpenProject);
    }
}
