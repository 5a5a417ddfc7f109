//! The `k_a` error as the eye sees it: in levels of 8-bit sRGB of the ambient-lit colour.
//!
//! Under unit ambient light a texel's colour is its `k_a` (per channel, linear). A display
//! shows it sRGB-encoded, clamped to `[0, 1]`; the error of a set's texel is how many 8-bit
//! levels its decoded `k_a`'s encoding lies from the exact one's (continuous, not rounded:
//! half a level is half a level), the largest of the three channels. A relative error on a
//! near-black texel is invisible here, a few levels on a mid grey are not.

use serde::{Deserialize, Serialize};

use crate::preset::BlockBudget;

/// Statistics of the error in levels of 8-bit sRGB (see the module).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SrgbError {
    /// The largest.
    pub max: f64,
    /// The 99.9th percentile (to a 64th of a level).
    pub p999: f64,
    /// The mean over texels.
    pub mean: f64,
}

impl SrgbError {
    /// Which of `budget`'s sRGB-level limits this misses: the p99.9, the mean.
    pub fn over(&self, budget: &BlockBudget) -> (bool, bool) {
        (
            self.p999 > budget.ka_error_srgb_p999,
            self.mean > budget.ka_error_srgb_mean,
        )
    }

    /// In the words the editor and the CLI use: "k_a within 1.4 levels of the displayed colour
    /// for 99.9 % of texels (mean 0.12, max 6.0)".
    pub fn describe(&self) -> String {
        format!(
            "k_a within {:.2} levels of the displayed colour for 99.9 % of texels (mean {:.3}, max {:.2})",
            self.p999, self.mean, self.max
        )
    }
}

/// Intervals of the encoding table over `sqrt(x)` in `[0, 1]`.
const TABLE: usize = 4096;

/// The sRGB encoding, in 8-bit levels, of linear values: a table over `sqrt(x)` read with
/// linear interpolation. In `sqrt(x)` the curve is nearly straight (`x^(1/2.4)` is `u^0.83`),
/// so 4096 intervals (16 KiB, in the first-level cache while a set is measured) keep it within
/// 1e-4 levels of the exact curve everywhere; a table over `x` needed 65536 (256 KiB, a cache
/// miss a lookup: the measure took twice as long).
pub(crate) struct SrgbLevels {
    table: Vec<f32>,
}

impl SrgbLevels {
    pub(crate) fn new() -> Self {
        Self {
            table: (0..=TABLE)
                .map(|i| {
                    let u = f64::from(i as u32) / TABLE as f64;
                    (255.0 * srgb_f64(u * u)) as f32
                })
                .collect(),
        }
    }

    /// The encoding of `linear` (clamped to `[0, 1]`, NaN as 0) in levels.
    #[inline]
    pub(crate) fn levels(&self, linear: f32) -> f32 {
        let x = if linear > 0.0 {
            linear.min(1.0).sqrt() * TABLE as f32
        } else {
            0.0
        };
        let i = (x as usize).min(TABLE - 1);
        let t = x - i as f32;
        self.table[i] + (self.table[i + 1] - self.table[i]) * t
    }

    /// The error of one texel: the largest channel's distance in levels.
    #[inline]
    pub(crate) fn distance(&self, exact: [f32; 3], got: [f32; 3]) -> f32 {
        (0..3).fold(0.0_f32, |worst, c| {
            worst.max((self.levels(got[c]) - self.levels(exact[c])).abs())
        })
    }
}

/// The sRGB encoding of `x` in `[0, 1]`, in `f64`.
fn srgb_f64(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Histogram bins per level.
const PER_LEVEL: f32 = 64.0;
/// Bins: up to 256 levels (the whole range).
const BINS: usize = 256 * 64 + 1;

/// An accumulator of texel errors in levels: max, sum, count and a histogram for the
/// percentile.
#[derive(Clone)]
pub(crate) struct SrgbStats {
    max: f32,
    sum: f64,
    count: u64,
    bins: Vec<u32>,
}

impl SrgbStats {
    pub(crate) fn new() -> Self {
        Self {
            max: 0.0,
            sum: 0.0,
            count: 0,
            bins: vec![0; BINS],
        }
    }

    #[inline]
    pub(crate) fn add(&mut self, levels: f32) {
        self.max = self.max.max(levels);
        self.sum += f64::from(levels);
        self.count += 1;
        let bin = ((levels * PER_LEVEL) as usize).min(BINS - 1);
        self.bins[bin] += 1;
    }

    #[must_use]
    pub(crate) fn merge(mut self, other: &Self) -> Self {
        self.max = self.max.max(other.max);
        self.sum += other.sum;
        self.count += other.count;
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
        self
    }

    /// Max, the 99.9th percentile (the top of its bin, at most the max) and mean.
    pub(crate) fn summary(&self) -> SrgbError {
        let target = (self.count as f64 * 0.999).ceil() as u64;
        let mut seen = 0_u64;
        let mut p999 = self.max;
        for (i, b) in self.bins.iter().enumerate() {
            seen += u64::from(*b);
            if seen >= target {
                p999 = ((i + 1) as f32 / PER_LEVEL).min(self.max);
                break;
            }
        }
        SrgbError {
            max: f64::from(self.max),
            p999: f64::from(p999),
            mean: if self.count > 0 {
                self.sum / self.count as f64
            } else {
                0.0
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_the_srgb_curve_and_the_stats_are_the_errors() {
        let levels = SrgbLevels::new();
        for i in 0..=100_000 {
            // Dense near black, where the curve bends most.
            let x = (f64::from(i) / 100_000.0).powi(3);
            let exact = 255.0 * srgb_f64(x);
            let got = f64::from(levels.levels(x as f32));
            assert!((got - exact).abs() < 1e-3, "{x}: {got} vs {exact}");
        }
        assert_eq!(levels.levels(f32::NAN), 0.0);
        assert!((levels.levels(7.0) - 255.0).abs() < 1e-3);
        // A near-black texel 50 % off is a fraction of a level; a mid grey 2 % off is more.
        assert!(levels.distance([0.0002; 3], [0.0003; 3]) < 0.5);
        assert!(levels.distance([0.2; 3], [0.204; 3]) > 1.0);
        let mut stats = SrgbStats::new();
        for i in 0..1000 {
            stats.add(if i == 0 { 10.0 } else { 0.5 });
        }
        let s = stats.summary();
        assert_eq!(s.max, 10.0);
        assert!((s.mean - (10.0 + 999.0 * 0.5) / 1000.0).abs() < 1e-9);
        assert!((s.p999 - 0.5).abs() <= 1.0 / 64.0 + 1e-9, "{s:?}");
        let both = stats.clone().merge(&stats).summary();
        assert_eq!(both.max, 10.0);
    }
}
