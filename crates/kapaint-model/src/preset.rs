//! Material presets: `presets/materials/*.ron`, built into the binary, plus user files.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;

use super::ModelError;
use super::texel::{MaterialValue, N_MAX};

/// A material preset as written in a `.ron` file.
///
/// Read only through its checks (`MaterialPresetFile`): values in range, a name.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(try_from = "MaterialPresetFile")]
pub struct MaterialPreset {
    /// Display name.
    pub name: String,
    /// Where the values come from.
    pub source: String,
    /// Diffuse coefficient, linear RGB in `[0, 1]`.
    pub kd: [f32; 3],
    /// Specular coefficient, linear RGB in `[0, 1]`.
    pub ks: [f32; 3],
    /// Phong exponent in `[0, 16384]`.
    pub n: f32,
    /// The ambient a published table gives (compared against the derived one in docs).
    pub table_ambient: Option<[f32; 3]>,
}

/// A preset as its file spells it, before it is checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialPresetFile {
    name: String,
    source: String,
    kd: [f32; 3],
    ks: [f32; 3],
    n: f32,
    #[serde(default)]
    table_ambient: Option<[f32; 3]>,
}

impl TryFrom<MaterialPresetFile> for MaterialPreset {
    type Error = String;

    fn try_from(f: MaterialPresetFile) -> Result<Self, String> {
        use super::check::{MAX_PATH_BYTES, all_in_range, bounded_text, in_range, name};
        name("name", &f.name)?;
        bounded_text("source", &f.source, MAX_PATH_BYTES)?;
        Ok(Self {
            kd: all_in_range("kd", f.kd, 0.0, 1.0)?,
            ks: all_in_range("ks", f.ks, 0.0, 1.0)?,
            n: in_range("n", f.n, 0.0, N_MAX)?,
            table_ambient: f
                .table_ambient
                .map(|a| all_in_range("table_ambient", a, 0.0, 1.0))
                .transpose()?,
            name: f.name,
            source: f.source,
        })
    }
}

/// Largest preset file read (bytes).
const MAX_PRESET_BYTES: u64 = 1 << 20;

impl MaterialPreset {
    /// Parses and validates preset text; errors name `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        <Self as PresetKind>::parse(path, text)
    }

    /// Reads and parses a preset file (a regular file of at most 1 MiB).
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        load::<Self>(path)
    }

    /// The preset's material value.
    pub fn value(&self) -> MaterialValue {
        MaterialValue::new(Vec3::from(self.kd), Vec3::from(self.ks), self.n)
    }
}

/// The text of a preset file: a regular file of at most `max_bytes`, UTF-8; errors name it.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, ModelError> {
    let bytes = kapaint_base::file_check::read_limited(path, max_bytes).map_err(|e| match e {
        kapaint_base::file_check::FileCheck::Io(source) => ModelError::io(path, source),
        other => ModelError::Preset {
            path: path.to_path_buf(),
            reason: format!("the file {other}"),
        },
    })?;
    String::from_utf8(bytes).map_err(|_| ModelError::Preset {
        path: path.to_path_buf(),
        reason: "not UTF-8 text".into(),
    })
}

/// A kind of preset file: RON text of at most [`Self::MAX_BYTES`], parsed and checked by
/// [`Self::parse`], shipped as `presets/FOLDER/*.ron` and kept by the user in
/// `FOLDER` of [`user_dir`]. The one loader every kind goes through ([`load`],
/// [`load_dir`], [`builtin_of`], [`user_folder`]).
pub trait PresetKind: Sized {
    /// The largest file read (bytes).
    const MAX_BYTES: u64;
    /// The folder under `presets/` that ships the kind, and under [`user_dir`] that keeps the
    /// user's (`""`: the user folder itself, for materials).
    const FOLDER: &'static str;
    /// The shipped folder's name when it differs from [`Self::FOLDER`].
    const SHIPPED_FOLDER: &'static str = Self::FOLDER;

    /// Parses and checks preset text; errors name `path`.
    ///
    /// # Errors
    /// Malformed RON, unknown fields or values a check refuses.
    fn parse(path: &Path, text: &str) -> Result<Self, ModelError>;
}

/// Reads and parses a preset file of kind `T` (a regular file of at most `T::MAX_BYTES`).
///
/// # Errors
/// The file cannot be read, is too large or not UTF-8, or does not parse.
pub fn load<T: PresetKind>(path: &Path) -> Result<T, ModelError> {
    T::parse(path, &read_text(path, T::MAX_BYTES)?)
}

