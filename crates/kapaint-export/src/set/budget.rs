//! A block-compressed set's trials judged against the preset's budget: whether one meets it,
//! how far each falls short, which of two is nearer, and whether more effort may still reach
//! it at the rate the last step bought.

use super::choice::{BlockLayout, Trial};
use super::perceptual::SrgbError;
use crate::preset::BlockBudget;

/// Whether a trial meets the budget: its sRGB-level error, and the optional limits.
pub(super) fn within(budget: &BlockBudget, t: &Trial) -> bool {
    shortfall(t, budget).0 == 0
}

/// How much better one trial must be than another to count as better (relative).
pub(super) const MIN_GAIN: f64 = 0.05;

/// Each of the budget's measures of a trial as a ratio to its limit (above 1 fails): the
/// sRGB-level p99.9 and mean, then the optional relative errors, and PSNR as the ratio of
/// squared errors.
pub(super) fn ratios(t: &Trial, budget: &BlockBudget) -> Vec<f64> {
    let srgb = t.srgb();
    let ratio = |v: f64, limit: f64| {
        if limit > 0.0 {
            v / limit
        } else if v > 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    };
    let mut out = vec![
        ratio(srgb.p999, budget.ka_error_srgb_p999),
        ratio(srgb.mean, budget.ka_error_srgb_mean),
    ];
    out.extend(budget.max_ka_error.map(|m| ratio(t.ka_error.max, m)));
    out.extend(budget.mean_ka_error.map(|m| ratio(t.ka_error.mean, m)));
    out.extend(
        budget
            .min_psnr
            .map(|m| t.min_psnr.map_or(0.0, |p| 10_f64.powf((m - p) / 10.0))),
    );
    out
}

/// How far a trial falls short of the budget: how many of its measures fail, and the worst
/// measure over its limit (see [`ratios`]).
fn shortfall(t: &Trial, budget: &BlockBudget) -> (usize, f64) {
    let ratios = ratios(t, budget);
    let failing = ratios.iter().filter(|r| **r > 1.0).count();
    (failing, ratios.into_iter().fold(0.0, f64::max))
}

/// The better of two trials against `budget`: the one that fails fewer measures, then the one
/// whose worst measure is nearer its limit (the earlier on a tie: fewer bytes, or the more
/// common format).
pub(super) fn better<'t>(a: &'t Trial, b: &'t Trial, budget: &BlockBudget) -> &'t Trial {
    if nearer(a, b, budget) { b } else { a }
}

/// Whether `b` is nearer `budget` than `a` (see [`better`]).
pub(super) fn nearer(a: &Trial, b: &Trial, budget: &BlockBudget) -> bool {
    let (fa, wa) = shortfall(a, budget);
    let (fb, wb) = shortfall(b, budget);
    fb < fa || (fb == fa && wb < wa * (1.0 - MIN_GAIN))
}

/// Whether more effort in `layout` may still meet the budget: the first step is always
/// taken; after that, each failing measure (its ratio to the limit, [`ratios`]), improving by
/// the factor the last step improved it, must reach its limit within the `left` steps there
/// are. A step that bought nothing ends the search.
pub(super) fn reachable(
    trials: &[Trial],
    layout: BlockLayout,
    budget: &BlockBudget,
    left: usize,
) -> bool {
    let mut same = trials.iter().rev().filter(|t| t.layout == layout);
    let Some(now) = same.next() else {
        return true;
    };
    let Some(before) = same.next() else {
        return true;
    };
    let steps = i32::try_from(left).unwrap_or(i32::MAX);
    ratios(now, budget)
        .into_iter()
        .zip(ratios(before, budget))
        .all(|(now, before)| {
            now <= 1.0 || (before > 0.0 && now < before && now * (now / before).powi(steps) <= 1.0)
        })
}

/// Whether `t` misses the budget only by sRGB-level measures that `floor` (the same files
/// uncompressed) misses too: then no encoding of those files can meet it.
pub(super) fn storage_misses(t: &Trial, floor: &SrgbError, budget: &BlockBudget) -> bool {
    let (p999, mean) = t.srgb().over(budget);
    let (floor_p999, floor_mean) = floor.over(budget);
    let failing = shortfall(t, budget).0;
    failing > 0
        && failing == usize::from(p999) + usize::from(mean)
        && (!p999 || floor_p999)
        && (!mean || floor_mean)
}
