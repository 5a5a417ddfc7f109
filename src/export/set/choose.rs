//! Block-compressed sets: the layout and BC7 effort, chosen by measurement.
//!
//! The export encodes level 0 with the cheapest profile first (the packed layout, `n` in
//! `k_d`'s BC7 alpha, at BC7's lowest effort), measures the set's `k_a` error and PSNR as a
//! consumer decodes them, and spends more only while the preset's budget is not met:
//! - where the packed layout fails, `n` moves out of the colour blocks (its own BC4 plane,
//!   or beside a grey `k_s` in a BC5 image) at the same effort: `n`'s endpoints no longer
//!   shared with `k_d`'s, both come out better;
//! - then the layout with the smaller `k_a` error takes more BC7 effort, a step at a time up
//!   to the preset's ceiling, while the rate at which the last step improved each failing
//!   measure could still meet the budget;
//! - at the ceiling, the trial with the smallest `k_a` error is kept, and the manifest says
//!   the budget was not met.
//!
//! The manifest records every trial and why the chosen one was chosen.

use std::time::Instant;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::encode::{Encoded, KtxTexels, StoredImage, ktx_image, srgb_image};
use super::manifest::Comp;
use super::measure::{Shape, ka_error_of_set};
use crate::export::blocks::{BlockKind, Encoder};
use crate::export::encoding::{KaError, NEncoding};
use crate::export::ktx::{self, Compressed};
use crate::export::preset::{Bc7Quality, BlockBudget, ExportPreset, Format};
use crate::model::texel::Texel;
use crate::reflectance::{AmbientApprox, ShadingModel};
use crate::task::Progress;

/// Where `n` goes in a block-compressed set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BlockLayout {
    /// In `k_d`'s BC7 alpha (the fewest bytes).
    Packed,
    /// Out of the colour blocks: a BC4 plane of its own, or with grey `k_s` in a BC5 image.
    NApart,
}

/// One encoding of level 0 that the export measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// Where `n` was.
    pub layout: BlockLayout,
    /// BC7's effort.
    pub bc7_effort: Bc7Quality,
    /// The set's `k_a` error, level 0 as a consumer decodes it.
    pub ka_error: KaError,
    /// The smallest PSNR of any compressed component (dB; `None` where all are exact).
    pub min_psnr: Option<f64>,
    /// Seconds spent encoding and measuring.
    pub seconds: f64,
}

/// How a block-compressed set's layout and effort were chosen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockChoice {
    /// The block encoder that ran.
    pub encoder: Encoder,
    /// Where `n` went.
    pub layout: BlockLayout,
    /// BC7's effort.
    pub bc7_effort: Bc7Quality,
    /// The preset's budget.
    pub budget: BlockBudget,
    /// Whether the chosen trial meets it.
    pub within_budget: bool,
    /// Why this one, in a sentence.
    pub reason: String,
    /// Every trial, in the order run.
    pub trials: Vec<Trial>,
}

/// A set's images: file stem and components.
pub(super) type Images = Vec<(&'static str, Vec<Comp>)>;

/// The images of the n-apart layout for the packed `images`, or `None` where `n` is not in a
/// colour image (constant, or already beside `k_s`).
pub(super) fn n_apart(images: &Images, mono_ks: bool) -> Option<Images> {
    let packed = images
        .iter()
        .position(|(_, c)| c.len() == 4 && c[3] == Comp::N)?;
    let mut out = images.clone();
    out[packed] = ("kd", out[packed].1[..3].to_vec());
    match out.iter().position(|(stem, _)| *stem == "ks") {
        Some(ks) if mono_ks => out[ks] = ("ks_n", vec![Comp::Ks(0), Comp::N]),
        _ => out.insert(packed + 1, ("n", vec![Comp::N])),
    }
    Some(out)
}

/// Everything the trials share.
pub(super) struct Job<'a> {
    pub texels: &'a [Texel],
    pub ka: &'a [Vec3],
    pub size: (u32, u32),
    pub preset: &'a ExportPreset,
    pub n_enc: Option<NEncoding>,
    pub shape: Shape<'a>,
    pub model: ShadingModel,
    pub approx: AmbientApprox,
}

