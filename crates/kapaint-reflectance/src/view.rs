//! The specular part of the ambient term at one view angle, before eq. (6) averages over it:
//! `chi_view(n, phi)`, the mean of `rho_s` over `theta in [0, pi/2]` and the light's full
//! azimuth `gamma in [-pi, pi]`, in the paper's plain angle measure, with
//! `phi = acos(N.V) in [0, pi/2]`:
//!
//! ```text
//! chi_view(n, phi) = (1/pi^2) Int_0^{pi/2} dt Int_{-pi}^{pi} dg rho_s(n, t, g, phi)
//! ```
//!
//! Its mean over the view, `(2/pi) Int_0^{pi/2} chi_view dphi`, is `chi(n)`: mirroring `V`
//! across the normal maps the paper's half-range azimuth box at `-phi` onto the other half of
//! the full azimuth at `phi` (`rho_s(t, g, -phi) = rho_s(t, pi - g, phi)`).
//!
//! # Method
//!
//! The same mirror folds the full azimuth onto the paper's quarter: with `F(p)` the lobe's
//! integral over `t in [0, pi/2], g in [0, pi/2]` at the signed view angle `p`,
//! `chi_view(n, phi) = (2/pi^2) (F(phi) + F(-phi))`. `F` is the inner integral of the exact
//! `chi(n)` for Blinn-Phong and Cook-Torrance ([`super::exact`], [`super::cook_torrance`]),
//! which integrate it over `p`. For original Phong, whose exact `chi` integrates `p` in closed
//! form instead, `F` integrates `t` in closed form: at fixed `g`,
//! `R.V = ct cp - st sp cg = M cos(t + d)` with `M^2 = 1 - sp^2 sg^2` and
//! `d = atan2(sp cg, cp)`, so the `t` integral of the positive part is `M^n` times an integral
//! of `cos^n` over `[d, d + pi/2]` cut at `pi/2`: for `d >= 0` the span `[d, pi/2]` (its peak
//! at the lower end), for `d < 0` the two spans `[0, -d]` and `[0, pi/2 + d]` (the peak inside,
//! at `t = -d`, which is the mirror direction). The `g` integral is graded towards `g = 0`,
//! where `M^n` peaks with width `1/(sqrt(n) |sp|)`, and cut where `M^n` falls below `e^-40`.
//!
//! **Grazing views.** At `phi -> pi/2` nothing is singular: `cp -> 0` only moves `d` towards
//! `+-pi/2` and the mirror direction to the horizon. The integrators take `phi` up to `pi/2`;
//! the CLI accepts views in `[0, 90)` degrees.

use std::f64::consts::{FRAC_PI_2, PI};

use super::ShadingModel;
use num_traits::Float;

use super::exact::{DEFAULT_LEVEL, EXACT_N_MAX, cook_torrance_n};
use super::model::lobe::lit;
use super::model::{blinn, phong};
use super::quadrature::TanhSinh;

/// `[chi_view_1(n, phi), chi_view_0(n, phi)]`: for Phong and Blinn-Phong `[chi_view, 0]`; for
/// Cook-Torrance the per-view forms of its two parts (`k_s chi_1 + chi_0`). `n` is clamped as
/// [`super::exact::chi_exact`] clamps it, `phi` (radians) into `[0, pi/2]`; NaN is 0.
pub fn chi_view_exact(model: ShadingModel, n: f64, phi: f64) -> [f64; 2] {
    chi_view_exact_at_level(model, n, phi, DEFAULT_LEVEL)
}

/// [`chi_view_exact`] with an explicit tanh-sinh level, for convergence studies.
pub fn chi_view_exact_at_level(model: ShadingModel, n: f64, phi: f64, level: u32) -> [f64; 2] {
    let n = if n.is_nan() {
        0.0
    } else {
        n.clamp(0.0, EXACT_N_MAX)
    };
    let phi = if phi.is_nan() {
        0.0
    } else {
        phi.clamp(0.0, FRAC_PI_2)
    };
    let rule = TanhSinh::new(level);
    let k = 2.0 / (PI * PI);
    match model {
        ShadingModel::Phong => [
            k * (phong::exact::at_p(&rule, n, phi) + phong::exact::at_p(&rule, n, -phi)),
            0.0,
        ],
        ShadingModel::BlinnPhong => [
            k * (blinn::exact::at_p(&rule, n, phi) + blinn::exact::at_p(&rule, n, -phi)),
            0.0,
        ],
        ShadingModel::CookTorrance => {
            let a = super::cook_torrance::alpha(cook_torrance_n(n));
            let (up, down) = (
                super::cook_torrance::over_t(&rule, a, phi),
                super::cook_torrance::over_t(&rule, a, -phi),
            );
            [k * (up[0] + down[0]), k * (up[1] + down[1])]
        }
    }
}

