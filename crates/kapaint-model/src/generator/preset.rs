//! Smart masks: a name and a generator, shipped in `presets/masks/*.ron` and saved by the
//! user into the `masks` folder of the user preset folder. Applying one makes the selected
//! layer's mask by its generator (`SetMaskGenerator`), one undo step.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::Generator;
use crate::ModelError;

/// A named generator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaskPreset {
    /// Display name.
    pub name: String,
    /// The generator (checked on reading).
    pub mask: Generator,
}

/// Largest smart mask file read (bytes).
const MAX_MASK_PRESET_BYTES: u64 = 64 << 10;

impl crate::preset::PresetKind for MaskPreset {
    const MAX_BYTES: u64 = MAX_MASK_PRESET_BYTES;
    const FOLDER: &'static str = "masks";

    fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        let error = |reason: String| ModelError::Preset {
            path: path.to_path_buf(),
            reason,
        };
        let preset: Self = ron::from_str(text).map_err(|e| error(e.to_string()))?;
        crate::check::name("name", &preset.name).map_err(error)?;
        Ok(preset)
    }
}

/// The shipped smart masks, by file stem.
const BUILTIN: &[(&str, &str)] = &[
    (
        "cavity-dirt",
        include_str!("../../../../presets/masks/cavity-dirt.ron"),
    ),
    ("dust", include_str!("../../../../presets/masks/dust.ron")),
    (
        "edge-wear",
        include_str!("../../../../presets/masks/edge-wear.ron"),
    ),
    (
        "grunge",
        include_str!("../../../../presets/masks/grunge.ron"),
    ),
];

impl MaskPreset {
    /// Parses and checks preset text; errors name `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        <Self as crate::preset::PresetKind>::parse(path, text)
    }

    /// Reads a preset file (a regular file of at most 64 KiB).
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        crate::preset::load::<Self>(path)
    }

    /// Saves the preset into `dir` (created if missing) as `STEM.ron`, atomically, replacing
    /// one of the same file name; returns the path.
    pub fn save(&self, dir: &Path) -> Result<PathBuf, ModelError> {
        let path = dir.join(format!("{}.ron", crate::preset::file_stem_for(&self.name)));
        let name = self.name.trim().to_string();
        crate::check::name("the smart mask's name", &name).map_err(|reason| {
            ModelError::Preset {
                path: path.clone(),
                reason,
            }
        })?;
        let preset = Self {
            name,
            mask: self.mask.clone(),
        };
        let text = ron::ser::to_string_pretty(&preset, ron::ser::PrettyConfig::default())
            .map_err(|e| ModelError::Internal(format!("smart mask: {e}")))?;
        std::fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
        kapaint_base::atomic::write_atomic(&path, text.as_bytes())
            .map_err(|e| ModelError::io(&path, e))?;
        Ok(path)
    }
}

/// The shipped smart masks, sorted by file stem.
pub fn builtin() -> Vec<MaskPreset> {
    crate::preset::builtin_of(BUILTIN)
        .into_iter()
        .map(|(_, p)| p)
        .collect()
}

/// Every `.ron` file in `dir`, sorted by name, each read or with its error.
pub fn load_dir(dir: &Path) -> Vec<Result<MaskPreset, ModelError>> {
    crate::preset::load_dir_of(dir)
        .into_iter()
        .map(|r| r.map(|(_, p)| p))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_smart_mask_is_built_in_and_valid() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/masks");
        let on_disk = load_dir(&dir);
        assert!(on_disk.iter().all(Result::is_ok), "{on_disk:?}");
        let on_disk: Vec<_> = on_disk.into_iter().flatten().collect();
        assert_eq!(builtin(), on_disk, "add new smart mask files to BUILTIN");
        let names: Vec<&str> = on_disk.iter().map(|p| p.name.as_str()).collect();
        for wanted in ["Edge wear", "Cavity dirt", "Dust", "Grunge"] {
            assert!(names.contains(&wanted), "{wanted} missing from {names:?}");
        }
        // Edge wear reads the curvature bake, cavity dirt the AO bake.
        let needs = |name: &str| {
            on_disk
                .iter()
                .find(|p| p.name == name)
                .map(|p| p.mask.bakes_needed())
        };
        assert_eq!(
            needs("Edge wear"),
            Some(vec![kapaint_mesh::bakes::BakeMap::Curvature])
        );
        assert_eq!(
            needs("Cavity dirt"),
            Some(vec![kapaint_mesh::bakes::BakeMap::Ao])
        );
    }

    #[test]
    fn a_saved_smart_mask_reads_back_exactly_and_bad_ones_are_refused() {
        let dir = std::env::temp_dir().join(format!("kapaint-masks-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let preset = builtin().remove(0);
        let mine = MaskPreset {
            name: "My dirt".into(),
            ..preset
        };
        let path = mine.save(&dir).expect("saves");
        assert_eq!(path, dir.join("my-dirt.ron"));
        assert_eq!(MaskPreset::load(&path).expect("loads"), mine);
        assert_eq!(load_dir(&dir).len(), 1);
        let bad = Path::new("bad.ron");
        for text in [
            "(name: \"x\", mask: Ao(black: 0.9, white: 0.1))",
            "(name: \"x\", mask: Noise(kind: Perlin, scale: NaN))",
            "(name: \" \", mask: Ao(black: 0.1, white: 0.9))",
            "(name: \"x\", mask: None)",
            "(name: \"x\", mask: Ao(black: 0.1, white: 0.9), colour: 1)",
        ] {
            assert!(MaskPreset::parse(bad, text).is_err(), "{text}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
