//! Accuracy of every approximation against the exact integrator.

use std::fmt::Write as _;

use rayon::prelude::*;

use kapaint_reflectance::cook_torrance::{self, karis};
use kapaint_reflectance::{AmbientApprox, ShadingModel, chi_f32, chi_parts_f32, exact::chi_exact};

/// A range of `n` sampled for an accuracy report.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Human-readable name of the range, e.g. `[1, 200]`.
    pub label: String,
    /// Sample points, ascending.
    pub points: Vec<f64>,
}

impl Grid {
    /// `count` points on `[lo, hi]`, spaced evenly in `ln(n + 1)` so that small `n`, where
    /// `chi` changes fastest, is sampled as densely as large `n`; both ends included.
    pub fn log_spaced(lo: f64, hi: f64, count: usize) -> Self {
        let (a, b) = ((lo + 1.0).ln(), (hi + 1.0).ln());
        let count = count.max(2);
        let points = (0..count)
            .map(|i| {
                if i == count - 1 {
                    hi
                } else {
                    (a + (b - a) * i as f64 / (count - 1) as f64).exp() - 1.0
                }
            })
            .collect();
        Self {
            label: format!("[{lo}, {hi}]"),
            points,
        }
    }

    /// The two ranges the acceptance criteria name: the paper's `[1, 200]` and the product's
    /// `[0, 16384]`, with `points` samples each.
    pub fn standard(points: usize) -> Vec<Self> {
        vec![
            Self::log_spaced(1.0, 200.0, points),
            Self::log_spaced(0.0, 16384.0, points),
        ]
    }
}

/// Exact `chi` at every point of a grid, for one model.
#[derive(Clone, Debug)]
pub struct ExactSamples {
    /// The model sampled.
    pub model: ShadingModel,
    /// `(n, chi_exact(n))`, ascending in `n`.
    pub samples: Vec<(f64, f64)>,
}

impl ExactSamples {
    /// Evaluates the exact integrator on the grid (in parallel across points).
    pub fn compute(model: ShadingModel, grid: &Grid) -> Self {
        let samples = grid
            .points
            .par_iter()
            .map(|&n| (n, chi_exact(model, n)))
            .collect();
        Self { model, samples }
    }
}

/// The exact Cook-Torrance `[chi_1, chi_0]` at every point of a grid.
#[derive(Clone, Debug)]
pub struct CtSamples {
    /// `(n, [chi_1, chi_0])`, ascending in `n`.
    pub samples: Vec<(f64, [f64; 2])>,
}

impl CtSamples {
    /// Evaluates the exact integrator on the grid (in parallel across points).
    pub fn compute(grid: &Grid) -> Self {
        let samples = grid
            .points
            .par_iter()
            .map(|&n| (n, cook_torrance::chi_exact(n)))
            .collect();
        Self { samples }
    }

    /// The error statistics of `approx(n) = [chi_1, chi_0]`, for each part.
    pub fn stats(&self, approx: impl Fn(f64) -> [f64; 2]) -> [ErrorStats; 2] {
        let got: Vec<[f64; 2]> = self.samples.iter().map(|&(n, _)| approx(n)).collect();
        [0, 1].map(|k| {
            ErrorStats::of(
                self.samples
                    .iter()
                    .zip(&got)
                    .map(|(&(n, exact), got)| (n, got[k], exact[k])),
            )
        })
    }

    /// The larger of the two parts' maximum relative errors.
    pub fn max_rel(&self, approx: impl Fn(f64) -> [f64; 2]) -> f64 {
        let [a, b] = self.stats(approx);
        a.max_rel.max(b.max_rel)
    }
}

/// `[chi_1(n), chi_0(n)]` by some method.
pub type ChiParts = fn(f64) -> [f64; 2];

/// The Cook-Torrance methods the reports measure: kapaint's fit (in `f32`, as a renderer
/// evaluates it), and Karis' published fit at the box's mean view and view-averaged.
pub fn cook_torrance_methods() -> [(&'static str, ChiParts); 3] {
    [
        ("fast", |n| {
            chi_parts_f32(ShadingModel::CookTorrance, AmbientApprox::Fast, n as f32).map(f64::from)
        }),
        ("karis", karis::chi_karis),
        ("karis (view-averaged)", karis::chi_karis_view_averaged),
    ]
}

/// One row of the Cook-Torrance accuracy table: one part of one method on one grid.
#[derive(Clone, Debug)]
pub struct CtAccuracyRow {
    /// `chi1` or `chi0`.
    pub part: &'static str,
    /// The method measured.
    pub method: &'static str,
    /// The grid's label.
    pub range: String,
    /// The measured errors.
    pub stats: ErrorStats,
}

/// Error statistics of one approximation over one grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorStats {
    /// Largest relative error `|approx / exact - 1|`.
    pub max_rel: f64,
    /// Where the largest error occurs.
    pub max_at_n: f64,
    /// Mean relative error over the grid points.
    pub mean_rel: f64,
}

