//! Block-compressed sets: the layout and BC7 effort, chosen by measurement.
//!
//! The export encodes level 0 with the cheapest profile first (the packed layout, `n` in
//! `k_d`'s BC7 alpha, at BC7's lowest effort), measures the set's `k_a` error as a consumer
//! decodes it (in levels of 8-bit sRGB of the ambient-lit colour, and relative) and PSNR, and
//! spends more only while the preset's budget is not met:
//! - where the packed layout fails, `n` moves out of the colour blocks (its own BC4 plane,
//!   or beside a grey `k_s` in a BC5 image) at the same effort: `n`'s endpoints no longer
//!   shared with `k_d`'s, both come out better;
//! - where that fails too, the colour images become BC6H (linear half floats, the same
//!   bytes as BC7): BC7 keeps 8-bit sRGB and its mode 6 shares one p-bit across channels,
//!   so flat blocks come out a level off, a large relative error in dark texels where `k_s`
//!   adds little;
//! - then the layout nearest the budget takes more effort, a step at a time up to the
//!   preset's ceiling, while the rate at which the last step improved each failing measure
//!   could still meet the budget;
//! - at the ceiling, the trial nearest the budget is kept, and the manifest says
//!   the budget was not met.
//!
//! "Nearest" is one rule ([`super::choice::NEAREST_RULE`], in the notices' words): fewest
//! failing measures, then the worst measure's ratio to its limit, the next, and so on, then
//! every number a trial shows. So no trial is kept while another is as good on every number
//! and better on one.
//!
//! The manifest records every trial and why the chosen one was chosen.

use std::time::Instant;

use super::budget::{better, nearer, reachable, storage_misses, within};
use super::choice::{BlockChoice, BlockLayout, NEAREST_RULE, Trial};
use super::encode::{Encoded, KtxTexels, StoredImage, ktx_image, spaces_of, srgb_image};
use super::failure::Failure;
use super::manifest::{Comp, is_colour};
use super::measure::{Shape, ka_error_of_set};
use super::perceptual::SrgbError;
use super::role::{Images, Role};
use super::trial::{ImageCodec, TrialImage};
use crate::blocks::{self, BlockEncoder, Coder};
use crate::codec::{Effort, Encoder};
use crate::encoding::{KaError, NEncoding};
use crate::file_kind::Compression;
use crate::preset::ExportPreset;
use glam::Vec3;
use kapaint_base::task::Progress;
use kapaint_model::texel::Texel;
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// Whether an image of `comps` is colour that BC6H can hold: three colour components.
fn half_image(comps: &[Comp]) -> bool {
    comps.len() == 3 && comps.iter().all(|c| is_colour(*c))
}

/// The images of the n-apart layout for the packed `images`, or `None` where `n` is not in a
/// colour image (constant, or already beside `k_s`).
pub(super) fn n_apart(images: &Images, mono_ks: bool) -> Option<Images> {
    let packed = images
        .iter()
        .position(|(_, c)| c.len() == 4 && c[3] == Comp::N)?;
    let mut out = images.clone();
    out[packed] = (Role::Kd, out[packed].1[..3].to_vec());
    match out.iter().position(|(role, _)| *role == Role::Ks) {
        Some(ks) if mono_ks => out[ks] = (Role::KsN, vec![Comp::Ks(0), Comp::N]),
        _ => out.insert(packed + 1, (Role::N, vec![Comp::N])),
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
    /// A block encoder the caller brought (a GPU's), used before the CPU's.
    pub brought: Option<&'a dyn BlockEncoder>,
}

/// The images of `want` (three-component colour as half floats where `half`): what the
/// last trial shares with it is kept (with its blocks), what it lacks is made.
///
/// # Errors
/// The preset has no blocks.
fn prepare<'a>(
    images: &mut Vec<TrialImage<'a>>,
    want: &Images,
    half: bool,
    job: &Job<'a>,
) -> Result<(), Failure> {
    let half_of = |comps: &[Comp]| half && half_image(comps);
    images.retain(|i| {
        want.iter()
            .any(|(r, c)| *r == i.role && *c == i.comps && half_of(c) == i.half)
    });
    for (role, comps) in want {
        if !images.iter().any(|i| i.role == *role) {
            let half = half_of(comps);
            let srgb = !half && srgb_image(job.preset.format, comps);
            let texels = KtxTexels::new(job.texels, job.ka, comps, srgb, half, job.n_enc);
            let format = job.preset.format;
            let codec = format
                .codec(texels.spaces())
                .map(ImageCodec::Strips)
                .or_else(|| format.whole_image(texels.spaces()).map(ImageCodec::Whole))
                .ok_or_else(|| format!("{} has no blocks", format.name()))?;
            let level0 = texels.level0();
            images.push(TrialImage {
                role: *role,
                comps: comps.clone(),
                srgb,
                half,
                texels,
                codec,
                level0,
                mips: None,
                compressed: None,
            });
        }
    }
    images.sort_by_key(|i| want.iter().position(|(r, _)| *r == i.role));
    Ok(())
}

