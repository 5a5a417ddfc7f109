//! `kapaint bench`: the k_a derive of a full map per method, timed against its error and a
//! memory copy.

use std::path::PathBuf;

use super::CliError;
use super::args::ModelArg;
use crate::reflectance::ShadingModel;
use crate::report::bench;

/// Time the k_a derive of a full map per method against its error and a memory copy.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Map side in texels.
    #[arg(long, default_value_t = 4096)]
    size: usize,
    /// Directory for bench.csv and bench.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timing repetitions (the best is kept).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Only this model's rows (default: all three).
    #[arg(long, value_enum)]
    model: Option<ModelArg>,
}

impl BenchArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A size out of range or beyond the memory available, or a failed write.
    pub fn run(self) -> Result<String, CliError> {
        let size = self.size;
        if !(16..=16384).contains(&size) {
            return Err(CliError::usage("--size must be in [16, 16384]"));
        }
        crate::memory::check_fits(&format!("--size {size}"), bench::bytes_needed(size))
            .map_err(|e| CliError::usage(format!("{e}: use a smaller --size")))?;
        if let Some(dir) = &self.out {
            std::fs::create_dir_all(dir).map_err(|e| {
                CliError::of_io(format!("cannot create {}: {e}", dir.display()), &e)
            })?;
        }
        let models = self
            .model
            .map_or(ShadingModel::ALL.to_vec(), |m| vec![m.into()]);
        let rows = bench::run(size, self.repeats, 48, &models);
        let table = bench::markdown(&rows, size);
        if let Some(dir) = self.out {
            let csv = dir.join("bench.csv");
            crate::atomic::write_atomic(&csv, bench::csv(&rows).as_bytes())
                .map_err(|e| CliError::io(format!("cannot write {}: {e}", csv.display())))?;
            bench::plot(&rows, &dir.join("bench.png")).map_err(CliError::io)?;
        }
        Ok(table)
    }
}
