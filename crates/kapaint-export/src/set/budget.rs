//! A block-compressed set's trials judged against the preset's budget: whether one meets it,
//! how far each falls short, which of two is nearer (the rule the notices name,
//! [`super::choice::NEAREST_RULE`]), and whether more effort may still reach it at the rate
//! the last step bought.

use std::cmp::Ordering;

use super::choice::{BlockLayout, Measure, Trial};
use super::perceptual::SrgbError;
use crate::preset::BlockBudget;

/// Whether a trial meets the budget: its sRGB-level error, and the optional limits.
pub(super) fn within(budget: &BlockBudget, t: &Trial) -> bool {
    failing(t, budget) == 0
}

/// Each measure the budget judges of a trial as a ratio to its limit (above 1 fails), in
/// [`Measure::ALL`]'s order: the sRGB-level p99.9 and mean, then the optional relative errors,
/// and PSNR as the ratio of squared errors.
pub(super) fn ratios(t: &Trial, budget: &BlockBudget) -> Vec<f64> {
    Measure::ALL
        .into_iter()
        .filter_map(|m| {
            let limit = m.limit(budget)?;
            let v = m.of(t);
            Some(match (m, v) {
                (Measure::Psnr, p) => p.map_or(0.0, |p| 10_f64.powf((limit - p) / 10.0)),
                (_, v) => {
                    let v = v.unwrap_or(0.0);
                    if limit > 0.0 {
                        v / limit
                    } else if v > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    }
                }
            })
        })
        .collect()
}

/// How many of a trial's judged measures fail (see [`ratios`]).
fn failing(t: &Trial, budget: &BlockBudget) -> usize {
    ratios(t, budget).iter().filter(|r| **r > 1.0).count()
}

/// Where a trial stands by [`super::choice::NEAREST_RULE`], to compare in order: how many
/// judged measures fail; their ratios to their limits, the worst first; then every measure's
/// badness ([`Measure::badness`]), judged or not.
fn standing(t: &Trial, budget: &BlockBudget) -> (usize, Vec<f64>, Vec<f64>) {
    let mut ratios = ratios(t, budget);
    let failing = ratios.iter().filter(|r| **r > 1.0).count();
    ratios.sort_by(|a, b| b.total_cmp(a));
    let badness = Measure::ALL.map(|m| m.badness(m.of(t))).to_vec();
    (failing, ratios, badness)
}

/// `a` against `b` by [`super::choice::NEAREST_RULE`] (`Less`: `a` is nearer the budget). A
/// trial at least as good as another on every number and better on one comes first: its
/// failing count is no more, its ratios sorted are each no more, and a badness is less.
fn order(a: &Trial, b: &Trial, budget: &BlockBudget) -> Ordering {
    let lexical = |x: &[f64], y: &[f64]| {
        x.iter()
            .zip(y)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(Ordering::Equal)
    };
    let (fails_a, ratios_a, badness_a) = standing(a, budget);
    let (fails_b, ratios_b, badness_b) = standing(b, budget);
    fails_a
        .cmp(&fails_b)
        .then_with(|| lexical(&ratios_a, &ratios_b))
        .then_with(|| lexical(&badness_a, &badness_b))
}

/// The better of two trials against `budget` by [`super::choice::NEAREST_RULE`] (the earlier
/// on a tie: fewer bytes, or the more common format).
pub(super) fn better<'t>(a: &'t Trial, b: &'t Trial, budget: &BlockBudget) -> &'t Trial {
    if nearer(a, b, budget) { b } else { a }
}

/// Whether `b` is nearer `budget` than `a` by [`super::choice::NEAREST_RULE`].
pub(super) fn nearer(a: &Trial, b: &Trial, budget: &BlockBudget) -> bool {
    order(b, a, budget) == Ordering::Less
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
    let failing = failing(t, budget);
    failing > 0
        && failing == usize::from(p999) + usize::from(mean)
        && (!p999 || floor_p999)
        && (!mean || floor_mean)
}
