//! `kapaint accuracy`: the error of every approximation against the exact integrator, what
//! the view average hides (`k_a` against `k_a` per view), and `k_a` (and `k_a` times AO)
//! against the traced reference with the mesh's own shadow.

use super::CliError;
use super::args::ModelArg;
use crate::reflectance::ShadingModel;
use crate::report::{accuracy, view};

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
    /// Meshes of the traced table: a built-in name or a mesh file, repeatable (default: the
    /// built-in torus, which shadows itself).
    #[arg(long)]
    mesh: Vec<String>,
    /// Samples per pixel of the traced table (1 to 65536).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65536))]
    samples: u32,
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
        let specs = if self.mesh.is_empty() {
            vec!["torus".to_owned()]
        } else {
            self.mesh
        };
        let meshes = specs
            .iter()
            .map(|spec| {
                // Traced where a camera's arithmetic holds it, whatever its scale.
                let mesh = crate::mesh::open(std::path::Path::new(spec))
                    .map_err(super::mesh_error)?
                    .viewable();
                let name = std::path::Path::new(spec)
                    .file_name()
                    .map_or_else(|| spec.clone(), |n| n.to_string_lossy().into_owned());
                Ok((name, mesh))
            })
            .collect::<Result<Vec<_>, CliError>>()?;
        let mut out =
            accuracy::accuracy_report(&accuracy::Grid::standard(points), &models).markdown();
        out.push('\n');
        out.push_str(&view::view_average_markdown(&view::view_average_rows(
            &models,
        )));
        let setup = view::TracedSetup {
            samples: self.samples,
            ..view::TracedSetup::default()
        };
        out.push('\n');
        out.push_str(&view::traced_markdown(
            &view::traced_rows(&meshes, &models, &setup),
            &setup,
        ));
        Ok(out)
    }
}
