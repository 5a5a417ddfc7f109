//! The reflectance core: the paper's ambient coefficient `k_a` derived from `k_d`, `k_s`, `n`.
//!
//! `k_a = (2/pi) k_d + k_s chi(n)` (eq. 6), where `chi(n)` is the average of the specular lobe
//! over the paper's angle box. [`exact`] computes `chi` to 1e-10; [`AmbientApprox`] selects the
//! closed forms a renderer evaluates per texel. Cook-Torrance ([`cook_torrance`]) carries the
//! method to microfacets: its Fresnel term makes the average affine in `k_s`,
//! `k_a = (2/pi) k_d + k_s chi_1(n) + chi_0(n)`; for Phong and Blinn-Phong `chi_1 = chi` and
//! `chi_0 = 0`, so [`chi_parts_f32`] and [`ka`] treat all three alike.
//!
//! # Input handling (the same on every path)
//!
//! * `n`: NaN and negative values are treated as `0`; `+inf` as the largest finite value.
//!   `chi` is then finite, in `(0, 1]` and non-increasing in `n`.
//! * `k_d`, `k_s`: NaN is treated as `0`; every component is clamped into `[0, 1]`.
//!
//! So every input gives a finite `k_a` in `[0, 2/pi + 1]`, never NaN and never a panic.
//! (Cook-Torrance also clamps `n` to [`cook_torrance::fast::N_MAX`], the limit of its roughness
//! mapping; there `chi_1 + chi_0 <= 0.52`.)

pub mod equivalent;
pub mod exact;
pub mod fast;
mod fast_coeffs;
pub mod fit;
pub mod geometry;
pub mod model;
pub mod quadrature;
pub mod view;
pub mod wgsl;

pub use model::{ShadingModel, cook_torrance};

use glam::Vec3;
use rayon::prelude::*;

/// `2/pi`: the diffuse part of eq. (6) is exactly `(2/pi) k_d`.
pub const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;

/// The paper's printed rounding of `2/pi` in eq. (8) and (11).
pub const PAPER_TWO_OVER_PI: f64 = 0.637;

/// How `chi(n)` is approximated when `k_a` is derived per texel.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
pub enum AmbientApprox {
    /// Eq. (8) and (11) exactly as printed, `0.637 k_d + a k_s (n + b)^c`.
    #[serde(rename = "paper", alias = "PaperPrinted")]
    PaperPrinted,
    /// The printed constants with the Blinn-Phong exponent corrected (`-0.875` is a misprint;
    /// our integrator puts the minimax exponent at [`PAPER_BLINN_CORRECTED_EXPONENT`]).
    #[serde(rename = "paper-corrected", alias = "PaperCorrected")]
    PaperCorrected,
    /// kapaint's own approximation: per-octave polynomials, max relative error <= 1e-4 on
    /// `n in [0, 16384]` for both models (see [`fast`]).
    #[default]
    #[serde(rename = "fast", alias = "Fast")]
    Fast,
}

impl AmbientApprox {
    /// All approximations, in a fixed order for reports.
    pub const ALL: [Self; 3] = [Self::PaperPrinted, Self::PaperCorrected, Self::Fast];

    /// The approximation `model` actually uses: the paper printed none for Cook-Torrance, so
    /// there every method is kapaint's fit.
    #[inline]
    #[must_use]
    pub fn for_model(self, model: ShadingModel) -> Self {
        if model.has_paper_forms() {
            self
        } else {
            Self::Fast
        }
    }

    /// The name used on the command line (`--method`) and in files.
    pub fn name(self) -> &'static str {
        match self {
            Self::PaperPrinted => "paper",
            Self::PaperCorrected => "paper-corrected",
            Self::Fast => "fast",
        }
    }

    /// The approximation [`AmbientApprox::name`] names.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }
}

/// The printed constants `(a, b, c)` of eq. (8): `chi ~= a (n + b)^c` for original Phong.
pub const PAPER_PHONG: (f64, f64, f64) = (0.97, 1.3, -0.873);

/// The printed constants `(a, b, c)` of eq. (11) for Blinn-Phong.
pub const PAPER_BLINN: (f64, f64, f64) = (2.5235, 3.0, -0.875);

/// The Blinn-Phong exponent that makes eq. (11) match its claimed 0.7 % error on `[1, 200]`
/// with the printed `a` and `b`: the minimax exponent, found by `fit::paper_exponent_minimax`.
pub const PAPER_BLINN_CORRECTED_EXPONENT: f64 = -0.858;

