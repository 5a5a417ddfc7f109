//! What a block-compressed export chose, as its manifest records it: the layout, the effort,
//! every trial measured, and why. Data only: `choose.rs` makes it.

use serde::{Deserialize, Serialize};

use super::perceptual::SrgbError;
use crate::blocks::Encoder;
use crate::codec::{AstcBlock, Effort};
use crate::encoding::KaError;
use crate::file_kind::Compression;
use crate::preset::BlockBudget;

/// Where `n` goes in a block-compressed set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BlockLayout {
    /// In `k_d`'s BC7 alpha (the fewest bytes).
    Packed,
    /// Out of the colour blocks: a BC4 plane of its own, or with grey `k_s` in a BC5 image.
    NApart,
    /// `n` apart, and the three-component colour images BC6H: linear half floats instead
    /// of BC7's 8-bit sRGB (the same bytes as `n-apart`).
    HalfColour,
}

impl BlockLayout {
    /// Whether colour images are half floats.
    pub(super) fn half(self) -> bool {
        self == Self::HalfColour
    }
}

/// One encoding of level 0 that the export measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// Where `n` was.
    pub layout: BlockLayout,
    /// BC7's (and BC6H's) effort.
    pub bc7_effort: Effort,
    /// The set's `k_a` error, level 0 as a consumer decodes it (relative).
    pub ka_error: KaError,
    /// The same in levels of 8-bit sRGB of the ambient-lit colour (absent in sets written
    /// before the perceptual budget).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ka_error_srgb: Option<SrgbError>,
    /// The smallest PSNR of any compressed component (dB; `None` where all are exact).
    pub min_psnr: Option<f64>,
    /// Seconds spent encoding and measuring.
    pub seconds: f64,
}

impl Trial {
    /// The trial and its measures, for the manifest's reason: what `budget` judges, then
    /// what it does not.
    pub(super) fn describe(&self, budget: &BlockBudget) -> String {
        let (judged, rest) = Measure::split(budget);
        let list = |measures: &[Measure]| -> Vec<String> {
            measures.iter().map(|m| m.show(m.of(self))).collect()
        };
        format!(
            "{:?} at {:?} (judged: {}; not judged: {})",
            self.layout,
            self.bc7_effort,
            list(&judged).join(", "),
            list(&rest).join(", ")
        )
    }

    /// The trial's sRGB-level error (zero for a trial recorded before it was measured).
    pub(super) fn srgb(&self) -> SrgbError {
        self.ka_error_srgb.unwrap_or_default()
    }
}

/// The rule that keeps a trial where none meets the budget, in the words the notices use. Its
/// last steps cover every number a trial shows, so a kept trial is never beaten on all of them.
pub(super) const NEAREST_RULE: &str = "fewest measures over their limits, then the smallest worst ratio to a limit, the next, and so on, then the lowest max, relative max and mean, and the highest PSNR";

/// A number the notices show of a trial. The budget judges the sRGB-level p99.9 and mean, and
/// the relative ones and PSNR where a preset sets limits for them; never the max, which a few
/// texels at stroke edges set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Measure {
    /// The sRGB-level error's 99.9th percentile (levels).
    P999,
    /// The sRGB-level error's mean (levels).
    Mean,
    /// The sRGB-level error's largest (levels).
    Max,
    /// The relative error's largest, per texel and colour channel.
    RelativeMax,
    /// The relative error's mean.
    RelativeMean,
    /// The smallest PSNR of any compressed component (dB; none where every one is exact).
    Psnr,
}

impl Measure {
    /// Every measure, in the order the notices list them.
    pub(super) const ALL: [Self; 6] = [
        Self::P999,
        Self::Mean,
        Self::Max,
        Self::RelativeMax,
        Self::RelativeMean,
        Self::Psnr,
    ];

