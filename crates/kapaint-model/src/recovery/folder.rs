//! Recovery folders: where they live, one session folder per editor process, which of them can
//! be recovered, loading one back, and writing a generation's journal.
//!
//! ```text
//! .NAME.kapaint-recovery/          beside the project (untitled work: in the state folder)
//!     HOST-PID-START/              one editor process's copy: its own, never another's
//!         journal-STAMP.bin        a generation: the whole document, then what changed
//! ```

use std::fs::File;
use std::io::{BufReader, Read as _, Seek as _, SeekFrom};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use super::journal::{self, Known, Snapshot};
use super::record::{self, JOURNAL_MAGIC, Next};
use super::replay::{self, Replay};
use super::session::Owner;
use crate::ModelError;
use crate::document::{Document, DocumentId};
use crate::project;

/// Where the recovery copies of a project live: the folder `.NAME-recovery` beside it, or for
/// untitled work `untitled.kapaint-recovery` in kapaint's state folder. Each editor process
/// keeps its own copy in a folder of its own inside.
pub fn recovery_path(project: Option<&Path>) -> PathBuf {
    if let Some(p) = project {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        return dir.join(format!(".{name}-recovery"));
    }
    project::state_dir().join("untitled.kapaint-recovery")
}

/// This process's session folder inside the recovery folder `recovery`.
pub(super) fn session_dir(recovery: &Path) -> PathBuf {
    recovery.join(Owner::this_process().file_name())
}

/// Makes `dir` (and, for the state folder, its parents) a folder only its owner may enter, or
/// checks that it is one already: a link, or a folder another user made, is refused (a
/// recovery folder in a shared project folder could be planted).
pub(super) fn private_dir(dir: &Path) -> std::io::Result<()> {
    if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty())
        && !parent.exists()
    {
        std::fs::create_dir_all(parent)?;
    }
    let mut builder = std::fs::DirBuilder::new();
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    match builder.create(dir) {
        Ok(()) => return Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(e),
    }
    let meta = std::fs::symlink_metadata(dir)?;
    let refuse = |why: &str| {
        Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            format!("{} {why}", dir.display()),
        ))
    };
    if !meta.is_dir() {
        return refuse("is not a folder (a link or a file is in the way)");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        if let Ok(me) = std::fs::metadata("/proc/self")
            && meta.uid() != me.uid()
        {
            return refuse("belongs to another user");
        }
    }
    Ok(())
}

/// A journal's file in a session folder.
pub(super) fn journal_file(dir: &Path, stamp: u64) -> PathBuf {
    dir.join(format!("journal-{stamp:020}.bin"))
}

/// The stamps of the generations in the session folder `dir`, newest first.
pub(super) fn generations(dir: &Path) -> Vec<u64> {
    let mut stamps: Vec<u64> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .filter_map(|e| {
            e.file_name()
                .to_str()?
                .strip_prefix("journal-")?
                .strip_suffix(".bin")?
                .parse()
                .ok()
        })
        .collect();
    stamps.sort_unstable_by(|a, b| b.cmp(a));
    stamps
}

/// What a look at a session folder finds: the identity and time of its newest generation that
/// holds a whole record.
struct Peek {
    id: DocumentId,
    modified: SystemTime,
}

/// A look at `session`'s newest journal with a whole first record, without reading it all.
fn peek(session: &Path) -> Option<Peek> {
    generations(session).into_iter().find_map(|stamp| {
        let path = journal_file(session, stamp);
        let mut file = File::open(&path).ok()?;
        let len = record::first_record_len(&mut file)?;
        file.seek(SeekFrom::Start(
            JOURNAL_MAGIC.len() as u64 + record::RECORD_HEAD,
        ))
        .ok()?;
        let id = replay::peek_id(&mut BufReader::new(&mut file).take(len), len).ok()?;
        Some(Peek {
            id,
            modified: file.metadata().ok()?.modified().ok()?,
        })
    })
}

/// The session folders in a recovery folder, with their owners.
fn sessions(recovery: &Path) -> Vec<(PathBuf, Owner)> {
    std::fs::read_dir(recovery)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
        .filter_map(|e| {
            let owner = Owner::from_file_name(e.file_name().to_str()?)?;
            Some((e.path(), owner))
        })
        .collect()
}

/// The recovery copy to offer when `project` opens (or untitled work, for `None`): the newest
/// copy an editor that has ended left behind, holding a whole record, written for this
/// project (its identity), and newer than the project file. Copies of running editors are
/// theirs and never offered; ended editors' copies that hold nothing to recover are removed.
pub fn offer(project: Option<&Path>) -> Option<PathBuf> {
    let recovery = recovery_path(project);
    let saved = project.and_then(|p| std::fs::metadata(p).ok()?.modified().ok());
    let id = project.and_then(project::read_id);
    remove_temporaries(&recovery);
    let mut best: Option<(SystemTime, PathBuf)> = None;
    for (dir, owner) in sessions(&recovery) {
        if owner.running() != Some(false) {
            continue;
        }
        let Some(found) = peek(&dir) else {
            // Killed before its first record was whole: nothing there to recover.
            remove(&dir);
            continue;
        };
        let ours = id.is_none_or(|id| id == found.id);
        let newer = saved.is_none_or(|saved| found.modified > saved);
        if ours && newer && best.as_ref().is_none_or(|(t, _)| found.modified > *t) {
            best = Some((found.modified, dir));
        }
    }
    best.map(|(_, dir)| dir)
}