/// The relative error statistics of `approx` (evaluated in `f32`, as a renderer would).
pub fn error_stats(approx: AmbientApprox, exact: &ExactSamples) -> ErrorStats {
    ErrorStats::of(
        exact
            .samples
            .iter()
            .map(|&(n, chi)| (n, f64::from(chi_f32(exact.model, approx, n as f32)), chi)),
    )
}

impl ErrorStats {
    /// The statistics of `(n, approximation, exact)` triples: the relative error
    /// `|approx / exact - 1|`, its largest value and where, and its mean.
    pub fn of(points: impl Iterator<Item = (f64, f64, f64)>) -> Self {
        let mut stats = Self {
            max_rel: 0.0,
            max_at_n: 0.0,
            mean_rel: 0.0,
        };
        let mut count = 0_usize;
        for (n, approx, exact) in points {
            let err = (approx / exact - 1.0).abs();
            stats.mean_rel += err;
            count += 1;
            if err > stats.max_rel {
                stats.max_rel = err;
                stats.max_at_n = n;
            }
        }
        stats.mean_rel /= count.max(1) as f64;
        stats
    }
}

/// One row of the accuracy table.
#[derive(Clone, Debug)]
pub struct AccuracyRow {
    /// The lobe.
    pub model: ShadingModel,
    /// The approximation measured.
    pub approx: AmbientApprox,
    /// The grid's label.
    pub range: String,
    /// The measured errors.
    pub stats: ErrorStats,
}

/// The whole accuracy report.
#[derive(Clone, Debug)]
pub struct AccuracyReport {
    /// Every model and approximation on every grid.
    pub rows: Vec<AccuracyRow>,
    /// Eq. (11)'s exponent on the first grid (the paper's `[1, 200]`), when Blinn-Phong is
    /// measured.
    pub exponent: Option<ExponentCheck>,
    /// Cook-Torrance's two parts, every method on every grid.
    pub cook_torrance: Vec<CtAccuracyRow>,
}

/// Whether the paper's printed exponent for `model` was a misprint kapaint corrects (eq. 11's
/// Blinn-Phong exponent): the model whose exponent the report checks.
fn has_corrected_exponent(model: ShadingModel) -> bool {
    let [printed, corrected] = [AmbientApprox::PaperPrinted, AmbientApprox::PaperCorrected]
        .map(|approx| kapaint_reflectance::paper_constants(model, approx));
    printed.is_some() && printed != corrected
}

/// Measures every approximation of `models` on every grid (at least one), evaluating the
/// exact integrator once per model and grid.
pub fn accuracy_report(grids: &[Grid], models: &[ShadingModel]) -> AccuracyReport {
    let mut rows = Vec::new();
    let mut exponent = None;
    for model in ShadingModel::PAPER
        .into_iter()
        .filter(|m| models.contains(m))
    {
        for (i, grid) in grids.iter().enumerate() {
            let exact = ExactSamples::compute(model, grid);
            for approx in AmbientApprox::ALL {
                rows.push(AccuracyRow {
                    model,
                    approx,
                    range: grid.label.clone(),
                    stats: error_stats(approx, &exact),
                });
            }
            if i == 0 && has_corrected_exponent(model) {
                exponent = Some(exponent_check(&exact));
            }
        }
    }
    let exponent = models.iter().any(|&m| has_corrected_exponent(m)).then(|| {
        exponent.unwrap_or_else(|| {
            exponent_check(&ExactSamples::compute(
                ShadingModel::BlinnPhong,
                &Grid::log_spaced(1.0, 200.0, 32),
            ))
        })
    });
    let mut cook_torrance = Vec::new();
    let ct_grids = if models.contains(&ShadingModel::CookTorrance) {
        grids
    } else {
        &[]
    };
    for grid in ct_grids {
        let exact = CtSamples::compute(grid);
        for (method, approx) in cook_torrance_methods() {
            for (part, stats) in ["chi1", "chi0"].into_iter().zip(exact.stats(approx)) {
                cook_torrance.push(CtAccuracyRow {
                    part,
                    method,
                    range: grid.label.clone(),
                    stats,
                });
            }
        }
    }
    AccuracyReport {
        rows,
        exponent,
        cook_torrance,
    }
}

