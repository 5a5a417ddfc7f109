//! A set's normal map: the project's tangent-space normal map beside the maps, as it stores it
//! (it lights only: `k_a` never reads it), named in `material.json` and read back with the set.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{SetError, io};
use kapaint_core::model::normal::NormalMap;
use kapaint_core::model::project::NORMAL_ENCODING;

/// The normal map's file in a set.
pub const NORMAL_FILE: &str = "normal.png";

/// A set's normal map: [`NORMAL_FILE`], 8-bit RGB, `2 c - 1` in the tangent frame (glTF's
/// convention, +Y up), at its own size.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalFile {
    /// [`NORMAL_FILE`].
    pub path: String,
    /// The project's normal encoding (`png-rgb8-tangent-normal`).
    pub encoding: String,
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Size in bytes.
    pub bytes: u64,
}

impl NormalFile {
    /// Writes `normal` into the set folder `dir`; its entry.
    ///
    /// # Errors
    /// A failed encode or write.
    pub(super) fn write(normal: &NormalMap, dir: &Path) -> Result<Self, SetError> {
        let path = dir.join(NORMAL_FILE);
        let png = normal.to_png().map_err(|e| io(&path, e))?;
        kapaint_core::atomic::write_atomic(&path, &png).map_err(|e| io(&path, e))?;
        Ok(Self {
            path: NORMAL_FILE.into(),
            encoding: NORMAL_ENCODING.into(),
            width: normal.width(),
            height: normal.height(),
            bytes: png.len() as u64,
        })
    }

    /// What a manifest may say of it: its one name and encoding, a size a map may have.
    ///
    /// # Errors
    /// Anything else, in a sentence.
    pub(super) fn check(&self) -> Result<(), String> {
        let max = kapaint_core::model::maps::MAX_SIDE;
        let sized = (1..=max).contains(&self.width) && (1..=max).contains(&self.height);
        if self.path != NORMAL_FILE || self.encoding != NORMAL_ENCODING || !sized {
            return Err(format!(
                "the normal map must be {NORMAL_FILE}, {NORMAL_ENCODING}, 1..={max} a side"
            ));
        }
        Ok(())
    }

    /// Reads it from the set folder `dir`, checked against this entry.
    ///
    /// # Errors
    /// A file that does not read or decode, or is not the size the entry says.
    pub(super) fn read(&self, dir: &Path) -> Result<NormalMap, SetError> {
        let path = dir.join(&self.path);
        let invalid = |reason: String| SetError::Invalid {
            path: path.clone(),
            reason,
        };
        let bytes = kapaint_core::file_check::read_limited(
            &path,
            kapaint_core::model::import::MAX_DECODED_BYTES,
        )
        .map_err(|e| {
            if e.is_io() {
                io(&path, e)
            } else {
                invalid(format!("the file {e}"))
            }
        })?;
        let map = NormalMap::from_png(&bytes).map_err(&invalid)?;
        if (map.width(), map.height()) != (self.width, self.height) {
            return Err(invalid(format!(
                "it is {}x{}, the manifest says {}x{}",
                map.width(),
                map.height(),
                self.width,
                self.height
            )));
        }
        Ok(map)
    }
}
