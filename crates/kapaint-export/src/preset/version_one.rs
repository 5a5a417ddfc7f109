//! Version-1 presets, whose block parameters sat beside the format: read only to say what to
//! write instead.

use serde::Deserialize;

use super::{Effort, PRESET_VERSION, some};

/// A version-1 preset's format and block parameters, as it spelled them (flat, beside the
/// format), to say what to write instead.
#[derive(Deserialize)]
pub(super) struct VersionOne {
    format: FormatOne,
    #[serde(default, alias = "bc7_quality", deserialize_with = "some")]
    max_bc7_effort: Option<Effort>,
    #[serde(default, deserialize_with = "some")]
    bc6h: Option<bool>,
    #[serde(default, deserialize_with = "some")]
    astc_block: Option<String>,
}

/// A version-1 format: a name without parameters.
#[derive(Clone, Copy, Debug, Deserialize)]
enum FormatOne {
    Png8,
    Png16,
    Exr,
    Ktx2,
    Ktx2Bc,
    Ktx2Astc,
    GltfPbr,
}

impl VersionOne {
    /// What to write instead, where the file uses the version-1 spelling of a block format
    /// or its parameters.
    pub(super) fn instead(&self) -> Option<String> {
        let effort = self.max_bc7_effort.unwrap_or_default();
        match self.format {
            FormatOne::Ktx2Bc => Some(format!(
                "write version: {PRESET_VERSION} and format: Ktx2Bc(max_effort: {effort:?}, bc6h: {})",
                self.bc6h.unwrap_or(true)
            )),
            FormatOne::Ktx2Astc => Some(format!(
                "write version: {PRESET_VERSION} and format: Ktx2Astc(block: {:?}, max_effort: {effort:?})",
                self.astc_block.as_deref().unwrap_or("4x4")
            )),
            other
                if self.max_bc7_effort.is_some()
                    || self.bc6h.is_some()
                    || self.astc_block.is_some() =>
            {
                Some(format!("remove them: {other:?} has no blocks"))
            }
            _ => None,
        }
    }
}