    /// `budget`'s limit of this measure, where it judges it.
    pub(super) fn limit(self, budget: &BlockBudget) -> Option<f64> {
        match self {
            Self::P999 => Some(budget.ka_error_srgb_p999),
            Self::Mean => Some(budget.ka_error_srgb_mean),
            Self::Max => None,
            Self::RelativeMax => budget.max_ka_error,
            Self::RelativeMean => budget.mean_ka_error,
            Self::Psnr => budget.min_psnr,
        }
    }

    /// The measures `budget` judges, and the others, each in [`Measure::ALL`]'s order.
    pub(super) fn split(budget: &BlockBudget) -> (Vec<Self>, Vec<Self>) {
        Self::ALL
            .into_iter()
            .partition(|m| m.limit(budget).is_some())
    }

    /// This measure of `t` (`None`: the PSNR where every component is exact).
    pub(super) fn of(self, t: &Trial) -> Option<f64> {
        let srgb = t.srgb();
        match self {
            Self::P999 => Some(srgb.p999),
            Self::Mean => Some(srgb.mean),
            Self::Max => Some(srgb.max),
            Self::RelativeMax => Some(t.ka_error.max),
            Self::RelativeMean => Some(t.ka_error.mean),
            Self::Psnr => t.min_psnr,
        }
    }

    /// How bad `value` is, the lower the better: the value, or the PSNR negated (exact the
    /// best).
    pub(super) fn badness(self, value: Option<f64>) -> f64 {
        match (self, value) {
            (Self::Psnr, Some(p)) => -p,
            (Self::Psnr, None) => f64::NEG_INFINITY,
            (_, v) => v.unwrap_or(0.0),
        }
    }

    /// `value` as the notices write it: "p99.9 1.88 levels", "relative max 4.10 %".
    pub(super) fn show(self, value: Option<f64>) -> String {
        let v = value.unwrap_or(0.0);
        match self {
            Self::P999 => format!("p99.9 {v:.2} levels"),
            Self::Mean => format!("mean {v:.3} levels"),
            Self::Max => format!("max {v:.2} levels"),
            Self::RelativeMax => format!("relative max {}", pct(v)),
            Self::RelativeMean => format!("relative mean {}", pct(v)),
            Self::Psnr => value.map_or_else(|| "PSNR exact".into(), |p| format!("PSNR {p:.1} dB")),
        }
    }

    /// Whether `value` misses `limit` (a PSNR under it, anything else over it).
    pub(super) fn misses(self, value: Option<f64>, limit: f64) -> bool {
        match (self, value) {
            (Self::Psnr, p) => p.is_some_and(|p| p < limit),
            (_, v) => v.unwrap_or(0.0) > limit,
        }
    }

    /// The judgement of `value` against `budget`, where it judges this measure: "p99.9 4.06
    /// levels (over)".
    fn judge(self, value: Option<f64>, budget: &BlockBudget) -> Option<String> {
        let limit = self.limit(budget)?;
        let side = if self.misses(value, limit) {
            "over"
        } else {
            "within"
        };
        Some(format!("{} ({side})", self.show(value)))
    }
}

/// How a block-compressed set's layout and effort were chosen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockChoice {
    /// The block encoder that finished the set.
    pub encoder: Encoder,
    /// Why the GPU encoder failed, where it began this set and a CPU encoder (`encoder`)
    /// finished it. Absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gpu_failed: Option<String>,
    /// Where `n` went.
    pub layout: BlockLayout,
    /// The effort, on the one scale every codec maps to its own (`Codec::effort_name`).
    pub bc7_effort: Effort,
    /// An ASTC set's footprint (`"4x4"`); absent for BC sets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub astc_block: Option<AstcBlock>,
    /// The first image's compression where its blocks are Basis Universal's
    /// (`"ktx2-uastc"`, `"ktx2-etc1s"`); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basis: Option<Compression>,
    /// The preset's budget.
    pub budget: BlockBudget,
    /// Whether the chosen trial meets it.
    pub within_budget: bool,
    /// Where the search weighed more effort in an 8-bit layout: the `k_a` error of the same
    /// files uncompressed (as `ktx2-raw` writes them), what storage alone costs before any
    /// block does. Absent otherwise (a trial met the budget first, or the layout in question
    /// was BC6H's half floats).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncompressed_ka_error_srgb: Option<SrgbError>,
    /// Why this one, in a sentence.
    pub reason: String,
    /// Every trial, in the order run.
    pub trials: Vec<Trial>,
}

