//! Cook-Torrance (GGX) under the paper's ambient model: the exact `chi_1(n)` and `chi_0(n)`.
//!
//! # The model, pinned
//!
//! The same box of angles as eq. (6) (see [`crate::geometry`]: `N = +Y`,
//! `L = (sin t cos g, cos t, sin t sin g)`, `V = (sin p, cos p, 0)`, the plain average
//! `(2/pi^3) Int dt dg dp` over `t in [0, pi/2]`, `g, p in [-pi/2, pi/2]`), with the specular
//! radiance factor (the BRDF times `N.L`)
//!
//! ```text
//! rho_s = D(h) G2(l, v) F(v.h) / (4 N.V)
//! D     = alpha^2 / (pi ((N.h)^2 (alpha^2 - 1) + 1)^2)                  GGX (Trowbridge-Reitz)
//! G2    = 1 / (1 + Lambda(l) + Lambda(v)),
//! Lambda(x) = (-1 + sqrt(1 + alpha^2 tan^2 theta_x)) / 2             Smith, height-correlated
//! F     = F0 + (1 - F0) (1 - v.h)^5, F0 = k_s per colour channel     Schlick
//! alpha = sqrt(2 / (n + 2))                                          from the painted n
//! ```
//!
//! `alpha` comes from the Phong exponent through the Blinn-Phong/Beckmann correspondence, so the
//! same maps drive all three models; `n = 0` gives `alpha = 1` (the roughest GGX surface), and
//! `alpha` falls as `sqrt(2/n)` for large `n`.
//!
//! Schlick's `F` is linear in `F0`, so the average of `rho_s` is `k_s chi_1(n) + chi_0(n)` with
//!
//! ```text
//! chi_1(n) = avg D G2 (1 - (1 - v.h)^5) / (4 N.V),   chi_0(n) = avg D G2 (1 - v.h)^5 / (4 N.V)
//! ```
//!
//! and `k_a = (2/pi) k_d + k_s chi_1(n) + chi_0(n)`.
//!
//! # Limits (derived here, checked by the tests)
//!
//! * `n = 0` (`alpha = 1`): `D = 1/pi` and `G2 / (4 N.V) = 1 / (2 (N.L + N.V))`, so
//!   `rho_s = F cos t / (2 pi (cos t + cos p))`. Swapping `t` and `p` (the box is symmetric in
//!   them once `g` is integrated out) shows `avg cos t / (cos t + cos p) = 1/2`, hence
//!   `chi_1(0) + chi_0(0) = 1 / (4 pi)`.
//! * `n -> infinity` (`alpha -> 0`): `D` tends to `delta(h - N) / (N.h)` in solid angle and
//!   `G2 -> 1`. With `d omega_l = 4 (v.h) d omega_h` and `d omega_l = sin t dt dg`, the `(t, g)`
//!   integral of `rho_s` tends to `F(cos p) / |sin p|` for `p < 0` (the mirror direction is in the
//!   box) and to 0 for `p > 0`. For `F = (1 - cos p)^5` that is integrable:
//!   `chi_0(inf) = (2/pi^3) Int_0^1 (1 - u)^4 / (1 + u) du = (2/pi^3) (16 ln 2 - 131/12)`.
//!   For `F = 1` the `1/|p|` is cut off where the peak meets the pole, `|p| ~ alpha`, so
//!   `chi_1 + chi_0` grows like `(2/pi^3) ln(1/alpha) = (1/pi^3) ln n`: a normalised lobe
//!   keeps its energy as it narrows, unlike Phong's.
//!
//! # Method
//!
//! As in [`crate::exact`] for Blinn-Phong: everything depends on `g` through `cos g`, so `g` is
//! folded onto `[0, pi/2]`; the lobe peaks at `g = 0, t = -p` for `p < 0` and towards the
//! corner `t = 0, g = pi/2` for `p >= 0`. GGX has a heavy tail (`D` falls only as the fourth
//! power of the angle), so nothing is cut off: every 1D integral is tanh-sinh over pieces graded
//! geometrically (`alpha 2^k`) away from the peak, which the poles of `D` at distance `alpha`
//! from it make converge geometrically. The integrand is written without cancellation: the
//! sine of the half-vector angle through half-angle forms, `1 - v.h` as `(1 - L.V) / (2 (1 +
//! v.h))`, and `G2 / (4 N.V)` in its `N.V`-free form.

use std::f64::consts::{FRAC_PI_2, PI};

use num_traits::Float;

use super::lobe::{Cosines, lit};

use crate::quadrature::{TanhSinh, break_points, graded_from};

pub mod fast;
pub(crate) mod fast_coeffs;
pub mod fit;
pub mod karis;

/// Largest exponent the exact integrator accepts; larger values are clamped to it. It is
/// `2^20 - 1`, so that the fit's last octave (`x = n + 1` up to `2^20`) is smooth to its end;
/// the model itself stops at [`fast::N_MAX`] (`1e6`), where [`crate::exact`] clamps.
pub const EXACT_N_MAX: f64 = ((1u64 << 20) - 1) as f64;

