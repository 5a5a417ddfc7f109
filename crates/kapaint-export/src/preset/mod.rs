//! Export presets: `presets/export/*.ron`, built into the binary, plus the user's own from
//! `$KAPAINT_EXPORT_PRESET_DIR`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

mod format;
pub mod textures;
mod version_one;

pub use self::format::Format;
pub use self::textures::{Channel, NormalGreen, TextureFile};
use self::version_one::VersionOne;
pub use crate::codec::{AstcBlock, Effort};

/// The version of the preset files this kapaint writes and reads: 2 gave each block format
/// its own parameters (`Ktx2Bc(max_effort:, bc6h:)`, `Ktx2Astc(block:, max_effort:)`).
pub const PRESET_VERSION: u32 = 2;

/// What a block-compressed set may lose, in what the eye sees: the `k_a` error in levels of
/// 8-bit sRGB of the ambient-lit colour ([`crate::set::perceptual`]), its 99.9th percentile and
/// mean over texels. The export encodes with the cheapest layout and effort first and spends
/// more only while one of these is not met. A user preset may add the older limits (`k_a`
/// errors relative, per texel and colour channel; PSNR per component, in dB, of level 0
/// against the uncompressed 8-bit values); the built-in ones do not.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockBudget {
    /// The 99.9th percentile of the sRGB-level error allowed.
    #[serde(default = "default_srgb_p999")]
    pub ka_error_srgb_p999: f64,
    /// The mean sRGB-level error allowed.
    #[serde(default = "default_srgb_mean")]
    pub ka_error_srgb_mean: f64,
    /// Largest relative `k_a` error allowed, where the preset sets one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_ka_error: Option<f64>,
    /// Mean relative `k_a` error allowed, where the preset sets one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_ka_error: Option<f64>,
    /// Smallest PSNR allowed of any component, where the preset sets one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_psnr: Option<f64>,
}

fn default_srgb_p999() -> f64 {
    2.0
}

fn default_srgb_mean() -> f64 {
    0.3
}

impl Default for BlockBudget {
    fn default() -> Self {
        Self {
            ka_error_srgb_p999: default_srgb_p999(),
            ka_error_srgb_mean: default_srgb_mean(),
            max_ka_error: None,
            mean_ka_error: None,
            min_psnr: None,
        }
    }
}

impl BlockBudget {
    /// The budget in words: "k_a within 2 levels of the displayed colour for 99.9 % of texels,
    /// mean 0.3 levels" (and the optional limits where set).
    pub fn describe(&self) -> String {
        use std::fmt::Write as _;
        let mut text = format!(
            "k_a within {} levels of the displayed colour for 99.9 % of texels, mean {} levels",
            self.ka_error_srgb_p999, self.ka_error_srgb_mean
        );
        if let Some(m) = self.max_ka_error {
            let _ = write!(text, ", relative max {:.2} %", m * 100.0);
        }
        if let Some(m) = self.mean_ka_error {
            let _ = write!(text, ", relative mean {:.2} %", m * 100.0);
        }
        if let Some(p) = self.min_psnr {
            let _ = write!(text, ", PSNR {p:.0} dB or more");
        }
        text
    }
}

/// How channels are packed into files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Layout {
    /// `k_d` RGB with `n` in alpha; `k_s` alone (one channel when monochrome).
    Packed,
    /// One file per channel.
    Separate,
}

/// An export preset.
///
/// Read only through its checks (`ExportPresetFile`): a name, and `n_bits` that the
/// format can store.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ExportPresetFile")]
pub struct ExportPreset {
    /// Name (what `--preset` takes, with the file stem).
    pub name: String,
    /// One line for menus.
    #[serde(default)]
    pub description: String,
    /// Image format, with its parameters.
    pub format: Format,
    /// Channel packing.
    pub layout: Layout,
    /// Bits per stored `n` code (8 or 16; EXR stores `n` as is).
    pub n_bits: u8,
    /// Also write a baked `k_a` map.
    #[serde(default)]
    pub include_ka: bool,
    /// What a block-compressed set may lose.
    pub budget: BlockBudget,
    /// KTX2 sets: the Zstandard level every KTX2 file's levels are supercompressed at
    /// ([`crate::ktx::ZSTD_LEVELS`]); `None`: stored as encoded.
    pub zstd: Option<u8>,
    /// A [`Format::PbrTextures`] preset's files and what their channels hold (empty for
    /// every other format).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<TextureFile>,
    /// Which way the normal map's green points in a PBR set (glTF's is always OpenGL's).
    #[serde(default)]
    pub normal_green: NormalGreen,
}

