//! The exact specular average `chi(n)` of eq. (6), to a relative accuracy of 1e-10.
//!
//! `chi(n) = (2/pi^3) * Int_t Int_g Int_p max(0, c)^n`, the plain average of the lobe over the
//! box `t in [0, pi/2], g in [-pi/2, pi/2], p in [-pi/2, pi/2]` (see [`super::geometry`]).
//!
//! # Method
//!
//! Both models depend on `g` only through `cos g`, so the `g` range is folded onto `[0, pi/2]`.
//!
//! **Original Phong.** For fixed `(t, g)`, `R.V = ct cp - st sp cg = M cos(p + d)` with
//! `M = sqrt(1 - st^2 sg^2)` and `d = atan2(st cg, ct)` in `[0, pi/2]`. The `p` integral of the
//! positive part therefore has a closed structure:
//!
//! ```text
//! Int_p max(0, R.V)^n dp = M^n * (C_n(pi/2) + C_n(pi/2 - d)),   C_n(x) = Int_0^x cos^n u du
//! ```
//!
//! The kink where `R.V` crosses zero becomes the fixed end `u = pi/2` of `C_n`, and the narrow
//! peak becomes the fixed end `u = 0`. What is left is a smooth 2D integral over `(t, g)` plus
//! a 1D integral `C_n` with both features at its ends.
//!
//! **Blinn-Phong.** `N.H >= 0` everywhere, so there is no kink. With
//! `sin^2(beta) = ((st + sp)^2 - 2 st sp (1 - cg)) / (2 + 2 ct cp + 2 st sp cg)` the lobe is
//! `(1 - sin^2 beta)^(n/2)`, evaluated through `ln_1p` so that it keeps full relative precision
//! next to the peak. For fixed `(p, t)` it is monotone in `g` (its peak is at `g = 0` when
//! `p < 0` and at `g = pi/2` when `p > 0`); for fixed `p < 0` its peak in `t` is at `t = -p`.
//!
//! **Quadrature.** Every 1D integral uses tanh-sinh ([`super::quadrature`]) with each peak,
//! kink or singular point placed at an interval end, where the rule's nodes cluster. Where the
//! lobe is below `e^-40` of its local maximum the integrand is cut (windows derived from exact
//! bounds of the lobe), so at large `n` the nodes go where the integral lives. The outer
//! variable is split geometrically (`2^k / sqrt(n)`) towards the ends where the peak curve
//! meets the box boundary, which turns the `ln n / n` behaviour into pieces of bounded
//! relative size. Halving the step of every rule doubles the node count; the tests show the
//! change falling below 1e-12 relative from one level to the next across `n in [0, 1e5]`.

use std::f64::consts::PI;

use super::ShadingModel;
use super::quadrature::TanhSinh;

/// Largest exponent the exact integrator accepts; larger values are clamped to it.
pub const EXACT_N_MAX: f64 = 1.0e6;

/// The tanh-sinh level used by [`chi_exact`]; the tests compare it with the next level.
pub const DEFAULT_LEVEL: u32 = 7;

