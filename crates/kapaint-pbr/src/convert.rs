//! The conversion of a PBR texel for one target model and mapping, and its error: table
//! lookups per texel (the tables are `table.rs`, `table_height.rs` and
//! `table_height_error.bin`, made by [`super::fit`]).
//!
//! Roughness indexes a dense table (`LUT_SIZE + 1` entries over `[0, 1]`, linear between
//! them) built once per target and mapping from the fitted rows: the exponent between rows is
//! linear in `ln(1 + n)`, the lobe height, the error numerators and GGX means linear in
//! roughness. Below the rows' first roughness (1/32) the exponent runs, linear in `ln(1 + n)`,
//! to a mirror (`N_MAX`) at 0, and the other rows hold their first row's values.
//!
//! The height-fitted mapping ([`NMapping::HeightFitted`], Phong and Blinn-Phong) converts
//! `k_s = F0 height(r)`, clamped per channel to `1 - k_d` (the energy guard painting keeps):
//! its error numerator is tabulated over `F0` and the clamp factor `q` (`k_s = q F0 height`),
//! looked up trilinearly in roughness row, `sqrt(F0)` and `q`.

use std::sync::OnceLock;

use glam::Vec3;

use super::fit::{CLAMP_NODES, KS_NODES};
use super::table::{ERROR, FITTED_N, GGX_MEANS, ROWS};
use super::table_height::HEIGHT_FIT;
use super::{DIELECTRIC_F0, Pbr, n_of_roughness, unit};
use kapaint_model::provenance::{ErrorSummary, NMapping};
use kapaint_model::texel::{MaterialValue, N_MAX};
use kapaint_reflectance::ShadingModel;

/// Intervals of the dense roughness table.
const LUT_SIZE: usize = 4096;

/// Rows per unit roughness (row `i` is roughness `(i + 2) / 64`).
const ROWS_PER_UNIT: f32 = 64.0;

/// Row index of the first row.
const FIRST_ROW: f32 = 2.0;

/// How near `k_d + k_s` is to 1 where the energy guard may have clamped `k_s`: two unorm16
/// steps (both are stored as unorm16).
const ON_GUARD: f32 = 2.0 / 65535.0;

/// The height mapping's error numerator, little-endian `f32` per row, target (Phong,
/// Blinn-Phong), `F0` node and clamp node.
const HEIGHT_ERROR_BYTES: &[u8] = include_bytes!("table_height_error.bin");
const _: () = assert!(HEIGHT_ERROR_BYTES.len() == ROWS * 2 * KS_NODES * CLAMP_NODES * 4);

/// [`HEIGHT_ERROR_BYTES`] as numbers (read once per process).
fn height_error() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        HEIGHT_ERROR_BYTES
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    })
}

/// One target model's conversion tables under one mapping.
pub struct Conversion {
    /// The target.
    model: ShadingModel,
    /// Whether the lobe height is fitted (the height-fitted mapping, Phong or Blinn-Phong).
    fitted: bool,
    /// Exponent at `r = i / LUT_SIZE`.
    n: Vec<f32>,
    /// The lobe height at the same roughness (`k_s = F0 height`; 1 unless fitted).
    height: Vec<f32>,
    /// GGX `[avg rho_1, avg rho_0]` at the same roughness.
    means: Vec<[f32; 2]>,
    /// The height-fixed error numerator at the `k_s` nodes, at the same roughness (empty when
    /// fitted: [`height_error`] holds that).
    error: Vec<[f32; KS_NODES]>,
}

