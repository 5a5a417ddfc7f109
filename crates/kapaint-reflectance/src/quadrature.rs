//! Tanh-sinh (double-exponential) quadrature on finite intervals.
//!
//! The rule maps `[-1, 1]` onto the real line with `x = tanh(pi/2 * sinh(t))` and applies the
//! trapezoidal rule with step `h` in `t`. Nodes cluster double-exponentially at both ends, so
//! integrable endpoint singularities (`max(0, cos u)^n` at its zero for fractional `n`, or a
//! narrow peak placed at an interval end) converge almost as fast as smooth integrands. Halving
//! `h` doubles the node count and, for analytic integrands, roughly doubles the number of
//! correct digits: that "order doubling" is how the exact integrator shows its convergence.
//!
//! The rule is meant for bounded integrands: nodes whose weight is below `WEIGHT_FLOOR` of the
//! interval are dropped, which bounds the neglected part by `1e-18` of `max|f| (b - a)` and
//! saves almost half of the nodes of a rule that runs to the end of double precision.

use std::f64::consts::FRAC_PI_2;

/// Nodes with a smaller weight (on `[-1, 1]`) are not evaluated.
const WEIGHT_FLOOR: f64 = 1e-18;

/// One node of the rule on the reference interval `[-1, 1]`.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// Distance of the node from the right end, `1 - x`, kept separately so that nodes very
    /// close to an end keep their full relative precision.
    one_minus_x: f64,
    /// Quadrature weight on `[-1, 1]`.
    weight: f64,
}

/// A tanh-sinh rule of a fixed level, reusable for any interval.
#[derive(Clone, Debug)]
pub struct TanhSinh {
    /// Nodes for `t >= 0`; the rule is symmetric, so `t < 0` mirrors them.
    nodes: Vec<Node>,
    /// Weight of the centre node `x = 0`.
    centre_weight: f64,
}

impl TanhSinh {
    /// Builds the rule with step `h = 2^(-level/2)`: two levels up halve the step and double
    /// the node count (level 6 has 55 nodes, level 8 has 109).
    pub fn new(level: u32) -> Self {
        let h = 0.5_f64.powf(0.5 * f64::from(level));
        let centre_weight = h * FRAC_PI_2;
        let mut nodes = Vec::new();
        for k in 1.. {
            let t = f64::from(k) * h;
            let u = FRAC_PI_2 * t.sinh();
            // 1 - tanh(u) = 2 / (1 + e^(2u)), exact in relative terms for large u.
            let one_minus_x = 2.0 / (1.0 + (2.0 * u).exp());
            let cosh_u = u.cosh();
            let weight = h * FRAC_PI_2 * t.cosh() / (cosh_u * cosh_u);
            // Stop once the weight no longer matters for a bounded integrand.
            if one_minus_x < 1e-300 || weight < WEIGHT_FLOOR {
                break;
            }
            nodes.push(Node {
                one_minus_x,
                weight,
            });
        }
        Self {
            nodes,
            centre_weight,
        }
    }

    /// Number of function evaluations per interval.
    pub fn len(&self) -> usize {
        2 * self.nodes.len() + 1
    }

