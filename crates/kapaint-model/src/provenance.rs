//! Where a document's maps came from: the report of a PBR import, kept with the project.

use serde::{Deserialize, Serialize};

/// The conversion error over a set's texels (relative, see `kapaint_pbr::convert::Conversion::error`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
#[serde(deny_unknown_fields)]
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
    /// The source material is seen from both sides (glTF's `doubleSided`): the `.glb` the
    /// `gltf-pbr` export writes says so too.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub double_sided: bool,
}

/// How a PBR texel's roughness and `F0` become a Phong or Blinn-Phong `n` and `k_s` (the
/// Cook-Torrance model needs no mapping: its own `n` is roughness's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NMapping {
    /// `n` and the lobe's height fitted together per roughness: `k_s = F0 height(r)` (at most
    /// `F0`, and at most `1 - k_d`), `n` strictly falling with roughness.
    #[default]
    HeightFitted,
    /// `k_s = F0` and `n` fitted alone: the mapping before the height fit, whose exponent stops
    /// falling at roughness 0.48.
    HeightFixed,
}

impl NMapping {
    /// Every mapping, the default first.
    pub const ALL: [Self; 2] = [Self::HeightFitted, Self::HeightFixed];

    /// The name reports, manifests and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Self::HeightFitted => "height-fitted",
            Self::HeightFixed => "height-fixed",
        }
    }

    /// The mapping a report or manifest names: [`Self::name`], or `fitted`, which reports
    /// written before the height fit name the height-fixed one by.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "fitted" => Some(Self::HeightFixed),
            _ => Self::ALL.into_iter().find(|m| m.name() == name),
        }
    }

    /// The name a report records for an import or export to `model`: the mapping's, or
    /// `cook-torrance` for that model, which maps roughness by its own `alpha`.
    pub fn report_name(self, model: kapaint_reflectance::ShadingModel) -> &'static str {
        if model.is_microfacet() {
            "cook-torrance"
        } else {
            self.name()
        }
    }
}