impl ExportPreset {
    /// The files a PBR preset writes, in order: the preset's layout, or glTF's for the
    /// `gltf-pbr` format (empty for a kapaint set).
    pub fn pbr_files(&self) -> Vec<TextureFile> {
        match self.format {
            Format::GltfPbr => textures::gltf(),
            Format::PbrTextures => self.textures.clone(),
            _ => Vec::new(),
        }
    }
}

/// An export preset as its file spells it, before it is checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportPresetFile {
    /// [`PRESET_VERSION`] (files before version 2 have none).
    #[serde(default = "version_one")]
    version: u32,
    name: String,
    #[serde(default)]
    description: String,
    format: Format,
    #[serde(default = "packed")]
    layout: Layout,
    #[serde(default = "eight")]
    n_bits: u8,
    #[serde(default)]
    include_ka: bool,
    #[serde(default = "default_srgb_p999")]
    ka_error_srgb_p999: f64,
    #[serde(default = "default_srgb_mean")]
    ka_error_srgb_mean: f64,
    #[serde(default, deserialize_with = "some")]
    max_ka_error: Option<f64>,
    #[serde(default, deserialize_with = "some")]
    mean_ka_error: Option<f64>,
    #[serde(default, deserialize_with = "some")]
    min_psnr: Option<f64>,
    #[serde(default, deserialize_with = "some")]
    zstd: Option<u8>,
    #[serde(default)]
    textures: Vec<TextureFile>,
    #[serde(default)]
    normal_green: NormalGreen,
}

fn version_one() -> u32 {
    1
}

fn packed() -> Layout {
    Layout::Packed
}

fn eight() -> u8 {
    8
}

/// An optional value as a preset spells it: bare (a limit as before the limits became
/// optional), present means set.
pub(super) fn some<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

pub(super) fn default_bc6h() -> bool {
    true
}

impl TryFrom<ExportPresetFile> for ExportPreset {
    type Error = String;

    fn try_from(f: ExportPresetFile) -> Result<Self, String> {
        use kapaint_model::check::{MAX_PATH_BYTES, bounded_text, name};
        if f.version > PRESET_VERSION {
            return Err(format!(
                "version {} is newer than this kapaint reads ({PRESET_VERSION})",
                f.version
            ));
        }
        if f.version < PRESET_VERSION && f.format.is_blocks() {
            return Err(format!(
                "a {} preset needs version: {PRESET_VERSION} (block parameters live in the format)",
                f.format.name()
            ));
        }
        name("name", &f.name)?;
        bounded_text("description", &f.description, MAX_PATH_BYTES)?;
        if !matches!(f.n_bits, 8 | 16) {
            return Err(format!("n_bits must be 8 or 16, got {}", f.n_bits));
        }
        if f.format.is_8bit() && f.n_bits != 8 {
            return Err(format!(
                "{} stores 8-bit components (n_bits: 8)",
                f.format.name()
            ));
        }
        if f.format.is_pbr() && f.include_ka {
            return Err("a PBR set has no k_a map (include_ka: false)".into());
        }
        check_pbr_layout(&f)?;
        if matches!(f.format, Format::Png16) && f.n_bits != 16 {
            return Err("16-bit PNGs store n in 16 bits (n_bits: 16)".into());
        }
        let budget = BlockBudget {
            ka_error_srgb_p999: f.ka_error_srgb_p999,
            ka_error_srgb_mean: f.ka_error_srgb_mean,
            max_ka_error: f.max_ka_error,
            mean_ka_error: f.mean_ka_error,
            min_psnr: f.min_psnr,
        };
        for (field, value, range) in [
            (
                "ka_error_srgb_p999",
                Some(budget.ka_error_srgb_p999),
                0.0..=255.0,
            ),
            (
                "ka_error_srgb_mean",
                Some(budget.ka_error_srgb_mean),
                0.0..=255.0,
            ),
            ("max_ka_error", budget.max_ka_error, 0.0..=100.0),
            ("mean_ka_error", budget.mean_ka_error, 0.0..=100.0),
            ("min_psnr", budget.min_psnr, 0.0..=200.0),
        ] {
            let Some(value) = value else { continue };
            if !range.contains(&value) {
                return Err(format!(
                    "{field} must be in {}..={}, got {value}",
                    range.start(),
                    range.end()
                ));
            }
        }
        if let Some(level) = f.zstd {
            if !f.format.is_ktx2() {
                return Err(format!(
                    "zstd supercompresses KTX2 files; a {} set has none",
                    f.format.name()
                ));
            }
            let levels = crate::ktx::ZSTD_LEVELS;
            if !levels.contains(&level) {
                return Err(format!(
                    "zstd must be a level in {}..={}, got {level}",
                    levels.start(),
                    levels.end()
                ));
            }
        }
        Ok(Self {
            name: f.name,
            description: f.description,
            format: f.format,
            layout: f.layout,
            n_bits: f.n_bits,
            include_ka: f.include_ka,
            budget,
            zstd: f.zstd,
            textures: f.textures,
            normal_green: f.normal_green,
        })
    }
}

