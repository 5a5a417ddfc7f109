//! `kapaint chi`: chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`; for
//! Cook-Torrance both parts of `k_s chi1(n) + chi0(n)`, as CSV `n,chi1,chi0`.

use std::fmt::Write as _;
use std::io::BufRead;

use super::CliError;
use super::args::{MethodArg, ModelArg, check_method, fmt17, parse_n, read_stdin_values};
use crate::reflectance::{self, ShadingModel, exact::chi_parts_exact};

/// Print chi(n), the specular part of k_a per unit k_s, as CSV `n,chi` (Cook-Torrance:
/// `n,chi1,chi0`, where its specular part is `k_s chi1 + chi0`).
#[derive(Debug, clap::Args)]
pub struct ChiArgs {
    /// Specular lobe.
    #[arg(long, value_enum)]
    model: ModelArg,
    /// How chi is computed.
    #[arg(long, value_enum)]
    method: MethodArg,
    /// View angles in degrees, `[0, 90)` (repeatable): prints `chi_view(n, view)`, the
    /// specular part at that angle between the normal and the eye, one row per pair.
    #[arg(long = "view", allow_hyphen_values = true)]
    views: Vec<String>,
    /// Exponents (n >= 0); a single `-` reads one value per line from stdin.
    #[arg(required = true, allow_hyphen_values = true)]
    n: Vec<String>,
}

/// Most `--view` values one run takes.
pub const MAX_VIEWS: usize = 4096;

/// A `--view` value: degrees in `[0, 90)`.
fn parse_view(text: &str) -> Result<f64, CliError> {
    let v: f64 = text.trim().parse().map_err(|_| {
        CliError::usage(format!("--view must be a number of degrees, got {text:?}"))
    })?;
    if !(0.0..90.0).contains(&v) {
        return Err(CliError::usage(format!(
            "--view must be in [0, 90) degrees, got {text}"
        )));
    }
    Ok(v)
}

impl ChiArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// An exponent that is not a number, negative, or beyond the method's range.
    pub fn run(self, stdin: &mut dyn BufRead) -> Result<String, CliError> {
        check_method(self.model.into(), self.method)?;
        if self.views.len() > MAX_VIEWS {
            return Err(CliError::usage(format!(
                "at most {MAX_VIEWS} --view values, got {}",
                self.views.len()
            )));
        }
        let views = self
            .views
            .iter()
            .map(|v| parse_view(v))
            .collect::<Result<Vec<_>, _>>()?;
        if !views.is_empty() && !matches!(self.method, MethodArg::Exact | MethodArg::Fast) {
            return Err(CliError::usage(
                "--view takes --method exact or --method fast (the paper printed no per-view form)",
            ));
        }
        let values = if self.n.len() == 1 && self.n[0] == "-" {
            read_stdin_values(stdin, self.method)?
        } else {
            self.n
                .iter()
                .map(|s| parse_n(s, self.method))
                .collect::<Result<Vec<_>, _>>()?
        };
        if views.is_empty() {
            return Ok(chi_csv(self.model.into(), self.method, &values));
        }
        chi_view_csv(self.model.into(), self.method, &values, &views)
    }
}

/// One row per `(n, view)` pair, `n` by `n`: `n,view,chi` (Cook-Torrance `n,view,chi1,chi0`).
fn chi_view_csv(
    model: ShadingModel,
    method: MethodArg,
    values: &[f64],
    views: &[f64],
) -> Result<String, CliError> {
    use rayon::prelude::*;
    let pairs: Vec<(f64, f64)> = values
        .iter()
        .flat_map(|&n| views.iter().map(move |&v| (n, v)))
        .collect();
    let parts = pairs
        .par_iter()
        .map(|&(n, v)| chi_view_value(model, method, n, v))
        .collect::<Result<Vec<[f64; 2]>, CliError>>()?;
    let two_parts = model == ShadingModel::CookTorrance;
    let mut out = String::from(if two_parts {
        "n,view,chi1,chi0\n"
    } else {
        "n,view,chi\n"
    });
    for ((n, v), [chi1, chi0]) in pairs.iter().zip(parts) {
        if two_parts {
            let _ = writeln!(out, "{n},{v},{},{}", fmt17(chi1), fmt17(chi0));
        } else {
            let _ = writeln!(out, "{n},{v},{}", fmt17(chi1));
        }
    }
    Ok(out)
}

/// `[chi_view_1, chi_view_0]` at `n` and `view` degrees by the chosen method.
fn chi_view_value(
    model: ShadingModel,
    method: MethodArg,
    n: f64,
    view: f64,
) -> Result<[f64; 2], CliError> {
    let phi = view.to_radians();
    match method {
        MethodArg::Fast => reflectance::view::chi_view_fast(model, n as f32, phi as f32)
            .map(|p| p.map(f64::from))
            .ok_or_else(|| {
                CliError::usage(format!(
                    "n = {n} is beyond the per-view table (n <= {})",
                    reflectance::view::VIEW_N_MAX
                ))
            }),
        _ => Ok(reflectance::view::chi_view_exact(model, n, phi)),
    }
}

fn chi_csv(model: ShadingModel, method: MethodArg, values: &[f64]) -> String {
    use rayon::prelude::*;
    let chis: Vec<[f64; 2]> = values
        .par_iter()
        .map(|&n| chi_parts_value(model, method, n))
        .collect();
    let two_parts = model == ShadingModel::CookTorrance;
    let mut out = String::from(if two_parts {
        "n,chi1,chi0\n"
    } else {
        "n,chi\n"
    });
    for (n, [chi1, chi0]) in values.iter().zip(chis) {
        if two_parts {
            let _ = writeln!(out, "{n},{},{}", fmt17(chi1), fmt17(chi0));
        } else {
            let _ = writeln!(out, "{n},{}", fmt17(chi1));
        }
    }
    out
}

/// `[chi_1(n), chi_0(n)]` by the chosen method (`chi_0 = 0` but for Cook-Torrance): the exact
/// integral in `f64`, approximations in `f32` as a renderer evaluates them.
pub fn chi_parts_value(model: ShadingModel, method: MethodArg, n: f64) -> [f64; 2] {
    match method.approx() {
        None => chi_parts_exact(model, n),
        Some(approx) => reflectance::chi_parts_f32(model, approx, n as f32).map(f64::from),
    }
}
