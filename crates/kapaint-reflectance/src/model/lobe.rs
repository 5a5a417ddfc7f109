//! What a specular lobe reads of the geometry: the cosines between the unit normal `N`, the
//! unit direction to the light `L` and the unit direction to the eye `V`, computed once for
//! every model. Each model's folder writes its lobe over [`Cosines`], generic in the float
//! type, so the preview's `f32` twin and the integrals' `f64` reference are the same source.

use glam::{DVec3, Vec3};
use num_traits::Float;

/// The cosines of one shading geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cosines<F> {
    /// `N.L`.
    pub nl: F,
    /// `N.V`.
    pub nv: F,
    /// `R.V`, with `R = 2 (N.L) N - L` the mirror direction of the light (original Phong).
    pub rv: F,
    /// `N.H`, with `H` the unit half vector `(L + V) / |L + V|` (0 where `L = -V`).
    pub nh: F,
    /// `|N x H|^2 = 1 - (N.H)^2`, written without cancellation next to the peak.
    pub cross2: F,
    /// `V.H`.
    pub vh: F,
    /// Whether `H` exists (`|L + V| > 0`; false also for NaN input).
    pub has_half: bool,
}

macro_rules! cosines_of {
    ($name:ident, $float:ty, $vec:ty) => {
        /// The cosines of unit `normal`, `l` (towards the light) and `v` (towards the eye).
        pub fn $name(normal: $vec, l: $vec, v: $vec) -> Cosines<$float> {
            let nl = normal.dot(l);
            let nv = normal.dot(v);
            let rv = (2.0 * nl * normal - l).dot(v);
            let sum = l + v;
            let len2 = sum.dot(sum);
            if len2 > 0.0 {
                let h = sum / len2.sqrt();
                let c = normal.cross(h);
                Cosines {
                    nl,
                    nv,
                    rv,
                    nh: normal.dot(h),
                    cross2: c.dot(c),
                    vh: v.dot(h),
                    has_half: true,
                }
            } else {
                Cosines {
                    nl,
                    nv,
                    rv,
                    nh: 0.0,
                    cross2: 1.0,
                    vh: 0.0,
                    has_half: false,
                }
            }
        }
    };
}

impl Cosines<f32> {
    cosines_of!(of, f32, Vec3);
}

impl Cosines<f64> {
    cosines_of!(of_f64, f64, DVec3);

    /// The cosines at a point `(theta, gamma, phi)` of the paper's box
    /// ([`crate::geometry`]: the normal along `+y`).
    pub fn of_box(theta: f64, gamma: f64, phi: f64) -> Self {
        Self::of_f64(
            DVec3::Y,
            crate::geometry::light_dir(theta, gamma),
            crate::geometry::view_dir(phi),
        )
    }
}

/// `max(0, c)^n` as the shaders compute it (`exp2(n log2 c)`, `c` capped at 1): 0 where
/// `c <= 0` or NaN, 1 where `n = 0` and `c > 0` (the limit `n -> 0` of the lobe).
#[inline]
#[expect(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "NaN takes the zero branch: `!(x > 0)` says so, `x <= 0` would not"
)]
pub fn power<F: Float>(c: F, n: F) -> F {
    if !(c > F::zero()) {
        return F::zero();
    }
    (n * c.min(F::one()).log2()).exp2()
}

/// `F` from an `f64` literal (exact for the constants the lobes use).
#[inline]
pub(crate) fn lit<F: Float>(x: f64) -> F {
    F::from(x).unwrap_or_else(F::nan)
}
