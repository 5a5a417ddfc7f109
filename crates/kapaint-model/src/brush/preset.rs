//! Brush presets: a name and brush settings, shipped in `presets/brushes/*.ron` and saved by
//! the user into the `brushes` folder of the user preset folder.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::BrushSettings;
use crate::ModelError;

/// A named set of brush settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrushPreset {
    /// Display name.
    pub name: String,
    /// The settings (each checked on reading; missing fields take the defaults).
    pub brush: BrushSettings,
}

/// Largest brush preset file read (bytes): room for the largest stamp.
const MAX_BRUSH_PRESET_BYTES: u64 = 8 << 20;

impl crate::preset::PresetKind for BrushPreset {
    const MAX_BYTES: u64 = MAX_BRUSH_PRESET_BYTES;
    const FOLDER: &'static str = "brushes";

    fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        let preset: Self = ron::from_str(text).map_err(|e| ModelError::Preset {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        crate::check::name("name", &preset.name).map_err(|reason| ModelError::Preset {
            path: path.to_path_buf(),
            reason,
        })?;
        Ok(Self {
            brush: preset.brush.sanitized(),
            ..preset
        })
    }
}

/// The shipped brush presets, by file stem.
const BUILTIN: &[(&str, &str)] = &[
    (
        "default",
        include_str!("../../../../presets/brushes/default.ron"),
    ),
    (
        "hard-round",
        include_str!("../../../../presets/brushes/hard-round.ron"),
    ),
    (
        "liner",
        include_str!("../../../../presets/brushes/liner.ron"),
    ),
    (
        "soft-round",
        include_str!("../../../../presets/brushes/soft-round.ron"),
    ),
];

impl BrushPreset {
    /// Parses and checks preset text; errors name `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        <Self as crate::preset::PresetKind>::parse(path, text)
    }

    /// Reads a preset file (a regular file of at most 8 MiB).
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        crate::preset::load::<Self>(path)
    }

    /// Saves the preset into `dir` (created if missing) as `STEM.ron`, atomically, replacing
    /// one of the same file name; returns the path.
    pub fn save(&self, dir: &Path) -> Result<PathBuf, ModelError> {
        let path = dir.join(format!("{}.ron", crate::preset::file_stem_for(&self.name)));
        crate::check::name("the preset's name", self.name.trim()).map_err(|reason| {
            ModelError::Preset {
                path: path.clone(),
                reason,
            }
        })?;
        let preset = Self {
            name: self.name.trim().to_string(),
            brush: self.brush.clone(),
        };
        let text = ron::ser::to_string_pretty(&preset, ron::ser::PrettyConfig::default())
            .map_err(|e| ModelError::Internal(format!("brush preset: {e}")))?;
        std::fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
        kapaint_base::atomic::write_atomic(&path, text.as_bytes())
            .map_err(|e| ModelError::io(&path, e))?;
        Ok(path)
    }
}

/// The shipped brush presets, sorted by file stem.
pub fn builtin() -> Vec<BrushPreset> {
    crate::preset::builtin_of(BUILTIN)
        .into_iter()
        .map(|(_, p)| p)
        .collect()
}

/// Every `.ron` file in `dir`, sorted by name, each read or with its error.
pub fn load_dir(dir: &Path) -> Vec<Result<BrushPreset, ModelError>> {
    crate::preset::load_dir_of(dir)
        .into_iter()
        .map(|r| r.map(|(_, p)| p))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_brush_preset_is_built_in_and_valid() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/brushes");
        let on_disk = load_dir(&dir);
        assert!(on_disk.iter().all(Result::is_ok), "{on_disk:?}");
        let on_disk: Vec<_> = on_disk.into_iter().flatten().collect();
        assert_eq!(builtin(), on_disk, "add new brush preset files to BUILTIN");
        assert!(on_disk.len() >= 4);
    }

    #[test]
    fn a_saved_brush_preset_reads_back_exactly() {
        let dir = std::env::temp_dir().join(format!("kapaint-brushes-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let preset = BrushPreset {
            name: "Grain dry".into(),
            brush: BrushSettings {
                radius_px: 12.5,
                hardness: 0.25,
                jitter: 0.4,
                mirror_x: true,
                stamp: Some(super::super::Stamp::grain(16)),
                ..BrushSettings::default()
            },
        };
        let path = preset.save(&dir).unwrap();
        assert_eq!(path, dir.join("grain-dry.ron"));
        assert_eq!(BrushPreset::load(&path).unwrap(), preset);
        // Out-of-range values are brought into range, unknown fields and empty names refused.
        let bad = Path::new("bad.ron");
        let wide = BrushPreset::parse(bad, "(name: \"x\", brush: (radius_px: 1e9))");
        assert!(wide.is_err(), "{wide:?}");
        assert!(BrushPreset::parse(bad, "(name: \"x\", brush: (), colour: 1)").is_err());
        assert!(BrushPreset::parse(bad, "(name: \" \", brush: ())").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
