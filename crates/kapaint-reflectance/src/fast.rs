//! kapaint's own real-time approximation of `chi(n)` (the default everywhere).
//!
//! Per octave of `x = n + 1`, a polynomial in the mantissa gives `g = x chi`; `chi = g / x`.
//! The octave and mantissa come from the float's bits, so the cost is a few integer
//! operations, one Horner chain and one division: no `powf`, no `ln` below `n = 32767`. Above
//! that, the derived asymptotic law `(A ln x + B + C / sqrt x) / x` takes over. How the
//! constants are fitted, and why this form, is in [`super::fit`]; the constants themselves are
//! generated into `fast_coeffs.rs`, the one source for Rust and WGSL.
//!
//! Both functions expect an already sanitized `n` (finite or `+inf`, `>= 0`); the public entry
//! points in [`super`] sanitize first.

use super::ShadingModel;
use super::fast_coeffs::{BLINN_OCTAVES, BLINN_TAIL, DEGREE, OCTAVES, PHONG_OCTAVES, PHONG_TAIL};

/// `x = n + 1` from which the asymptotic tail is used.
pub const TAIL_START_X: f32 = (1u32 << OCTAVES) as f32;

/// The coefficient table and tail of one model.
#[derive(Clone, Copy, Debug)]
pub struct FastTable {
    /// Per-octave polynomial coefficients, lowest power first.
    pub octaves: &'static [[f32; DEGREE + 1]; OCTAVES],
    /// `[A, B, C]` of the asymptotic tail.
    pub tail: &'static [f32; 3],
}

/// The coefficient table and tail of a model. Cook-Torrance has a table of pairs of its own
/// ([`super::cook_torrance::fast`]); callers dispatch to it first, and get Phong's here.
#[inline]
pub fn table(model: ShadingModel) -> FastTable {
    match model {
        ShadingModel::Phong | ShadingModel::CookTorrance => FastTable {
            octaves: &PHONG_OCTAVES,
            tail: &PHONG_TAIL,
        },
        ShadingModel::BlinnPhong => FastTable {
            octaves: &BLINN_OCTAVES,
            tail: &BLINN_TAIL,
        },
    }
}

/// `chi(n)` in `f32` for a sanitized `n >= 0`.
#[inline]
pub fn chi_f32(model: ShadingModel, n: f32) -> f32 {
    chi_f32_with(table(model), n)
}

/// [`chi_f32`] with the model's table already selected (for hot loops).
#[inline]
pub fn chi_f32_with(table: FastTable, n: f32) -> f32 {
    let FastTable { octaves, tail } = table;
    let x = n + 1.0;
    if x >= TAIL_START_X {
        let [a, b, c] = *tail;
        return (a * x.ln() + b + c / x.sqrt()) / x;
    }
    let (octave, s) = octave_f32(x, OCTAVES);
    let coefficients = &octaves[octave];
    let mut g = coefficients[DEGREE];
    for k in (0..DEGREE).rev() {
        g = g * s + coefficients[k];
    }
    g / x
}

/// `chi(n)` in `f64` for a sanitized `n >= 0`, from the same constants as [`chi_f32`].
pub fn chi_f64(model: ShadingModel, n: f64) -> f64 {
    let FastTable { octaves, tail } = table(model);
    let x = n + 1.0;
    if x >= f64::from(TAIL_START_X) {
        let [a, b, c] = tail.map(f64::from);
        return (a * x.ln() + b + c / x.sqrt()) / x;
    }
    let (octave, s) = octave_f64(x, OCTAVES);
    let g = octaves[octave]
        .iter()
        .rev()
        .fold(0.0, |acc, &c| acc * s + f64::from(c));
    g / x
}

/// The octave of `x >= 1` (its binary exponent, at most `octaves - 1`) and the position in it,
/// `s = 2 mantissa - 3 in [-1, 1)`: from the float's bits, no `log2`. The fits of both
/// families are polynomials in `s` per octave.
#[inline]
pub fn octave_f32(x: f32, octaves: usize) -> (usize, f32) {
    let bits = x.to_bits();
    // x in [1, 2^octaves): the biased exponent is 127..127+octaves-1.
    let octave = ((bits >> 23) as usize).saturating_sub(127).min(octaves - 1);
    let mantissa = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    (octave, 2.0 * mantissa - 3.0)
}

/// [`octave_f32`] in `f64`.
#[inline]
pub fn octave_f64(x: f64, octaves: usize) -> (usize, f64) {
    let bits = x.to_bits();
    let octave = ((bits >> 52) as usize)
        .saturating_sub(1023)
        .min(octaves - 1);
    let mantissa = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    (octave, 2.0 * mantissa - 3.0)
}
