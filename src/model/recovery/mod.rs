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

mod folder;
mod record;
#[cfg(test)]
mod tests;

pub use folder::{load, modified, recovery_path, remove};

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::ModelError;
use super::document::Document;
use super::tile::Tile;
use folder::{append_record, write_generation};

/// Time between recovery copies while the document changes: at most this much work is lost
/// when the process is killed.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(20);

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
            .filter(|g| g.size == size && g.journal_bytes <= g.base_bytes.max(64 << 20))
            // The journal holds composite tiles: only a stack of one plain layer is that.
            .filter(|_| doc.stack().is_flat());
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
            let snapshot = doc.snapshot();
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
