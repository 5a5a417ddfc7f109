//! Fitting the constants of [`super::fast`] from [`super::exact`], and of the corrected paper
//! exponent. `cargo run --release --example fit_fast` regenerates `fast_coeffs.rs` with this
//! code; a test checks that the committed file is what the fit produces.
//!
//! # The form of `Fast`
//!
//! With `x = n + 1`, the function `g(x) = x chi(x - 1)` is smooth and slowly varying: the
//! `1/(n+1)` of the Phong lobe's kink cancels, and at large `n` it grows like `A ln x + B`.
//! Each octave `x in [2^e, 2^(e+1))` gets a polynomial in `s = 2 x / 2^e - 3 in [-1, 1)` that
//! interpolates `g` at the Chebyshev-Lobatto points of the octave. The end points are among
//! those points, so neighbouring octaves agree at their shared end to rounding: the
//! approximation is continuous. Evaluating it needs the float's exponent and mantissa (bit
//! operations), a short Horner chain and one division: cheaper than one `powf`.
//!
//! Beyond the last octave, `g(x) = A ln x + B + C / sqrt(x)` with the derived slope `A`
//! ([`super::exact::asymptotic_slope`]) and `B`, `C` matched to the exact values at the
//! boundary and at `x = 2^19`.

use rayon::prelude::*;

use super::ShadingModel;
use super::exact::{asymptotic_slope, chi_exact};

/// Octaves covered by polynomials: `x = n + 1 in [1, 2^15)`, i.e. `n in [0, 32767)`.
pub const FIT_OCTAVES: usize = 15;

/// Where the asymptotic tail starts: `x = 2^FIT_OCTAVES`.
pub const TAIL_START_X: f64 = (1u64 << FIT_OCTAVES) as f64;

/// Second matching point of the tail, `x = 2^19`.
pub const TAIL_MATCH_X: f64 = (1u64 << 19) as f64;

/// A fitted `Fast` approximation for one model.
#[derive(Clone, Debug, PartialEq)]
pub struct FastFit {
    /// Polynomial degree per octave.
    pub degree: usize,
    /// Per octave, the coefficients of `g` in powers of `s`, lowest first.
    pub octaves: Vec<Vec<f64>>,
    /// `(A, B, C)` of the tail `g = A ln x + B + C / sqrt(x)`.
    pub tail: [f64; 3],
}

impl FastFit {
    /// Evaluates the fitted `chi(n)` in `f64` (for measuring the fit itself).
    pub fn chi(&self, n: f64) -> f64 {
        let x = n.max(0.0) + 1.0;
        if x >= TAIL_START_X {
            let [a, b, c] = self.tail;
            return (a * x.ln() + b + c / x.sqrt()) / x;
        }
        let (octave, s) = super::fast::octave_f64(x, FIT_OCTAVES);
        horner(&self.octaves[octave], s) / x
    }
}

/// Evaluates a polynomial with coefficients lowest power first.
pub fn horner(coefficients: &[f64], s: f64) -> f64 {
    coefficients.iter().rev().fold(0.0, |acc, &c| acc * s + c)
}

/// The Chebyshev-Lobatto points `-cos(pi j / d)`, `j = 0..=d`, ascending from -1 to 1.
pub fn lobatto_nodes(degree: usize) -> Vec<f64> {
    (0..=degree)
        .map(|j| -(std::f64::consts::PI * j as f64 / degree as f64).cos())
        .map(|s| if s.abs() < 1e-15 { 0.0 } else { s })
        .collect()
}

/// `x` for the node `s` of `octave`.
pub fn node_x(octave: usize, s: f64) -> f64 {
    (1u64 << octave) as f64 * (s + 3.0) / 2.0
}

/// The `x` of every node of the first `octaves` octaves, ascending, each shared end point once.
pub fn octave_node_xs(octaves: usize, nodes: &[f64]) -> Vec<f64> {
    let mut xs: Vec<f64> = (0..octaves)
        .flat_map(|octave| nodes.iter().map(move |&s| node_x(octave, s)))
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs
}

