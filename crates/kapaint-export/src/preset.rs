//! Export presets: `presets/export/*.ron`, built into the binary, plus the user's own from
//! `$KAPAINT_EXPORT_PRESET_DIR`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use crate::astc_block::AstcBlock;

/// Image format of the exported files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Format {
    /// 8-bit PNG (colour in sRGB).
    Png8,
    /// 16-bit PNG (linear).
    Png16,
    /// Float OpenEXR (linear; `n` as is).
    Exr,
    /// KTX2, 8 bits per component, uncompressed, with a full mip chain.
    Ktx2,
    /// KTX2 block-compressed with a full mip chain: BC7 for three or four components, BC5
    /// for two, BC4 for one.
    Ktx2Bc,
    /// KTX2 with ASTC LDR blocks and a full mip chain (phones, standalone headsets): one
    /// footprint for every image (`astc_block`, 4x4 by default), `k_d` sRGB.
    Ktx2Astc,
    /// glTF's metallic-roughness PNGs (8-bit): base colour (sRGB), metallic-roughness (G
    /// roughness, B metallic), and the normal map where the project has one; converted back
    /// from `k_d`, `k_s`, `n` ([`crate::gltf_pbr`]). `layout`, `n_bits` and `include_ka` do
    /// not apply.
    GltfPbr,
}

impl Format {
    /// Whether files hold 8-bit components (PNG8 and both KTX2 kinds).
    pub fn is_8bit(self) -> bool {
        matches!(
            self,
            Self::Png8 | Self::Ktx2 | Self::Ktx2Bc | Self::Ktx2Astc | Self::GltfPbr
        )
    }

    /// Whether files are KTX2 containers.
    pub fn is_ktx2(self) -> bool {
        matches!(self, Self::Ktx2 | Self::Ktx2Bc | Self::Ktx2Astc)
    }

    /// Whether files are block-compressed (BC or ASTC), their layout and effort chosen
    /// against the preset's budget.
    pub fn is_blocks(self) -> bool {
        matches!(self, Self::Ktx2Bc | Self::Ktx2Astc)
    }

    /// The files' extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png8 | Self::Png16 | Self::GltfPbr => "png",
            Self::Exr => "exr",
            Self::Ktx2 | Self::Ktx2Bc | Self::Ktx2Astc => "ktx2",
        }
    }
}

/// BC7 encoder effort (BC4 and BC5 have one speed): slower finds better endpoints. Ordered
/// from the cheapest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Bc7Quality {
    /// Fewest partitions and modes tried.
    UltraFast,
    /// About 1 dB under `Basic` at a fraction of the time.
    VeryFast,
    /// More modes.
    Fast,
    /// The reference encoder's basic profile: the most a preset spends by default.
    #[default]
    Basic,
    /// Exhaustive.
    Slow,
}

impl Bc7Quality {
    /// Every effort, cheapest first.
    pub const ALL: [Self; 5] = [
        Self::UltraFast,
        Self::VeryFast,
        Self::Fast,
        Self::Basic,
        Self::Slow,
    ];
}

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
    /// Image format.
    pub format: Format,
    /// Channel packing.
    pub layout: Layout,
    /// Bits per stored `n` code (8 or 16; EXR stores `n` as is).
    pub n_bits: u8,
    /// Also write a baked `k_a` map.
    #[serde(default)]
    pub include_ka: bool,
    /// The most BC7 effort a `Ktx2Bc` export may spend meeting its budget.
    pub max_bc7_effort: Bc7Quality,
    /// What a `Ktx2Bc` set may lose.
    pub budget: BlockBudget,
    /// Whether a `Ktx2Bc` export may store colour as BC6H (linear half floats) when BC7
    /// misses the budget; off for consumers that sample only BC7 (RON `bc6h`, default on).
    pub bc6h: bool,
    /// A `Ktx2Astc` set's footprint (RON `astc_block: "6x6"`, default 4x4); the loader
    /// refuses one ASTC does not define.
    pub astc_block: AstcBlock,
}

/// An export preset as its file spells it, before it is checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportPresetFile {
    name: String,
    #[serde(default)]
    description: String,
    format: Format,
    layout: Layout,
    n_bits: u8,
    #[serde(default)]
    include_ka: bool,
    /// Older presets name the ceiling `bc7_quality`.
    #[serde(default, alias = "bc7_quality")]
    max_bc7_effort: Bc7Quality,
    #[serde(default = "default_srgb_p999")]
    ka_error_srgb_p999: f64,
    #[serde(default = "default_srgb_mean")]
    ka_error_srgb_mean: f64,
    #[serde(default, deserialize_with = "some_number")]
    max_ka_error: Option<f64>,
    #[serde(default, deserialize_with = "some_number")]
    mean_ka_error: Option<f64>,
    #[serde(default, deserialize_with = "some_number")]
    min_psnr: Option<f64>,
    #[serde(default = "default_bc6h")]
    bc6h: bool,
    #[serde(default, deserialize_with = "some_block")]
    astc_block: Option<AstcBlock>,
}

