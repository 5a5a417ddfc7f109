//! `kapaint accuracy`: the error of every approximation against the exact integrator.

use super::CliError;
use super::args::ModelArg;
use crate::reflectance::ShadingModel;
use crate::report::accuracy;

/// Most sample points `kapaint accuracy` takes per range (each costs an exact integral per
/// model: 256 points take about a minute on 2 cores).
pub const MAX_ACCURACY_POINTS: usize = 256;

/// Print the error of every approximation against the exact integrator (markdown).
#[derive(Debug, clap::Args)]
pub struct AccuracyArgs {
    /// Sample points per n range (2 to 256, spaced evenly in ln(n + 1)).
    #[arg(long, default_value_t = 96)]
    points: usize,
    /// Only this model's tables (default: all three).
    #[arg(long, value_enum)]
    model: Option<ModelArg>,
}

impl AccuracyArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A point count outside 2 to [`MAX_ACCURACY_POINTS`].
    pub fn run(self) -> Result<String, CliError> {
        let points = self.points;
        if !(2..=MAX_ACCURACY_POINTS).contains(&points) {
            return Err(CliError::usage(format!(
                "--points must be 2 to {MAX_ACCURACY_POINTS}, got {points}"
            )));
        }
        let models = self
            .model
            .map_or(ShadingModel::ALL.to_vec(), |m| vec![m.into()]);
        Ok(accuracy::accuracy_report(&accuracy::Grid::standard(points), &models).markdown())
    }
}