/// A PBR layout where the format takes one: `textures` with `PbrTextures` (checked), none
/// elsewhere; DirectX green only where the layout is the preset's own.
fn check_pbr_layout(f: &ExportPresetFile) -> Result<(), String> {
    match f.format {
        Format::PbrTextures => textures::check(&f.textures),
        other if !f.textures.is_empty() => Err(format!(
            "textures lays out a PbrTextures set; a {} set has its own files",
            other.name()
        )),
        other if f.normal_green != NormalGreen::OpenGl => Err(format!(
            "normal_green applies to a PbrTextures set's normal map, not a {} set's",
            other.name()
        )),
        _ => Ok(()),
    }
}

/// Why a preset could not be used.
#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// The file is malformed.
    #[error("{path}: {reason}")]
    Malformed {
        /// The preset file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// No preset of that name.
    #[error("unknown export preset {name:?} (known: {known})")]
    Unknown {
        /// The name asked for.
        name: String,
        /// The names there are.
        known: String,
    },
}

const BUILTIN: &[(&str, &str)] = &[
    (
        "16-bit",
        include_str!("../../../../presets/export/16-bit.ron"),
    ),
    (
        "compact",
        include_str!("../../../../presets/export/compact.ron"),
    ),
    ("exr", include_str!("../../../../presets/export/exr.ron")),
    (
        "gltf-pbr",
        include_str!("../../../../presets/export/gltf-pbr.ron"),
    ),
    (
        "godot",
        include_str!("../../../../presets/export/godot.ron"),
    ),
    ("ktx2", include_str!("../../../../presets/export/ktx2.ron")),
    (
        "ktx2-astc",
        include_str!("../../../../presets/export/ktx2-astc.ron"),
    ),
    (
        "ktx2-uastc",
        include_str!("../../../../presets/export/ktx2-uastc.ron"),
    ),
    (
        "ktx2-etc1s",
        include_str!("../../../../presets/export/ktx2-etc1s.ron"),
    ),
    (
        "ktx2-raw",
        include_str!("../../../../presets/export/ktx2-raw.ron"),
    ),
    (
        "separate",
        include_str!("../../../../presets/export/separate.ron"),
    ),
    (
        "unity-hdrp",
        include_str!("../../../../presets/export/unity-hdrp.ron"),
    ),
    (
        "unity-urp",
        include_str!("../../../../presets/export/unity-urp.ron"),
    ),
    (
        "unreal",
        include_str!("../../../../presets/export/unreal.ron"),
    ),
    (
        "with-ka",
        include_str!("../../../../presets/export/with-ka.ron"),
    ),
];