thread_local! {
    static CALLS_ON_THIS_THREAD: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How many exact integrals the calling thread has run: the editor's tests check that its
/// UI thread never runs one (each takes 45 ms to 3.5 s).
pub fn calls_on_this_thread() -> u64 {
    CALLS_ON_THIS_THREAD.with(std::cell::Cell::get)
}

fn count_call() {
    CALLS_ON_THIS_THREAD.with(|c| c.set(c.get() + 1));
}

/// `chi(n)`, the specular average of eq. (6), for `model` at the default quadrature level.
///
/// `n` is clamped into `[0, EXACT_N_MAX]`; NaN is treated as 0. At `n = 0` the value is the
/// limit `n -> 0`: the fraction of the box where the lobe's cosine is positive.
pub fn chi_exact(model: ShadingModel, n: f64) -> f64 {
    chi_exact_at_level(model, n, DEFAULT_LEVEL)
}

/// [`chi_exact`] with an explicit tanh-sinh level (step `2^(-level/2)`), for convergence
/// studies: `level + 2` doubles the nodes of every rule.
pub fn chi_exact_at_level(model: ShadingModel, n: f64, level: u32) -> f64 {
    count_call();
    let n = if n.is_nan() {
        0.0
    } else {
        n.clamp(0.0, EXACT_N_MAX)
    };
    let rule = TanhSinh::new(level);
    match model {
        // Phong's outer integrand is smooth enough for one level less (measured: no change in
        // the 13th digit), which saves a third of its time.
        ShadingModel::Phong => {
            crate::model::phong::exact::chi(&TanhSinh::new(level.saturating_sub(1)), &rule, n)
        }
        ShadingModel::BlinnPhong => crate::model::blinn::exact::chi(&rule, n),
        // chi_1, the part that scales with k_s; see `super::cook_torrance` for both parts.
        ShadingModel::CookTorrance => {
            super::cook_torrance::chi_exact_at_level(cook_torrance_n(n), level)[0]
        }
    }
}

/// `[chi_1(n), chi_0(n)]` by the exact integrators: `[chi(n), 0]` for Phong and Blinn-Phong,
/// both parts of [`super::cook_torrance::chi_exact`] for Cook-Torrance.
pub fn chi_parts_exact(model: ShadingModel, n: f64) -> [f64; 2] {
    match model {
        ShadingModel::CookTorrance => {
            count_call();
            super::cook_torrance::chi_exact(cook_torrance_n(n))
        }
        ShadingModel::Phong | ShadingModel::BlinnPhong => [chi_exact(model, n), 0.0],
    }
}

/// `n` within the Cook-Torrance model's limit [`super::cook_torrance::fast::N_MAX`] (the
/// integrator itself reaches a little further, to the end of the fit's last octave); NaN is 0.
pub(crate) fn cook_torrance_n(n: f64) -> f64 {
    if n.is_nan() {
        0.0
    } else {
        n.min(f64::from(super::cook_torrance::fast::N_MAX))
    }
}

/// Monte Carlo estimate of `chi(n)` straight from the vector definition in
/// [`super::geometry`]: the mean of the lobe over `samples` uniform points of the box, with its
/// standard error. An independent check of [`chi_exact`] that shares no code with it.
pub fn chi_monte_carlo(model: ShadingModel, n: f64, samples: u64, seed: u64) -> (f64, f64) {
    let [estimate] =
        super::geometry::box_average(samples, seed, |t, g, p| [rho_s(model, n, t, g, p)]);
    estimate
}

/// Leading slope of the large-`n` law `chi(n) ~ (A ln n + B) / n`, derived by Laplace's
/// method around the peak curve `g = 0, p = -t`: `A = 2/pi^2` for Phong, `8/pi^2` for
/// Blinn-Phong (the Blinn lobe is four times wider in solid angle). Cook-Torrance's law has
/// no `1/n` (a normalised lobe keeps its energy): `chi_1 + chi_0 ~ A ln n + B` with
/// `A = 1/pi^3` ([`super::cook_torrance::SUM_LOG_SLOPE`]).
pub fn asymptotic_slope(model: ShadingModel) -> f64 {
    match model {
        ShadingModel::Phong => 2.0 / (PI * PI),
        ShadingModel::BlinnPhong => 8.0 / (PI * PI),
        ShadingModel::CookTorrance => super::cook_torrance::SUM_LOG_SLOPE,
    }
}

/// The specular reflectance `rho_s = max(0, cos)^n`, with `0^0` taken as 0: at `n = 0` the
/// lobe is the indicator of the set where the cosine is positive, which is the limit of
/// `max(0, cos)^n` as `n -> 0`. For Cook-Torrance, its radiance factor with `F0 = 1`
/// (`chi_1 + chi_0` is its average).
pub fn rho_s(model: ShadingModel, n: f64, theta: f64, gamma: f64, phi: f64) -> f64 {
    let [first, second] = model.lobe_in_box(super::sanitize_n_f64(n), theta, gamma, phi);
    first + second
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::phong::exact::cos_power_integral;
    use crate::quadrature::break_points;
    use std::f64::consts::FRAC_PI_2;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn phong_matches_the_check_values_of_the_notes() {
        for (n, expected) in [(1.0, 0.470_676), (10.0, 0.116_724), (200.0, 0.009_377_5)] {
            let chi = chi_exact(ShadingModel::Phong, n);
            assert!(
                rel(chi, expected) < 1e-5,
                "chi({n}) = {chi}, notes say {expected}"
            );
        }
    }

    #[test]
    fn blinn_at_zero_is_one() {
        let chi = chi_exact(ShadingModel::BlinnPhong, 0.0);
        assert!(rel(chi, 1.0) < 1e-13, "{chi}");
    }

    #[test]
    fn doubling_the_order_converges_to_1e12() {
        let ns = [0.0, 0.01, 0.3, 1.0, 10.0, 200.0, 16384.0, 1.0e5];
        for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
            for &n in &ns {
                let coarse = chi_exact_at_level(model, n, DEFAULT_LEVEL - 2);
                let fine = chi_exact_at_level(model, n, DEFAULT_LEVEL);
                let finer = chi_exact_at_level(model, n, DEFAULT_LEVEL + 2);
                // Doubling the nodes of every rule changes the value by less than 1e-12.
                let step = rel(fine, finer);
                assert!(step < 1e-12, "{model:?} n={n}: levels differ by {step:e}");
                // The previous doubling moved the value at least as much (convergence, not
                // agreement by accident), unless both are at rounding level.
                let before = rel(coarse, finer);
                assert!(
                    before >= step || before < 1e-14,
                    "{model:?} n={n}: {before:e} {step:e}"
                );
            }
        }
    }

    #[test]
    fn phong_reduction_matches_brute_force_p_integral() {
        // Check the closed p-integral against direct quadrature of the vector definition,
        // split at the kink where R.V crosses zero.
        let rule = TanhSinh::new(12);
        for &(n, t, g) in &[
            (0.5_f64, 0.4_f64, 0.3_f64),
            (3.0, 1.1, 0.9),
            (40.0, 0.7, 0.05),
        ] {
            let m = (1.0 - (t.sin() * g.sin()).powi(2)).sqrt();
            let to_kink = t.cos().atan2(t.sin() * g.cos());
            let reduced = m.powf(n)
                * (cos_power_integral(&rule, n, FRAC_PI_2) + cos_power_integral(&rule, n, to_kink));
            let kink = FRAC_PI_2 - (t.sin() * g.cos()).atan2(t.cos());
            let peak = -(t.sin() * g.cos()).atan2(t.cos());
            let brute = rule.integrate_pieces(&break_points(-FRAC_PI_2, kink, [peak]), |p| {
                super::rho_s(ShadingModel::Phong, n, t, g, p)
            });
            assert!(rel(reduced, brute) < 1e-12, "n={n}: {reduced} vs {brute}");
        }
    }

    #[test]
    fn monte_carlo_agrees_within_error_bars() {
        for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
            for n in [0.0, 1.0, 10.0, 50.0] {
                let (mean, err) = chi_monte_carlo(model, n, 2_000_000, 7);
                let exact = chi_exact(model, n);
                assert!(
                    (mean - exact).abs() < 4.5 * err + 1e-12,
                    "{model:?} n={n}: MC {mean} +- {err}, exact {exact}"
                );
            }
        }
    }

    #[test]
    fn large_n_follows_the_derived_log_law() {
        // n chi(n) - A ln n tends to a constant; its change between decades shrinks.
        for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
            let a = asymptotic_slope(model);
            let c = |n: f64| n * chi_exact(model, n) - a * n.ln();
            let d1 = (c(1.0e4) - c(1.0e3)).abs();
            let d2 = (c(1.0e5) - c(1.0e4)).abs();
            assert!(d2 < 0.5 * d1, "{model:?}: constants drift {d1} then {d2}");
            // The local slope d(n chi)/d(ln n) approaches A.
            let slope =
                (1.0e5 * chi_exact(model, 1.0e5) - 5.0e4 * chi_exact(model, 5.0e4)) / 2.0_f64.ln();
            assert!(rel(slope, a) < 0.02, "{model:?}: slope {slope} vs {a}");
        }
    }
}