/// The tanh-sinh level used by [`chi_exact`]; the tests compare it with the next level.
pub const DEFAULT_LEVEL: u32 = 6;

/// GGX roughness for a Phong exponent: `alpha = sqrt(2 / (n + 2))`. NaN and negative `n` are
/// taken as 0 (`alpha = 1`); `+inf` gives 0.
pub fn alpha(n: f64) -> f64 {
    let n = if n.is_nan() { 0.0 } else { n.max(0.0) };
    (2.0 / (n + 2.0)).sqrt()
}

/// The lobe, the one source every path evaluates: `rho_s` split as `F0 * first + second` at
/// the cosines `c`, for `n` already sanitized (the `f32` callers also clamp it to
/// [`fast::N_MAX`], as the shaders do). Zero where `N.L <= 0`, `N.V <= 0` or there is no half
/// vector.
#[inline]
pub fn lobe<F: Float>(c: &Cosines<F>, n: F) -> [F; 2] {
    if !(c.nl > F::zero() && c.nv > F::zero() && c.has_half) {
        return [F::zero(); 2];
    }
    let a2 = lit::<F>(2.0) / (n + lit(2.0));
    let m = F::one() - c.vh.max(F::zero()).min(F::one());
    parts(a2, c.nl, c.nv, c.cross2, m)
}

/// `D G2 F / (4 N.V)` split as `F0 * first + second`, from `alpha^2`, `N.L`, `N.V`,
/// `|N x H|^2` and `1 - V.H`: GGX's `D = a2 / (pi (a2 + (1 - a2) |N x H|^2)^2)` (no
/// cancellation next to the peak), the height-correlated Smith term in the form that stays
/// finite at grazing angles (`G2 / (4 N.L N.V)` times `N.L`), Schlick's `(1 - V.H)^5`.
#[inline]
#[expect(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "NaN takes the zero branch: `!(x > 0)` says so, `x <= 0` would not"
)]
pub(crate) fn parts<F: Float>(a2: F, nl: F, nv: F, cross2: F, m: F) -> [F; 2] {
    let one = F::one();
    let q = a2 + (one - a2) * cross2;
    let d = a2 / (lit::<F>(PI) * q * q);
    let smith = nv * (nl * nl * (one - a2) + a2).sqrt() + nl * (nv * nv * (one - a2) + a2).sqrt();
    if !(smith > F::zero()) {
        return [F::zero(); 2];
    }
    let base = d * nl / (lit::<F>(2.0) * smith);
    let m2 = m * m;
    let s = m2 * m2 * m;
    [base * (one - s), base * s]
}

/// [`lobe`] at a point `(theta, gamma, phi)` of the box, `n` sanitized as [`alpha`] does: the
/// reference the reduced integrand and the Monte Carlo check use.
pub fn rho_s_parts(n: f64, theta: f64, gamma: f64, phi: f64) -> [f64; 2] {
    let n = if n.is_nan() { 0.0 } else { n.max(0.0) };
    lobe(&Cosines::of_box(theta, gamma, phi), n)
}

/// The integrand of the exact integral at `(t, g, p)` (`g` folded onto `[0, pi/2]`): the two
/// parts of [`rho_s_parts`], evaluated without cancellation (see the module documentation).
fn integrand(
    a: f64,
    (st, ct): (f64, f64),
    g: f64,
    (p, sp, cp): (f64, f64, f64),
    t: f64,
) -> [f64; 2] {
    let a2 = a * a;
    let cg = g.cos();
    let half_g = (0.5 * g).sin();
    // |L + V|^2 sin^2(beta) = |(L + V) x N|^2, as sums of terms of one sign.
    let cross2 = if p < 0.0 {
        let sum = 2.0 * (0.5 * (t + p)).sin() * (0.5 * (t - p)).cos(); // st + sp
        sum * sum - 4.0 * st * sp * half_g * half_g
    } else {
        st * st + sp * sp + 2.0 * st * sp * cg
    };
    let len2 = 2.0 + 2.0 * (ct * cp + st * sp * cg); // |L + V|^2 = 2 (1 + L.V)
    if len2 <= 0.0 {
        return [0.0; 2];
    }
    let sin2 = (cross2 / len2).clamp(0.0, 1.0);
    // 1 - L.V as terms of one sign; then 1 - v.h = (1 - L.V) / (2 (1 + v.h)).
    let one_minus_lv = if p < 0.0 {
        let s = (0.5 * (t + p)).sin();
        let c = (0.5 * g).cos();
        2.0 * s * s - 2.0 * st * sp * c * c
    } else {
        let s = (0.5 * (t - p)).sin();
        2.0 * s * s + 2.0 * st * sp * half_g * half_g
    };
    let vh = (1.0 - 0.5 * one_minus_lv).max(0.0).sqrt();
    parts(a2, ct, cp, sin2, 0.5 * one_minus_lv / (1.0 + vh))
}

/// `[chi_1(n), chi_0(n)]` at the default quadrature level. `n` is clamped into
/// `[0, EXACT_N_MAX]`; NaN is taken as 0.
pub fn chi_exact(n: f64) -> [f64; 2] {
    chi_exact_at_level(n, DEFAULT_LEVEL)
}

