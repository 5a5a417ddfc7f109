//! `kapaint render`: the preview renderer, headless, into a PNG or EXR.

use std::path::{Path, PathBuf};

use glam::DVec3;

use clap::ValueEnum;

use super::args::{MethodArg, ModelArg, parse_light, parse_n, parse_rgb, parse_size};
use super::{CliError, model_error};
use crate::mesh;
use crate::model::{self, project};
use crate::reflectance::{AmbientApprox, ShadingModel};
use crate::render::ViewMode;

/// The arguments of `kapaint render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// Project whose maps to render.
    #[arg(long, conflicts_with_all = ["kd", "ks", "n"])]
    project: Option<PathBuf>,
    /// Uniform diffuse coefficient `R,G,B` (without --project).
    #[arg(long)]
    kd: Option<String>,
    /// Uniform specular coefficient `S` or `R,G,B` (without --project).
    #[arg(long)]
    ks: Option<String>,
    /// Uniform Phong exponent (without --project).
    #[arg(long, allow_hyphen_values = true)]
    n: Option<String>,
    /// sphere, plane, cube, torus or a mesh file (default: the project's, else sphere).
    #[arg(long)]
    mesh: Option<String>,
    /// One model, or a comparison of the --sides models.
    #[arg(long, value_enum)]
    model: RenderModel,
    /// The two models a compare-split, compare-side or compare-diff shows, `LEFT,RIGHT`.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "phong,blinn")]
    sides: Vec<ModelArg>,
    /// What the image shows.
    #[arg(long, value_enum)]
    view: ViewArg,
    /// How k_a's chi is computed (Cook-Torrance always uses its fast fit: the paper printed
    /// no form for it).
    #[arg(long, value_enum, default_value = "fast")]
    method: ApproxArg,
    /// Direction towards the light, `X,Y,Z`.
    #[arg(long, allow_hyphen_values = true)]
    light: Option<String>,
    /// Ambient (sky) intensity I_a.
    #[arg(long, default_value_t = 0.3)]
    ia: f32,
    /// Directional light intensity I_l.
    #[arg(long, default_value_t = 0.8)]
    il: f32,
    /// Image size `WxH` (or `W` for a square).
    #[arg(long, default_value = "512x512")]
    size: String,
    /// Camera angle around the vertical axis, degrees.
    #[arg(long, default_value_t = 30.0, allow_hyphen_values = true)]
    yaw: f32,
    /// Camera angle above the horizon, degrees.
    #[arg(long, default_value_t = 20.0, allow_hyphen_values = true)]
    pitch: f32,
    /// Samples per pixel of a traced view (ka-traced, ka-traced-error): 1 to 1048576
    /// (default 64).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::render::traced::MAX_SAMPLES)))]
    samples: Option<u32>,
    /// Output image: .png or .exr.
    #[arg(long)]
    out: PathBuf,
}

/// `kapaint render --model`: one model (by its name), or a comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RenderModel {
    /// One model.
    Single(ShadingModel),
    /// The --sides models left and right of a divider.
    CompareSplit,
    /// The --sides models side by side, one camera.
    CompareSide,
    /// |left - right| of the --sides models, as a heatmap.
    CompareDiff,
    /// Phong, Blinn-Phong and Cook-Torrance side by side.
    CompareThree,
}