impl ExportPreset {
    /// Parses and checks a preset's text (`path` names it in errors).
    ///
    /// # Errors
    /// Malformed RON, unknown fields, or values out of range.
    pub fn parse(path: &Path, text: &str) -> Result<Self, PresetError> {
        ron::from_str(text).map_err(|e| {
            // The version-1 spelling: say what it is spelled as now.
            let old = ron::from_str::<VersionOne>(text)
                .ok()
                .and_then(|v| v.instead());
            PresetError::Malformed {
                path: path.to_path_buf(),
                reason: match old {
                    Some(instead) => format!(
                        "the version-1 spelling of a block format: since preset version {PRESET_VERSION}, max_bc7_effort, bc6h and astc_block live in the format; {instead}"
                    ),
                    None => e.to_string(),
                },
            }
        })
    }
}

/// The built-in presets.
pub fn builtin() -> Vec<ExportPreset> {
    BUILTIN
        .iter()
        .filter_map(|(stem, text)| {
            ExportPreset::parse(&PathBuf::from(format!("presets/export/{stem}.ron")), text).ok()
        })
        .collect()
}

/// The built-in presets that write kapaint sets (every one but the PBR exports).
pub fn builtin_sets() -> Vec<ExportPreset> {
    builtin()
        .into_iter()
        .filter(|p| !p.format.is_pbr())
        .collect()
}

/// The folder of the user's export presets: `$KAPAINT_EXPORT_PRESET_DIR` where it is set,
/// else the `export` folder of the user preset folder every kind of preset shares
/// ([`kapaint_model::preset::user_dir`]).
pub fn user_dir() -> Option<PathBuf> {
    std::env::var_os("KAPAINT_EXPORT_PRESET_DIR")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| kapaint_model::preset::user_dir().map(|d| d.join("export")))
}