    /// Always false: a rule has at least its centre node.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Integrates `f` over `[a, b]`. Nodes that round onto an end point are skipped, so `f` is
    /// never called exactly at `a` or `b` (where it may be singular).
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let [v] = self.integrate_n(a, b, |x| [f(x)]);
        v
    }

    /// [`Self::integrate`] of `K` integrands at once, evaluated at the same nodes (for
    /// integrands that share most of their work).
    pub fn integrate_n<const K: usize>(
        &self,
        a: f64,
        b: f64,
        mut f: impl FnMut(f64) -> [f64; K],
    ) -> [f64; K] {
        let mut sum = [0.0; K];
        if b <= a {
            return sum;
        }
        let mut add = |w: f64, v: [f64; K]| {
            for (s, v) in sum.iter_mut().zip(v) {
                *s += w * v;
            }
        };
        let half = 0.5 * (b - a);
        let mid = a + half;
        add(self.centre_weight, f(mid));
        for node in &self.nodes {
            let offset = half * node.one_minus_x;
            let right = b - offset;
            let left = a + offset;
            if right < b {
                add(node.weight, f(right));
            }
            if left > a {
                add(node.weight, f(left));
            }
        }
        sum.map(|v| v * half)
    }

    /// Integrates `f` over consecutive intervals between sorted break points.
    pub fn integrate_pieces(&self, breaks: &[f64], mut f: impl FnMut(f64) -> f64) -> f64 {
        let [v] = self.integrate_pieces_n(breaks, |x| [f(x)]);
        v
    }

    /// [`Self::integrate_pieces`] of `K` integrands at once.
    pub fn integrate_pieces_n<const K: usize>(
        &self,
        breaks: &[f64],
        mut f: impl FnMut(f64) -> [f64; K],
    ) -> [f64; K] {
        let mut sum = [0.0; K];
        for w in breaks.windows(2) {
            let v = self.integrate_n(w[0], w[1], &mut f);
            for (s, v) in sum.iter_mut().zip(v) {
                *s += v;
            }
        }
        sum
    }
}

impl TanhSinh {
    /// The rule's nodes and weights over consecutive intervals between sorted break points,
    /// as `(x, weight)`: `sum weight * f(x)` is [`Self::integrate_pieces`] of `f`. Nodes that
    /// round onto an end point are left out.
    pub fn points(&self, breaks: &[f64]) -> Vec<(f64, f64)> {
        let mut terms: Vec<(f64, f64)> = Vec::new();
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a {
                continue;
            }
            let half = 0.5 * (b - a);
            terms.push((a + half, half * self.centre_weight));
            for node in &self.nodes {
                let offset = half * node.one_minus_x;
                if b - offset < b {
                    terms.push((b - offset, half * node.weight));
                }
                if a + offset > a {
                    terms.push((a + offset, half * node.weight));
                }
            }
        }
        terms
    }

    /// [`Self::integrate_pieces`] with the integrand evaluated in parallel. The terms are
    /// summed in a fixed order afterwards, so the result does not depend on the thread count.
    pub fn integrate_pieces_par(&self, breaks: &[f64], f: impl Fn(f64) -> f64 + Sync) -> f64 {
        let [v] = self.integrate_pieces_par_n(breaks, |x| [f(x)]);
        v
    }

    /// [`Self::integrate_pieces_par`] of `K` integrands at once.
    pub fn integrate_pieces_par_n<const K: usize>(
        &self,
        breaks: &[f64],
        f: impl Fn(f64) -> [f64; K] + Sync,
    ) -> [f64; K] {
        use rayon::prelude::*;
        let terms = self.points(breaks);
        let values: Vec<[f64; K]> = terms
            .par_iter()
            .map(|&(x, w)| f(x).map(|v| w * v))
            .collect();
        let mut sum = [0.0; K];
        for v in values {
            for (s, v) in sum.iter_mut().zip(v) {
                *s += v;
            }
        }
        sum
    }
}

/// Sorts break points, keeps those inside `[a, b]`, adds the ends and drops duplicates.
pub fn break_points(a: f64, b: f64, interior: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut points: Vec<f64> = interior
        .into_iter()
        .filter(|x| x.is_finite() && *x > a && *x < b)
        .collect();
    points.push(a);
    points.push(b);
    points.sort_by(f64::total_cmp);
    points.dedup_by(|x, y| (*x - *y).abs() <= 1e-15 * (1.0 + y.abs()));
    points
}

