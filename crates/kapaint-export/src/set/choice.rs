//! What a block-compressed export chose, as its manifest records it: the layout, the effort,
//! every trial measured, and why. Data only: `choose.rs` makes it.

use serde::{Deserialize, Serialize};

use super::perceptual::SrgbError;
use crate::astc_block::AstcBlock;
use crate::blocks::Encoder;
use crate::encoding::KaError;
use crate::preset::{Bc7Quality, BlockBudget};

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
    pub bc7_effort: Bc7Quality,
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
    /// The trial and its measures, for the manifest's reason.
    pub(super) fn describe(&self) -> String {
        let srgb = self.ka_error_srgb.map_or_else(String::new, |e| {
            format!(
                "k_a within {:.2} levels for 99.9 % of texels (mean {:.3}, max {:.2}), ",
                e.p999, e.mean, e.max
            )
        });
        format!(
            "{:?} at {:?}: {srgb}relative max {}, mean {}, PSNR {}",
            self.layout,
            self.bc7_effort,
            pct(self.ka_error.max),
            pct(self.ka_error.mean),
            self.min_psnr
                .map_or_else(|| "exact".into(), |p| format!("{p:.1} dB"))
        )
    }

    /// The trial's sRGB-level error (zero for a trial recorded before it was measured).
    pub(super) fn srgb(&self) -> SrgbError {
        self.ka_error_srgb.unwrap_or_default()
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
    /// BC7's effort (or ASTC's on the same scale: `blocks::astc::preset_of`).
    pub bc7_effort: Bc7Quality,
    /// An ASTC set's footprint (`"4x4"`); absent for BC sets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub astc_block: Option<AstcBlock>,
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
    /// One line for people: the layout and effort chosen, the encoder, and the budget's
    /// verdict (the manifest's `blocks` has the trials and the reason).
    pub fn summary(&self) -> String {
        let layout = match (self.layout, self.astc_block) {
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
        };
        let encoder = if self.gpu_failed.is_some() {
            format!("{encoder} encoder (the GPU encoder failed part-way)")
        } else {
            format!("{encoder} encoder")
        };
        let verdict = if self.within_budget {
            format!("within the k_a budget ({})", self.budget.describe())
        } else {
            let floor = self
                .uncompressed_ka_error_srgb
                .filter(|f| f.over(&self.budget) != (false, false))
                .map_or_else(String::new, |f| {
                    format!(
                        "; the same files uncompressed are over it too (k_a within {:.2} levels for 99.9 % of texels, mean {:.3}): 8-bit storage alone misses it",
                        f.p999, f.mean
                    )
                });
            format!(
                "over the k_a budget ({}): kept the nearest of {} trials{floor}",
                self.budget.describe(),
                self.trials.len()
            )
        };
        format!("{layout} at {:?}, {encoder}, {verdict}", self.bc7_effort)
    }
}

/// A fraction as a percentage with two decimals.
pub(super) fn pct(v: f64) -> String {
    format!("{:.2} %", v * 100.0)
}