/// Samples `sample` once at each of `xs` (ascending; in parallel) and returns the lookup of a
/// sampled `x`: the truth a fit's octaves are interpolated from.
pub fn sampled_at<T: Copy + Send>(
    xs: Vec<f64>,
    sample: impl Fn(f64) -> T + Sync,
) -> impl Fn(f64) -> T {
    let values: Vec<T> = xs.par_iter().map(|&x| sample(x)).collect();
    move |x| values[xs.partition_point(|&v| v < x)]
}

/// `g(x) = x chi(x - 1)` by the exact integrator.
pub fn g_exact(model: ShadingModel, x: f64) -> f64 {
    x * chi_exact(model, x - 1.0)
}

/// Solves the Vandermonde system: the coefficients of the polynomial through `(s_j, y_j)`.
pub fn interpolate(nodes: &[f64], values: &[f64]) -> Vec<f64> {
    let size = nodes.len();
    let mut matrix: Vec<Vec<f64>> = nodes
        .iter()
        .zip(values)
        .map(|(&s, &y)| {
            let mut row: Vec<f64> = (0..size).map(|k| s.powi(k as i32)).collect();
            row.push(y);
            row
        })
        .collect();
    // Gaussian elimination with partial pivoting; the systems here are at most 13 x 13.
    for col in 0..size {
        let pivot = (col..size)
            .max_by(|&a, &b| matrix[a][col].abs().total_cmp(&matrix[b][col].abs()))
            .unwrap_or(col);
        matrix.swap(col, pivot);
        let pivot_row = matrix[col].clone();
        for row in matrix.iter_mut().skip(col + 1) {
            let factor = row[col] / pivot_row[col];
            for (value, &p) in row.iter_mut().zip(&pivot_row).skip(col) {
                *value -= factor * p;
            }
        }
    }
    let mut coefficients = vec![0.0; size];
    for row in (0..size).rev() {
        let tail: f64 = (row + 1..size)
            .map(|k| matrix[row][k] * coefficients[k])
            .sum();
        coefficients[row] = (matrix[row][size] - tail) / matrix[row][row];
    }
    coefficients
}

/// Fits `Fast` for `model` with `sample(x) = g(x)` as the truth: the exact integrator for the
/// shipped constants, or a cheaper reference when exploring degrees.
pub fn fit_with(model: ShadingModel, degree: usize, sample: impl Fn(f64) -> f64 + Sync) -> FastFit {
    let nodes = lobatto_nodes(degree);
    // Every octave's nodes; shared end points are evaluated once.
    let mut xs = octave_node_xs(FIT_OCTAVES, &nodes);
    xs.push(TAIL_MATCH_X);
    let lookup = sampled_at(xs, sample);
    let octaves = (0..FIT_OCTAVES)
        .map(|octave| {
            let ys: Vec<f64> = nodes.iter().map(|&s| lookup(node_x(octave, s))).collect();
            interpolate(&nodes, &ys)
        })
        .collect();
    let a = asymptotic_slope(model);
    let (x0, x1) = (TAIL_START_X, TAIL_MATCH_X);
    let (r0, r1) = (lookup(x0) - a * x0.ln(), lookup(x1) - a * x1.ln());
    // r = B + C / sqrt(x) through both points.
    let c = (r0 - r1) / (x0.sqrt().recip() - x1.sqrt().recip());
    let b = r0 - c / x0.sqrt();
    FastFit {
        degree,
        octaves,
        tail: [a, b, c],
    }
}

/// Fits `Fast` for `model` against the exact integrator.
pub fn fit_exact(model: ShadingModel, degree: usize) -> FastFit {
    fit_with(model, degree, |x| g_exact(model, x))
}

