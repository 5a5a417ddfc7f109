//! Where a document's maps came from: the report of a PBR import, kept with the project.

use serde::{Deserialize, Serialize};

/// The conversion error over a set's texels (relative, see `kapaint_core::pbr::convert::Conversion::error`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorSummary {
    /// Largest.
    pub max: f32,
    /// Mean over texels.
    pub mean: f32,
    /// 99th percentile.
    pub p99: f32,
}

/// What an import did, kept with the project.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImportReport {
    /// Where the set came from (file names, or "constant").
    pub source: String,
    /// The target model's name.
    pub model: String,
    /// How `n` was made from roughness.
    pub n_mapping: String,
    /// The conversion error.
    pub error: ErrorSummary,
    /// What was done to fit the inputs together (resampling), one line each.
    #[serde(default)]
    pub notes: Vec<String>,
}