/// Largest `n` the per-view table covers.
pub const VIEW_N_MAX: f32 = 16384.0;

/// Where `(n, phi)` falls in the table, in `[0, 1]^2`: `u` along
/// `log2(1 + n) / log2(1 + VIEW_N_MAX)`; `v` along the view angle, logarithmically from both
/// ends, `v = 1/2 + (ln(1 + w phi) / ln(1 + w pi/2) - ln(1 + g x) / ln(1 + g pi/2)) / 2` with
/// `x = pi/2 - phi`, `w = sqrt(1 + n)` (the inverse of the lobe's width) and
/// `g = hypot(w, VIEW_GRAZE)` (a smooth max): a sharp lobe's head-on peak and its cut by the horizon are as many
/// nodes wide as a broad lobe's, between them `chi_view` falls as a power of `phi` (a straight
/// line in `ln`), and the last degree before grazing is resolved whatever `n`.
///
/// Generic in the float type: the table's nodes are placed in `f64`, the renderer looks up in
/// `f32`, and `shaders/view_coords.wgsl`'s `view_table_coords` is checked against the `f32`
/// form by the GPU tests.
pub fn table_coords<F: Float>(n: F, phi: F) -> (F, F) {
    let one = F::one();
    let half_pi = lit::<F>(FRAC_PI_2);
    let width = (one + n).sqrt();
    let graze = width.hypot(lit(VIEW_GRAZE));
    let u = (one + n).log2() / (one + lit(f64::from(VIEW_N_MAX))).log2();
    let head_on = (width * phi).ln_1p() / (width * half_pi).ln_1p();
    let grazing = (graze * (half_pi - phi)).ln_1p() / (graze * half_pi).ln_1p();
    let half = lit::<F>(0.5);
    (u, half + half * (head_on - grazing))
}

/// The finest angle (its inverse, per radian) the table resolves at grazing views whatever
/// `n`: Cook-Torrance's and Phong's `chi_view` meet 90 degrees like `x ln x` in the angle `x`
/// left to the horizon, which is smooth in `ln x`.
pub const VIEW_GRAZE: f64 = 256.0;