/// An ASTC footprint as a preset spells it: a bare `"WxH"`, present means set.
fn some_block<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<AstcBlock>, D::Error> {
    AstcBlock::deserialize(d).map(Some)
}

/// An optional limit as a preset spells it: a bare number (as before the limits became
/// optional), present means set.
fn some_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    f64::deserialize(d).map(Some)
}

fn default_bc6h() -> bool {
    true
}

impl TryFrom<ExportPresetFile> for ExportPreset {
    type Error = String;

    fn try_from(f: ExportPresetFile) -> Result<Self, String> {
        use kapaint_core::model::check::{MAX_PATH_BYTES, bounded_text, name};
        name("name", &f.name)?;
        bounded_text("description", &f.description, MAX_PATH_BYTES)?;
        if !matches!(f.n_bits, 8 | 16) {
            return Err(format!("n_bits must be 8 or 16, got {}", f.n_bits));
        }
        if f.format.is_8bit() && f.n_bits != 8 {
            return Err(format!(
                "{:?} stores 8-bit components (n_bits: 8)",
                f.format
            ));
        }
        if f.format == Format::GltfPbr && f.include_ka {
            return Err("a glTF PBR set has no k_a map (include_ka: false)".into());
        }
        if f.astc_block.is_some() && f.format != Format::Ktx2Astc {
            return Err(format!(
                "astc_block applies to Ktx2Astc presets, not {:?}",
                f.format
            ));
        }
        if f.format == Format::Png16 && f.n_bits != 16 {
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
        Ok(Self {
            name: f.name,
            description: f.description,
            format: f.format,
            layout: f.layout,
            n_bits: f.n_bits,
            include_ka: f.include_ka,
            max_bc7_effort: f.max_bc7_effort,
            budget,
            bc6h: f.bc6h,
            astc_block: f.astc_block.unwrap_or_default(),
        })
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
    ("16-bit", include_str!("../../../presets/export/16-bit.ron")),
    (
        "compact",
        include_str!("../../../presets/export/compact.ron"),
    ),
    ("exr", include_str!("../../../presets/export/exr.ron")),
    (
        "gltf-pbr",
        include_str!("../../../presets/export/gltf-pbr.ron"),
    ),
    ("ktx2", include_str!("../../../presets/export/ktx2.ron")),
    (
        "ktx2-astc",
        include_str!("../../../presets/export/ktx2-astc.ron"),
    ),
    (
        "ktx2-raw",
        include_str!("../../../presets/export/ktx2-raw.ron"),
    ),
    (
        "separate",
        include_str!("../../../presets/export/separate.ron"),
    ),
    (
        "with-ka",
        include_str!("../../../presets/export/with-ka.ron"),
    ),
];

impl ExportPreset {
    /// Parses and checks a preset's text (`path` names it in errors).
    ///
    /// # Errors
    /// Malformed RON, unknown fields, or values out of range.
    pub fn parse(path: &Path, text: &str) -> Result<Self, PresetError> {
        ron::from_str(text).map_err(|e| PresetError::Malformed {
            path: path.to_path_buf(),
            reason: e.to_string(),
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

/// The built-in presets that write kapaint sets (every one but the glTF PBR export).
pub fn builtin_sets() -> Vec<ExportPreset> {
    builtin()
        .into_iter()
        .filter(|p| p.format != Format::GltfPbr)
        .collect()
}

/// The folder of the user's export presets: `$KAPAINT_EXPORT_PRESET_DIR` where it is set,
/// else the `export` folder of the user preset folder every kind of preset shares
/// ([`kapaint_core::model::preset::user_dir`]).
pub fn user_dir() -> Option<PathBuf> {
    std::env::var_os("KAPAINT_EXPORT_PRESET_DIR")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| kapaint_core::model::preset::user_dir().map(|d| d.join("export")))
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
            let text = kapaint_core::model::preset::read_text(&path, 1 << 20).map_err(|e| {
                PresetError::Malformed {
                    path: path.clone(),
                    reason: match e {
                        kapaint_core::model::ModelError::Preset { reason, .. } => reason,
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
            "gltf-pbr",
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
            "(name: \"a\", format: Ktx2Bc, layout: Packed, n_bits: 8, max_ka_error: -1.0)",
            "(name: \"a\", format: Ktx2Bc, layout: Packed, n_bits: 8, min_psnr: NaN)",
            "(name: \"a\", format: Ktx2Astc, layout: Packed, n_bits: 8, astc_block: \"7x7\")",
            "(name: \"a\", format: Ktx2Astc, layout: Packed, n_bits: 8, astc_block: \"4x4x4\")",
            "(name: \"a\", format: Ktx2Astc, layout: Packed, n_bits: 8, astc_block: 4)",
            "(name: \"a\", format: Ktx2Bc, layout: Packed, n_bits: 8, astc_block: \"4x4\")",
        ] {
            let err = ExportPreset::parse(path, text).unwrap_err().to_string();
            assert!(err.starts_with("x.ron: "), "{err}");
        }
    }
}
