//! The conversion of a PBR texel for one target model, and its error: table lookups per texel
//! (the tables are `table.rs`, made by [`super::fit`]).
//!
//! Roughness indexes a dense table (`LUT_SIZE + 1` entries over `[0, 1]`, linear between
//! them) built once per target from the fitted rows: the exponent between rows is linear in
//! `ln(1 + n)`, the error numerators and GGX means linear in roughness. Below the rows' first
//! roughness (1/32) the exponent runs, linear in `ln(1 + n)`, to a mirror (`N_MAX`) at 0, and
//! the error rows hold their first row's values.

use std::sync::OnceLock;

use glam::Vec3;

use super::fit::KS_NODES;
use super::table::{ERROR, FITTED_N, GGX_MEANS, ROWS};
use super::{DIELECTRIC_F0, Pbr, n_of_roughness, unit};
use crate::model::provenance::ErrorSummary;
use crate::model::texel::{MaterialValue, N_MAX};
use crate::reflectance::ShadingModel;

/// Intervals of the dense roughness table.
const LUT_SIZE: usize = 4096;

/// Rows per unit roughness (row `i` is roughness `(i + 2) / 64`).
const ROWS_PER_UNIT: f32 = 64.0;

/// Row index of the first row.
const FIRST_ROW: f32 = 2.0;

/// One target model's conversion tables.
pub struct Conversion {
    /// The target.
    model: ShadingModel,
    /// Exponent at `r = i / LUT_SIZE`.
    n: Vec<f32>,
    /// GGX `[avg rho_1, avg rho_0]` at the same roughness.
    means: Vec<[f32; 2]>,
    /// The error numerator at the `k_s` nodes, at the same roughness.
    error: Vec<[f32; KS_NODES]>,
}

/// The target's index in the tables.
fn column(model: ShadingModel) -> usize {
    match model {
        ShadingModel::Phong => 0,
        ShadingModel::BlinnPhong => 1,
        ShadingModel::CookTorrance => 2,
    }
}

impl Conversion {
    /// The tables for `model` (built once per process).
    pub fn for_model(model: ShadingModel) -> &'static Self {
        static TABLES: [OnceLock<Conversion>; 3] =
            [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        TABLES[column(model)].get_or_init(|| Self::build(model))
    }

    fn build(model: ShadingModel) -> Self {
        let k = column(model);
        let size = LUT_SIZE + 1;
        let (mut n, mut means, mut error) = (
            Vec::with_capacity(size),
            Vec::with_capacity(size),
            Vec::with_capacity(size),
        );
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        for i in 0..size {
            let r = i as f32 / LUT_SIZE as f32;
            let x = r * ROWS_PER_UNIT - FIRST_ROW;
            let (row, t) = if x <= 0.0 {
                (0, 0.0)
            } else {
                let row = (x as usize).min(ROWS - 2);
                (row, (x - row as f32).min(1.0))
            };
            n.push(if model == ShadingModel::CookTorrance {
                n_of_roughness(r)
            } else if x < 0.0 {
                // To a mirror at r = 0.
                let s = r * ROWS_PER_UNIT / FIRST_ROW;
                lerp(N_MAX.ln_1p(), FITTED_N[0][k].ln_1p(), s).exp_m1()
            } else {
                lerp(FITTED_N[row][k].ln_1p(), FITTED_N[row + 1][k].ln_1p(), t).exp_m1()
            });
            let (m0, m1) = (GGX_MEANS[row], GGX_MEANS[row + 1]);
            means.push([lerp(m0[0], m1[0], t), lerp(m0[1], m1[1], t)]);
            let (e0, e1) = (&ERROR[row][k], &ERROR[row + 1][k]);
            error.push(std::array::from_fn(|j| lerp(e0[j], e1[j], t)));
        }
        Self {
            model,
            n,
            means,
            error,
        }
    }

    /// The target model.
    pub fn model(&self) -> ShadingModel {
        self.model
    }

    /// The dense table's position of a roughness: `(index, fraction)`.
    fn locate(roughness: f32) -> (usize, f32) {
        let x = unit(roughness) * LUT_SIZE as f32;
        let i = (x as usize).min(LUT_SIZE - 1);
        (i, (x - i as f32).min(1.0))
    }

    /// The target's exponent for a roughness.
    pub fn n(&self, roughness: f32) -> f32 {
        let (i, t) = Self::locate(roughness);
        let (a, b) = (self.n[i], self.n[i + 1]);
        (a + (b - a) * t).clamp(0.0, N_MAX)
    }

    /// The roughness whose exponent is `n`: the smoothest roughness the target gives an
    /// exponent at most `n` (the fitted exponents never grow with roughness, and are constant
    /// over the rough end for Phong and Blinn-Phong: a value there comes back as the flat
    /// part's smoothest roughness). For Cook-Torrance, its mapping's inverse.
    pub fn roughness(&self, n: f32) -> f32 {
        let n = crate::reflectance::sanitize_n_f32(n);
        if self.model == ShadingModel::CookTorrance {
            return super::roughness_of_n(n);
        }
        // The first entry at most n (entries are non-increasing).
        let i = self.n.partition_point(|&v| v > n);
        if i == 0 {
            return 0.0;
        }
        if i > LUT_SIZE {
            return 1.0;
        }
        let (a, b) = (self.n[i - 1], self.n[i]);
        let t = if a > b { (a - n) / (a - b) } else { 1.0 };
        (((i - 1) as f32 + t.clamp(0.0, 1.0)) / LUT_SIZE as f32).clamp(0.0, 1.0)
    }

