//! Blinn-Phong's exact integrals: the box average `chi(n)` and the lobe's integral at one
//! signed view angle, which the per-view average takes at `p` and `-p`; see [`crate::exact`]
//! for the method.

use std::f64::consts::{FRAC_PI_2, PI};

use crate::quadrature::{
    TanhSinh, break_points, graded_from, peak_scale, pow1p, window_angle, window_sin2,
};

pub(crate) fn chi(rule: &TanhSinh, n: f64) -> f64 {
    let window = window_sin2(n);
    let scale = peak_scale(n);
    let p_max = (2.0 * window.sqrt()).min(1.0).asin();
    let p_breaks = break_points(
        -FRAC_PI_2,
        p_max,
        graded_from(0.0, -1.0, scale, FRAC_PI_2 / 2.0)
            .chain(graded_from(-FRAC_PI_2, 1.0, scale, FRAC_PI_2 / 2.0))
            .chain([0.0]),
    );
    let outer = rule.integrate_pieces_par(&p_breaks, |p| at_p(rule, n, p));
    4.0 / (PI * PI * PI) * outer
}

/// The Blinn lobe's integral over `t in [0, pi/2]` and `g in [0, pi/2]` at the view angle
/// `p` (signed): what [`chi_exact`] integrates over `p`, and what the per-view average
/// ([`super::view`]) takes at `p` and `-p`.
pub(crate) fn at_p(rule: &TanhSinh, n: f64, p: f64) -> f64 {
    let window = window_sin2(n);
    let spread = window_angle(n);
    let (sp, cp) = p.sin_cos();
    let t_breaks = if p < 0.0 {
        // The lobe is at most cos^n((t + p)/2), so t stays within 2*spread of -p.
        break_points(
            (-p - 2.0 * spread).max(0.0),
            (-p + 2.0 * spread).min(FRAC_PI_2),
            [-p],
        )
    } else {
        // sin^2(beta) >= st^2/4 when p >= 0.
        break_points(0.0, (2.0 * window.sqrt()).min(1.0).asin(), [])
    };
    rule.integrate_pieces(&t_breaks, |t| {
        let (st, ct) = t.sin_cos();
        let sum_half = 2.0 * (0.5 * (t + p)).sin() * (0.5 * (t - p)).cos(); // st + sp
        let a = st * st + sp * sp;
        let b = 2.0 * st * sp;
        let e = 2.0 + 2.0 * ct * cp;
        let sin2 = |g: f64| {
            let h = (0.5 * g).sin();
            let num = sum_half * sum_half - 2.0 * b * h * h;
            let den = e + b * g.cos();
            if den > 0.0 {
                (num / den).clamp(0.0, 1.0)
            } else {
                1.0
            }
        };
        let lobe = |g: f64| pow1p(0.5 * n, -sin2(g));
        let (g_lo, g_hi) = blinn_g_window(n, a, b, e, sin2);
        rule.integrate(g_lo, g_hi, lobe)
    })
}

/// The `g` range where the Blinn lobe is above `e^-WINDOW_LOG` of its peak, for fixed `(p, t)`.
///
/// With `c = cos g`, `sin^2 beta = (a + b c) / (e + b c)` is monotone in `c`, so the window
/// edge solves a linear equation.
fn blinn_g_window(n: f64, a: f64, b: f64, e: f64, sin2: impl Fn(f64) -> f64) -> (f64, f64) {
    if n == 0.0 || b.abs() < 1e-300 {
        return (0.0, FRAC_PI_2);
    }
    let peak_g = if b < 0.0 { 0.0 } else { FRAC_PI_2 };
    let s_peak = sin2(peak_g);
    // (1 - s)^(n/2) = e^-W (1 - s_peak)^(n/2)  =>  1 - s = e^(-2W/n) (1 - s_peak).
    let s_edge = 1.0 - (1.0 - window_sin2(n)) * (1.0 - s_peak);
    let denom = b * (1.0 - s_edge);
    if denom == 0.0 {
        return (0.0, FRAC_PI_2);
    }
    let c_edge = (s_edge * e - a) / denom;
    if b < 0.0 {
        // Peak at g = 0; the lobe falls as c falls.
        if c_edge <= 0.0 {
            (0.0, FRAC_PI_2)
        } else {
            (0.0, c_edge.min(1.0).acos())
        }
    } else if c_edge >= 1.0 {
        (0.0, FRAC_PI_2)
    } else {
        (c_edge.max(0.0).acos(), FRAC_PI_2)
    }
}
