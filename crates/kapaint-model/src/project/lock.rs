//! Two kapaints on one project: saves that never overwrite another's, and a lock that says who
//! has the project open.
//!
//! A save knows which file it replaces ([`OnDisk`]: the file as it was read or last saved).
//! Before it renames its file into place it locks that file (`flock`, so two saves of the
//! same file take turns) and checks that the project on disk is still that one; if another
//! process saved meanwhile, this save goes beside it (`P.kapaint.conflict-TIME-PID.kapaint`)
//! instead, and says so. Every save writes a new file (temporary and rename), so a file that
//! changed is always another inode or another size or time.
//!
//! An editor that opens a project writes `.P.kapaint.lock` beside it (its host, PID and start
//! time; see [`crate::recovery::session::Owner`]); another editor opening the project
//! reads it and warns. A lock whose process has ended is stale and taken over.

use std::path::{Path, PathBuf};

use crate::ModelError;
use crate::document::Document;
use crate::recovery::session::Owner;

/// The project file as a process read or last wrote it: what a save expects to replace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OnDisk {
    len: u64,
    modified: Option<std::time::SystemTime>,
    /// Device and inode (0 where the system has none).
    file: (u64, u64),
}

impl OnDisk {
    /// The file at `path` now, if there is one.
    pub fn of(path: &Path) -> Option<Self> {
        Some(Self::from_meta(&std::fs::metadata(path).ok()?))
    }

    fn from_meta(meta: &std::fs::Metadata) -> Self {
        #[cfg(unix)]
        let file = {
            use std::os::unix::fs::MetadataExt as _;
            (meta.dev(), meta.ino())
        };
        #[cfg(not(unix))]
        let file = (0, 0);
        Self {
            len: meta.len(),
            modified: meta.modified().ok(),
            file,
        }
    }
}

/// Saves `doc` to `path`, which the caller read or last saved as `expected` (`None`: the
/// caller means to replace whatever is there, a Save As). Returns the file as saved.
///
/// # Errors
/// [`ModelError::Conflict`] when the project on disk is no longer `expected` (the result is
/// then written beside it, and the project left as the other process saved it); otherwise
/// as [`super::save`].
pub fn save_checked(
    doc: &Document,
    path: &Path,
    expected: Option<&OnDisk>,
) -> Result<OnDisk, ModelError> {
    let Some(expected) = expected else {
        super::save(doc, path)?;
        return OnDisk::of(path).ok_or_else(|| gone(path));
    };
    let target = kapaint_base::atomic::through_links(path);
    if !target.exists() {
        // Gone (moved or deleted meanwhile): nothing there to overwrite.
        super::save(doc, path)?;
        return OnDisk::of(path).ok_or_else(|| gone(path));
    }
    // Held until the new file is in place: a second save of the same file waits here, then
    // finds the file changed.
    let held = std::fs::File::open(&target).ok();
    if let Some(f) = &held {
        f.lock().map_err(|e| ModelError::io(path, e))?;
    }
    let now = held
        .as_ref()
        .and_then(|f| Some(OnDisk::from_meta(&f.metadata().ok()?)))
        .filter(|at_lock| OnDisk::of(&target).as_ref() == Some(at_lock));
    if now.as_ref() != Some(expected) {
        drop(held);
        let beside = conflict_path(path);
        super::save(doc, &beside)?;
        return Err(ModelError::Conflict {
            path: path.to_path_buf(),
            written: beside,
        });
    }
    super::save(doc, path)?;
    let saved = OnDisk::of(path).ok_or_else(|| gone(path));
    drop(held);
    saved
}

fn gone(path: &Path) -> ModelError {
    ModelError::io(
        path,
        std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "the file went away right after it was saved",
        ),
    )
}

