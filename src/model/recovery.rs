//! Crash recovery: autosave copies that cost only what changed.
//!
//! A recovery copy is a folder (`.NAME.kapaint-recovery` beside the project, or
//! `untitled.kapaint-recovery` in kapaint's state folder) holding one generation:
//! - `base-STAMP.kapaint`, a whole project written at the first autosave;
//! - `journal-STAMP.bin`, to which every later autosave appends one record: the settings and
//!   the tiles changed since the record before, with a checksum.
//!
//! An autosave is due every [`AUTOSAVE_INTERVAL`] while the document changes, and runs on a
//! background thread: the editor only takes a snapshot of the changed tiles (shared
//! copy-on-write, no copy). When the journal outgrows its base, the next autosave starts a
//! new generation and removes the old one once the new one is on disk. A record cut short by
//! a crash fails its checksum and is ignored, so recovery gets every autosave before it. A
//! failed autosave is truncated away and retried one interval later.

use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

use super::ModelError;
use super::document::{Document, DocumentSettings};
use super::maps::MaterialMaps;
use super::project;
use super::tile::{Plane, TILE_TEXELS, Tile};

/// Time between recovery copies while the document changes: at most this much work is lost
/// when the process is killed.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(20);

/// The journal's first bytes.
const JOURNAL_MAGIC: &[u8; 8] = b"KPJRNL01";

/// A record's first bytes.
const RECORD_MAGIC: &[u8; 4] = b"KPRC";

/// Largest record read back (bytes): every tile of an 8192^2 map, with room to spare.
const MAX_RECORD_BYTES: u64 = 2 << 30;

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

fn journal_file(dir: &Path, stamp: u64) -> PathBuf {
    dir.join(format!("journal-{stamp:020}.bin"))
}

/// The stamps of the generations whose base is in `dir`, newest first.
fn generations(dir: &Path) -> Vec<u64> {
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
    Document::from_parts(maps, settings)
}

/// The next record's payload, if the file holds a whole one whose checksum matches.
fn read_record(file: &mut std::fs::File) -> Option<Vec<u8>> {
    let mut head = [0_u8; 12];
    file.read_exact(&mut head).ok()?;
    if &head[..4] != RECORD_MAGIC {
        return None;
    }
    let len = u64::from_le_bytes(head[4..12].try_into().ok()?);
    if len > MAX_RECORD_BYTES {
        return None;
    }
    let mut payload = Vec::new();
    std::io::Read::by_ref(file)
        .take(len)
        .read_to_end(&mut payload)
        .ok()?;
    let mut sum = [0_u8; 4];
    file.read_exact(&mut sum).ok()?;
    (payload.len() as u64 == len && crc32fast::hash(&payload) == u32::from_le_bytes(sum))
        .then_some(payload)
}

/// What one record changes.
struct Change {
    settings: DocumentSettings,
    tiles: Vec<(usize, Tile)>,
}

/// A little-endian reader over a record's bytes.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.0.len() < n {
            return Err("the record ends early".into());
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<u16, String> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn value<const C: usize>(&mut self) -> Result<[u16; C], String> {
        let mut v = [0_u16; C];
        for c in &mut v {
            *c = self.u16()?;
        }
        Ok(v)
    }

    fn plane<const C: usize>(&mut self) -> Result<Plane<[u16; C]>, String> {
        match self.u8()? {
            0 => Ok(Plane::Uniform(self.value()?)),
            1 => {
                let mut data = Vec::with_capacity(TILE_TEXELS);
                for _ in 0..TILE_TEXELS {
                    data.push(self.value()?);
                }
                Ok(Plane::Data(data.into_boxed_slice()))
            }
            k => Err(format!("unknown plane kind {k}")),
        }
    }
}

/// Decodes and checks a record against the maps it applies to.
fn decode_record(record: &[u8], maps: &MaterialMaps) -> Result<Change, String> {
    let mut r = Bytes(record);
    let (w, h) = (r.u32()?, r.u32()?);
    if (w, h) != (maps.width(), maps.height()) {
        return Err("the record is for another map size".into());
    }
    let json_len = r.u32()? as usize;
    let settings: DocumentSettings =
        serde_json::from_slice(r.take(json_len)?).map_err(|e| e.to_string())?;
    let count = r.u32()? as usize;
    let mut tiles = Vec::with_capacity(count.min(maps.tile_count()));
    for _ in 0..count {
        let id = r.u32()? as usize;
        if id >= maps.tile_count() {
            return Err(format!("tile {id} is outside the maps"));
        }
        let kd = r.plane::<3>()?;
        let ks = r.plane::<3>()?;
        let n = match r.plane::<1>()? {
            Plane::Uniform([v]) => Plane::Uniform(v),
            Plane::Data(d) => Plane::Data(d.iter().map(|v| v[0]).collect()),
        };
        let valid = match &n {
            Plane::Uniform(v) => project::valid_n_bits(*v),
            Plane::Data(d) => d.iter().all(|v| project::valid_n_bits(*v)),
        };
        if !valid {
            return Err(format!("tile {id} holds an invalid exponent"));
        }
        tiles.push((id, Tile { kd, ks, n }));
    }
    Ok(Change { settings, tiles })
}