/// Renders the generated Rust source of `fast_coeffs.rs`. Coefficients are stored as `f32`,
/// the precision the per-texel path and the shaders use; the `f64` path reads the same values.
pub fn render_rust(phong: &FastFit, blinn: &FastFit) -> String {
    use std::fmt::Write as _;
    let degree = phong.degree;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "//! Generated by `cargo run --release --example fit_fast`: do not edit by hand.\n\
         //! The single source of the `Fast` constants for Rust and WGSL (see `fit.rs`).\n\n\
         #![expect(clippy::unreadable_literal, reason = \"generated fit constants, printed in full\")]\n\n\
         /// Polynomial degree per octave.\n\
         pub const DEGREE: usize = {degree};\n\n\
         /// Octaves covered by polynomials, `x = n + 1 in [1, 2^OCTAVES)`.\n\
         pub const OCTAVES: usize = {FIT_OCTAVES};"
    );
    for (name, fit) in [("PHONG", phong), ("BLINN", blinn)] {
        let _ = writeln!(
            out,
            "\n/// Per-octave coefficients of `g = (n + 1) chi` in powers of `s`, lowest first.\n\
             pub const {name}_OCTAVES: [[f32; DEGREE + 1]; OCTAVES] = ["
        );
        for coefficients in &fit.octaves {
            let row: Vec<String> = coefficients
                .iter()
                .map(|&c| format!("{:e}", c as f32))
                .collect();
            let _ = writeln!(out, "    [{}],", row.join(", "));
        }
        let tail: Vec<String> = fit
            .tail
            .iter()
            .map(|&c| format!("{:e}", c as f32))
            .collect();
        let _ = writeln!(
            out,
            "];\n\n/// Tail `g = A ln x + B + C / sqrt(x)` beyond the last octave: `[A, B, C]`.\n\
             pub const {name}_TAIL: [f32; 3] = [{}];",
            tail.join(", ")
        );
    }
    out
}

/// Maximum relative error of `a (n + b)^c` against `reference` over the sample points.
pub fn power_law_max_error(a: f64, b: f64, c: f64, samples: &[(f64, f64)]) -> f64 {
    samples
        .iter()
        .map(|&(n, chi)| (a * (n + b).powf(c) / chi - 1.0).abs())
        .fold(0.0, f64::max)
}

/// The exponent `c` minimising the maximum relative error of `a (n + b)^c` over the samples
/// `(n, chi)`, by golden-section search on `[c_lo, c_hi]` (the max error is unimodal in `c`).
pub fn paper_exponent_minimax(
    a: f64,
    b: f64,
    samples: &[(f64, f64)],
    (c_lo, c_hi): (f64, f64),
) -> (f64, f64) {
    let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (c_lo, c_hi);
    let err = |c: f64| power_law_max_error(a, b, c, samples);
    while hi - lo > 1e-9 {
        let m1 = hi - ratio * (hi - lo);
        let m2 = lo + ratio * (hi - lo);
        if err(m1) < err(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let c = 0.5 * (lo + hi);
    (c, err(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_reproduces_a_polynomial() {
        let nodes = lobatto_nodes(5);
        let poly = [0.5, -1.0, 0.25, 2.0, -0.125, 0.75];
        let values: Vec<f64> = nodes.iter().map(|&s| horner(&poly, s)).collect();
        let coefficients = interpolate(&nodes, &values);
        for (c, p) in coefficients.iter().zip(poly) {
            assert!((c - p).abs() < 1e-12, "{c} vs {p}");
        }
        assert_eq!(nodes[0], -1.0);
        assert_eq!(nodes[5], 1.0);
    }

    #[test]
    fn fit_of_a_known_function_is_continuous_and_accurate() {
        // g(x) = 0.2 ln x + 1: what chi looks like at large n.
        let fit = fit_with(ShadingModel::Phong, 6, |x| 0.2 * x.ln() + 1.0);
        for octave in 1..FIT_OCTAVES {
            let x = (1u64 << octave) as f64;
            let below = horner(&fit.octaves[octave - 1], 1.0) / x;
            let above = horner(&fit.octaves[octave], -1.0) / x;
            assert!((below / above - 1.0).abs() < 1e-12);
        }
        for i in 0..2000 {
            let n = 16384.0 * (f64::from(i) / 2000.0).powi(3);
            let want = (0.2 * (n + 1.0).ln() + 1.0) / (n + 1.0);
            assert!((fit.chi(n) / want - 1.0).abs() < 1e-5, "n={n}");
        }
    }
}
