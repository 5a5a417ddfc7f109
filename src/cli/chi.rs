//! `kapaint chi`: chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`; for
//! Cook-Torrance both parts of `k_s chi1(n) + chi0(n)`, as CSV `n,chi1,chi0`.

use std::fmt::Write as _;
use std::io::{BufRead, Write};

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
    /// Exponents (n >= 0); a single `-` reads one value per line from stdin (all of them are
    /// read and checked before the first row). The exact method integrates each value, about
    /// 0.04 s of one core: rows stream out as they are computed, with a bar and an estimate
    /// on a terminal.
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
        let mut out = Vec::new();
        self.stream(stdin, &mut out)?;
        String::from_utf8(out).map_err(|_| CliError::io("chi wrote text that is not UTF-8"))
    }

    /// Runs the command, writing its rows to `out` as they are computed (a block at a time,
    /// in order): every value is read and checked first, so a bad one stops the run before a
    /// row is written; a terminal shows a bar with an estimate meanwhile.
    ///
    /// # Errors
    /// As [`Self::run`]; a failed write (exit 1).
    pub fn stream(self, stdin: &mut dyn BufRead, out: &mut dyn Write) -> Result<(), CliError> {
        let (model, method, values, views) = self.checked(stdin)?;
        let two_parts = model.has_second_part();
        let header = match (views.is_empty(), two_parts) {
            (true, false) => "n,chi\n",
            (true, true) => "n,chi1,chi0\n",
            (false, false) => "n,view,chi\n",
            (false, true) => "n,view,chi1,chi0\n",
        };
        let write_error = |e: std::io::Error| CliError::io(format!("writing the rows: {e}"));
        out.write_all(header.as_bytes()).map_err(write_error)?;
        let rows = values.len() * views.len().max(1);
        let progress = crate::task::Progress::default();
        progress.start("chi", rows as u64);
        let write_block = |block: &[f64], out: &mut dyn Write| -> Result<(), CliError> {
            let text = if views.is_empty() {
                chi_csv(model, method, block)
            } else {
                chi_view_csv(model, method, block, &views)?
            };
            out.write_all(text.as_bytes()).map_err(write_error)?;
            out.flush().map_err(write_error)?;
            progress.advance((block.len() * views.len().max(1)) as u64);
            Ok(())
        };
        super::progress::with_bar("chi", &progress, || {
            // Exact integrals (tens of milliseconds each) in blocks of a few per core, so the
            // first rows come within a second; the approximations in large blocks.
            let rows_per_block = if method.approx().is_none() {
                8 * rayon::current_num_threads()
            } else {
                STREAM_BLOCK
            };
            let block = (rows_per_block / views.len().max(1)).max(1);
            values
                .chunks(block)
                .try_for_each(|b| write_block(b, &mut *out))
        })
    }

    /// The model, method, exponents and view angles, every one checked.
    fn checked(
        self,
        stdin: &mut dyn BufRead,
    ) -> Result<(ShadingModel, MethodArg, Vec<f64>, Vec<f64>), CliError> {
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
        // The per-view table's reach, before any row is written.
        if !views.is_empty()
            && matches!(self.method, MethodArg::Fast)
            && let Some(n) = values
                .iter()
                .find(|&&n| !(0.0..=reflectance::view::VIEW_N_MAX).contains(&(n as f32)))
        {
            return Err(CliError::usage(format!(
                "n = {n} is beyond the per-view table (n <= {})",
                reflectance::view::VIEW_N_MAX
            )));
        }
        Ok((self.model.into(), self.method, values, views))
    }
}

/// Rows of an approximation computed and written together while streaming.
const STREAM_BLOCK: usize = 4096;

/// One row per `(n, view)` pair, `n` by `n`: `n,view,chi` (Cook-Torrance `n,view,chi1,chi0`),
/// no header.
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
    let two_parts = model.has_second_part();
    let mut out = String::new();
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

/// One row per `n`: `n,chi` (Cook-Torrance `n,chi1,chi0`), no header.
fn chi_csv(model: ShadingModel, method: MethodArg, values: &[f64]) -> String {
    use rayon::prelude::*;
    let chis: Vec<[f64; 2]> = values
        .par_iter()
        .map(|&n| chi_parts_value(model, method, n))
        .collect();
    let two_parts = model.has_second_part();
    let mut out = String::new();
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