/// Every `.ron` file of kind `T` in `dir`, sorted by name, with its file stem, each read or
/// with its error.
pub fn load_dir_of<T: PresetKind>(dir: &Path) -> Vec<Result<(String, T), ModelError>> {
    ron_files(dir)
        .into_iter()
        .map(|p| {
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            load::<T>(&p).map(|preset| (stem, preset))
        })
        .collect()
}

/// The shipped presets of kind `T` (file stems and texts), parsed, by stem.
pub fn builtin_of<T: PresetKind>(files: &[(&str, &str)]) -> Vec<(String, T)> {
    files
        .iter()
        .filter_map(|(stem, text)| {
            let path = PathBuf::from(format!("presets/{}/{stem}.ron", T::SHIPPED_FOLDER));
            T::parse(&path, text).ok().map(|p| ((*stem).to_string(), p))
        })
        .collect()
}

/// Where the user keeps presets of kind `T`: its folder in [`user_dir`].
pub fn user_folder<T: PresetKind>() -> Option<PathBuf> {
    user_dir().map(|d| {
        if T::FOLDER.is_empty() {
            d
        } else {
            d.join(T::FOLDER)
        }
    })
}

impl PresetKind for MaterialPreset {
    const MAX_BYTES: u64 = MAX_PRESET_BYTES;
    const FOLDER: &'static str = "";
    const SHIPPED_FOLDER: &'static str = "materials";

    fn parse(path: &Path, text: &str) -> Result<Self, ModelError> {
        ron::from_str(text).map_err(|e| ModelError::Preset {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }
}

macro_rules! builtin {
    ($($stem:literal),* $(,)?) => {
        /// The file stems and texts of the presets shipped in `presets/materials/`.
        pub const BUILTIN_FILES: &[(&str, &str)] = &[
            $(($stem, include_str!(concat!("../../../presets/materials/", $stem, ".ron")))),*
        ];
    };
}

builtin!(
    "black-plastic",
    "black-rubber",
    "brass",
    "bronze",
    "chrome",
    "clay",
    "copper",
    "cyan-plastic",
    "cyan-rubber",
    "default",
    "emerald",
    "gold",
    "green-plastic",
    "green-rubber",
    "jade",
    "mirror",
    "obsidian",
    "pearl",
    "red-plastic",
    "red-rubber",
    "ruby",
    "silver",
    "turquoise",
    "white-plastic",
    "white-rubber",
    "yellow-plastic",
    "yellow-rubber",
);

/// The built-in presets by file stem, sorted.
pub fn builtin() -> Vec<(String, MaterialPreset)> {
    builtin_of(BUILTIN_FILES)
}

/// The user's preset folder: `$KAPAINT_PRESET_DIR`, else `$XDG_CONFIG_HOME/kapaint/presets`,
/// else `~/.config/kapaint/presets`. Material presets are its `.ron` files; every other kind
/// lives in its own folder in it ([`PresetKind::FOLDER`]: `brushes`, `masks`, and `export`
/// for export presets). It may not exist yet: saving a preset creates it.
pub fn user_dir() -> Option<PathBuf> {
    std::env::var_os("KAPAINT_PRESET_DIR")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("XDG_CONFIG_HOME")
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))
                .map(|d| d.join("kapaint").join("presets"))
        })
}

/// A file stem for a preset named `name`: lower case letters, digits and dashes (at most
/// 64 characters; "preset" if nothing is left).
pub fn file_stem_for(name: &str) -> String {
    let mut stem = String::new();
    for c in name.trim().chars() {
        if c.is_ascii_alphanumeric() {
            stem.push(c.to_ascii_lowercase());
        } else if !stem.ends_with('-') && !stem.is_empty() {
            stem.push('-');
        }
    }
    let stem: String = stem.trim_end_matches('-').chars().take(64).collect();
    if stem.is_empty() {
        "preset".into()
    } else {
        stem
    }
}

/// Saves `value` as the material preset `name` in `dir` (created if missing), atomically, as
/// `STEM.ron`; returns its file stem and path. A preset of the same file name is replaced.
///
/// # Errors
/// An empty or over-long name, or a failure to write.
pub fn save_user(
    dir: &Path,
    name: &str,
    value: MaterialValue,
) -> Result<(String, PathBuf), ModelError> {
    let name = name.trim();
    let stem = file_stem_for(name);
    let path = dir.join(format!("{stem}.ron"));
    super::check::name("the preset's name", name).map_err(|reason| ModelError::Preset {
        path: path.clone(),
        reason,
    })?;
    let v = value.sanitized();
    let text = format!(
        "(\n    name: {name:?},\n    source: \"saved in kapaint\",\n    kd: ({}, {}, {}),\n    ks: ({}, {}, {}),\n    n: {},\n)\n",
        v.kd.x, v.kd.y, v.kd.z, v.ks.x, v.ks.y, v.ks.z, v.n
    );
    // The text must read back as the preset it describes.
    MaterialPreset::parse(&path, &text)?;
    std::fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
    kapaint_base::atomic::write_atomic(&path, text.as_bytes())
        .map_err(|e| ModelError::io(&path, e))?;
    Ok((stem, path))
}