impl ValueEnum for RenderModel {
    fn value_variants<'a>() -> &'a [Self] {
        static VARIANTS: std::sync::LazyLock<Vec<RenderModel>> = std::sync::LazyLock::new(|| {
            let compare = [
                RenderModel::CompareSplit,
                RenderModel::CompareSide,
                RenderModel::CompareDiff,
                RenderModel::CompareThree,
            ];
            ShadingModel::ALL
                .into_iter()
                .map(RenderModel::Single)
                .chain(compare)
                .collect()
        });
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        use clap::builder::PossibleValue;
        Some(match self {
            Self::Single(model) => {
                PossibleValue::new(model.name()).help(super::args::model_help(*model))
            }
            Self::CompareSplit => PossibleValue::new("compare-split")
                .help("The --sides models left and right of a divider"),
            Self::CompareSide => PossibleValue::new("compare-side")
                .help("The --sides models side by side, one camera"),
            Self::CompareDiff => PossibleValue::new("compare-diff")
                .help("|left - right| of the --sides models, as a heatmap"),
            Self::CompareThree => PossibleValue::new("compare-three")
                .help("Phong, Blinn-Phong and Cook-Torrance side by side"),
        })
    }
}

/// `kapaint render --view`: a view mode by its name ([`ViewMode::name`]), the list of valid
/// values made from [`ViewMode::ALL`] so that it cannot drift from the views.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewArg(pub ViewMode);

impl ValueEnum for ViewArg {
    fn value_variants<'a>() -> &'a [Self] {
        static VARIANTS: std::sync::LazyLock<Vec<ViewArg>> =
            std::sync::LazyLock::new(|| ViewMode::ALL.into_iter().map(ViewArg).collect());
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()))
    }
}

/// `kapaint render --method`: the approximations of chi (the render has no exact integral).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ApproxArg {
    /// kapaint's fast approximation.
    Fast,
    /// Eq. (8) / (11) as printed.
    Paper,
    /// Eq. (8) / (11) with the Blinn exponent corrected.
    PaperCorrected,
}

impl From<ApproxArg> for AmbientApprox {
    fn from(a: ApproxArg) -> Self {
        match a {
            ApproxArg::Fast => Self::Fast,
            ApproxArg::Paper => Self::PaperPrinted,
            ApproxArg::PaperCorrected => Self::PaperCorrected,
        }
    }
}

/// What `render` draws: maps, the normal map, the mesh they come with, and the project's AO
/// bake (for the AO stand-in's view).
type Material = (
    model::MaterialMaps,
    Option<std::sync::Arc<model::normal::NormalMap>>,
    OwnMesh,
    Option<std::sync::Arc<mesh::bakes::Baked>>,
);

/// The mesh a project names: a built-in name or a file, or the mesh it keeps inside itself.
enum OwnMesh {
    Spec(PathBuf),
    Kept(mesh::Mesh),
}

/// The maps to render (a project's, or one uniform material), the project's normal map and
/// the mesh they come with.
fn render_material(a: &RenderArgs) -> Result<Material, CliError> {
    if let Some(file) = &a.project {
        let doc = super::open_project(file)?;
        let own = if doc.settings().mesh.is_embedded() {
            OwnMesh::Kept(project::own_mesh(&doc).map_err(model_error)?)
        } else {
            OwnMesh::Spec(PathBuf::from(doc.settings().mesh.spec()))
        };
        let normal = doc.normal().cloned();
        let ao = doc.bake_of(mesh::bakes::BakeMap::Ao).cloned();
        return Ok((doc.into_parts().0, normal, own, ao));
    }
    let d = model::MaterialValue::default();
    let kd =
        a.kd.as_deref()
            .map(|t| parse_rgb("--kd", t, false))
            .transpose()?;
    let ks =
        a.ks.as_deref()
            .map(|t| parse_rgb("--ks", t, true))
            .transpose()?;
    let n =
        a.n.as_deref()
            .map(|t| parse_n(t, MethodArg::Fast))
            .transpose()?;
    let value = model::MaterialValue::new(
        kd.map_or(d.kd, DVec3::as_vec3),
        ks.map_or(d.ks, DVec3::as_vec3),
        n.map_or(d.n, |v| v as f32),
    );
    let maps = model::MaterialMaps::new(16, 16, value).map_err(model_error)?;
    Ok((maps, None, OwnMesh::Spec(PathBuf::from("sphere")), None))
}

