//! Crash recovery: autosave copies that cost only what changed, one per editor process.
//!
//! Each editor process keeps its copy in a session folder of its own inside the project's
//! recovery folder (see [`recovery_path`]), so two editors on one project never touch each other's
//! copy. A copy is a journal: its first record is the whole document (layers, masks, settings,
//! selection, normal map), and every later record holds the layer structure and only the tiles
//! changed since the record before, each record checksummed and flushed to disk before the next
//! autosave. A kill therefore loses at most the work since the last record plus the record
//! being written, whatever the document's size: a record cut short fails its check and
//! recovery takes the one before.
//!
//! An autosave is due every [`AUTOSAVE_INTERVAL`] while the document changes, and runs on a
//! background thread: the editor only takes a snapshot (tiles shared copy-on-write, no copy).
//! When the journal outgrows its first record, the next autosave starts a new generation (a
//! new journal whose first record is the whole document) and removes the old one once the new
//! one is on disk. A failed autosave is cut back and retried one interval later, as a new
//! generation.

mod folder;
mod journal;
mod record;
mod replay;
pub mod session;
#[cfg(test)]
mod tests;

pub use folder::{load, offer, recovery_path, remove};

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::ModelError;
use super::document::Document;
use folder::{Generation, session_dir};
use journal::Snapshot;

/// Time between recovery copies while the document changes: at most this much work is lost
/// when the process is killed.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(20);

/// Journals smaller than this are never compacted into a new generation (bytes).
const MIN_COMPACT_BYTES: u64 = 64 << 20;

/// What a finished autosave reports back.
type Outcome = Result<Generation, ModelError>;

/// An autosave on its thread: the document version it makes safe, and the thread.
struct Job {
    version: u64,
    handle: std::thread::JoinHandle<Outcome>,
}

/// Autosave on a timer: [`Autosaver::poll`] (each frame, or from any loop) snapshots the
/// document when a recovery copy is due, and writes it on a named background thread, so
/// painting never waits on the disk.
pub struct Autosaver {
    interval: Duration,
    /// The project's recovery folder; this process's copy is its session folder inside.
    recovery: PathBuf,
    last_time: Instant,
    /// The document version the recovery copy holds.
    saved_version: u64,
    generation: Option<Generation>,
    job: Option<Job>,
    /// Copies this one replaces (a recovered copy, one left where a moved copy could not
    /// follow): removed once this one holds a record.
    superseded: Vec<PathBuf>,
    /// The recovery folder to move to once the autosave in flight is done.
    moving_to: Option<PathBuf>,
}

impl std::fmt::Debug for Autosaver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Autosaver")
            .field("recovery", &self.recovery)
            .field("interval", &self.interval)
            .finish_non_exhaustive()
    }
}

impl Autosaver {
    /// Writes recovery copies of the project at `project` (untitled work: `None`) every
    /// `interval` while the document changes; the document's current state counts as safe (it
    /// was just opened or saved).
    pub fn new(interval: Duration, project: Option<&Path>, doc: &Document) -> Self {
        Self {
            interval,
            recovery: recovery_path(project),
            last_time: Instant::now(),
            saved_version: doc.version(),
            generation: None,
            job: None,
            superseded: Vec::new(),
            moving_to: None,
        }
    }

    /// Like [`Autosaver::new`], for a document recovered from the copy `from`: its first copy
    /// is due at once, and `from` is removed once that copy is on disk (until then, it is all
    /// that holds the recovered work).
    pub fn recovering(
        interval: Duration,
        project: Option<&Path>,
        doc: &Document,
        from: PathBuf,
    ) -> Self {
        let mut saver = Self::new(interval, project, doc);
        saver.saved_version = doc.version().wrapping_add(1);
        saver.last_time = Instant::now()
            .checked_sub(interval)
            .unwrap_or_else(Instant::now);
        if from != saver.session() {
            saver.superseded.push(from);
        }
        saver
    }

    /// Autosaves every `interval` from now on (the next copy falls due `interval` after the
    /// last).
    pub fn set_interval(&mut self, interval: Duration) {
        self.interval = interval;
    }

    /// This process's recovery copy: its session folder.
    pub fn session(&self) -> PathBuf {
        session_dir(&self.recovery)
    }

    /// The recovery folder of the project (this process's copy is inside it).
    pub fn recovery_folder(&self) -> &Path {
        &self.recovery
    }

