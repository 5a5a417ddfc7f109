//! kapaint's real-time approximation of the Cook-Torrance `[chi_1(n), chi_0(n)]`.
//!
//! Per octave of `x = n + 1`, one polynomial in the mantissa for each function, evaluated as a
//! pair (a `vec2` Horner chain in the shaders): a few integer operations and one chain of
//! multiply-adds, no division, no `powf`, no `ln`. How the constants are fitted is in
//! [`super::fit`]; they are generated into `fast_coeffs.rs`, the one source for Rust and the
//! shaders.
//!
//! # The mapping's limit
//!
//! `n` is clamped to [`N_MAX`] (`alpha = sqrt(2 / (N_MAX + 2)) ~= 1.41e-3`, a near mirror):
//! the box average of a mirror is unbounded (`chi_1 + chi_0` grows like `ln(n) / pi^3`, see
//! [`super`]), and a GGX lobe narrower than that is below what `f32` shading resolves. So
//! `chi_1 <= 0.51` and `k_a <= 2/pi + 1` for every input, as for the other models.

use glam::Vec4;

use super::fast_coeffs::{CHI_OCTAVES, DEGREE, OCTAVES};
use crate::fast::{octave_f32, octave_f64};

/// The largest exponent the Cook-Torrance model uses; larger values (and `+inf`) are clamped
/// to it (the exact integrator reaches a little further, to the end of the fit's last
/// octave).
pub const N_MAX: f32 = 1.0e6;

/// `[chi_1(n), chi_0(n)]` in `f32` for a sanitized `n >= 0`.
#[inline]
pub fn chi_f32(n: f32) -> [f32; 2] {
    let x = n.min(N_MAX) + 1.0;
    let (octave, s) = octave_f32(x, OCTAVES);
    let coefficients = &CHI_OCTAVES[octave];
    // Both parts in the lanes of one SIMD register: one multiply and one add a step.
    let lanes = |[a, b]: [f32; 2]| Vec4::new(a, b, 0.0, 0.0);
    let s = Vec4::splat(s);
    let mut g = lanes(coefficients[DEGREE]);
    for &c in coefficients[..DEGREE].iter().rev() {
        g = g * s + lanes(c);
    }
    [g.x, g.y]
}

/// `[chi_1(n), chi_0(n)]` in `f64` for a sanitized `n >= 0`, from the same constants.
pub fn chi_f64(n: f64) -> [f64; 2] {
    let x = n.min(f64::from(N_MAX)) + 1.0;
    let (octave, s) = octave_f64(x, OCTAVES);
    CHI_OCTAVES[octave].iter().rev().fold([0.0; 2], |acc, c| {
        [acc[0] * s + f64::from(c[0]), acc[1] * s + f64::from(c[1])]
    })
}