/// Removes the temporary files in a recovery folder (earlier builds wrote its copies through
/// them, and a kill left them there, as large as the project): nothing writes one there now.
fn remove_temporaries(recovery: &Path) {
    for entry in std::fs::read_dir(recovery).into_iter().flatten().flatten() {
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && entry.file_name().to_string_lossy().ends_with(".tmp") {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Removes a recovery copy (a session folder, or a whole recovery folder) and, when that
/// leaves the recovery folder above it empty, that too.
pub fn remove(path: &Path) {
    let _ = std::fs::remove_dir_all(path);
    if let Some(parent) = path.parent()
        && parent
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.ends_with("-recovery"))
    {
        // Only when empty: another editor's copy may be in it.
        let _ = std::fs::remove_dir(parent);
    }
}

/// Loads the recovery copy in `session`: the newest generation with a whole record, every
/// whole record of its journal replayed in turn.
///
/// # Errors
/// No generation holds a whole record.
pub fn load(session: &Path) -> Result<Document, ModelError> {
    for stamp in generations(session) {
        if let Some(doc) = replay(&journal_file(session, stamp)) {
            return Ok(doc);
        }
    }
    Err(ModelError::Project {
        path: session.to_path_buf(),
        reason: "the recovery copy holds no whole record".into(),
    })
}

/// The document as of the last whole record of `journal`, if it holds one.
fn replay(journal: &Path) -> Option<Document> {
    let file = File::open(journal).ok()?;
    let size = file.metadata().ok()?.len();
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let mut magic = [0_u8; 8];
    reader.read_exact(&mut magic).ok()?;
    if &magic != JOURNAL_MAGIC {
        return None;
    }
    let mut state = Replay::default();
    let mut at = JOURNAL_MAGIC.len() as u64;
    while let Next::Record((decoded, next)) =
        record::read_next(&mut reader, at, size, replay::decode)
    {
        if state.apply(decoded).is_err() {
            break;
        }
        at = next;
    }
    state.into_document()
}

/// A generation being appended to.
pub(super) struct Generation {
    pub(super) stamp: u64,
    /// Bytes in the journal so far.
    pub(super) bytes: u64,
    /// Bytes of its first record (the whole document).
    pub(super) first_bytes: u64,
    pub(super) known: Known,
}

/// Writes `snap` into the session folder `dir`: one record appended to `generation`, or,
/// without one, a new generation whose first record is the whole document (the older ones
/// are removed once it is on disk).
pub(super) fn write(
    dir: &Path,
    generation: Option<Generation>,
    snap: &Snapshot,
) -> Result<Generation, ModelError> {
    let io = |path: &Path, e: std::io::Error| ModelError::io(path, e);
    if let Some(g) = generation {
        let path = journal_file(dir, g.stamp);
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(|e| io(&path, e))?;
        let mut known = None;
        let end = record::append(&mut file, g.bytes, |out| {
            known = Some(journal::write_record(out, snap, &g.known)?);
            Ok(())
        })
        .map_err(|e| io(&path, e))?;
        return Ok(Generation {
            bytes: end,
            known: known.unwrap_or_default(),
            ..g
        });
    }
    if let Some(recovery) = dir.parent() {
        private_dir(recovery).map_err(|e| io(recovery, e))?;
    }
    private_dir(dir).map_err(|e| io(dir, e))?;
    let old = generations(dir);
    let stamp = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
        .max(old.first().map_or(0, |s| s + 1));
    let path = journal_file(dir, stamp);
    // Made new: never through a link planted at its name.
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&path)
        .map_err(|e| io(&path, e))?;
    let guard = kapaint_base::atomic::TempPath::new(path.clone());
    std::io::Write::write_all(&mut file, JOURNAL_MAGIC).map_err(|e| io(&path, e))?;
    let at = JOURNAL_MAGIC.len() as u64;
    let mut known = None;
    let end = record::append(&mut file, at, |out| {
        known = Some(journal::write_record(out, snap, &Known::default())?);
        Ok(())
    })
    .map_err(|e| io(&path, e))?;
    guard.keep();
    for stamp in old {
        let _ = std::fs::remove_file(journal_file(dir, stamp));
    }
    Ok(Generation {
        stamp,
        bytes: end,
        first_bytes: end - at,
        known: known.unwrap_or_default(),
    })
}