/// Encodes a record: the settings and the tiles, then its length and checksum around it.
fn encode_record(
    (w, h): (u32, u32),
    settings: &DocumentSettings,
    tiles: &[(usize, Arc<Tile>)],
) -> Result<Vec<u8>, String> {
    fn plane<const C: usize>(out: &mut Vec<u8>, p: &Plane<[u16; C]>) {
        let values: &[[u16; C]] = match p {
            Plane::Uniform(v) => {
                out.push(0);
                std::slice::from_ref(v)
            }
            Plane::Data(d) => {
                out.push(1);
                d
            }
        };
        for c in values.iter().flatten() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    let json = serde_json::to_vec(settings).map_err(|e| e.to_string())?;
    let mut payload = Vec::with_capacity(16 + json.len() + tiles.len() * (TILE_TEXELS * 14 + 8));
    payload.extend_from_slice(&w.to_le_bytes());
    payload.extend_from_slice(&h.to_le_bytes());
    payload.extend_from_slice(&(json.len() as u32).to_le_bytes());
    payload.extend_from_slice(&json);
    payload.extend_from_slice(&(tiles.len() as u32).to_le_bytes());
    for (id, tile) in tiles {
        payload.extend_from_slice(&(*id as u32).to_le_bytes());
        plane(&mut payload, &tile.kd);
        plane(&mut payload, &tile.ks);
        let n = match &tile.n {
            Plane::Uniform(v) => Plane::Uniform([*v]),
            Plane::Data(d) => Plane::Data(d.iter().map(|v| [*v]).collect()),
        };
        plane(&mut payload, &n);
    }
    let mut record = Vec::with_capacity(payload.len() + 16);
    record.extend_from_slice(RECORD_MAGIC);
    record.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    record.extend_from_slice(&payload);
    record.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    Ok(record)
}

/// The generation an autosaver appends to.
#[derive(Clone, Copy, Debug)]
struct Generation {
    stamp: u64,
    base_bytes: u64,
    journal_bytes: u64,
    size: (u32, u32),
}

/// What a finished autosave reports back.
type Outcome = Result<Generation, ModelError>;

/// An autosave on its thread: the document version it makes safe, the maps version its
/// tiles go up to, and the thread.
struct Job {
    version: u64,
    maps_version: u64,
    handle: std::thread::JoinHandle<Outcome>,
}

/// Autosave on a timer: [`Autosaver::poll`] (each frame, or from any loop) snapshots what
/// changed when a recovery copy is due, and writes it on a named background thread, so
/// painting never waits on the disk.
pub struct Autosaver {
    interval: Duration,
    path: PathBuf,
    last_time: Instant,
    /// The document version the recovery copy holds.
    saved_version: u64,
    /// The maps version whose tiles the recovery copy holds.
    maps_version: u64,
    generation: Option<Generation>,
    job: Option<Job>,
}

impl std::fmt::Debug for Autosaver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Autosaver")
            .field("path", &self.path)
            .field("interval", &self.interval)
            .finish_non_exhaustive()
    }
}

impl Autosaver {
    /// Writes recovery copies to the folder `path` every `interval` while the document
    /// changes; the document's current state counts as safe (it was just opened or saved).
    pub fn new(interval: Duration, path: PathBuf, doc: &Document) -> Self {
        Self {
            interval,
            path,
            last_time: Instant::now(),
            saved_version: doc.version(),
            maps_version: doc.maps().version(),
            generation: None,
            job: None,
        }
    }

    /// Where recovery copies go.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the recovery copy holds the document as it is.
    pub fn is_current(&self, doc: &Document) -> bool {
        self.job.is_none() && self.saved_version == doc.version()
    }

    /// How long until [`Autosaver::poll`] has something to do: the rest of the interval while
    /// the document differs from its recovery copy, a moment while a save runs, `None` when
    /// the copy is current. An idle window must wake up then, or a stroke followed by nothing
    /// would never be saved.
    pub fn next_poll(&self, doc: &Document, now: Instant) -> Option<Duration> {
        if self.job.is_some() {
            return Some(Duration::from_millis(100));
        }
        (doc.version() != self.saved_version).then(|| {
            self.interval
                .saturating_sub(now.duration_since(self.last_time))
        })
    }

