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
    /// Exponents (n >= 0); a single `-` reads one value per line from stdin.
    #[arg(required = true, allow_hyphen_values = true)]
    n: Vec<String>,
}

impl ChiArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// An exponent that is not a number, negative, or beyond the method's range.
    pub fn run(self, stdin: &mut dyn BufRead) -> Result<String, CliError> {
        check_method(self.model.into(), self.method)?;
        let values = if self.n.len() == 1 && self.n[0] == "-" {
            read_stdin_values(stdin, self.method)?
        } else {
            self.n
                .iter()
                .map(|s| parse_n(s, self.method))
                .collect::<Result<Vec<_>, _>>()?
        };
        Ok(chi_csv(self.model.into(), self.method, &values))
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
