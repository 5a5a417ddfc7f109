//! `kapaint render`: the preview renderer, headless, into a PNG or EXR.

use std::path::PathBuf;

use glam::DVec3;

use super::args::{MethodArg, parse_light, parse_n, parse_rgb, parse_size};
use super::{CliError, model_error};
use crate::mesh;
use crate::model::{self, project};
use crate::reflectance::{AmbientApprox, ShadingModel};

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
    /// phong, blinn, cook-torrance, compare-split (the --sides models left and right of a
    /// divider), compare-side (the two side by side, one camera), compare-diff (|left -
    /// right| heatmap) or compare-three (Phong, Blinn-Phong and Cook-Torrance side by side).
    #[arg(long, value_parser = ["phong", "blinn", "cook-torrance", "compare-split", "compare-side", "compare-diff", "compare-three"])]
    model: String,
    /// The two models a compare-split, compare-side or compare-diff shows, `LEFT,RIGHT`.
    #[arg(long, default_value = "phong,blinn")]
    sides: String,
    /// shaded, ka, kd, ks, n, diffuse, specular, ambient (or checker, n-false-colour).
    #[arg(long, value_parser = ["shaded", "ka", "kd", "ks", "n", "diffuse", "specular", "ambient", "checker", "n-false-colour"])]
    view: String,
    /// How k_a's chi is computed (Cook-Torrance always uses its fast fit: the paper printed
    /// no form for it).
    #[arg(long, value_parser = ["fast", "paper", "paper-corrected"], default_value = "fast")]
    method: String,
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
    /// Output image: .png or .exr.
    #[arg(long)]
    out: PathBuf,
}

/// What `render` draws: maps, the normal map, and the mesh they come with.
type Material = (
    model::MaterialMaps,
    Option<std::sync::Arc<model::normal::NormalMap>>,
    std::path::PathBuf,
);

/// The maps to render (a project's, or one uniform material), the project's normal map and
/// the mesh they come with.
fn render_material(a: &RenderArgs) -> Result<Material, CliError> {
    if let Some(file) = &a.project {
        let doc = project::load(file).map_err(model_error)?;
        let spec = PathBuf::from(doc.settings().mesh.spec());
        let normal = doc.normal().cloned();
        return Ok((doc.into_parts().0, normal, spec));
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
    Ok((maps, None, std::path::PathBuf::from("sphere")))
}

/// `--sides LEFT,RIGHT`: two model names.
fn parse_sides(text: &str) -> Result<[ShadingModel; 2], CliError> {
    let names: Vec<&str> = text.split(',').map(str::trim).collect();
    let model = |name: &str| {
        ShadingModel::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                CliError::usage(format!(
                    "--sides: unknown model {name:?} (phong, blinn or cook-torrance)"
                ))
            })
    };
    match names.as_slice() {
        [a, b] => Ok([model(a)?, model(b)?]),
        _ => Err(CliError::usage(format!(
            "--sides takes two models, LEFT,RIGHT; got {text:?}"
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
    use crate::render::{Camera, FrameSettings, Lighting, ViewMode};
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
    let (maps, normal, own_mesh) = render_material(&a)?;
    let mesh_spec = a.mesh.map_or(own_mesh, std::path::PathBuf::from);
    let mesh = mesh::open(&mesh_spec).map_err(super::mesh_error)?;
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
    let sides = parse_sides(&a.sides)?;
    let (model, compare) = match a.model.as_str() {
        "phong" => (ShadingModel::Phong, Compare::Single),
        "blinn" => (ShadingModel::BlinnPhong, Compare::Single),
        "cook-torrance" => (ShadingModel::CookTorrance, Compare::Single),
        "compare-split" => (sides[0], Compare::Split),
        "compare-side" => (sides[0], Compare::SideBySide),
        "compare-three" => (ShadingModel::Phong, Compare::ThreeWay),
        _ => (sides[0], Compare::Difference),
    };
    let models = if compare == Compare::ThreeWay {
        ShadingModel::ALL
    } else {
        [sides[0], sides[1], ShadingModel::CookTorrance]
    };
    let approx = match a.method.as_str() {
        "paper" => AmbientApprox::PaperPrinted,
        "paper-corrected" => AmbientApprox::PaperCorrected,
        _ => AmbientApprox::Fast,
    };
    let view = ViewMode::from_name(&a.view)
        .ok_or_else(|| CliError::usage(format!("unknown view {:?}", a.view)))?;
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