/// The inverse of [`table_coords`]: `(n, phi)` at table position `(u, v)` in `[0, 1]^2`.
fn table_point(u: f64, v: f64) -> (f64, f64) {
    let n = ((u * (1.0 + f64::from(VIEW_N_MAX)).log2()).exp2() - 1.0).max(0.0);
    // v is increasing in phi: bisection.
    let (mut lo, mut hi) = (0.0, FRAC_PI_2);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if table_coords(n, mid).1 < v {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (n, 0.5 * (lo + hi))
}

/// `ln chi_view` of `model`'s parts at every node of a `nodes x nodes` table, row by row in
/// `u`: what [`view_table_bytes`] stores. Runs the exact integrator at every node.
pub fn view_table(model: ShadingModel, nodes: usize) -> Vec<[f64; 2]> {
    use rayon::prelude::*;
    let last = (nodes - 1) as f64;
    (0..nodes * nodes)
        .into_par_iter()
        .map(|k| {
            let (n, phi) = table_point((k / nodes) as f64 / last, (k % nodes) as f64 / last);
            chi_view_exact(model, n, phi).map(|c| if c > 0.0 { c.ln() } else { -745.0 })
        })
        .collect()
}

/// The worst relative error of `table` (a part of [`view_table`] as `f32`) against the exact
/// integrator at the centres of its cells (where interpolation is furthest from the nodes),
/// and where it is: `(error, n, phi)`.
pub fn table_error(
    model: ShadingModel,
    part: usize,
    nodes: usize,
    table: &[f32],
) -> (f64, f64, f64) {
    use rayon::prelude::*;
    let coefficients = spline::coefficients(table, nodes);
    let last = (nodes - 1) as f64;
    let cells = nodes - 1;
    (0..cells * cells)
        .into_par_iter()
        .map(|k| {
            let (u, v) = (
                ((k / cells) as f64 + 0.5) / last,
                ((k % cells) as f64 + 0.5) / last,
            );
            let (n, phi) = table_point(u, v);
            let exact = chi_view_exact(model, n, phi)[part];
            let (tu, tv) = table_coords(n, phi);
            let fast = f64::from(spline::eval(&coefficients, nodes, tu, tv).exp());
            ((fast / exact - 1.0).abs(), n, phi)
        })
        .reduce(|| (0.0, 0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Nodes per side of the shipped table.
pub const VIEW_NODES: usize = 128;

/// The tables in the order `view_table.bin` stores them: Phong, Blinn-Phong, Cook-Torrance's
/// `chi_1`, then its `chi_0`.
const TABLES: [(ShadingModel, usize); 4] = [
    (ShadingModel::Phong, 0),
    (ShadingModel::BlinnPhong, 0),
    (ShadingModel::CookTorrance, 0),
    (ShadingModel::CookTorrance, 1),
];

/// The bytes of `view_table.bin`: the four tables of `nodes^2` nodes as little-endian `f32`
/// (`ln chi_view`, rows in `u`), with each table's worst error between the nodes (see
/// [`table_error`]) on stderr. Runs the exact integrator at every node.
pub fn view_table_bytes(nodes: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(TABLES.len() * nodes * nodes * 4);
    let mut computed: Option<(ShadingModel, Vec<[f64; 2]>)> = None;
    for (model, part) in TABLES {
        if computed.as_ref().is_none_or(|(m, _)| *m != model) {
            computed = Some((model, view_table(model, nodes)));
        }
        let Some((_, table)) = &computed else {
            continue;
        };
        let values: Vec<f32> = table.iter().map(|v| v[part] as f32).collect();
        let (e, n, phi) = table_error(model, part, nodes, &values);
        eprintln!(
            "{model:?} part {part}: worst {e:.2e} at n {n:.1}, view {:.2} deg",
            phi.to_degrees()
        );
        out.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    }
    out
}

/// Coefficients per side of a shipped table's spline: a ring of one around the nodes.
pub const VIEW_COEFFICIENTS: usize = VIEW_NODES + 2;

/// The shipped tables' spline coefficients (`VIEW_COEFFICIENTS^2` each, rows in `u`), in the
/// order Phong, Blinn-Phong, Cook-Torrance's `chi_1`, its `chi_0`: decoded once from
/// `view_table.bin` (the nodes' `ln chi_view`) and made into the not-a-knot cubic B-spline
/// through them. What the shaders read (see `shaders/ambient_view.wgsl`).
pub fn view_coefficients() -> &'static [Vec<f32>; 4] {
    static TABLE: std::sync::LazyLock<[Vec<f32>; 4]> = std::sync::LazyLock::new(|| {
        let bytes = include_bytes!("view_table.bin");
        let size = VIEW_NODES * VIEW_NODES;
        std::array::from_fn(|k| {
            bytes[k * size * 4..(k + 1) * size * 4]
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect::<Vec<f32>>()
        })
        .map(|nodes| spline::coefficients(&nodes, VIEW_NODES))
    });
    &TABLE
}

/// `chi_view` from the table in `f32`, as a renderer evaluates it: `[chi_view, 0]` for Phong
/// and Blinn-Phong, both parts for Cook-Torrance. The cubic B-spline through the nodes of
/// `ln chi_view` over `log2(1 + n)` and the view angle in lobe widths from both ends (see
/// docs/reflectance.md). `None` for an `n` beyond [`VIEW_N_MAX`] or NaN; `phi` is clamped
/// into `[0, pi/2]`.
pub fn chi_view_fast(model: ShadingModel, n: f32, phi: f32) -> Option<[f32; 2]> {
    if n.is_nan() || !(0.0..=VIEW_N_MAX).contains(&n) {
        return None;
    }
    let phi = if phi.is_nan() {
        0.0
    } else {
        phi.clamp(0.0, std::f32::consts::FRAC_PI_2)
    };
    let (u, v) = table_coords(n, phi);
    let t = view_coefficients();
    let at = |c: &[f32]| spline::eval(c, VIEW_NODES, f64::from(u), f64::from(v)).exp();
    Some(match model {
        ShadingModel::Phong => [at(&t[0]), 0.0],
        ShadingModel::BlinnPhong => [at(&t[1]), 0.0],
        ShadingModel::CookTorrance => [at(&t[2]), at(&t[3])],
    })
}

/// `k_a` per view: the paper's ambient coefficient with `chi_view` at the view angle `phi`
/// (radians, between the eye and the normal) instead of its mean over the view:
/// `(2/pi) k_d + k_s chi_view(n, phi)`, and `(2/pi) k_d + k_s chi_view_1 + chi_view_0` for
/// Cook-Torrance. Inputs are sanitized as [`super::ka`] sanitizes them (an `n` beyond the table
/// is the table's last, `16384`, which is also the largest `n` a texel holds).
#[inline]
pub fn ka_view(
    model: ShadingModel,
    kd: glam::Vec3,
    ks: glam::Vec3,
    n: f32,
    phi: f32,
) -> glam::Vec3 {
    let kd = kd.map(super::sanitize_coefficient);
    let ks = ks.map(super::sanitize_coefficient);
    let n = super::sanitize_n_f32(n).min(VIEW_N_MAX);
    let [slope, offset] = chi_view_fast(model, n, phi).unwrap_or([0.0, 0.0]);
    super::TWO_OVER_PI as f32 * kd + ks * slope + glam::Vec3::splat(offset)
}

mod spline;

#[cfg(test)]
mod tests;
