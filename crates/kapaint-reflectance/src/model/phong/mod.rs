//! Original Phong: `rho_s = max(0, R.V)^n` (eq. 4), whose ambient the paper approximates by
//! eq. (8). Its lobe, once; its exact integrals ([`exact`]); how the traced renderer samples it.

pub mod exact;

use num_traits::Float;

use super::lobe::{Cosines, power};

/// The lobe at the cosines `c`, for a sanitized `n`: `[max(0, R.V)^n, 0]` where the light is
/// above the surface (`N.L > 0`), else 0.
#[inline]
#[expect(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "NaN takes the zero branch: `!(x > 0)` says so, `x <= 0` would not"
)]
pub fn lobe<F: Float>(c: &Cosines<F>, n: F) -> [F; 2] {
    if !(c.nl > F::zero()) {
        return [F::zero(); 2];
    }
    [power(c.rv, n), F::zero()]
}

/// The lobe's angular width in the light direction, about `1/sqrt(n)` (`n > 0`).
pub fn width(n: f32) -> f32 {
    n.sqrt().recip()
}

/// The width across the mirror direction (in the light's azimuth) at the light's polar angle
/// `theta`, seen at view angle `phi`: `R.V` falls like `sin theta sin phi (1 + cos gamma)`.
pub fn across(width: f32, theta: f32, phi: f32) -> f32 {
    width / (theta.sin() * phi.sin()).max(1e-12).sqrt()
}