/// [`chi_exact`] with an explicit tanh-sinh level: `level + 2` doubles the nodes of every rule.
pub fn chi_exact_at_level(n: f64, level: u32) -> [f64; 2] {
    let n = if n.is_nan() {
        0.0
    } else {
        n.clamp(0.0, EXACT_N_MAX)
    };
    let a = alpha(n);
    let rule = TanhSinh::new(level);
    let p_breaks = p_pieces(a);
    let outer = rule.integrate_pieces_par_n(&p_breaks, |p| over_t(&rule, a, p));
    // 2 for the folded g range, 2/pi^3 for the average.
    outer.map(|v| 4.0 / (PI * PI * PI) * v)
}

/// The `(t, g)` integral at fixed `p`.
pub(crate) fn over_t(rule: &TanhSinh, a: f64, p: f64) -> [f64; 2] {
    let (sp, cp) = p.sin_cos();
    let cp = cp.max(0.0);
    rule.integrate_pieces_n(&t_pieces(a, p), |t| {
        let (st, ct) = t.sin_cos();
        rule.integrate_pieces_n(&g_pieces(a, p, st), |g| {
            integrand(a, (st, ct), g, (p, sp, cp), t)
        })
    })
}

/// The pieces of the view angle `p` in `[-pi/2, pi/2]` for a GGX lobe of feature width
/// `scale` (`alpha`): graded geometrically away from the head-on view and from `-pi/2`, where
/// the peak meets the box's edges. With [`t_pieces`] and [`g_pieces`], the product rule every
/// box integral of GGX uses (the exact `chi` here, the PBR fit's node set).
pub fn p_pieces(scale: f64) -> Vec<f64> {
    let quarter = FRAC_PI_2 / 2.0;
    break_points(
        -FRAC_PI_2,
        FRAC_PI_2,
        graded_from(0.0, -1.0, scale, quarter)
            .chain(graded_from(0.0, 1.0, scale, quarter))
            .chain(graded_from(-FRAC_PI_2, 1.0, scale, quarter))
            .chain([0.0]),
    )
}

/// The pieces of the light's polar angle `t` at view angle `p`: graded both ways from the
/// lobe's peak, the mirror direction `t = -p`, or the pole for `p >= 0`.
pub fn t_pieces(scale: f64, p: f64) -> Vec<f64> {
    let peak = (-p).max(0.0);
    break_points(
        0.0,
        FRAC_PI_2,
        graded_from(peak, -1.0, scale, FRAC_PI_2)
            .chain(graded_from(peak, 1.0, scale, FRAC_PI_2))
            .chain([peak]),
    )
}

/// The pieces of the folded azimuth `g` in `[0, pi/2]` at view angle `p` and `sin t = st`:
/// graded from the peak (`g = 0` for `p < 0`, `pi/2` otherwise), of width `scale / sin t`.
pub fn g_pieces(scale: f64, p: f64, st: f64) -> Vec<f64> {
    let (g_peak, g_sign) = if p < 0.0 {
        (0.0, 1.0)
    } else {
        (FRAC_PI_2, -1.0)
    };
    let width = if st > 0.0 { scale / st } else { f64::INFINITY };
    break_points(
        0.0,
        FRAC_PI_2,
        graded_from(g_peak, g_sign, width, FRAC_PI_2),
    )
}

/// Monte Carlo estimates of `[chi_1(n), chi_0(n)]` straight from the vectors
/// ([`rho_s_parts`]) with their standard errors: the mean over `samples` uniform points of
/// the box. Shares only the lobe's formula (`parts`) with [`chi_exact`]'s reduction, not
/// its geometry.
pub fn chi_monte_carlo(n: f64, samples: u64, seed: u64) -> [(f64, f64); 2] {
    crate::geometry::box_average(samples, seed, |t, g, p| rho_s_parts(n, t, g, p))
}

/// `chi_1(0) + chi_0(0) = 1 / (4 pi)` (see the module documentation).
pub const SUM_AT_ZERO: f64 = 1.0 / (4.0 * PI);

/// `chi_0(n)` as `n -> infinity`: `(2/pi^3) (16 ln 2 - 131/12)`.
pub fn chi0_limit() -> f64 {
    2.0 / (PI * PI * PI) * (16.0 * std::f64::consts::LN_2 - 131.0 / 12.0)
}

/// The slope of `chi_1 + chi_0` against `ln n` as `n -> infinity`: `1/pi^3`.
pub const SUM_LOG_SLOPE: f64 = 1.0 / (PI * PI * PI);

/// The lobe's angular width in the light direction: GGX's `2 alpha`.
pub fn width(n: f32) -> f32 {
    2.0 * (2.0 / (n + 2.0)).sqrt()
}

/// The width across the mirror direction, as Blinn-Phong's (the peak follows the half
/// vector).
pub fn across(width: f32, theta: f32, phi: f32) -> f32 {
    super::blinn::across(width, theta, phi)
}

#[cfg(test)]
mod tests;