/// The `.ron` files in `dir`, sorted by name (none where it cannot be read).
pub(crate) fn ron_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    paths.sort();
    paths
}

/// Every `.ron` file in `dir`, sorted by name, each parsed or with its error.
pub fn load_dir(dir: &Path) -> Vec<Result<(String, MaterialPreset), ModelError>> {
    load_dir_of(dir)
}

/// Finds a preset by file stem or display name (case-insensitive): user presets first, then
/// built-in ones. A malformed user file with that name is an error naming the file.
pub fn find(name: &str) -> Result<MaterialPreset, ModelError> {
    let matches = |stem: &str, p: &MaterialPreset| {
        stem.eq_ignore_ascii_case(name) || p.name.eq_ignore_ascii_case(name)
    };
    if let Some(dir) = user_dir() {
        for entry in load_dir(&dir) {
            match entry {
                Ok((stem, preset)) if matches(&stem, &preset) => return Ok(preset),
                Err(ModelError::Preset { path, reason })
                    if path
                        .file_stem()
                        .is_some_and(|s| s.eq_ignore_ascii_case(name)) =>
                {
                    return Err(ModelError::Preset { path, reason });
                }
                _ => {}
            }
        }
    }
    let all = builtin();
    all.iter()
        .find(|(stem, p)| matches(stem, p))
        .map(|(_, p)| p.clone())
        .ok_or_else(|| ModelError::UnknownPreset {
            name: name.to_string(),
            known: all
                .iter()
                .map(|(s, _)| s.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_preset_is_built_in_and_valid() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/materials");
        let on_disk: Vec<_> = load_dir(&dir);
        assert!(on_disk.len() >= 16);
        for entry in &on_disk {
            assert!(entry.is_ok(), "{entry:?}");
        }
        let built_in = builtin();
        assert_eq!(
            built_in.len(),
            on_disk.len(),
            "add new preset files to builtin!()"
        );
        for ((a, pa), (b, pb)) in built_in.iter().zip(on_disk.iter().flatten()) {
            assert_eq!((a, pa), (b, pb));
        }
        assert!(built_in.iter().all(|(_, p)| !p.source.is_empty()));
    }

    #[test]
    fn a_saved_preset_reads_back_exactly() {
        let dir = std::env::temp_dir().join(format!("kapaint-preset-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let value = MaterialValue::new(Vec3::new(0.8, 0.1, 0.05), Vec3::splat(0.3), 250.0);
        let (stem, path) = save_user(&dir, "  Rusty Red #2 ", value).unwrap();
        assert_eq!(stem, "rusty-red-2");
        assert_eq!(path, dir.join("rusty-red-2.ron"));
        let back = MaterialPreset::load(&path).unwrap();
        assert_eq!(back.name, "Rusty Red #2");
        assert_eq!(back.value(), value);
        let listed = load_dir(&dir);
        assert_eq!(listed.len(), 1);
        assert!(save_user(&dir, "   ", value).is_err());
        assert_eq!(file_stem_for("!!!"), "preset");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn find_by_stem_or_name() {
        assert_eq!(find("brass").unwrap().name, "Brass");
        assert_eq!(find("Black Plastic").unwrap().n, 32.0);
        let err = find("unobtainium").unwrap_err().to_string();
        assert!(
            err.contains("unobtainium") && err.contains("brass"),
            "{err}"
        );
    }

    #[test]
    fn malformed_presets_name_the_file_and_the_problem() {
        let path = Path::new("bad.ron");
        for (text, needle) in [
            (
                "(name: \"x\", source: \"s\", kd: (1, 0, 0), ks: (0, 0, 0))",
                "n",
            ),
            (
                "(name: \"x\", source: \"s\", kd: (2, 0, 0), ks: (0, 0, 0), n: 1)",
                "kd",
            ),
            (
                "(name: \"x\", source: \"s\", kd: (1, 0, 0), ks: (0, 0, 0), n: -1)",
                "n must",
            ),
            (
                "(name: \"x\", source: \"s\", kd: (1, 0, 0), ks: (0, 0, 0), n: 1, extra: 3)",
                "extra",
            ),
            ("not ron at all", ""),
        ] {
            let err = MaterialPreset::parse(path, text).unwrap_err().to_string();
            assert!(err.starts_with("preset bad.ron"), "{err}");
            assert!(err.contains(needle), "{err} should mention {needle}");
        }
    }
}