impl Job<'_> {
    fn measure(&self, stored: &[StoredImage<'_>]) -> (KaError, SrgbError) {
        ka_error_of_set(
            self.texels,
            self.shape,
            stored,
            self.preset.format,
            self.model,
            self.approx,
        )
    }
}

/// The chosen images, level 0 as compressed, with their mip chains: the set's files.
fn with_mips(
    images: &mut [TrialImage<'_>],
    coder: (Coder<'_>, Effort),
    size: (u32, u32),
    progress: &Progress,
) -> Result<Vec<Encoded>, Failure> {
    progress.start("encode", images.len() as u64 * u64::from(size.1));
    let mut encoded = Vec::with_capacity(images.len());
    for image in images {
        let written = image.written(coder, size, progress)?;
        if progress.is_cancelled() {
            return Err(Failure::Cancelled);
        }
        encoded.push((
            image.role.file("ktx2"),
            image.comps.clone(),
            ktx_image(written, image.srgb, image.half),
        ));
    }
    Ok(encoded)
}

fn tried(trials: &[Trial], layout: BlockLayout) -> bool {
    trials.iter().any(|t| t.layout == layout)
}

/// Encodes a block-compressed set: trials on level 0 from the cheapest profile up (see the
/// module), then the chosen images with their mip chains.
///
/// # Errors
/// A failed encode, or [`Failure::Cancelled`].
pub(super) fn encode_blocks(
    job: &Job<'_>,
    packed: &Images,
    apart: Option<&Images>,
    progress: &Progress,
) -> Result<(Vec<Encoded>, BlockChoice), Failure> {
    // The brought encoder encodes what it can; the CPU the rest ([`blocks::encode`]).
    let encoder = Coder::best(job.brought);
    let search = Search::new(job, packed, apart);
    let mut images = Vec::new();
    let found = search.run(&mut images, encoder, progress)?;
    let pick = found.trials[found.chosen].clone();
    if (pick.layout, pick.bc7_effort) != found.last {
        // The pick is an earlier trial: encode its level 0 again.
        let want = search.images_of(pick.layout);
        prepare(&mut images, want, pick.layout.half(), job)?;
        compress_all(&mut images, encoder, pick.bc7_effort, job, progress)?;
    }
    let encoded = with_mips(&mut images, (encoder, pick.bc7_effort), job.size, progress)?;
    // What the manifest names: the encoder of the first image's blocks (a GPU that failed on
    // the way handed the rest to the CPU, for the rest of the process).
    let names = images.first().map_or(encoder.name(), |i| match &i.codec {
        ImageCodec::Strips(codec) => blocks::encoder_name(encoder, &**codec),
        ImageCodec::Whole(_) => Encoder::Basisu,
    });
    let budget = job.preset.budget;
    let within_budget = within(&budget, &pick);
    let uncompressed_ka_error_srgb = found.floor;
    Ok((
        encoded,
        BlockChoice {
            encoder: names,
            gpu_failed: encoder.failure(),
            layout: pick.layout,
            bc7_effort: pick.bc7_effort,
            astc_block: job.preset.format.astc_block(),
            basis: images
                .first()
                .map(|i| match &i.codec {
                    ImageCodec::Strips(codec) => codec.compression(),
                    ImageCodec::Whole(codec) => codec.compression(),
                })
                .filter(|c| matches!(c, Compression::Ktx2Uastc | Compression::Ktx2Etc1s)),
            budget,
            within_budget,
            uncompressed_ka_error_srgb,
            reason: found.reason,
            trials: found.trials,
        },
    ))
}

/// The search's answer: every trial, the one chosen and why, and the layout and effort the
/// images were last compressed at.
struct Found {
    trials: Vec<Trial>,
    chosen: usize,
    reason: String,
    last: (BlockLayout, Effort),
    /// The same files uncompressed, where more effort in an 8-bit layout was weighed.
    floor: Option<SrgbError>,
}

/// The layouts and efforts a block-compressed set may take.
struct Search<'j, 'a> {
    job: &'j Job<'a>,
    packed: &'j Images,
    apart: &'j Images,
    /// The layouts to try at the lowest effort, in order.
    layouts: Vec<BlockLayout>,
    /// The efforts up to the preset's ceiling, lowest first.
    efforts: Vec<Effort>,
}

impl<'j, 'a> Search<'j, 'a> {
    fn new(job: &'j Job<'a>, packed: &'j Images, apart: Option<&'j Images>) -> Self {
        let ceiling = job.preset.format.max_effort().unwrap_or_default();
        let efforts = Effort::ALL.into_iter().filter(|e| *e <= ceiling).collect();
        // Fewest bytes first; then, for the same bytes, n apart in BC7 (the more common
        // format: with blocks of one colour exact, its stroke edges come nearer the budget
        // than BC6H's), then BC6H colour where there is a colour image and the format allows
        // it (half floats meet a mean that 8-bit storage itself misses; ASTC has no LDR half
        // floats).
        let format = job.preset.format;
        let apart_images = apart.unwrap_or(packed);
        let mut layouts = vec![BlockLayout::Packed];
        if apart.is_some() {
            layouts.push(BlockLayout::NApart);
        }
        if format.half_colour() && apart_images.iter().any(|(_, c)| half_image(c)) {
            layouts.push(BlockLayout::HalfColour);
        }
        // Where every block costs the same whatever it holds (ASTC's 16 bytes) and both
        // layouts have as many images (a grey k_s: kd_n + ks, or kd + ks_n), they cost the
        // same, and n apart, on endpoints of its own, goes first.
        if format.same_bytes_per_block() && apart.is_some_and(|a| a.len() == packed.len()) {
            layouts.reverse();
        }
        Self {
            job,
            packed,
            apart: apart_images,
            layouts,
            efforts,
        }
    }

    /// The images of a layout.
    fn images_of(&self, layout: BlockLayout) -> &'j Images {
        match layout {
            BlockLayout::Packed => self.packed,
            BlockLayout::NApart | BlockLayout::HalfColour => self.apart,
        }
    }

    /// Trials until one meets the budget or more effort would not: the layouts in order at
    /// the lowest effort, then more effort for the one nearest the budget.
    fn run(
        &self,
        images: &mut Vec<TrialImage<'a>>,
        encoder: Coder<'_>,
        progress: &Progress,
    ) -> Result<Found, Failure> {
        let budget = self.job.preset.budget;
        let (mut layout, mut step) = (self.layouts[0], 0);
        let mut trials: Vec<Trial> = Vec::new();
        let mut floor = None;
        loop {
            let effort = self.efforts[step];
            // What the images hold once this trial ran (`layout` may move on below).
            let ran = (layout, effort);
            prepare(images, self.images_of(layout), layout.half(), self.job)?;
            let trial = run_trial(images, encoder, layout, effort, self.job, progress)?;
            let here = trial.describe(&budget);
            let met = within(&budget, &trial);
            trials.push(trial);
            if met {
                return Ok(Found {
                    chosen: trials.len() - 1,
                    trials,
                    reason: format!("{here}: within the budget"),
                    last: ran,
                    floor,
                });
            }
            // The layout failed: the next one, at the same effort.
            if let Some(next) = self.layouts.iter().find(|l| !tried(&trials, **l)) {
                layout = *next;
                continue;
            }
            // Then more effort for the best layout, while it buys something.
            if trials.len() == self.layouts.len() {
                layout = trials
                    .iter()
                    .reduce(|a, b| better(a, b, &budget))
                    .map_or(layout, |t| t.layout);
            }
            // What 8-bit files cost uncompressed, where more effort in an 8-bit layout is in
            // question (measured once, from images that are not half floats: every 8-bit
            // layout stores the same values): no block does better than that.
            if floor.is_none() && !layout.half() && images.iter().all(|i| !i.half) {
                let plain: Vec<StoredImage> = images.iter().map(TrialImage::uncompressed).collect();
                floor = Some(self.job.measure(&plain).1);
            }
            let stored_misses = self.storage_misses(floor, &trials, layout);
            if !stored_misses && let Some(next) = self.more_effort(&trials, layout, step) {
                step = next;
                continue;
            }
            return Ok(self.nearest(trials, step, &here, ran, (stored_misses, floor)));
        }
    }

    /// Whether no effort can bring 8-bit `layout` within the budget: its last trial misses it
    /// only where the same files uncompressed (`floor`) miss it too.
    fn storage_misses(
        &self,
        floor: Option<SrgbError>,
        trials: &[Trial],
        layout: BlockLayout,
    ) -> bool {
        let (Some(floor), false) = (floor, layout.half()) else {
            return false;
        };
        trials
            .iter()
            .rev()
            .find(|t| t.layout == layout)
            .is_some_and(|t| storage_misses(t, &floor, &self.job.preset.budget))
    }

    /// The next effort for `layout` after `step`, where more effort may still meet the budget.
    fn more_effort(&self, trials: &[Trial], layout: BlockLayout, step: usize) -> Option<usize> {
        let left = self.efforts.len() - step - 1;
        if left == 0 || !reachable(trials, layout, &self.job.preset.budget, left) {
            return None;
        }
        // Skip the steps that would encode the same blocks again (BC6H has no effort between
        // ultra-fast and very-fast; BC4 and BC5 have one), while a step is left after them.
        let mut next = step + 1;
        while next + 1 < self.efforts.len()
            && self.same_blocks(layout, self.efforts[step], self.efforts[next])
        {
            next += 1;
        }
        Some(next)
    }

    /// Whether every image of `layout` is encoded alike at efforts `a` and `b` (its codec
    /// does not tell them apart).
    fn same_blocks(&self, layout: BlockLayout, a: Effort, b: Effort) -> bool {
        let (job, format) = (self.job, self.job.preset.format);
        self.images_of(layout).iter().all(|(_, comps)| {
            let half = layout.half() && half_image(comps);
            let srgb = !half && srgb_image(format, comps);
            let spaces = spaces_of(comps, srgb, half, job.n_enc);
            // A whole-image codec (ETC1S) tells every effort apart.
            format.whole_image(&spaces).is_none()
                && format
                    .codec(&spaces)
                    .is_none_or(|c| c.effort(a) == c.effort(b))
        })
    }

    /// Nothing met the budget: the trial nearest it, and why.
    fn nearest(
        &self,
        trials: Vec<Trial>,
        step: usize,
        here: &str,
        last: (BlockLayout, Effort),
        (stored_misses, floor): (bool, Option<SrgbError>),
    ) -> Found {
        let budget = &self.job.preset.budget;
        let chosen = (0..trials.len())
            .reduce(|a, b| {
                if nearer(&trials[a], &trials[b], budget) {
                    b
                } else {
                    a
                }
            })
            .unwrap_or(0);
        let kept = trials[chosen].describe(budget);
        // The last trial where it is not the one kept.
        let last_tried = if chosen + 1 == trials.len() {
            String::new()
        } else {
            format!(" (the last: {here})")
        };
        let reason = if stored_misses {
            format!(
                "no trial met the budget, and no effort can: the same files uncompressed miss it too; kept the trial nearest it, {kept}, by {NEAREST_RULE}{last_tried}"
            )
        } else if step + 1 < self.efforts.len() {
            format!(
                "no trial met the budget, and more effort, at the rate the last step bought, would not: kept the trial nearest it, {kept}, by {NEAREST_RULE}{last_tried}"
            )
        } else {
            format!(
                "no trial up to {:?} met the budget: kept the trial nearest it, {kept}, by {NEAREST_RULE}{last_tried}",
                self.efforts[self.efforts.len() - 1]
            )
        };
        Found {
            trials,
            chosen,
            reason,
            last,
            floor,
        }
    }
}

/// Compresses every image's level 0 at `effort`.
fn compress_all(
    images: &mut [TrialImage<'_>],
    encoder: Coder<'_>,
    effort: Effort,
    job: &Job<'_>,
    progress: &Progress,
) -> Result<(), Failure> {
    progress.start("encode", images.len() as u64 * u64::from(job.size.1));
    for image in images {
        image.compress(encoder, effort, job.size, progress)?;
        if progress.is_cancelled() {
            break;
        }
    }
    Ok(())
}

/// One trial: level 0 of `images` compressed at `effort`, and the set measured as a consumer
/// decodes it.
fn run_trial(
    images: &mut [TrialImage<'_>],
    encoder: Coder<'_>,
    layout: BlockLayout,
    effort: Effort,
    job: &Job<'_>,
    progress: &Progress,
) -> Result<Trial, Failure> {
    let started = Instant::now();
    compress_all(images, encoder, effort, job, progress)?;
    if progress.is_cancelled() {
        return Err(Failure::Cancelled);
    }
    let stored: Vec<StoredImage> = images.iter().map(TrialImage::stored).collect();
    let (ka_error, ka_error_srgb) = job.measure(&stored);
    let min_psnr = images
        .iter_mut()
        .filter_map(|i| i.psnr().into_iter().flatten().reduce(f64::min))
        .reduce(f64::min);
    Ok(Trial {
        layout,
        bc7_effort: effort,
        ka_error,
        ka_error_srgb: Some(ka_error_srgb),
        min_psnr,
        seconds: started.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn n_apart_takes_n_out_of_the_colour_image() {
        let kd_n = (
            Role::KdN,
            vec![Comp::Kd(0), Comp::Kd(1), Comp::Kd(2), Comp::N],
        );
        let kd = (Role::Kd, vec![Comp::Kd(0), Comp::Kd(1), Comp::Kd(2)]);
        // Grey k_s: n joins it in a BC5 image.
        let grey = vec![kd_n.clone(), (Role::Ks, vec![Comp::Ks(0)])];
        assert_eq!(
            n_apart(&grey, true).unwrap(),
            vec![kd.clone(), (Role::KsN, vec![Comp::Ks(0), Comp::N])]
        );
        // Colour k_s, or k_s constant: n alone, as BC4.
        let colour = vec![
            kd_n.clone(),
            (Role::Ks, vec![Comp::Ks(0), Comp::Ks(1), Comp::Ks(2)]),
        ];
        assert_eq!(
            n_apart(&colour, false).unwrap()[1],
            (Role::N, vec![Comp::N])
        );
        assert_eq!(
            n_apart(&vec![kd_n], true).unwrap(),
            vec![kd, (Role::N, vec![Comp::N])]
        );
        // n already apart from colour: nothing to move.
        assert!(n_apart(&vec![(Role::KsN, vec![Comp::Ks(0), Comp::N])], true).is_none());
    }
}
