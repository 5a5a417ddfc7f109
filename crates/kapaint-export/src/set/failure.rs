//! Why an image of the set could not be encoded: cancelled (the export ends quietly, leaving
//! nothing at the target) or failed (its error line). The stages say which; the export acts on
//! it, never on a message's words.

use crate::ktx::KtxError;

/// An encode that did not finish.
#[derive(Debug)]
pub(super) enum Failure {
    /// Cancelled through its progress.
    Cancelled,
    /// Failed, and why.
    Failed(String),
}

impl From<KtxError> for Failure {
    fn from(e: KtxError) -> Self {
        match e {
            KtxError::Cancelled => Self::Cancelled,
            e => Self::Failed(e.to_string()),
        }
    }
}

impl From<String> for Failure {
    fn from(e: String) -> Self {
        Self::Failed(e)
    }
}

impl From<&str> for Failure {
    fn from(e: &str) -> Self {
        Self::Failed(e.to_string())
    }
}