    /// Reports a finished autosave (its result), and starts the next one if one is due.
    pub fn poll(&mut self, doc: &Document, now: Instant) -> Option<Result<PathBuf, ModelError>> {
        let finished = if self.job.as_ref().is_some_and(|j| j.handle.is_finished()) {
            self.finish()
        } else {
            None
        };
        let due = self.job.is_none()
            && doc.version() != self.saved_version
            && now.duration_since(self.last_time) >= self.interval;
        if due {
            // Counted from the start, so a failing disk is retried one interval later.
            self.last_time = now;
            if let Err(e) = self.start(doc) {
                return Some(Err(e));
            }
        }
        finished
    }

    /// Starts an autosave now (a new generation, or a record appended to this one).
    fn start(&mut self, doc: &Document) -> Result<(), ModelError> {
        let size = (doc.maps().width(), doc.maps().height());
        let version = doc.version();
        let maps_version = doc.maps().version();
        let append = self
            .generation
            .filter(|g| g.size == size && g.journal_bytes <= g.base_bytes.max(64 << 20));
        let dir = self.path.clone();
        let work: Box<dyn FnOnce() -> Outcome + Send> = if let Some(generation) = append {
            let tiles: Vec<(usize, Arc<Tile>)> = doc
                .maps()
                .tiles_changed_since(self.maps_version)
                .into_iter()
                .map(|id| (id, Arc::clone(doc.maps().tile(id))))
                .collect();
            let settings = doc.settings().clone();
            Box::new(move || append_record(&dir, generation, size, &settings, &tiles))
        } else {
            let snapshot = Document::from_parts(doc.maps().clone(), doc.settings().clone());
            Box::new(move || write_generation(&dir, &snapshot))
        };
        let handle = std::thread::Builder::new()
            .name("kapaint-autosave".into())
            .spawn(work)
            .map_err(|e| ModelError::io(&self.path, e))?;
        self.job = Some(Job {
            version,
            maps_version,
            handle,
        });
        Ok(())
    }

    /// Waits for an autosave in flight, if any, and reports it.
    pub fn wait(&mut self) -> Option<Result<PathBuf, ModelError>> {
        self.finish()
    }

    fn finish(&mut self) -> Option<Result<PathBuf, ModelError>> {
        let job = self.job.take()?;
        let outcome = job.handle.join().unwrap_or_else(|_| {
            Err(ModelError::io(
                &self.path,
                std::io::Error::other("the autosave thread stopped unexpectedly"),
            ))
        });
        Some(match outcome {
            Ok(generation) => {
                self.generation = Some(generation);
                self.saved_version = job.version;
                self.maps_version = job.maps_version;
                Ok(self.path.clone())
            }
            Err(e) => {
                // Nothing counts as saved: the same changes go into the next attempt (a new
                // generation if the journal may be damaged).
                self.generation = None;
                Err(e)
            }
        })
    }
}