/// Where a save that found its project changed goes: `P.kapaint.conflict-SECONDS-PID.kapaint`
/// beside it.
fn conflict_path(path: &Path) -> PathBuf {
    let seconds = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let name = path.file_name().map_or_else(
        || "project.kapaint".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    path.with_file_name(format!(
        "{name}.conflict-{seconds}-{}.kapaint",
        std::process::id()
    ))
}

/// The lock file of a project: `.NAME.lock` beside it.
fn lock_path(project: &Path) -> PathBuf {
    let name = project
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    project.with_file_name(format!(".{name}.lock"))
}

/// Another kapaint that has `project` open (its lock is there and its process runs, or runs
/// on another machine, where it cannot be told), if one does.
pub fn holder(project: &Path) -> Option<Owner> {
    let text = kapaint_base::file_check::read_limited(&lock_path(project), 4096).ok()?;
    let owner = Owner::from_file_name(String::from_utf8(text).ok()?.trim())?;
    (owner != *Owner::this_process() && owner.running() != Some(false)).then_some(owner)
}

/// This process's lock on a project: removed when dropped, if it still names this process.
#[derive(Debug)]
pub struct ProjectLock {
    path: PathBuf,
}

impl ProjectLock {
    /// Marks `project` as open in this process (taking over a stale lock, or another's when
    /// the user chose to open anyway).
    ///
    /// # Errors
    /// The lock file cannot be written (a read-only folder): the caller may go on without.
    pub fn take(project: &Path) -> std::io::Result<Self> {
        let path = lock_path(project);
        let line = format!("{}\n", Owner::this_process().file_name());
        kapaint_base::atomic::write_atomic(&path, line.as_bytes())?;
        Ok(Self { path })
    }
}

impl Drop for ProjectLock {
    fn drop(&mut self) {
        let ours = std::fs::read_to_string(&self.path).is_ok_and(|text| {
            Owner::from_file_name(text.trim()).as_ref() == Some(Owner::this_process())
        });
        if ours {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DocumentSettings, FillRegion};
    use crate::{PaintCommand, SettingsCommand};

    fn temp(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("kapaint-lock-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_save_over_a_file_another_process_saved_goes_beside_it() {
        let dir = temp("conflict");
        let p = dir.join("P.kapaint");
        let doc = Document::new(32, 32, DocumentSettings::default()).unwrap();
        let first = save_checked(&doc, &p, None).unwrap();
        // Two runs read the same file; the first saves; the second finds it changed.
        let mut a = crate::project::load(&p).unwrap();
        let mut b = crate::project::load(&p).unwrap();
        a.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
        b.apply(SettingsCommand::SwapMaterials).unwrap();
        b.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
        let saved = save_checked(&a, &p, Some(&first)).unwrap();
        assert_ne!(saved, first);
        let err = save_checked(&b, &p, Some(&first)).unwrap_err();
        let ModelError::Conflict { written, .. } = &err else {
            panic!("{err}");
        };
        assert!(
            written
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("P.kapaint.conflict-"),
            "{err}"
        );
        // A's edit is in the project, B's beside it: nothing lost.
        let on_disk = crate::project::load(&p).unwrap();
        assert_eq!(on_disk.maps().value(1, 1), a.maps().value(1, 1));
        let beside = crate::project::load(written).unwrap();
        assert_eq!(beside.maps().value(1, 1), b.maps().value(1, 1));
        // The file as A saved it is what A may save over next.
        save_checked(&a, &p, Some(&saved)).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_lock_names_its_process_and_a_stale_one_is_not_a_holder() {
        let dir = temp("lock");
        let p = dir.join("P.kapaint");
        assert_eq!(holder(&p), None);
        let lock = ProjectLock::take(&p).unwrap();
        assert_eq!(
            holder(&p),
            None,
            "this process's own lock holds nothing back"
        );
        drop(lock);
        assert!(!lock_path(&p).exists());
        let other = Owner {
            pid: 1,
            start: 0,
            ..Owner::this_process().clone()
        };
        std::fs::write(lock_path(&p), other.file_name()).unwrap();
        if std::path::Path::new("/proc/1").exists() {
            assert_eq!(holder(&p), Some(other), "PID 1 runs");
        }
        let gone = Owner {
            pid: 4_194_305,
            ..Owner::this_process().clone()
        };
        std::fs::write(lock_path(&p), gone.file_name()).unwrap();
        assert_eq!(holder(&p), None, "a stale lock holds nothing back");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