    /// A PBR texel as the target's material: `k_d`, `k_s` as [`super::to_material`], `n`
    /// from the target's table.
    pub fn material(&self, p: Pbr) -> MaterialValue {
        let base = p.base.map(unit);
        let m = unit(p.metallic);
        MaterialValue::new(
            base * (1.0 - m),
            Vec3::splat(DIELECTRIC_F0).lerp(base, m),
            self.n(p.roughness),
        )
    }

    /// The texel's conversion error: per channel, the box average of the absolute difference
    /// between the Cook-Torrance shading of the PBR values and the target's shading of the
    /// converted ones, over the Cook-Torrance mean `(2/pi) k_d + k_s avg rho_1 + avg rho_0`;
    /// the largest of the three channels.
    pub fn error(&self, p: Pbr) -> f32 {
        let base = p.base.map(unit);
        let m = unit(p.metallic);
        self.error_of(
            base * (1.0 - m),
            Vec3::splat(DIELECTRIC_F0).lerp(base, m),
            p.roughness,
        )
    }

    /// [`Self::error`] of a texel given as its `k_d`, `k_s` (any workflow) and roughness.
    pub fn error_of(&self, kd: Vec3, ks: Vec3, roughness: f32) -> f32 {
        self.error_parts(kd, ks, roughness)
            .iter()
            .filter(|[_, mean]| *mean > 0.0)
            .fold(0.0_f32, |worst, [num, mean]| worst.max(num / mean))
    }

    /// Per channel, the error's `[numerator, Cook-Torrance mean]` (see [`Self::error`]).
    pub fn error_parts(&self, kd: Vec3, ks: Vec3, roughness: f32) -> [[f32; 2]; 3] {
        let (kd, ks) = (kd.map(unit), ks.map(unit));
        let (i, t) = Self::locate(roughness);
        let lerp = |a: f32, b: f32| a + (b - a) * t;
        let means = [
            lerp(self.means[i][0], self.means[i + 1][0]),
            lerp(self.means[i][1], self.means[i + 1][1]),
        ];
        let (e0, e1) = (&self.error[i], &self.error[i + 1]);
        std::array::from_fn(|c| {
            let (d, s) = (kd[c], ks[c]);
            // k_s nodes are (j / (KS_NODES - 1))^2: interpolate in sqrt(k_s).
            let x = s.sqrt() * (KS_NODES - 1) as f32;
            let j = (x as usize).min(KS_NODES - 2);
            let u = (x - j as f32).min(1.0);
            let at = |e: &[f32; KS_NODES]| e[j] + (e[j + 1] - e[j]) * u;
            [
                lerp(at(e0), at(e1)).max(0.0),
                std::f32::consts::FRAC_2_PI * d + s * means[0] + means[1],
            ]
        })
    }
}

/// Histogram bins of the error, logarithmic from `1e-6` to `1e3` (0.5 % wide).
const BINS: usize = 4096;
const LOG_LO: f32 = -6.0;
const LOG_HI: f32 = 3.0;

fn bin_of(e: f32) -> usize {
    if e <= 0.0 || e.is_nan() {
        return 0;
    }
    let x = (e.log10() - LOG_LO) / (LOG_HI - LOG_LO) * BINS as f32;
    (x.max(0.0) as usize).min(BINS - 1)
}

fn bin_top(i: usize) -> f32 {
    10f32.powf(LOG_LO + (i + 1) as f32 / BINS as f32 * (LOG_HI - LOG_LO))
}

/// Statistics of per-texel conversion errors: max, mean, and the 99th percentile from a
/// histogram (merged across bands).
#[derive(Clone)]
pub struct ErrorStats {
    max: f32,
    sum: f64,
    count: u64,
    bins: Vec<u64>,
}

impl Default for ErrorStats {
    fn default() -> Self {
        Self::new()
    }
}

impl ErrorStats {
    /// No texels yet.
    pub fn new() -> Self {
        Self {
            max: 0.0,
            sum: 0.0,
            count: 0,
            bins: vec![0; BINS],
        }
    }

    /// One texel's error.
    pub fn add(&mut self, e: f32) {
        self.max = self.max.max(e);
        self.sum += f64::from(e);
        self.count += 1;
        self.bins[bin_of(e)] += 1;
    }

    /// Both sets of texels.
    #[must_use]
    pub fn merge(mut self, other: &Self) -> Self {
        self.max = self.max.max(other.max);
        self.sum += other.sum;
        self.count += other.count;
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
        self
    }

    /// Max, mean and 99th percentile (to the histogram's 0.5 %).
    pub fn summary(&self) -> ErrorSummary {
        let target = (self.count as f64 * 0.99).ceil() as u64;
        let mut seen = 0;
        let mut p99 = self.max;
        for (i, b) in self.bins.iter().enumerate() {
            seen += b;
            if seen >= target {
                p99 = bin_top(i).min(self.max);
                break;
            }
        }
        ErrorSummary {
            max: self.max,
            mean: if self.count > 0 {
                (self.sum / self.count as f64) as f32
            } else {
                0.0
            },
            p99,
        }
    }
}