/// One image of a trial: its texels, level 0 as stored, and level 0 compressed.
struct TrialImage<'a> {
    stem: &'static str,
    comps: Vec<Comp>,
    srgb: bool,
    texels: KtxTexels<'a>,
    level0: Vec<u8>,
    compressed: Option<(Bc7Quality, Compressed)>,
}

impl TrialImage<'_> {
    fn kind(&self, effort: Bc7Quality) -> BlockKind {
        BlockKind::for_channels(self.comps.len(), effort)
    }

    /// Compresses level 0 at `effort`, unless it already is (BC4 and BC5 have one effort).
    fn compress(&mut self, encoder: Encoder, effort: Bc7Quality, size: (u32, u32), p: &Progress) {
        let kind = self.kind(effort);
        let fresh = match &self.compressed {
            Some((e, _)) => matches!(kind, BlockKind::Bc7 { .. }) && *e != effort,
            None => true,
        };
        if fresh {
            let c =
                ktx::compress_level(encoder, kind, &self.level0, size, self.comps.len(), Some(p));
            self.compressed = Some((effort, c));
        } else {
            p.advance(u64::from(size.1));
        }
    }

    fn stored(&self) -> StoredImage {
        StoredImage {
            comps: self.comps.clone(),
            data: self
                .compressed
                .as_ref()
                .map_or_else(Vec::new, |(_, c)| c.decoded.clone()),
            srgb: self.srgb,
        }
    }
}

/// The images of `want`: what the last trial shares with it is kept (with its blocks), what
/// it lacks is made.
fn prepare<'a>(images: &mut Vec<TrialImage<'a>>, want: &Images, job: &Job<'a>) {
    images.retain(|i| want.iter().any(|(s, c)| *s == i.stem && *c == i.comps));
    for (stem, comps) in want {
        if !images.iter().any(|i| i.stem == *stem) {
            let srgb = srgb_image(Format::Ktx2Bc, comps);
            let texels = KtxTexels::new(job.texels, job.ka, comps, srgb, job.n_enc);
            let level0 = texels.level0();
            images.push(TrialImage {
                stem,
                comps: comps.clone(),
                srgb,
                texels,
                level0,
                compressed: None,
            });
        }
    }
    images.sort_by_key(|i| want.iter().position(|(s, _)| *s == i.stem));
}

impl Job<'_> {
    fn measure(&self, stored: &[StoredImage]) -> KaError {
        ka_error_of_set(
            self.texels,
            self.shape,
            stored,
            Format::Ktx2Bc,
            self.model,
            self.approx,
        )
    }
}

fn within(budget: &BlockBudget, ka: KaError) -> bool {
    ka.max <= budget.max_ka_error && ka.mean <= budget.mean_ka_error
}

/// How much better one trial must be than another to count as better (relative).
const MIN_GAIN: f64 = 0.05;

fn tried(trials: &[Trial], layout: BlockLayout) -> bool {
    trials.iter().any(|t| t.layout == layout)
}

/// The better of two trials: the smaller `k_a` max error (the packed layout on a tie: fewer
/// bytes).
fn better<'t>(a: &'t Trial, b: &'t Trial) -> &'t Trial {
    if b.ka_error.max < a.ka_error.max * (1.0 - MIN_GAIN) {
        b
    } else {
        a
    }
}

