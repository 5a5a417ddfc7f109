//! The jobs that open, recover and save the project, and the project file the document
//! belongs to, with the recent files (what the editor does with their results is [`crate::carry`]'s).

use std::path::{Path, PathBuf};

use super::jobs::{load_project, open_done, save_done, with_fallback};
use super::layout::layout_path;
use crate::desk::JobStart;
use crate::results::{OpenedProject, Saved};
use kapaint_model::{Document, project, recovery};

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

impl Project {
    /// Remembers `path` at the top of the recent files.
    pub(super) fn remember(&mut self, path: &Path) {
        push_recent(&mut self.recent, path);
        save_recent(&self.recent);
    }
}

/// Saves `doc` to `path` on a worker (a snapshot of the maps, so painting goes on); a save
/// over the project's own file expects it as `expected` (as this editor last read or wrote
/// it).
pub(super) fn save_to(
    doc: &Document,
    path: PathBuf,
    expected: Option<project::OnDisk>,
) -> JobStart {
    let snapshot = doc.snapshot();
    let version = doc.version();
    JobStart::new(
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
        save_done,
    )
}

/// Opens `path` on a worker (`read_only`: another kapaint has it and the user chose so).
pub(super) fn open(path: PathBuf, read_only: bool) -> JobStart {
    JobStart::new(
        "Open",
        {
            let path = path.clone();
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
            }
        },
        open_done,
    )
    .opening(path)
}

/// Opens the recovery copy `from` as the project at `path` (unsaved). A copy that cannot be
/// recovered is removed (it would be offered at every start) and the project opens as saved,
/// with a notice saying why.
pub(super) fn recover(from: PathBuf, path: Option<PathBuf>) -> JobStart {
    let opens = path.clone().unwrap_or_else(|| from.clone());
    JobStart::new(
        "Recover",
        move |progress| {
            progress.start("open", 1);
            // Recovered work replaces the project as it is on disk now.
            let on_disk = path.as_deref().and_then(project::OnDisk::of);
            let recovered = recovery::load(&from)
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
        open_done,
    )
    .opening(opens)
}

/// How many recent files are kept.
pub const RECENT_MAX: usize = 10;

/// `list` with `path` moved to the front, without duplicates, at most [`RECENT_MAX`] long.
pub fn push_recent(list: &mut Vec<PathBuf>, path: &Path) {
    let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    list.retain(|p| *p != path);
    list.insert(0, path);
    list.truncate(RECENT_MAX);
}

pub(super) fn recent_path() -> Option<PathBuf> {
    layout_path().map(|p| p.with_file_name("recent.json"))
}

pub(super) fn load_recent() -> Vec<PathBuf> {
    recent_path()
        .and_then(|p| kapaint_base::file_check::read_limited(&p, 1 << 20).ok())
        .map(|text| parse_recent(&text))
        .unwrap_or_default()
}

/// The recent-files list from its JSON: at most [`RECENT_MAX`] entries, each a path of at
/// most 4096 bytes without control characters (anything else is dropped, a list that does
/// not parse is empty).
pub fn parse_recent(json: &[u8]) -> Vec<PathBuf> {
    let Ok(list) = serde_json::from_slice::<Vec<String>>(json) else {
        return Vec::new();
    };
    list.into_iter()
        .filter(|p| {
            !p.is_empty()
                && kapaint_model::check::bounded_text(
                    "path",
                    p,
                    kapaint_model::check::MAX_PATH_BYTES,
                )
                .is_ok()
        })
        .take(RECENT_MAX)
        .map(PathBuf::from)
        .collect()
}

pub(super) fn save_recent(list: &[PathBuf]) {
    if let (Some(path), Ok(json)) = (recent_path(), serde_json::to_vec_pretty(list)) {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let _ = kapaint_base::atomic::write_atomic(&path, &json);
    }
}