/// The constants `(a, b, c)` of `chi ~= a (n + b)^c` for a paper approximation; `None` for
/// [`AmbientApprox::Fast`] and for Cook-Torrance (the paper printed no form for it).
pub fn paper_constants(model: ShadingModel, approx: AmbientApprox) -> Option<(f64, f64, f64)> {
    match (model, approx) {
        (_, AmbientApprox::Fast) | (ShadingModel::CookTorrance, _) => None,
        (ShadingModel::Phong, _) => Some(PAPER_PHONG),
        (ShadingModel::BlinnPhong, AmbientApprox::PaperCorrected) => {
            Some((PAPER_BLINN.0, PAPER_BLINN.1, PAPER_BLINN_CORRECTED_EXPONENT))
        }
        (ShadingModel::BlinnPhong, AmbientApprox::PaperPrinted) => Some(PAPER_BLINN),
    }
}

/// The coefficient of `k_d` in `k_a` for an approximation: the printed 0.637 for the paper's
/// forms, exactly `2/pi` for [`AmbientApprox::Fast`].
pub fn diffuse_factor(approx: AmbientApprox) -> f64 {
    match approx {
        AmbientApprox::Fast => TWO_OVER_PI,
        AmbientApprox::PaperPrinted | AmbientApprox::PaperCorrected => PAPER_TWO_OVER_PI,
    }
}

/// Maps any `f32` exponent onto the supported domain `[0, f32::MAX]` (see module docs).
#[inline]
#[expect(
    clippy::manual_clamp,
    reason = "`clamp` would keep NaN; max/min map it to the lower end"
)]
pub fn sanitize_n_f32(n: f32) -> f32 {
    // `max` returns the non-NaN operand, so NaN becomes 0 here.
    n.max(0.0).min(f32::MAX)
}

/// Maps any `f64` exponent onto the supported domain `[0, f64::MAX]` (see module docs).
#[inline]
#[expect(
    clippy::manual_clamp,
    reason = "`clamp` would keep NaN; max/min map it to the lower end"
)]
pub fn sanitize_n_f64(n: f64) -> f64 {
    n.max(0.0).min(f64::MAX)
}

/// Maps a reflectance coefficient into `[0, 1]`, NaN to 0.
#[inline]
#[expect(
    clippy::manual_clamp,
    reason = "`clamp` would keep NaN; max/min map it to the lower end"
)]
pub fn sanitize_coefficient(k: f32) -> f32 {
    k.max(0.0).min(1.0)
}

/// `[chi_1(n), chi_0(n)]` in `f32`: the specular part of `k_a` is `k_s chi_1 + chi_0`
/// (`chi_1 = chi`, `chi_0 = 0` for Phong and Blinn-Phong).
#[inline]
pub fn chi_parts_f32(model: ShadingModel, approx: AmbientApprox, n: f32) -> [f32; 2] {
    match model {
        ShadingModel::CookTorrance => cook_torrance::fast::chi_f32(sanitize_n_f32(n)),
        ShadingModel::Phong | ShadingModel::BlinnPhong => [chi_f32(model, approx, n), 0.0],
    }
}

/// [`chi_parts_f32`] in `f64`.
pub fn chi_parts_f64(model: ShadingModel, approx: AmbientApprox, n: f64) -> [f64; 2] {
    match model {
        ShadingModel::CookTorrance => cook_torrance::fast::chi_f64(sanitize_n_f64(n)),
        ShadingModel::Phong | ShadingModel::BlinnPhong => [chi_f64(model, approx, n), 0.0],
    }
}

/// `chi(n)` in `f32`, the precision of the per-texel path and of the shaders; for
/// Cook-Torrance, `chi_1(n)` (see [`chi_parts_f32`]).
#[inline]
pub fn chi_f32(model: ShadingModel, approx: AmbientApprox, n: f32) -> f32 {
    let n = sanitize_n_f32(n);
    if model.has_second_part() {
        return chi_parts_f32(model, approx, n)[0];
    }
    match paper_constants(model, approx) {
        None => fast::chi_f32(model, n),
        // Eq. (8) / (11).
        Some((a, b, c)) => a as f32 * (n + b as f32).powf(c as f32),
    }
}

/// `chi(n)` in `f64`; agrees with [`chi_f32`] to `f32` rounding.
pub fn chi_f64(model: ShadingModel, approx: AmbientApprox, n: f64) -> f64 {
    let n = sanitize_n_f64(n);
    if model.has_second_part() {
        return chi_parts_f64(model, approx, n)[0];
    }
    match paper_constants(model, approx) {
        None => fast::chi_f64(model, n),
        Some((a, b, c)) => a * (n + b).powf(c),
    }
}

