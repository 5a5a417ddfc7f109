//! The recovery folder: where it lives, its generations, loading it back and writing to it.

use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use super::record::{JOURNAL_MAGIC, decode_record, encode_record, read_record};
use super::{Generation, Outcome};
use crate::model::ModelError;
use crate::model::document::{Document, DocumentSettings};
use crate::model::project;
use crate::model::tile::Tile;

/// Where the recovery copy of a project lives: the folder `.NAME-recovery` beside it, or for
/// an unsaved document `untitled.kapaint-recovery` in kapaint's state folder.
pub fn recovery_path(project: Option<&Path>) -> PathBuf {
    if let Some(p) = project {
        let dir = p.parent().unwrap_or(Path::new("."));
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        return dir.join(format!(".{name}-recovery"));
    }
    project::state_dir().join("untitled.kapaint-recovery")
}

/// When the recovery copy at `path` was last written (the newest file in it), if it exists.
pub fn modified(path: &Path) -> Option<SystemTime> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_dir() {
        return meta.modified().ok();
    }
    std::fs::read_dir(path)
        .ok()?
        .filter_map(Result::ok)
        .filter_map(|e| e.metadata().ok()?.modified().ok())
        .max()
}

/// Removes the recovery copy at `path` (after a clean exit or a save).
pub fn remove(path: &Path) {
    if path.is_dir() {
        let _ = std::fs::remove_dir_all(path);
    } else {
        let _ = std::fs::remove_file(path);
    }
}

/// One generation's files in `dir`.
fn base_file(dir: &Path, stamp: u64) -> PathBuf {
    dir.join(format!("base-{stamp:020}.kapaint"))
}

pub(super) fn journal_file(dir: &Path, stamp: u64) -> PathBuf {
    dir.join(format!("journal-{stamp:020}.bin"))
}

/// The stamps of the generations whose base is in `dir`, newest first.
pub(super) fn generations(dir: &Path) -> Vec<u64> {
    let mut stamps: Vec<u64> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .filter_map(|e| {
            e.file_name()
                .to_str()?
                .strip_prefix("base-")?
                .strip_suffix(".kapaint")?
                .parse()
                .ok()
        })
        .collect();
    stamps.sort_unstable_by(|a, b| b.cmp(a));
    stamps
}

/// Loads the recovery copy at `path`: the newest base that loads, with every whole record of
/// its journal replayed on it. (A plain project file, as older versions wrote, loads as is.)
///
/// # Errors
/// No loadable base.
pub fn load(path: &Path) -> Result<Document, ModelError> {
    if !path.is_dir() {
        return project::load(path);
    }
    let mut last_error = None;
    for stamp in generations(path) {
        match project::load(&base_file(path, stamp)) {
            Ok(doc) => {
                return Ok(replay(
                    doc,
                    &journal_file(path, stamp),
                    &base_file(path, stamp),
                ));
            }
            Err(e) => last_error = Some(e),
        }
    }
    Err(last_error.unwrap_or_else(|| ModelError::Project {
        path: path.to_path_buf(),
        reason: "the recovery folder holds no copy".into(),
    }))
}

/// `doc` with every whole, valid record of `journal` replayed on it (up to the first that
/// is not).
fn replay(doc: Document, journal: &Path, base: &Path) -> Document {
    if !std::fs::metadata(journal).is_ok_and(|m| m.len() > JOURNAL_MAGIC.len() as u64) {
        // No record: the generation as written, layers and all.
        return doc;
    }
    let normal = doc.normal().cloned();
    let (mut maps, mut settings) = doc.into_parts();
    if let Ok(mut file) = std::fs::File::open(journal) {
        let mut magic = [0_u8; 8];
        if file.read_exact(&mut magic).is_ok() && &magic == JOURNAL_MAGIC {
            while let Some(record) = read_record(&mut file) {
                let Ok(change) = decode_record(&record, &maps) else {
                    break;
                };
                for (id, tile) in change.tiles {
                    maps.replace_tile(id, Arc::new(tile));
                }
                settings = project::settings_from_file(change.settings, base);
            }
        }
    }
    let mut doc = Document::from_parts(maps, settings);
    doc.set_normal(normal);
    doc
}

/// Writes a new generation (a base copy and an empty journal) into `dir`, then removes the
/// older ones.
pub(super) fn write_generation(dir: &Path, doc: &Document) -> Outcome {
    std::fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
    let old = generations(dir);
    let stamp = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
        .max(old.first().map_or(0, |s| s + 1));
    let base = base_file(dir, stamp);
    project::save(doc, &base)?;
    let journal = journal_file(dir, stamp);
    crate::atomic::write_atomic(&journal, JOURNAL_MAGIC)
        .map_err(|e| ModelError::io(&journal, e))?;
    for stamp in old {
        let _ = std::fs::remove_file(base_file(dir, stamp));
        let _ = std::fs::remove_file(journal_file(dir, stamp));
    }
    let base_bytes = std::fs::metadata(&base).map_or(0, |m| m.len());
    Ok(Generation {
        stamp,
        base_bytes,
        journal_bytes: JOURNAL_MAGIC.len() as u64,
        size: (doc.maps().width(), doc.maps().height()),
    })
}

/// Appends one record to the generation's journal and flushes it to disk; on failure the
/// journal is cut back to what it was.
pub(super) fn append_record(
    dir: &Path,
    generation: Generation,
    size: (u32, u32),
    settings: &DocumentSettings,
    tiles: &[(usize, Arc<Tile>)],
) -> Outcome {
    let path = journal_file(dir, generation.stamp);
    let fail = |e: std::io::Error| ModelError::io(&path, e);
    let record =
        encode_record(size, settings, tiles).map_err(|e| fail(std::io::Error::other(e)))?;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .map_err(fail)?;
    file.seek(std::io::SeekFrom::Start(generation.journal_bytes))
        .map_err(fail)?;
    let written = file.write_all(&record).and_then(|()| file.sync_data());
    if let Err(e) = written {
        let _ = file.set_len(generation.journal_bytes);
        return Err(fail(e));
    }
    Ok(Generation {
        journal_bytes: generation.journal_bytes + record.len() as u64,
        ..generation
    })
}
