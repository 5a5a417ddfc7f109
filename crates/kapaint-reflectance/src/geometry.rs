//! The paper's reconstructed geometry (Fig. 1 of the paper is lost; see NOTES.md).
//!
//! `N = +Y`. `theta` is the angle between `N` and `L`, `gamma` the azimuth of `L` measured from
//! the X axis, and `phi` the signed angle between `N` and `V`, with `V` in the XY plane:
//!
//! ```text
//! L = (sin t cos g, cos t, sin t sin g),  t in [0, pi/2], g in [-pi/2, pi/2]
//! V = (sin p, cos p, 0),                  p in [-pi/2, pi/2]
//! ```
//!
//! This module states the box with vectors; each model's lobe over it is in
//! [`crate::model`] ([`crate::model::Cosines::of_box`]), the definition that the fast reduced
//! integrals of [`super::exact`] are checked against.

use glam::DVec3;

/// Light direction for polar angle `theta` and azimuth `gamma` (radians).
pub fn light_dir(theta: f64, gamma: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * gamma.cos(),
        theta.cos(),
        theta.sin() * gamma.sin(),
    )
}

/// View direction for the signed angle `phi` from the normal (radians).
pub fn view_dir(phi: f64) -> DVec3 {
    DVec3::new(phi.sin(), phi.cos(), 0.0)
}

/// Golden-section search for the minimum of a unimodal `f` on `[lo, hi]`: `iterations`
/// steps, each shrinking the interval by `(sqrt 5 - 1) / 2`; returns the final interval.
pub fn golden_section(
    mut f: impl FnMut(f64) -> f64,
    (mut lo, mut hi): (f64, f64),
    iterations: usize,
) -> (f64, f64) {
    let g = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..iterations {
        if fa < fb {
            hi = b;
            b = a;
            fb = fa;
            a = hi - g * (hi - lo);
            fa = f(a);
        } else {
            lo = a;
            a = b;
            fa = fb;
            b = lo + g * (hi - lo);
            fb = f(b);
        }
    }
    (lo, hi)
}

/// The mean over `samples` uniform points of the box (`t in [0, pi/2]`, `g` and `p` in
/// `[-pi/2, pi/2]`, from a SplitMix64 stream seeded with `seed`) of each of `f`'s `K` values,
/// with its standard error: the Monte Carlo estimates that check the exact integrators
/// straight from the vector definitions.
pub fn box_average<const K: usize>(
    samples: u64,
    seed: u64,
    mut f: impl FnMut(f64, f64, f64) -> [f64; K],
) -> [(f64, f64); K] {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut state = seed;
    let mut next = move || {
        // SplitMix64, mapped to [0, 1).
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    };
    let (mut sum, mut sum_sq) = ([0.0; K], [0.0; K]);
    for _ in 0..samples {
        let t = next() * FRAC_PI_2;
        let g = (next() - 0.5) * PI;
        let p = (next() - 0.5) * PI;
        for (k, v) in f(t, g, p).into_iter().enumerate() {
            sum[k] += v;
            sum_sq[k] += v * v;
        }
    }
    let count = samples as f64;
    std::array::from_fn(|k| {
        let mean = sum[k] / count;
        let var = (sum_sq[k] / count - mean * mean).max(0.0);
        (mean, (var / count).sqrt())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Cosines;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn phong_cosine_matches_the_closed_form_in_notes() {
        for &(t, g, p) in &[
            (0.3_f64, 0.2_f64, -0.7_f64),
            (1.2, -1.0, 0.4),
            (FRAC_PI_2, 0.0, 1.0),
        ] {
            let closed = t.cos() * p.cos() - t.sin() * p.sin() * g.cos();
            let c = Cosines::of_box(t, g, p).rv;
            assert!((c - closed).abs() < 1e-15);
        }
    }

    #[test]
    fn blinn_cosine_matches_the_closed_form_in_notes() {
        for &(t, g, p) in &[(0.3_f64, 0.2_f64, -0.7_f64), (1.2, -1.0, 0.4)] {
            let l = light_dir(t, g);
            let v = view_dir(p);
            let closed = (t.cos() + p.cos()) / (l + v).length();
            let c = Cosines::of_box(t, g, p).nh;
            assert!((c - closed).abs() < 1e-15);
        }
    }

    #[test]
    fn the_lobe_peaks_on_the_mirror_direction() {
        // g = 0, p = -t puts V on the mirror of L: both cosines are 1.
        let c = Cosines::of_box(0.6, 0.0, -0.6);
        for (name, c) in [("R.V", c.rv), ("N.H", c.nh)] {
            assert!((c - 1.0).abs() < 1e-15, "{name}: {c}");
        }
    }
}