/// The ambient coefficient `k_a = (2/pi) k_d + k_s chi(n)` of one texel (eq. 6 with the
/// selected approximation of `chi`; eq. (8) or (11) for the paper's forms), and
/// `(2/pi) k_d + k_s chi_1(n) + chi_0(n)` for Cook-Torrance.
#[inline]
pub fn ka(model: ShadingModel, approx: AmbientApprox, kd: Vec3, ks: Vec3, n: f32) -> Vec3 {
    let approx = approx.for_model(model);
    let kd = kd.map(sanitize_coefficient);
    let ks = ks.map(sanitize_coefficient);
    let [slope, offset] = chi_parts_f32(model, approx, n);
    diffuse_factor(approx) as f32 * kd + ks * slope + Vec3::splat(offset)
}

/// Texels per parallel work item of [`derive_ka_par`]: large enough to amortise scheduling,
/// small enough to balance two to sixty-four cores on a 4096^2 map.
pub const DERIVE_CHUNK_TEXELS: usize = 1 << 14;

/// Texels per block of the derive: the block's `chi` values stay in L1 between the two passes.
const DERIVE_BLOCK_TEXELS: usize = 256;

/// Derives a `k_a` buffer from `k_d`, `k_s` and `n` buffers on the calling thread.
///
/// All slices must have the same length. Works in blocks of 256 texels: a scalar pass
/// evaluates `chi` (table lookups do not vectorise), then a flat pass over the `f32`
/// components computes `(2/pi) k_d + k_s chi`, which the compiler vectorises.
pub fn derive_ka(
    model: ShadingModel,
    approx: AmbientApprox,
    kd: &[Vec3],
    ks: &[Vec3],
    n: &[f32],
    out: &mut [Vec3],
) {
    assert_same_lengths(kd, ks, n, out);
    if model.has_second_part() {
        derive_with::<true>(kd, ks, n, out, TWO_OVER_PI as f32, |n| {
            cook_torrance::fast::chi_f32(sanitize_n_f32(n))
        });
        return;
    }
    match paper_constants(model, approx) {
        // Monomorphise the hot loop per approximation so the choice is made once per buffer.
        None => {
            let table = fast::table(model);
            derive_with::<false>(kd, ks, n, out, TWO_OVER_PI as f32, |n| {
                [fast::chi_f32_with(table, sanitize_n_f32(n)), 0.0]
            });
        }
        Some((a, b, c)) => {
            let (a, b, c) = (a as f32, b as f32, c as f32);
            derive_with::<false>(kd, ks, n, out, PAPER_TWO_OVER_PI as f32, |n| {
                [a * (sanitize_n_f32(n) + b).powf(c), 0.0]
            });
        }
    }
}

fn assert_same_lengths(kd: &[Vec3], ks: &[Vec3], n: &[f32], out: &[Vec3]) {
    assert!(
        kd.len() == out.len() && ks.len() == out.len() && n.len() == out.len(),
        "derive_ka: buffer lengths differ"
    );
}

/// The derive's loop with `chi(n) = [chi_1, chi_0]` and the `k_d` factor `diffuse`, on the
/// calling thread; `OFFSET` says whether `chi` has a `chi_0` to add (Cook-Torrance), so the
/// other models keep the loop without it. Public so that other fits (Karis', in the bench) are
/// timed in the very same loop.
#[inline]
pub fn derive_with<const OFFSET: bool>(
    kd: &[Vec3],
    ks: &[Vec3],
    n: &[f32],
    out: &mut [Vec3],
    diffuse: f32,
    chi: impl Fn(f32) -> [f32; 2],
) {
    let kd: &[f32] = bytemuck::cast_slice(kd);
    let ks: &[f32] = bytemuck::cast_slice(ks);
    let out: &mut [f32] = bytemuck::cast_slice_mut(out);
    // One spare slot: with an offset, each texel's three copies are written as one four-wide
    // store (the fourth overwritten by the next texel), which halves that loop's stores.
    let mut chi3 = [0.0_f32; 3 * DERIVE_BLOCK_TEXELS + 1];
    let mut offset3 = [0.0_f32; 3 * DERIVE_BLOCK_TEXELS + 1];
    for (block, n_block) in n.chunks(DERIVE_BLOCK_TEXELS).enumerate() {
        let start = 3 * block * DERIVE_BLOCK_TEXELS;
        let len = 3 * n_block.len();
        if OFFSET {
            for (i, &e) in n_block.iter().enumerate() {
                let [slope, offset] = chi(e);
                chi3[3 * i..3 * i + 4].copy_from_slice(&[slope; 4]);
                offset3[3 * i..3 * i + 4].copy_from_slice(&[offset; 4]);
            }
        } else {
            for (c, &e) in chi3.chunks_exact_mut(3).zip(n_block) {
                c.fill(chi(e)[0]);
            }
        }
        let o = &mut out[start..start + len];
        let d = &kd[start..start + len];
        let s = &ks[start..start + len];
        if OFFSET {
            for ((((o, &d), &s), &c), &z) in o
                .iter_mut()
                .zip(d)
                .zip(s)
                .zip(&chi3[..len])
                .zip(&offset3[..len])
            {
                *o = diffuse * sanitize_coefficient(d) + sanitize_coefficient(s) * c + z;
            }
        } else {
            for (((o, &d), &s), &c) in o.iter_mut().zip(d).zip(s).zip(&chi3[..len]) {
                *o = diffuse * sanitize_coefficient(d) + sanitize_coefficient(s) * c;
            }
        }
    }
}