/// Writes a new generation (a base copy and an empty journal) into `dir`, then removes the
/// older ones.
fn write_generation(dir: &Path, doc: &Document) -> Outcome {
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
fn append_record(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Command, FillRegion, MaterialValue};

    fn temp(tag: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("kapaint-recovery-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn stroke(doc: &mut Document, y: f32) {
        doc.apply(Command::Stroke {
            tool: crate::model::StrokeTool::Brush,
            points: vec![
                crate::model::brush::StrokePoint {
                    pos: glam::Vec2::new(3.0, y),
                    pressure: 1.0,
                },
                crate::model::brush::StrokePoint {
                    pos: glam::Vec2::new(180.0, y + 7.0),
                    pressure: 1.0,
                },
            ],
        })
        .unwrap();
    }

    /// Texel for texel over the map (a loaded plane may be uniform where the painted one is
    /// full, and what lies past a partial tile's edge is not stored).
    fn same_maps(a: &Document, b: &Document) -> bool {
        let (w, h) = (a.maps().width(), a.maps().height());
        (0..h).all(|y| (0..w).all(|x| a.maps().texel(x, y) == b.maps().texel(x, y)))
    }

    #[test]
    fn every_autosave_after_the_first_appends_only_what_changed() {
        let dir = temp("journal");
        let path = dir.join(".p.kapaint-recovery");
        let mut doc = Document::new(200, 130, DocumentSettings::default()).unwrap();
        let mut saver = Autosaver::new(Duration::ZERO, path.clone(), &doc);
        let t = Instant::now();
        assert!(saver.poll(&doc, t).is_none());
        assert!(saver.wait().is_none(), "nothing changed, nothing written");
        stroke(&mut doc, 20.0);
        saver.poll(&doc, t);
        saver.wait().unwrap().unwrap();
        let base_bytes = saver.generation.unwrap().base_bytes;
        assert!(same_maps(&load(&path).unwrap(), &doc));
        // Later changes, settings included, land in the journal; the base stays.
        for (k, y) in [60.0, 100.0].into_iter().enumerate() {
            stroke(&mut doc, y);
            doc.apply(Command::SetModel(if k == 0 {
                crate::reflectance::ShadingModel::BlinnPhong
            } else {
                crate::reflectance::ShadingModel::Phong
            }))
            .unwrap();
            saver.poll(&doc, t);
            saver.wait().unwrap().unwrap();
            let back = load(&path).unwrap();
            assert!(same_maps(&back, &doc));
            assert_eq!(back.settings(), doc.settings());
        }
        let g = saver.generation.unwrap();
        assert_eq!(g.base_bytes, base_bytes);
        assert_eq!(generations(&path).len(), 1);
        // A record cut short (a kill mid-write) is ignored: recovery gets the one before.
        let before = load(&path).unwrap();
        stroke(&mut doc, 120.0);
        saver.poll(&doc, t);
        saver.wait().unwrap().unwrap();
        let journal = journal_file(&path, g.stamp);
        let full = std::fs::metadata(&journal).unwrap().len();
        std::fs::OpenOptions::new()
            .write(true)
            .open(&journal)
            .unwrap()
            .set_len(full - 100)
            .unwrap();
        assert!(same_maps(&load(&path).unwrap(), &before));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_failed_autosave_is_retried_and_its_folder_made() {
        let dir = temp("retry");
        // The state folder of a fresh machine does not exist yet.
        let path = dir.join("state/kapaint/untitled.kapaint-recovery");
        let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
        let mut saver = Autosaver::new(Duration::from_secs(20), path.clone(), &doc);
        doc.apply(Command::Fill(FillRegion::All)).unwrap();
        let t = Instant::now();
        saver.poll(&doc, t + Duration::from_secs(21));
        saver.wait().unwrap().unwrap();
        assert!(saver.is_current(&doc));
        // A file where the folder should be: the autosave fails and counts nothing as saved.
        remove(&path);
        std::fs::write(&path, b"in the way").unwrap();
        doc.apply(Command::SetPrimary(MaterialValue::new(
            glam::Vec3::X,
            glam::Vec3::ZERO,
            5.0,
        )))
        .unwrap();
        doc.apply(Command::Fill(FillRegion::All)).unwrap();
        saver.poll(&doc, t + Duration::from_secs(42));
        assert!(saver.wait().unwrap().is_err());
        assert!(!saver.is_current(&doc));
        assert!(
            saver.poll(&doc, t + Duration::from_secs(50)).is_none(),
            "not before the interval"
        );
        assert!(saver.wait().is_none());
        std::fs::remove_file(&path).unwrap();
        saver.poll(&doc, t + Duration::from_secs(63));
        saver.wait().unwrap().unwrap();
        assert!(saver.is_current(&doc));
        assert!(same_maps(&load(&path).unwrap(), &doc));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_next_poll_is_when_the_copy_falls_due() {
        let dir = temp("next");
        let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
        let mut saver = Autosaver::new(Duration::from_secs(20), dir.join("r"), &doc);
        let t = saver.last_time;
        assert_eq!(saver.next_poll(&doc, t), None, "nothing to save");
        doc.apply(Command::Fill(FillRegion::All)).unwrap();
        assert_eq!(
            saver.next_poll(&doc, t + Duration::from_secs(5)),
            Some(Duration::from_secs(15))
        );
        assert_eq!(
            saver.next_poll(&doc, t + Duration::from_secs(25)),
            Some(Duration::ZERO)
        );
        saver.poll(&doc, t + Duration::from_secs(25));
        assert!(
            saver.next_poll(&doc, t).is_some(),
            "a save runs: look again soon"
        );
        saver.wait().unwrap().unwrap();
        assert_eq!(saver.next_poll(&doc, t + Duration::from_secs(26)), None);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn recovery_folders_sit_beside_the_project() {
        let p = recovery_path(Some(Path::new("/work/art/cow.kapaint")));
        assert_eq!(p, Path::new("/work/art/.cow.kapaint-recovery"));
        assert!(recovery_path(None).ends_with("kapaint/untitled.kapaint-recovery"));
    }
}