/// Whether more effort in `layout` may still meet the budget: the first step is always
/// taken; after that, each failing measure, improving at the rate the last step improved it
/// (a factor for the `k_a` errors, dB for PSNR), must reach its budget within the `left`
/// steps there are. A step that bought nothing ends the search.
fn reachable(trials: &[Trial], layout: BlockLayout, budget: &BlockBudget, left: usize) -> bool {
    let mut same = trials.iter().rev().filter(|t| t.layout == layout);
    let Some(now) = same.next() else {
        return true;
    };
    let Some(before) = same.next() else {
        return true;
    };
    let steps = i32::try_from(left).unwrap_or(i32::MAX);
    let error_ok = |now: f64, before: f64, limit: f64| {
        now <= limit || (before > 0.0 && now < before && now * (now / before).powi(steps) <= limit)
    };
    let psnr_ok = match (now.min_psnr, before.min_psnr) {
        (None, _) => true,
        (Some(p), _) if p >= budget.min_psnr => true,
        (Some(p), Some(q)) => p > q && p + (p - q) * f64::from(steps) >= budget.min_psnr,
        (Some(_), None) => false,
    };
    error_ok(now.ka_error.max, before.ka_error.max, budget.max_ka_error)
        && error_ok(
            now.ka_error.mean,
            before.ka_error.mean,
            budget.mean_ka_error,
        )
        && psnr_ok
}

fn pct(v: f64) -> String {
    format!("{:.2} %", v * 100.0)
}