impl AccuracyReport {
    /// The tables of the models measured, as markdown, one blank line between them.
    pub fn markdown(&self) -> String {
        let mut tables = Vec::new();
        if !self.rows.is_empty() {
            tables.push(markdown(&self.rows));
        }
        if let Some(check) = &self.exponent {
            tables.push(exponent_markdown(check));
        }
        if !self.cook_torrance.is_empty() {
            tables.push(cook_torrance_markdown(&self.cook_torrance));
        }
        tables.join("\n")
    }
}

/// Renders the Cook-Torrance rows as a markdown table, with a note on Karis' setup.
pub fn cook_torrance_markdown(rows: &[CtAccuracyRow]) -> String {
    let mut out = String::from(
        "| cook-torrance | method | n range | max rel error | at n | mean rel error |\n\
         |---|---|---|---|---|---|\n",
    );
    for row in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3e} | {} | {:.3e} |",
            row.part,
            row.method,
            row.range,
            row.stats.max_rel,
            format_n(row.stats.max_at_n),
            row.stats.mean_rel,
        );
    }
    out.push_str(
        "\nkaris: Karis' environment-BRDF fit (Unreal Engine 4, 2014) as k_s A + B, roughness sqrt(alpha), \
         at N.V = 2/pi or averaged over the box's views. It fits another lighting setup (the \
         solid-angle, N.L-weighted hemisphere seen from one view), so its error here is what \
         a user would get by using it for this ambient term, not the fit's own error.\n",
    );
    out
}

/// Renders the rows as a markdown table.
pub fn markdown(rows: &[AccuracyRow]) -> String {
    let mut out = String::from(
        "| model | method | n range | max rel error | at n | mean rel error |\n\
         |---|---|---|---|---|---|\n",
    );
    for row in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3e} | {} | {:.3e} |",
            row.model.name(),
            row.approx.name(),
            row.range,
            row.stats.max_rel,
            format_n(row.stats.max_at_n),
            row.stats.mean_rel,
        );
    }
    out
}

/// The paper's eq. (11) exponent check: with the printed `a` and `b`, the exponent that
/// minimises the max relative error on `exact` (Blinn-Phong samples on `[1, 200]`), beside
/// the printed one.
#[derive(Clone, Debug)]
pub struct ExponentCheck {
    /// The printed exponent and its max relative error.
    pub printed: (f64, f64),
    /// The minimax exponent and its max relative error.
    pub minimax: (f64, f64),
    /// The shipped corrected exponent and its max relative error.
    pub shipped: (f64, f64),
}

/// Runs the exponent check on Blinn-Phong samples.
pub fn exponent_check(exact: &ExactSamples) -> ExponentCheck {
    use kapaint_reflectance::{PAPER_BLINN, PAPER_BLINN_CORRECTED_EXPONENT, fit};
    let (a, b, c) = PAPER_BLINN;
    let err = |c: f64| fit::power_law_max_error(a, b, c, &exact.samples);
    ExponentCheck {
        printed: (c, err(c)),
        minimax: fit::paper_exponent_minimax(a, b, &exact.samples, (-0.95, -0.8)),
        shipped: (
            PAPER_BLINN_CORRECTED_EXPONENT,
            err(PAPER_BLINN_CORRECTED_EXPONENT),
        ),
    }
}

/// Renders the exponent check as a markdown table.
pub fn exponent_markdown(check: &ExponentCheck) -> String {
    let mut out = String::from(
        "| eq. (11), a = 2.5235, b = 3 | exponent c | max rel error on [1, 200] |\n|---|---|---|\n",
    );
    for (label, (c, e)) in [
        ("as printed", check.printed),
        ("minimax (our integrator)", check.minimax),
        ("shipped correction", check.shipped),
    ] {
        let _ = writeln!(out, "| {label} | {c:.4} | {:.3} % |", 100.0 * e);
    }
    out
}

/// Formats a sample point compactly (grid points are not round numbers).
pub fn format_n(n: f64) -> String {
    if n == n.round() {
        format!("{n}")
    } else {
        format!("{n:.4}")
    }
}
