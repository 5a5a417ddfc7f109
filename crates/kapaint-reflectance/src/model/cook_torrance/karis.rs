//! Karis' analytic fit of the environment BRDF (the split-sum's `DFG` term), measured against
//! the exact `chi_1`, `chi_0`.
//!
//! B. Karis, "Physically Based Shading on Mobile" (Unreal Engine 4, 2014), fits the
//! directional albedo of a GGX/Smith/Schlick lobe as `F0 A + B`, two functions of the
//! perceptual roughness `r` (`alpha = r^2`) and `N.V`. Its published constants are
//!
//! ```text
//! c0 = (-1, -0.0275, -0.572, 0.022),  c1 = (1, 0.0425, 1.04, -0.04)
//! q  = r c0 + c1
//! a  = min(q.x^2, 2^(-9.28 N.V)) q.x + q.y
//! (A, B) = (-1.04 a + q.z, 1.04 a + q.w)
//! ```
//!
//! # A different lighting setup
//!
//! That fit answers another question: the reflectance of uniform light over the hemisphere,
//! weighted by solid angle and `N.L`, seen from one view direction. kapaint's `chi_1`, `chi_0`
//! average the radiance factor over the paper's box of angles (plain `dt dg dp`, every view of
//! the box). What a user would get by dropping the fit into the paper's ambient term is
//! `k_a = (2/pi) k_d + k_s A + B`, with `r = sqrt(alpha) = (2 / (n + 2))^(1/4)` and, since `k_a`
//! has no view, the view the box averages over; [`chi_karis`] takes the box's mean cosine
//! `N.V = 2/pi` (one evaluation per texel, as a shader would), [`chi_karis_view_averaged`] the
//! mean of `A`, `B` over the box's views. `kapaint accuracy` and `kapaint bench` measure both
//! against [`super::chi_exact`].

use std::f64::consts::{FRAC_2_PI, FRAC_PI_2};

/// `(A, B)` of Karis' fit at perceptual roughness `r` and `N.V`.
pub fn env_brdf(r: f64, n_dot_v: f64) -> [f64; 2] {
    let q = [
        1.0 - r,
        0.0425 - 0.0275 * r,
        1.04 - 0.572 * r,
        0.022 * r - 0.04,
    ];
    let a = (q[0] * q[0]).min((-9.28 * n_dot_v).exp2()) * q[0] + q[1];
    [-1.04 * a + q[2], 1.04 * a + q[3]]
}

/// Perceptual roughness for a Phong exponent: `r = sqrt(alpha)`, `alpha = sqrt(2 / (n + 2))`.
pub fn roughness(n: f64) -> f64 {
    super::alpha(n).sqrt()
}

/// Karis' fit as `[chi_1, chi_0]` at the box's mean view cosine `2/pi`.
pub fn chi_karis(n: f64) -> [f64; 2] {
    env_brdf(roughness(n), FRAC_2_PI)
}

/// `f32` twin of [`chi_karis`], the per-texel cost `kapaint bench` measures.
#[inline]
pub fn chi_karis_f32(n: f32) -> [f32; 2] {
    let r = (2.0 / (n.max(0.0) + 2.0)).sqrt().sqrt();
    let q = [
        1.0 - r,
        0.0425 - 0.0275 * r,
        1.04 - 0.572 * r,
        0.022 * r - 0.04,
    ];
    // 2^(-9.28 * 2/pi), the fit's view term at the box's mean cosine.
    let view = (-9.28 * std::f32::consts::FRAC_2_PI).exp2();
    let a = (q[0] * q[0]).min(view) * q[0] + q[1];
    [-1.04 * a + q[2], 1.04 * a + q[3]]
}

/// Karis' fit as `[chi_1, chi_0]` averaged over the box's views `p in [-pi/2, pi/2]`
/// (`N.V = cos p`), by the midpoint rule on 4096 intervals (the fit's `min` has a kink, so no
/// higher-order rule would do better).
pub fn chi_karis_view_averaged(n: f64) -> [f64; 2] {
    const STEPS: usize = 4096;
    let r = roughness(n);
    let mut sum = [0.0; 2];
    for i in 0..STEPS {
        // By symmetry in p, half the range.
        let p = FRAC_PI_2 * (i as f64 + 0.5) / STEPS as f64;
        let [a, b] = env_brdf(r, p.cos());
        sum[0] += a;
        sum[1] += b;
    }
    sum.map(|s| s / STEPS as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_limits_hold() {
        // A smooth surface (r = 0) seen along the normal: the fit's corner values by hand.
        let [a, b] = env_brdf(0.0, 1.0);
        assert!((a - (1.04 - 1.04 * ((-9.28_f64).exp2() + 0.0425))).abs() < 1e-12);
        assert!((b - (1.04 * ((-9.28_f64).exp2() + 0.0425) - 0.04)).abs() < 1e-12);
        for n in [0.0_f32, 1.0, 30.0, 1000.0, 1.0e6] {
            let single = chi_karis_f32(n);
            let double = chi_karis(f64::from(n));
            for k in 0..2 {
                assert!((f64::from(single[k]) - double[k]).abs() < 1e-6, "n = {n}");
            }
        }
    }
}
