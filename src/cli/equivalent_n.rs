//! `kapaint equivalent-n`: the exponent of the other model whose highlight matches.

use std::fmt::Write as _;

use super::CliError;
use super::args::{MethodArg, ModelArg, parse_n};

/// The exponent of the other model whose highlight matches (CSV "n,equivalent").
#[derive(Debug, clap::Args)]
pub struct EquivalentNArgs {
    /// The model the given exponents belong to.
    #[arg(long, value_enum)]
    from: ModelArg,
    /// Exponents (n >= 0).
    #[arg(required = true, allow_hyphen_values = true)]
    n: Vec<String>,
}

impl EquivalentNArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// An exponent that is not a number or negative.
    pub fn run(self) -> Result<String, CliError> {
        let values = self
            .n
            .iter()
            .map(|t| parse_n(t, MethodArg::Fast))
            .collect::<Result<Vec<f64>, _>>()?;
        let mut out = String::from("n,equivalent\n");
        for v in values {
            let m = crate::reflectance::equivalent::equivalent_exponent(self.from.into(), v);
            let _ = writeln!(out, "{v},{m:.6}");
        }
        Ok(out)
    }
}