/// Encodes a block-compressed set: trials on level 0 from the cheapest profile up (see the
/// module), then the chosen images with their mip chains.
///
/// # Errors
/// A failed encode, or cancelled (`"cancelled"`).
#[expect(
    clippy::too_many_lines,
    reason = "one search: encode, measure, decide, in a loop"
)]
pub(super) fn encode_blocks(
    job: &Job<'_>,
    packed: &Images,
    apart: Option<&Images>,
    progress: &Progress,
) -> Result<(Vec<Encoded>, BlockChoice), String> {
    let encoder = Encoder::best();
    let budget = job.preset.budget;
    let efforts: Vec<Bc7Quality> = Bc7Quality::ALL
        .into_iter()
        .filter(|e| *e <= job.preset.max_bc7_effort)
        .collect();
    let mut layout = BlockLayout::Packed;
    let mut step = 0;
    let mut trials: Vec<Trial> = Vec::new();
    let mut images: Vec<TrialImage<'_>> = Vec::new();
    let (w, h) = job.size;
    let reason;
    let chosen;
    loop {
        let effort = efforts[step];
        let want = match layout {
            BlockLayout::NApart => apart.unwrap_or(packed),
            BlockLayout::Packed => packed,
        };
        prepare(&mut images, want, job);
        let started = Instant::now();
        progress.start("encode", images.len() as u64 * u64::from(h));
        for image in &mut images {
            image.compress(encoder, effort, (w, h), progress);
            if progress.is_cancelled() {
                return Err("cancelled".into());
            }
        }
        let stored: Vec<StoredImage> = images.iter().map(TrialImage::stored).collect();
        let ka_error = job.measure(&stored);
        let min_psnr = images
            .iter()
            .filter_map(|i| {
                let (_, c) = i.compressed.as_ref()?;
                ktx::psnr(&i.level0, &c.decoded, i.comps.len())
                    .into_iter()
                    .flatten()
                    .reduce(f64::min)
            })
            .reduce(f64::min);
        let psnr_ok = min_psnr.is_none_or(|p| p >= budget.min_psnr);
        let ka_ok = within(&budget, ka_error);
        trials.push(Trial {
            layout,
            bc7_effort: effort,
            ka_error,
            min_psnr,
            seconds: started.elapsed().as_secs_f64(),
        });
        let here = format!(
            "{layout:?} at {effort:?}: k_a max {}, mean {}, PSNR {}",
            pct(ka_error.max),
            pct(ka_error.mean),
            min_psnr.map_or_else(|| "exact".into(), |p| format!("{p:.1} dB"))
        );
        if ka_ok && psnr_ok {
            reason = format!("{here}: within the budget");
            chosen = trials.len() - 1;
            break;
        }
        // The packed layout failed: n apart, at the same effort, next.
        if layout == BlockLayout::Packed && apart.is_some() && !tried(&trials, BlockLayout::NApart)
        {
            layout = BlockLayout::NApart;
            continue;
        }
        // Then more effort for the better layout, while it buys something.
        if trials.len() == 2 && apart.is_some() {
            layout = better(&trials[0], &trials[1]).layout;
        }
        if step + 1 < efforts.len() && reachable(&trials, layout, &budget, efforts.len() - step - 1)
        {
            step += 1;
            continue;
        }
        // Nothing met the budget: the smallest k_a error, at the highest PSNR among equals.
        chosen = (0..trials.len())
            .min_by(|a, b| {
                let (x, y) = (&trials[*a], &trials[*b]);
                x.ka_error.max.total_cmp(&y.ka_error.max).then(
                    y.min_psnr
                        .unwrap_or(f64::MAX)
                        .total_cmp(&x.min_psnr.unwrap_or(f64::MAX)),
                )
            })
            .unwrap_or(0);
        reason = if step + 1 < efforts.len() {
            format!(
                "no trial met the budget, and more effort, at the rate the last step bought, would not: kept the smallest k_a error ({here} last)"
            )
        } else {
            format!(
                "no trial up to {:?} met the budget: kept the smallest k_a error ({here} last)",
                job.preset.max_bc7_effort
            )
        };
        break;
    }
    let pick = trials[chosen].clone();
    if pick.layout != layout || pick.bc7_effort != efforts[step] {
        // The pick is an earlier trial: encode its level 0 again.
        let want = match pick.layout {
            BlockLayout::NApart => apart.unwrap_or(packed),
            BlockLayout::Packed => packed,
        };
        prepare(&mut images, want, job);
        progress.start("encode", images.len() as u64 * u64::from(h));
        for image in &mut images {
            image.compress(encoder, pick.bc7_effort, (w, h), progress);
        }
    }
    // The chosen images with their mips.
    progress.start("encode", images.len() as u64 * u64::from(h));
    let mut encoded = Vec::with_capacity(images.len());
    for image in images {
        let compressed = image.compressed.map(|(_, c)| c);
        let written = ktx::encode(
            &image.texels.source((w, h), &image.level0),
            Some((encoder, pick.bc7_effort)),
            compressed,
            progress,
        )?;
        if progress.is_cancelled() {
            return Err("cancelled".into());
        }
        encoded.push((
            format!("{}.ktx2", image.stem),
            image.comps,
            ktx_image(written, image.srgb),
        ));
    }
    let within_budget =
        within(&budget, pick.ka_error) && pick.min_psnr.is_none_or(|p| p >= budget.min_psnr);
    Ok((
        encoded,
        BlockChoice {
            encoder,
            layout: pick.layout,
            bc7_effort: pick.bc7_effort,
            budget,
            within_budget,
            reason,
            trials,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn n_apart_takes_n_out_of_the_colour_image() {
        let kd_n = ("kd_n", vec![Comp::Kd(0), Comp::Kd(1), Comp::Kd(2), Comp::N]);
        let kd = ("kd", vec![Comp::Kd(0), Comp::Kd(1), Comp::Kd(2)]);
        // Grey k_s: n joins it in a BC5 image.
        let grey = vec![kd_n.clone(), ("ks", vec![Comp::Ks(0)])];
        assert_eq!(
            n_apart(&grey, true).unwrap(),
            vec![kd.clone(), ("ks_n", vec![Comp::Ks(0), Comp::N])]
        );
        // Colour k_s, or k_s constant: n alone, as BC4.
        let colour = vec![
            kd_n.clone(),
            ("ks", vec![Comp::Ks(0), Comp::Ks(1), Comp::Ks(2)]),
        ];
        assert_eq!(n_apart(&colour, false).unwrap()[1], ("n", vec![Comp::N]));
        assert_eq!(
            n_apart(&vec![kd_n], true).unwrap(),
            vec![kd, ("n", vec![Comp::N])]
        );
        // n already apart from colour: nothing to move.
        assert!(n_apart(&vec![("ks_n", vec![Comp::Ks(0), Comp::N])], true).is_none());
    }
}