/// A roughness' place among the fitted rows: `(row, fraction)`, the first row below them.
fn row_of(roughness: f32) -> (usize, f32) {
    let x = unit(roughness) * ROWS_PER_UNIT - FIRST_ROW;
    if x <= 0.0 {
        return (0, 0.0);
    }
    let row = (x as usize).min(ROWS - 2);
    (row, (x - row as f32).min(1.0))
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

impl Conversion {
    /// The tables for `model` under `mapping` (built once per process; the Cook-Torrance
    /// model's are the same for every mapping).
    pub fn for_model(model: ShadingModel, mapping: NMapping) -> &'static Self {
        const MODELS: usize = ShadingModel::ALL.len();
        static TABLES: [OnceLock<Conversion>; 2 * MODELS] = [const { OnceLock::new() }; 2 * MODELS];
        let fitted = mapping == NMapping::HeightFitted && !model.is_microfacet();
        let slot = model.index() + if fitted { MODELS } else { 0 };
        TABLES[slot].get_or_init(|| Self::build(model, fitted))
    }

    fn build(model: ShadingModel, fitted: bool) -> Self {
        let k = model.index();
        let size = LUT_SIZE + 1;
        let (mut n, mut height, mut means, mut error) = (
            Vec::with_capacity(size),
            Vec::with_capacity(size),
            Vec::with_capacity(size),
            Vec::with_capacity(size),
        );
        let row_n = |row: usize| {
            if fitted {
                HEIGHT_FIT[row][k][0]
            } else {
                FITTED_N[row][k]
            }
        };
        for i in 0..size {
            let r = i as f32 / LUT_SIZE as f32;
            let x = r * ROWS_PER_UNIT - FIRST_ROW;
            let (row, t) = row_of(r);
            n.push(if model.is_microfacet() {
                n_of_roughness(r)
            } else if x < 0.0 {
                // To a mirror at r = 0.
                let s = r * ROWS_PER_UNIT / FIRST_ROW;
                lerp(N_MAX.ln_1p(), row_n(0).ln_1p(), s).exp_m1()
            } else {
                lerp(row_n(row).ln_1p(), row_n(row + 1).ln_1p(), t).exp_m1()
            });
            height.push(if fitted {
                lerp(HEIGHT_FIT[row][k][1], HEIGHT_FIT[row + 1][k][1], t)
            } else {
                1.0
            });
            let (m0, m1) = (GGX_MEANS[row], GGX_MEANS[row + 1]);
            means.push([lerp(m0[0], m1[0], t), lerp(m0[1], m1[1], t)]);
            if !fitted {
                let (e0, e1) = (&ERROR[row][k], &ERROR[row + 1][k]);
                error.push(std::array::from_fn(|j| lerp(e0[j], e1[j], t)));
            }
        }
        Self {
            model,
            fitted,
            n,
            height,
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
        lerp(self.n[i], self.n[i + 1], t).clamp(0.0, N_MAX)
    }

    /// The lobe height for a roughness: `k_s = F0 height` before the energy guard (1 unless
    /// the height is fitted).
    pub fn height(&self, roughness: f32) -> f32 {
        let (i, t) = Self::locate(roughness);
        lerp(self.height[i], self.height[i + 1], t)
    }

    /// The roughness whose exponent is `n`: the smoothest roughness the target gives an
    /// exponent at most `n`. The height-fitted exponents fall strictly, so this is their
    /// inverse; the height-fixed ones are constant over the rough end (a value there comes
    /// back as the flat part's smoothest roughness). For Cook-Torrance, its mapping's inverse.
    pub fn roughness(&self, n: f32) -> f32 {
        let n = kapaint_reflectance::sanitize_n_f32(n);
        if self.model.is_microfacet() {
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

    /// A texel given as its `k_d`, `F0` (any workflow) and roughness as the target's material:
    /// `k_d` as it is, `k_s = F0 height(r)` (per channel at most `1 - k_d` when the height is
    /// fitted), `n` from the table.
    pub fn convert(&self, kd: Vec3, f0: Vec3, roughness: f32) -> MaterialValue {
        let kd = kd.map(unit);
        MaterialValue::new(
            kd,
            self.ks_at(kd, f0, self.height(roughness)),
            self.n(roughness),
        )
    }

    /// The converted `k_s` of `k_d` and `F0` where the lobe height is `height` (see
    /// [`Self::convert`]).
    pub fn ks_at(&self, kd: Vec3, f0: Vec3, height: f32) -> Vec3 {
        let f0 = f0.map(unit);
        if self.fitted {
            (f0 * height).min(Vec3::ONE - kd.map(unit))
        } else {
            f0
        }
    }

    /// A PBR texel as the target's material ([`Self::convert`] of `k_d = base (1 - metallic)`
    /// and `F0 = mix(0.04, base, metallic)`).
    pub fn material(&self, p: Pbr) -> MaterialValue {
        let base = p.base.map(unit);
        let m = unit(p.metallic);
        self.convert(
            base * (1.0 - m),
            Vec3::splat(DIELECTRIC_F0).lerp(base, m),
            p.roughness,
        )
    }

    /// The target's material as a PBR texel, the inverse of [`Self::material`] where the
    /// energy guard left `k_s` whole: roughness by [`Self::roughness`], `F0 = k_s / height`,
    /// then metallic and base colour as [`super::from_material`].
    pub fn pbr(&self, v: MaterialValue) -> Pbr {
        let roughness = self.roughness(v.n);
        self.pbr_with(
            v.kd,
            v.ks,
            roughness,
            self.height(roughness),
            self.f0_tolerance(roughness),
        )
    }

    /// How far from the dielectric `F0` a mean `F0` read back at `roughness` may lie and still
    /// be a dielectric: the stored `k_s`'s unorm16 step, and the dielectric's `F0` times the
    /// height's uncertainty (the roughness read from a half-float `n` is uncertain by a step
    /// of `n` over the exponent's slope), both over the height.
    pub fn f0_tolerance(&self, roughness: f32) -> f32 {
        let (i, _) = Self::locate(roughness);
        let height = self.height(roughness).max(f32::MIN_POSITIVE);
        let slope = |v: &[f32]| (v[i] - v[i + 1]).abs() * LUT_SIZE as f32;
        let n_step = self.n(roughness).max(1e-3) / 1024.0;
        let dr = n_step / slope(&self.n).max(f32::MIN_POSITIVE);
        let dh = (slope(&self.height) * dr).min(1.0);
        (super::F0_TOLERANCE + DIELECTRIC_F0 * dh) / height
    }

    /// [`Self::pbr`] of `k_d` and `k_s` at a roughness already found, with its lobe height and
    /// [`Self::f0_tolerance`] (the export's tables hold them per stored `n`). `F0 = k_s /
    /// height`, at most 1; a dielectric's `F0` is read within the tolerance. A channel the
    /// energy guard clamped (`k_d + k_s = 1`: a near-white dielectric, whose `F0` the clamp
    /// took) reads as the dielectric `F0` where less would be left, so such a dielectric comes
    /// back whole.
    pub fn pbr_with(&self, kd: Vec3, ks: Vec3, roughness: f32, height: f32, tolerance: f32) -> Pbr {
        let (kd, ks) = (kd.map(unit), ks.map(unit));
        let height = height.max(f32::MIN_POSITIVE);
        let mut f0 = (ks / height).map(unit);
        if self.fitted {
            for c in 0..3 {
                if kd[c] + ks[c] >= 1.0 - ON_GUARD && f0[c] < DIELECTRIC_F0 {
                    f0[c] = DIELECTRIC_F0;
                }
            }
        }
        super::pbr_of(kd, f0, roughness, tolerance)
    }

    /// The texel's conversion error: per channel, the box average of the absolute difference
    /// between the Cook-Torrance shading of the PBR values and the target's shading of the
    /// converted ones, over the Cook-Torrance mean `(2/pi) k_d + F0 avg rho_1 + avg rho_0`;
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

    /// [`Self::error`] of a texel given as its `k_d`, `F0` (any workflow) and roughness.
    pub fn error_of(&self, kd: Vec3, f0: Vec3, roughness: f32) -> f32 {
        self.error_parts(kd, f0, roughness)
            .iter()
            .filter(|[_, mean]| *mean > 0.0)
            .fold(0.0_f32, |worst, [num, mean]| worst.max(num / mean))
    }

    /// Per channel, the error's `[numerator, Cook-Torrance mean]` (see [`Self::error`]) for a
    /// texel given as its `k_d`, `F0` and roughness, converted by [`Self::convert`] (the energy
    /// guard's clamp counted).
    pub fn error_parts(&self, kd: Vec3, f0: Vec3, roughness: f32) -> [[f32; 2]; 3] {
        let (kd, f0) = (kd.map(unit), f0.map(unit));
        let (i, t) = Self::locate(roughness);
        let means = [
            lerp(self.means[i][0], self.means[i + 1][0], t),
            lerp(self.means[i][1], self.means[i + 1][1], t),
        ];
        let height = self.height(roughness);
        std::array::from_fn(|c| {
            let (d, s) = (kd[c], f0[c]);
            // F0 nodes are (j / (KS_NODES - 1))^2: interpolate in sqrt(F0).
            let x = s.sqrt() * (KS_NODES - 1) as f32;
            let j = (x as usize).min(KS_NODES - 2);
            let u = (x - j as f32).min(1.0);
            let numerator = if self.fitted {
                let ks = s * height;
                let q = if ks > 1.0 - d { (1.0 - d) / ks } else { 1.0 };
                self.height_numerator(roughness, (j, u), q)
            } else {
                let at = |e: &[f32; KS_NODES]| lerp(e[j], e[j + 1], u);
                lerp(at(&self.error[i]), at(&self.error[i + 1]), t)
            };
            [
                numerator.max(0.0),
                std::f32::consts::FRAC_2_PI * d + s * means[0] + means[1],
            ]
        })
    }

    /// The height mapping's error numerator at a roughness, an `F0` node position `(j, u)`
    /// and clamp factor `q`: trilinear in the row, `sqrt(F0)` and `q`.
    fn height_numerator(&self, roughness: f32, (j, u): (usize, f32), q: f32) -> f32 {
        let table = height_error();
        let (row, t) = row_of(roughness);
        let y = q.clamp(0.0, 1.0) * (CLAMP_NODES - 1) as f32;
        let l = (y as usize).min(CLAMP_NODES - 2);
        let v = (y - l as f32).min(1.0);
        let k = self.model.index();
        let at = |row: usize, j: usize| {
            let base = ((row * 2 + k) * KS_NODES + j) * CLAMP_NODES + l;
            lerp(table[base], table[base + 1], v)
        };
        let in_row = |row: usize| lerp(at(row, j), at(row, j + 1), u);
        lerp(in_row(row), in_row(row + 1), t)
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