/// Geometric break points `start + sign * scale * 2^k` for k = 0, 1, ... while they stay
/// within `span` of `start`: they resolve a feature of width `scale` at `start` and the slowly
/// varying tail after it with intervals of bounded relative size.
pub fn graded_from(start: f64, sign: f64, scale: f64, span: f64) -> impl Iterator<Item = f64> {
    let mut offset = scale;
    std::iter::from_fn(move || {
        if offset >= span || offset.is_nan() || scale <= 0.0 {
            return None;
        }
        let point = start + sign * offset;
        offset *= 2.0;
        Some(point)
    })
}

/// The lobe is neglected where it is below `e^-WINDOW_LOG` of its local maximum.
const WINDOW_LOG: f64 = 40.0;

/// `exp(n * ln_1p(y))`, i.e. `(1 + y)^n` for `y in [-1, 0]`, with `0^0 = 1`.
pub(crate) fn pow1p(n: f64, y: f64) -> f64 {
    if n == 0.0 { 1.0 } else { (n * y.ln_1p()).exp() }
}

/// `1 - e^(-2 WINDOW_LOG / n)`: the largest `sin^2` of a lobe `(1 - sin^2)^(n/2)` that still
/// counts.
pub(crate) fn window_sin2(n: f64) -> f64 {
    if n == 0.0 {
        1.0
    } else {
        -(-2.0 * WINDOW_LOG / n).exp_m1()
    }
}

/// Largest angle `u` with `cos^n u >= e^-WINDOW_LOG`.
pub(crate) fn window_angle(n: f64) -> f64 {
    window_sin2(n).sqrt().min(1.0).asin()
}

/// Feature width `1/sqrt(n)` of the peak, used to grade the outer intervals.
pub(crate) fn peak_scale(n: f64) -> f64 {
    if n > 0.0 {
        n.sqrt().recip()
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_and_endpoint_singularities() {
        let rule = TanhSinh::new(8);
        let cubic = rule.integrate(0.0, 2.0, |x| x * x * x);
        assert!((cubic - 4.0).abs() < 1e-14, "{cubic}");
        // x^0.3 on [0, 1] has an infinite derivative at 0 and still converges.
        let singular = rule.integrate(0.0, 1.0, |x| x.powf(0.3));
        assert!((singular - 1.0 / 1.3).abs() < 1e-14, "{singular}");
        // sqrt(1 - x) has an infinite derivative at the right end.
        let root = rule.integrate(0.0, 1.0, |x| (1.0 - x).sqrt());
        assert!((root - 2.0 / 3.0).abs() < 1e-14, "{root}");
    }

    #[test]
    fn more_levels_converge() {
        let exact = std::f64::consts::PI / 2.0;
        let mut last = f64::INFINITY;
        for level in (2..12).step_by(2) {
            let q = TanhSinh::new(level).integrate(-1.0, 1.0, |x| (1.0 - x * x).sqrt());
            let err = (q - exact).abs();
            assert!(err <= last.max(1e-15), "level {level}: {err} after {last}");
            last = err;
        }
        assert!(last < 1e-13);
    }

    #[test]
    fn parallel_pieces_equal_serial_pieces() {
        let rule = TanhSinh::new(7);
        let breaks = [0.0, 0.1, 0.5, 2.0];
        let f = |x: f64| (x * 3.0).sin() + x.sqrt();
        let serial = rule.integrate_pieces(&breaks, f);
        let parallel = rule.integrate_pieces_par(&breaks, f);
        assert!((serial - parallel).abs() < 1e-14);
    }

    #[test]
    fn break_points_are_sorted_and_unique() {
        let b = break_points(0.0, 1.0, [0.5, 0.25, 0.5, 2.0, f64::NAN, -1.0]);
        assert_eq!(b, vec![0.0, 0.25, 0.5, 1.0]);
        let g: Vec<f64> = graded_from(0.0, 1.0, 0.1, 1.0).collect();
        assert_eq!(g.len(), 4);
        assert!((g[3] - 0.8).abs() < 1e-12);
    }
}