impl BlockChoice {
    /// The trial kept (the one whose layout and effort the set has).
    pub fn kept(&self) -> Option<&Trial> {
        self.trials
            .iter()
            .rev()
            .find(|t| t.layout == self.layout && t.bc7_effort == self.bc7_effort)
    }

    /// One line for people: the layout and effort chosen, the encoder, and the budget's
    /// verdict with every number it rests on, beside the numbers it does not judge (the
    /// manifest's `blocks` has the trials and the reason).
    pub fn summary(&self) -> String {
        let basis = match self.basis {
            Some(Compression::Ktx2Etc1s) => Some("ETC1S"),
            _ if self.encoder == Encoder::Basisu => Some("UASTC"),
            _ => None,
        };
        let layout = match (self.layout, self.astc_block) {
            (BlockLayout::Packed, _) if let Some(b) = basis => {
                format!("{b}, n packed in k_d's alpha")
            }
            (BlockLayout::NApart, _) if let Some(b) = basis => format!("{b}, n apart"),
            (BlockLayout::Packed, None) => "n packed in k_d's BC7".to_string(),
            (BlockLayout::NApart, None) => "n apart (BC4/BC5), colour BC7".into(),
            (BlockLayout::HalfColour, _) => "n apart (BC4/BC5), colour BC6H".into(),
            (BlockLayout::Packed, Some(b)) => format!("ASTC {b}, n packed in k_d's alpha"),
            (BlockLayout::NApart, Some(b)) => format!("ASTC {b}, n apart"),
        };
        let encoder = match self.encoder {
            Encoder::Ispc => "ISPC",
            Encoder::Portable => "portable CPU",
            Encoder::Gpu => "GPU",
            Encoder::Astcenc => "astcenc",
            Encoder::Basisu => "Basis Universal",
        };
        let encoder = if self.gpu_failed.is_some() {
            format!("{encoder} encoder (the GPU encoder failed part-way)")
        } else {
            format!("{encoder} encoder")
        };
        let (judged, rest) = Measure::split(&self.budget);
        let kept = self.kept();
        let value = |m: Measure| kept.and_then(|t| m.of(t));
        let judged: Vec<String> = judged
            .iter()
            .filter_map(|m| m.judge(value(*m), &self.budget))
            .collect();
        let rest: Vec<String> = rest.iter().map(|m| m.show(value(*m))).collect();
        let side = if self.within_budget { "within" } else { "over" };
        let mut verdict = format!(
            "{side} the k_a budget ({}), which judges level 0: {}",
            self.budget.describe(),
            judged.join(", ")
        );
        if !self.within_budget {
            let floor = self
                .uncompressed_ka_error_srgb
                .filter(|f| f.over(&self.budget) != (false, false))
                .map_or_else(String::new, |f| {
                    format!(
                        "; the same files uncompressed are over it too (k_a within {:.2} levels for 99.9 % of texels, mean {:.3}): 8-bit storage alone misses it",
                        f.p999, f.mean
                    )
                });
            verdict = format!(
                "{verdict}; kept the nearest of {} trials by {NEAREST_RULE}{floor}",
                self.trials.len()
            );
        }
        format!(
            "{layout} at {:?}, {encoder}: {verdict}; not judged: {}, nor the mip levels past 0",
            self.bc7_effort,
            rest.join(", ")
        )
    }
}

/// A fraction as a percentage with two decimals.
pub(super) fn pct(v: f64) -> String {
    format!("{:.2} %", v * 100.0)
}