/// `--sides LEFT,RIGHT`: exactly two models.
fn sides(models: &[ModelArg]) -> Result<[ShadingModel; 2], CliError> {
    match models {
        [a, b] => Ok([(*a).into(), (*b).into()]),
        _ => Err(CliError::usage(format!(
            "--sides takes two models, LEFT,RIGHT; got {}",
            models.len()
        ))),
    }
}

impl RenderArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// Bad arguments, a project or mesh that does not load, a GPU that fails, a failed write.
    pub fn run(self) -> Result<String, CliError> {
        render_command(self)
    }
}

fn render_command(a: RenderArgs) -> Result<String, CliError> {
    use crate::gpu::headless::{self, Compare};
    use crate::render::{Camera, FrameSettings, Lighting};
    let (width, height) = parse_size(&a.size)?;
    let ext = a
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        return Err(CliError::usage(format!(
            "{}: --out must end in .png or .exr",
            a.out.display()
        )));
    }
    let (maps, normal, own_mesh, ao) = render_material(&a)?;
    let mesh = match (a.mesh, own_mesh) {
        (Some(spec), _) => mesh::open(Path::new(&spec)).map_err(super::mesh_error)?,
        (None, OwnMesh::Spec(spec)) => mesh::open(&spec).map_err(super::mesh_error)?,
        (None, OwnMesh::Kept(kept)) => kept,
    };
    // The AO bake is of the mesh as it is (its hash); the picture is of the mesh where a
    // camera's arithmetic holds it (one of coordinates like 1e30, moved into its unit frame).
    let mesh_hash = mesh.content_hash();
    let mesh = mesh.viewable();
    let light = match &a.light {
        Some(text) => parse_light(text)?,
        None => Lighting::default().light,
    };
    for (flag, v) in [("--ia", a.ia), ("--il", a.il)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(CliError::usage(format!("{flag} must be >= 0, got {v}")));
        }
    }
    if !(a.yaw.is_finite() && a.pitch.is_finite()) {
        return Err(CliError::usage("--yaw and --pitch must be finite"));
    }
    let sides = sides(&a.sides)?;
    let (model, compare) = match a.model {
        RenderModel::Single(model) => (model, Compare::Single),
        RenderModel::CompareSplit => (sides[0], Compare::Split),
        RenderModel::CompareSide => (sides[0], Compare::SideBySide),
        RenderModel::CompareDiff => (sides[0], Compare::Difference),
        RenderModel::CompareThree => (ShadingModel::Phong, Compare::ThreeWay),
    };
    let models = if compare == Compare::ThreeWay {
        ShadingModel::ALL
    } else {
        [sides[0], sides[1], ShadingModel::CookTorrance]
    };
    let approx = AmbientApprox::from(a.method);
    let ViewArg(view) = a.view;
    let camera = Camera {
        yaw: a.yaw.to_radians(),
        pitch: a.pitch.to_radians().clamp(-1.55, 1.55),
        ..Camera::default()
    }
    .framing(&mesh.positions);
    let settings = FrameSettings {
        model,
        approx,
        view,
        lighting: Lighting {
            light,
            ia: a.ia,
            il: a.il,
        },
        camera,
    };
    let single = compare == Compare::Single;
    let size = (width, height);
    if let Some(report) = super::render_traced::route(
        a.samples,
        single,
        (&mesh, mesh_hash, &maps, ao.as_deref()),
        &settings,
        size,
        &a.out,
    )? {
        return Ok(report);
    }
    let gpu = crate::gpu::Gpu::headless().map_err(|e| CliError {
        message: e.to_string(),
        code: 1,
    })?;
    headless::run(
        &gpu,
        &headless::Request {
            mesh: &mesh,
            maps: &maps,
            normal: normal.as_ref(),
            settings,
            compare,
            models,
            size: (width, height),
            out: a.out,
        },
    )
    .map_err(|e| CliError::io(e.to_string()))
}
