//! Modified (Blinn-)Phong: `rho_s = max(0, N.H)^n` (eq. 9), whose ambient the paper
//! approximates by eq. (11). Its lobe, once; its exact integrals ([`exact`]); how the traced
//! renderer samples it.

pub mod exact;

use num_traits::Float;

use super::lobe::{Cosines, power};

/// The lobe at the cosines `c`, for a sanitized `n`: `[max(0, N.H)^n, 0]` where the light is
/// above the surface (`N.L > 0`) and the half vector exists, else 0.
#[inline]
pub fn lobe<F: Float>(c: &Cosines<F>, n: F) -> [F; 2] {
    if !(c.nl > F::zero() && c.has_half) {
        return [F::zero(); 2];
    }
    [power(c.nh, n), F::zero()]
}

/// The lobe's angular width in the light direction, about `2/sqrt(n)` (`n > 0`): the half
/// vector turns half as fast as the light.
pub fn width(n: f32) -> f32 {
    2.0 * n.sqrt().recip()
}

/// The width across the mirror direction at the light's polar angle `theta`, seen at view
/// angle `phi`: the half vector turns by `sin theta / (2 cos phi)` per radian of azimuth.
pub fn across(width: f32, theta: f32, phi: f32) -> f32 {
    width * phi.cos() / theta.sin().max(1e-6)
}