/// Finds a preset by name or file stem: a user file (`NAME.ron` in [`user_dir`]) first,
/// then the built-in ones.
///
/// # Errors
/// A malformed user preset, or no preset of that name.
pub fn find(name: &str) -> Result<ExportPreset, PresetError> {
    if let Some(dir) = user_dir() {
        let path = dir.join(format!("{name}.ron"));
        if path.exists() {
            // The one reader every preset file goes through (size, regular file, UTF-8).
            let text = kapaint_model::preset::read_text(&path, 1 << 20).map_err(|e| {
                PresetError::Malformed {
                    path: path.clone(),
                    reason: match e {
                        kapaint_model::ModelError::Preset { reason, .. } => reason,
                        other => other.to_string(),
                    },
                }
            })?;
            return ExportPreset::parse(&path, &text);
        }
    }
    let all = builtin();
    if let Some((_, text)) = BUILTIN
        .iter()
        .find(|(stem, _)| stem.eq_ignore_ascii_case(name))
    {
        return ExportPreset::parse(&PathBuf::from(format!("presets/export/{name}.ron")), text);
    }
    all.iter()
        .find(|p| p.name.eq_ignore_ascii_case(name))
        .cloned()
        .ok_or_else(|| PresetError::Unknown {
            name: name.to_string(),
            known: all
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses_and_is_found() {
        assert_eq!(builtin().len(), BUILTIN.len());
        for name in [
            "compact",
            "16-bit",
            "separate",
            "exr",
            "with-ka",
            "ktx2",
            "ktx2-astc",
            "ktx2-raw",
            "ktx2-uastc",
            "ktx2-etc1s",
            "gltf-pbr",
            "unreal",
            "unity-hdrp",
            "unity-urp",
            "godot",
        ] {
            assert_eq!(find(name).unwrap().name, name);
        }
        assert!(matches!(find("nope"), Err(PresetError::Unknown { .. })));
    }

    #[test]
    fn malformed_presets_name_the_file() {
        let path = Path::new("x.ron");
        for text in [
            "(",
            "(name: \"a\", format: Png8, layout: Packed, n_bits: 7)",
            "(name: \"a\", format: Png16, layout: Packed, n_bits: 8)",
            "(name: \"a\", format: Gif, layout: Packed, n_bits: 8)",
            "(name: \"a\", format: Png8, layout: Packed, n_bits: 8, extra: 1)",
            "(version: 2, name: \"a\", format: Ktx2Bc(), layout: Packed, n_bits: 8, max_ka_error: -1.0)",
            "(version: 2, name: \"a\", format: Ktx2Bc(), layout: Packed, n_bits: 8, min_psnr: NaN)",
            "(version: 2, name: \"a\", format: Ktx2Astc(block: \"7x7\"), layout: Packed, n_bits: 8)",
            "(version: 2, name: \"a\", format: Ktx2Astc(block: \"4x4x4\"), layout: Packed, n_bits: 8)",
            "(version: 2, name: \"a\", format: Ktx2Astc(block: 4), layout: Packed, n_bits: 8)",
            "(version: 2, name: \"a\", format: Ktx2Bc(block: \"4x4\"), layout: Packed, n_bits: 8)",
            "(version: 2, name: \"a\", format: Ktx2Bc(max_effort: Hard), layout: Packed, n_bits: 8)",
            "(version: 3, name: \"a\", format: Png8, layout: Packed, n_bits: 8)",
            "(name: \"a\", format: Ktx2Bc(), layout: Packed, n_bits: 8)",
            "(version: 2, name: \"a\", format: PbrTextures)",
            "(version: 2, name: \"a\", format: PbrTextures, textures: [(file: \"a.png\", channels: [\"gloss\"])])",
            "(version: 2, name: \"a\", format: PbrTextures, textures: [(file: \"a.png\", channels: [\"one\"]), (file: \"A.png\", channels: [\"zero\"])])",
            "(version: 2, name: \"a\", format: PbrTextures, include_ka: true, textures: [(file: \"a.png\", channels: [\"one\"])])",
            "(version: 2, name: \"a\", format: GltfPbr, normal_green: DirectX)",
            "(version: 2, name: \"a\", format: Png8, textures: [(file: \"a.png\", channels: [\"one\"])])",
        ] {
            let err = ExportPreset::parse(path, text).unwrap_err().to_string();
            assert!(err.starts_with("x.ron: "), "{err}");
        }
    }

    #[test]
    fn the_version_one_spelling_is_refused_with_the_new_one() {
        let path = Path::new("old.ron");
        for (text, instead) in [
            (
                "(name: \"a\", format: Ktx2Bc, layout: Packed, n_bits: 8, max_bc7_effort: Fast, bc6h: false)",
                "write version: 2 and format: Ktx2Bc(max_effort: Fast, bc6h: false)",
            ),
            (
                "(name: \"a\", format: Ktx2Bc, layout: Packed, n_bits: 8, bc7_quality: Slow)",
                "write version: 2 and format: Ktx2Bc(max_effort: Slow, bc6h: true)",
            ),
            (
                "(name: \"a\", format: Ktx2Astc, layout: Packed, n_bits: 8, astc_block: \"6x6\")",
                "write version: 2 and format: Ktx2Astc(block: \"6x6\", max_effort: Basic)",
            ),
            (
                "(name: \"a\", format: Png8, layout: Packed, n_bits: 8, bc6h: true)",
                "remove them: Png8 has no blocks",
            ),
        ] {
            let err = ExportPreset::parse(path, text).unwrap_err().to_string();
            assert!(err.starts_with("old.ron: the version-1 spelling"), "{err}");
            assert!(err.ends_with(instead), "{err}");
            // What it says to write reads as it says.
            if let Some(format) = instead.strip_prefix("write version: 2 and ") {
                let new = format!("(version: 2, name: \"a\", {format}, layout: Packed, n_bits: 8)");
                ExportPreset::parse(path, &new).unwrap();
            }
        }
        // A version-1 preset without blocks still reads as it did.
        let png = "(name: \"a\", format: Png8, layout: Packed, n_bits: 8)";
        assert_eq!(ExportPreset::parse(path, png).unwrap().format, Format::Png8);
    }
}