    /// Whether the recovery copy holds the document as it is.
    pub fn is_current(&self, doc: &Document) -> bool {
        self.job.is_none() && self.saved_version == doc.version()
    }

    /// After the document was saved under another name (`Save As`, or the first save of
    /// untitled work): the recovery copy follows it to the new project's recovery folder, so
    /// it is never offered as the old project's work. Where it cannot be moved (another file
    /// system), the next copy is written there whole and the old one removed after it.
    pub fn relocate(&mut self, project: Option<&Path>) {
        self.moving_to = Some(recovery_path(project));
        if self.job.is_none() {
            self.apply_move();
        }
    }

    fn apply_move(&mut self) {
        let Some(to) = self.moving_to.take() else {
            return;
        };
        if to == self.recovery {
            return;
        }
        let from = self.session();
        self.recovery = to;
        let moved = !from.exists()
            || (folder::private_dir(&self.recovery).is_ok()
                && std::fs::rename(&from, self.session()).is_ok());
        if moved {
            if let Some(old) = from.parent() {
                // Only when empty: another editor's copy may be in it.
                let _ = std::fs::remove_dir(old);
            }
        } else {
            self.superseded.push(from);
            self.generation = None;
            // Due at the next interval, even if nothing changes meanwhile.
            self.saved_version = self.saved_version.wrapping_add(1);
        }
    }

    /// The project was saved holding the document at `version`. When that is the document as
    /// it is now, the work is safe in the project: the copy goes (after an autosave in flight)
    /// and the next change starts a new one, so a copy written after the save is never offered
    /// as unsaved work. Changes made while the save ran keep their copy.
    pub fn saved(&mut self, doc: &Document, version: u64) {
        if doc.version() == version {
            self.discard();
            self.saved_version = version;
            self.last_time = Instant::now();
        }
    }

    /// Removes this process's recovery copy (and any it replaces), after waiting for an
    /// autosave in flight: the work was saved, or the user discarded it.
    pub fn discard(&mut self) {
        let _ = self.finish();
        remove(&self.session());
        for old in self.superseded.drain(..) {
            remove(&old);
        }
        self.generation = None;
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

    /// Starts an autosave now: a record appended to this generation, or a new generation when
    /// there is none or its journal has outgrown its first record.
    fn start(&mut self, doc: &Document) -> Result<(), ModelError> {
        let version = doc.version();
        let generation = self
            .generation
            .take()
            .filter(|g| g.bytes <= g.first_bytes.saturating_mul(2).max(MIN_COMPACT_BYTES));
        let snapshot = Snapshot::of(doc);
        let dir = self.session();
        let handle = std::thread::Builder::new()
            .name("kapaint-autosave".into())
            .spawn(move || folder::write(&dir, generation, &snapshot))
            .map_err(|e| ModelError::io(&self.recovery, e))?;
        self.job = Some(Job { version, handle });
        Ok(())
    }

    /// Writes a copy now, whatever the timer says, if the document differs from its copy, and
    /// waits for it (and for one in flight).
    ///
    /// # Errors
    /// The autosave's failure.
    pub fn save_now(&mut self, doc: &Document) -> Result<(), ModelError> {
        if let Some(Err(e)) = self.finish() {
            return Err(e);
        }
        if doc.version() == self.saved_version {
            return Ok(());
        }
        self.last_time = Instant::now();
        self.start(doc)?;
        self.finish().unwrap_or(Ok(PathBuf::new())).map(|_| ())
    }

    /// Waits for an autosave in flight, if any, and reports it.
    pub fn wait(&mut self) -> Option<Result<PathBuf, ModelError>> {
        self.finish()
    }

    fn finish(&mut self) -> Option<Result<PathBuf, ModelError>> {
        let job = self.job.take()?;
        let outcome = job.handle.join().unwrap_or_else(|_| {
            Err(ModelError::io(
                &self.recovery,
                std::io::Error::other("the autosave thread stopped unexpectedly"),
            ))
        });
        let reported = match outcome {
            Ok(generation) => {
                self.generation = Some(generation);
                self.saved_version = job.version;
                for old in self.superseded.drain(..) {
                    remove(&old);
                }
                Ok(self.session())
            }
            // Nothing counts as saved: the same changes go into the next attempt, a new
            // generation (the journal may be damaged).
            Err(e) => Err(e),
        };
        self.apply_move();
        Some(reported)
    }
}
