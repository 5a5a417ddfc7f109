//! Phong's exact integrals: the box average `chi(n)` (the `p` integral in closed form) and
//! the per-view integral at one view angle (the `t` integral in closed form); see
//! [`crate::exact`] and [`crate::view`] for the method.

use std::f64::consts::{FRAC_PI_2, PI};

use crate::quadrature::{
    TanhSinh, break_points, graded_from, peak_scale, pow1p, window_angle, window_sin2,
};

/// `C_n(x) = Int_0^x cos^n u du` for `x in [0, pi/2]`.
pub(crate) fn cos_power_integral(rule: &TanhSinh, n: f64, x: f64) -> f64 {
    let upper = x.min(window_angle(n));
    rule.integrate(0.0, upper, |u| {
        let s = (0.5 * u).sin();
        // cos u = 1 - 2 sin^2(u/2), exact in relative terms next to the peak at u = 0.
        pow1p(n, -2.0 * s * s)
    })
}

pub(crate) fn chi(outer_rule: &TanhSinh, rule: &TanhSinh, n: f64) -> f64 {
    let half_full = cos_power_integral(rule, n, FRAC_PI_2);
    let g_window = window_sin2(n);
    let scale = peak_scale(n);
    let breaks = break_points(
        0.0,
        FRAC_PI_2,
        graded_from(0.0, 1.0, scale, FRAC_PI_2 / 2.0).chain(graded_from(
            FRAC_PI_2,
            -1.0,
            scale,
            FRAC_PI_2 / 2.0,
        )),
    );
    let outer = outer_rule.integrate_pieces_par(&breaks, |t| {
        let (st, ct) = t.sin_cos();
        // M^n = (1 - st^2 sg^2)^(n/2) drops below the window at sg = sqrt(window)/st.
        let sg_max = if st > 0.0 { g_window.sqrt() / st } else { 1.0 };
        let g_max = sg_max.min(1.0).asin();
        rule.integrate(0.0, g_max, |g| {
            let (sg, cg) = g.sin_cos();
            let m_pow = pow1p(0.5 * n, -(st * sg) * (st * sg));
            let to_kink = ct.atan2(st * cg); // pi/2 - d
            m_pow * (half_full + cos_power_integral(rule, n, to_kink))
        })
    });
    // Factor 2 for the folded g range; 2/pi^3 for the average.
    4.0 / (PI * PI * PI) * outer
}

/// Head-on Phong in closed form: `chi_view(n, 0) = (2/pi) Int_0^{pi/2} cos^n t dt
/// = Gamma((n+1)/2) / (sqrt(pi) Gamma(n/2 + 1))`, by the log-gamma ratio.
pub fn phong_head_on(n: f64) -> f64 {
    // (2/pi) * (sqrt(pi)/2) Gamma((n+1)/2) / Gamma(n/2 + 1).
    (ln_gamma(0.5 * (n + 1.0)) - ln_gamma(0.5 * n + 1.0)).exp() / PI.sqrt()
}

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7, 9 terms: about 1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + G + 0.5;
    let sum = C
        .iter()
        .enumerate()
        .skip(1)
        .fold(C[0], |s, (i, c)| s + c / (x + i as f64));
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// Phong's lobe integrated over `t in [0, pi/2]` (in closed form per `g`) and `g in [0, pi/2]`
/// at the signed view angle `p`.
pub(crate) fn at_p(rule: &TanhSinh, n: f64, p: f64) -> f64 {
    let (sp, cp) = p.sin_cos();
    let s = sp.abs();
    // M^n = (1 - sp^2 sg^2)^(n/2) falls below the window at sg = sqrt(window) / |sp|.
    let g_max = if s > 0.0 {
        (window_sin2(n).sqrt() / s).min(1.0).asin()
    } else {
        FRAC_PI_2
    };
    let scale = if s > 0.0 {
        peak_scale(n) / s
    } else {
        f64::INFINITY
    };
    let breaks = break_points(0.0, g_max, graded_from(0.0, 1.0, scale, g_max / 2.0));
    let spread = window_angle(n);
    // Int_a^b cos^n u du for 0 <= a <= b <= pi/2, its peak at `a`: cut where cos^n(u) falls
    // below the window of cos^n(a) (cos u <= cos a cos(u - a) there).
    let from = |a: f64, b: f64| {
        let b = b.min(a + spread);
        if b <= a {
            return 0.0;
        }
        rule.integrate(a, b, |u| {
            let h = (0.5 * u).sin();
            pow1p(n, -2.0 * h * h)
        })
    };
    rule.integrate_pieces(&breaks, |g| {
        let (sg, cg) = g.sin_cos();
        let m_pow = pow1p(0.5 * n, -(s * sg) * (s * sg));
        let d = (sp * cg).atan2(cp);
        let t_part = if d >= 0.0 {
            from(d, FRAC_PI_2)
        } else {
            from(0.0, -d) + from(0.0, FRAC_PI_2 + d)
        };
        m_pow * t_part
    })
}
