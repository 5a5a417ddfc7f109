//! `kapaint chi`: chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`.

use std::fmt::Write as _;
use std::io::BufRead;

use super::CliError;
use super::args::{MethodArg, ModelArg, fmt17, parse_n, read_stdin_values};
use crate::reflectance::{self, ShadingModel, exact::chi_exact};

/// Print chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`.
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
    let chis: Vec<f64> = values
        .par_iter()
        .map(|&n| chi_value(model, method, n))
        .collect();
    let mut out = String::from("n,chi\n");
    for (n, chi) in values.iter().zip(chis) {
        let _ = writeln!(out, "{n},{}", fmt17(chi));
    }
    out
}

/// `chi(n)` by the chosen method: the exact integral in `f64`, approximations in `f32` as a
/// renderer evaluates them.
pub fn chi_value(model: ShadingModel, method: MethodArg, n: f64) -> f64 {
    match method.approx() {
        None => chi_exact(model, n),
        Some(approx) => f64::from(reflectance::chi_f32(model, approx, n as f32)),
    }
}