/// [`derive_ka`] split over all threads of the rayon pool, in chunks of
/// [`DERIVE_CHUNK_TEXELS`]. The result is identical to the single-threaded one.
pub fn derive_ka_par(
    model: ShadingModel,
    approx: AmbientApprox,
    kd: &[Vec3],
    ks: &[Vec3],
    n: &[f32],
    out: &mut [Vec3],
) {
    assert_same_lengths(kd, ks, n, out);
    out.par_chunks_mut(DERIVE_CHUNK_TEXELS)
        .enumerate()
        .for_each(|(i, chunk)| {
            let start = i * DERIVE_CHUNK_TEXELS;
            let end = start + chunk.len();
            derive_ka(
                model,
                approx,
                &kd[start..end],
                &ks[start..end],
                &n[start..end],
                chunk,
            );
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ka_is_the_paper_formula() {
        let kd = Vec3::new(0.8, 0.4, 0.2);
        let ks = Vec3::splat(0.5);
        let got = ka(
            ShadingModel::Phong,
            AmbientApprox::PaperPrinted,
            kd,
            ks,
            10.0,
        );
        // Eq. (8) at n = 10.
        let chi = 0.97 * (11.3_f64).powf(-0.873);
        let want = 0.637 * kd.as_dvec3() + 0.5 * glam::DVec3::splat(chi);
        assert!(
            (got.as_dvec3() - want).abs().max_element() < 1e-6,
            "{got} {want}"
        );
    }

    #[test]
    fn hostile_inputs_give_finite_documented_values() {
        let weird = [
            f32::NAN,
            -1.0,
            -0.0,
            0.0,
            1e-45,
            f32::MIN_POSITIVE,
            1e30,
            f32::INFINITY,
        ];
        for model in ShadingModel::ALL {
            for approx in AmbientApprox::ALL {
                for &n in &weird {
                    for &k in &weird {
                        let v = ka(model, approx, Vec3::splat(k), Vec3::splat(k), n);
                        assert!(v.is_finite(), "{model:?} {approx:?} n={n} k={k}: {v}");
                        assert!(v.min_element() >= 0.0 && v.max_element() <= 2.0);
                    }
                    let chi = chi_f32(model, approx, n);
                    assert!(
                        chi > 0.0 && chi <= 1.0,
                        "{model:?} {approx:?} chi({n}) = {chi}"
                    );
                }
                // NaN and negative n behave like 0; +inf like the largest float.
                assert_eq!(
                    chi_f32(model, approx, f32::NAN),
                    chi_f32(model, approx, 0.0)
                );
                assert_eq!(chi_f32(model, approx, -5.0), chi_f32(model, approx, 0.0));
                assert_eq!(
                    chi_f32(model, approx, f32::INFINITY),
                    chi_f32(model, approx, f32::MAX)
                );
            }
        }
    }

    #[test]
    fn batch_equals_scalar_and_parallel_equals_serial() {
        let count = 3 * DERIVE_CHUNK_TEXELS + 17;
        let kd: Vec<Vec3> = (0..count)
            .map(|i| Vec3::splat((i % 97) as f32 / 96.0))
            .collect();
        let ks: Vec<Vec3> = (0..count)
            .map(|i| Vec3::new(0.3, (i % 5) as f32 / 4.0, 1.0))
            .collect();
        let n: Vec<f32> = (0..count).map(|i| (i % 20_000) as f32 * 0.9).collect();
        for model in ShadingModel::ALL {
            for approx in AmbientApprox::ALL {
                let mut serial = vec![Vec3::ZERO; count];
                let mut parallel = vec![Vec3::ONE; count];
                derive_ka(model, approx, &kd, &ks, &n, &mut serial);
                derive_ka_par(model, approx, &kd, &ks, &n, &mut parallel);
                assert_eq!(serial, parallel);
                for i in (0..count).step_by(997) {
                    assert_eq!(serial[i], ka(model, approx, kd[i], ks[i], n[i]));
                }
            }
        }
    }
}
