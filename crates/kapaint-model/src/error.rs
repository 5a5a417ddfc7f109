//! Errors of the model layer: every one names what failed and why, for one line of UI or CLI.

use std::path::PathBuf;

/// A model-layer failure.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// A map size outside `1..=8192` per side.
    #[error("map size {width}x{height} is not supported (each side must be 1 to 8192 texels)")]
    InvalidSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A project file is truncated, corrupt or from an unknown version.
    #[error("{path}: not a valid kapaint project: {reason}")]
    Project {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A preset file is malformed.
    #[error("preset {path}: {reason}")]
    Preset {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// No preset of that name.
    #[error("no material preset named {name:?} (known: {known})")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// An image could not be imported.
    #[error("{path}: {reason}")]
    Image {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A paint script is malformed.
    #[error("script {path}: {reason}")]
    Script {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A save found the project changed on disk since it was read (another kapaint saved it):
    /// the result went beside it instead.
    #[error(
        "{path} changed on disk since it was opened (another kapaint saved it); this result was written to {written} instead"
    )]
    Conflict {
        /// The project.
        path: PathBuf,
        /// Where this save's result went.
        written: PathBuf,
    },
    /// A document the project format cannot hold (a field past its limit): nothing was written.
    #[error("{path}: cannot be saved: {reason}")]
    Unsaveable {
        /// The file.
        path: PathBuf,
        /// Which field, and why.
        reason: String,
    },
    /// A command that cannot run in the document's state (e.g. a pick outside the map).
    #[error("{0}")]
    Command(String),
    /// A broken invariant inside kapaint (parts of a document that do not fit together): not
    /// the input's fault.
    #[error("internal error: {0}")]
    Internal(String),
}

impl ModelError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }
}
