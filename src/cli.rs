//! The `kapaint` command line. Output formats here are a contract for scripts.
//!
//! Every bad argument ends the program with one line on stderr and exit code 2, before any
//! output is written, so a script never sees a partial table.

use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use glam::DVec3;

use crate::mesh;
use crate::model::{self, Channel, Document, DocumentSettings, ModelError, import, project};
use crate::reflectance::{
    self, AmbientApprox, ShadingModel, TWO_OVER_PI,
    exact::{EXACT_N_MAX, chi_exact},
};
use crate::report::{accuracy, bench};

/// Exit code for bad arguments or input.
pub const EXIT_USAGE: i32 = 2;

/// A failure to report: one line of text and an exit code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// What went wrong, as one line for stderr.
    pub message: String,
    /// The process exit code.
    pub code: i32,
}

impl CliError {
    /// A bad-argument error (exit code 2).
    pub fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: EXIT_USAGE,
        }
    }
}

/// Paint per-texel Phong reflectance and preview it with a derived ambient term.
#[derive(Debug, Parser)]
#[command(name = "kapaint", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`.
    Chi {
        /// Specular lobe.
        #[arg(long, value_enum)]
        model: ModelArg,
        /// How chi is computed.
        #[arg(long, value_enum)]
        method: MethodArg,
        /// Exponents (n >= 0); a single `-` reads one value per line from stdin.
        #[arg(required = true, allow_hyphen_values = true)]
        n: Vec<String>,
    },
    /// Print k_a = (2/pi) k_d + k_s chi(n) of one texel as `r,g,b`.
    Ka {
        /// Specular lobe.
        #[arg(long, value_enum)]
        model: ModelArg,
        /// How chi is computed.
        #[arg(long, value_enum)]
        method: MethodArg,
        /// Diffuse coefficient `R,G,B`, each in [0, 1].
        #[arg(long)]
        kd: String,
        /// Specular coefficient `S` or `R,G,B`, each in [0, 1].
        #[arg(long)]
        ks: String,
        /// Phong exponent (n >= 0).
        #[arg(long, allow_hyphen_values = true)]
        n: String,
    },
    /// Print the error of every approximation against the exact integrator (markdown).
    Accuracy {
        /// Sample points per n range (spaced evenly in ln(n + 1)).
        #[arg(long, default_value_t = 96)]
        points: usize,
    },
    /// Create a project of one material everywhere.
    New {
        /// Map size, `W` or `WxH` (each 1 to 8192).
        #[arg(long)]
        size: String,
        /// Material preset (file stem or name), e.g. `brass`.
        #[arg(long, default_value = "default")]
        preset: String,
        /// Project file to write.
        #[arg(long)]
        out: PathBuf,
        /// Mesh the material is painted on: sphere, plane, cube, torus or a mesh file.
        #[arg(long, default_value = "sphere")]
        mesh: String,
        /// Overwrite an existing file.
        #[arg(long)]
        force: bool,
    },
    /// Print a project's resolution, per-channel min/mean/max and memory.
    Info {
        /// Project file.
        file: PathBuf,
    },
    /// Import an image (PNG, JPEG, TGA, EXR) into one channel of a project.
    Import {
        /// Project file (rewritten atomically unless --out is given).
        file: PathBuf,
        /// Channel to replace.
        #[arg(long, value_parser = ["kd", "ks", "n"])]
        channel: String,
        /// Image file.
        #[arg(long)]
        image: PathBuf,
        /// Write the result here instead of over FILE.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Replay a paint script (RON list of commands) on a project and save it.
    Paint {
        /// Project file (rewritten atomically unless --out is given).
        file: PathBuf,
        /// Script of commands (see README).
        #[arg(long)]
        script: PathBuf,
        /// Mesh for strokes on the surface and island/part fills (default: the project's).
        #[arg(long)]
        mesh: Option<String>,
        /// Write the result here instead of over FILE.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Export projects as compact texture sets (images + material.json).
    Export {
        /// Project files (several: one set per project, in OUT/<project name>/).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Export preset: compact, 16-bit, separate, exr, with-ka, ktx2, ktx2-raw, or a user
        /// preset.
        #[arg(long, default_value = "compact")]
        preset: String,
        /// Target folder (must not exist, or be empty).
        #[arg(long)]
        out: PathBuf,
        /// Print the memory report, the n encoding and the k_a error.
        #[arg(long)]
        report: bool,
        /// Keep texels outside the mesh's UV islands as painted (by default they are filled
        /// from the nearest island, which needs the project's mesh).
        #[arg(long)]
        no_padding: bool,
    },
    /// Rebuild a project from an exported set.
    ImportSet {
        /// The set's material.json.
        manifest: PathBuf,
        /// Project file to write.
        #[arg(long)]
        out: PathBuf,
        /// Overwrite an existing file.
        #[arg(long)]
        force: bool,
    },
    /// The exponent of the other model whose highlight matches (CSV "n,equivalent").
    EquivalentN {
        /// The model the given exponents belong to.
        #[arg(long, value_enum)]
        from: ModelArg,
        /// Exponents (n >= 0).
        #[arg(required = true, allow_hyphen_values = true)]
        n: Vec<String>,
    },
    /// Render the preview headless (no window, no display) into a PNG or EXR.
    Render(RenderArgs),
    /// Print a mesh's vertices, triangles, UV islands, bounds, and whether normals and UVs were
    /// present (FILE is an .obj file, or sphere, plane, cube, torus).
    MeshInfo {
        /// Mesh file or built-in name.
        file: PathBuf,
    },
    /// Time the k_a derive of a full map per method against its error and a memory copy.
    Bench {
        /// Map side in texels.
        #[arg(long, default_value_t = 4096)]
        size: usize,
        /// Directory for bench.csv and bench.png.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Timing repetitions (the best is kept).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
    },
}

/// `--model` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ModelArg {
    /// Original Phong, eq. (8).
    Phong,
    /// Blinn-Phong, eq. (11).
    Blinn,
}

impl From<ModelArg> for ShadingModel {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Phong => Self::Phong,
            ModelArg::Blinn => Self::BlinnPhong,
        }
    }
}

/// `--method` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// The exact integral of eq. (6).
    Exact,
    /// Eq. (8) / (11) as printed.
    Paper,
    /// Eq. (8) / (11) with the Blinn exponent corrected.
    PaperCorrected,
    /// kapaint's fast approximation.
    Fast,
}

impl MethodArg {
    fn approx(self) -> Option<AmbientApprox> {
        match self {
            Self::Exact => None,
            Self::Paper => Some(AmbientApprox::PaperPrinted),
            Self::PaperCorrected => Some(AmbientApprox::PaperCorrected),
            Self::Fast => Some(AmbientApprox::Fast),
        }
    }
}

/// Parses arguments, runs, prints errors; returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return 0;
            }
            // Clap's message is several lines; its first line says what is wrong.
            let rendered = e.render().to_string();
            let first = rendered.lines().next().unwrap_or("error: bad arguments");
            eprintln!("kapaint: {}", first.trim_start_matches("error: "));
            return EXIT_USAGE;
        }
    };
    let stdin = std::io::stdin();
    match run(cli.command, &mut stdin.lock()) {
        Ok(text) => {
            let mut stdout = std::io::stdout().lock();
            if stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
                .is_err()
            {
                return 1;
            }
            0
        }
        Err(e) => {
            eprintln!("kapaint: {}", e.message);
            e.code
        }
    }
}

/// Runs a parsed command and returns everything it prints, or the error to report.
#[allow(clippy::too_many_lines)] // One arm per subcommand, each short.
pub fn run(command: Command, stdin: &mut dyn BufRead) -> Result<String, CliError> {
    match command {
        Command::Chi { model, method, n } => {
            let values = if n.len() == 1 && n[0] == "-" {
                read_stdin_values(stdin)?
            } else {
                n.iter()
                    .map(|s| parse_n(s, method))
                    .collect::<Result<Vec<_>, _>>()?
            };
            Ok(chi_csv(model.into(), method, &values))
        }
        Command::Ka {
            model,
            method,
            kd,
            ks,
            n,
        } => {
            let kd = parse_rgb("--kd", &kd, false)?;
            let ks = parse_rgb("--ks", &ks, true)?;
            let n = parse_n(&n, method)?;
            let ka = ka_value(model.into(), method, kd, ks, n);
            Ok(format!("{},{},{}\n", fmt17(ka.x), fmt17(ka.y), fmt17(ka.z)))
        }
        Command::Accuracy { points } => {
            if points < 2 {
                return Err(CliError::usage("--points must be at least 2"));
            }
            Ok(accuracy::accuracy_report(&accuracy::Grid::standard(points)).markdown())
        }
        Command::New {
            size,
            preset,
            out,
            mesh,
            force,
        } => {
            let (w, h) = parse_size(&size)?;
            // A mesh file must exist and load now, not at the first stroke on it.
            mesh::open(std::path::Path::new(&mesh)).map_err(|e| CliError::usage(e.to_string()))?;
            if out.exists() && !force {
                return Err(CliError::usage(format!(
                    "{} exists; pass --force to overwrite it",
                    out.display()
                )));
            }
            let preset = model::preset::find(&preset).map_err(model_error)?;
            let settings = DocumentSettings {
                base: preset.value(),
                secondary: preset.value(),
                preset: Some(preset.name.clone()),
                mesh: model::document::MeshRef::from_spec(&mesh),
                ..DocumentSettings::default()
            };
            let doc = Document::new(w, h, settings).map_err(model_error)?;
            project::save(&doc, &out).map_err(model_error)?;
            Ok(format!(
                "created {} ({w}x{h}, {})\n",
                out.display(),
                preset.name
            ))
        }
        Command::Info { file } => {
            let doc = project::load(&file).map_err(model_error)?;
            let bytes = std::fs::metadata(&file).map_or(0, |m| m.len());
            Ok(info_text(&file, &doc, bytes))
        }
        Command::Import {
            file,
            channel,
            image,
            out,
        } => {
            let channel = Channel::from_name(&channel)
                .ok_or_else(|| CliError::usage(format!("unknown channel {channel:?}")))?;
            let mut doc = project::load(&file).map_err(model_error)?;
            import::import_file(&mut doc, channel, &image).map_err(model_error)?;
            let target = out.unwrap_or(file);
            project::save(&doc, &target).map_err(model_error)?;
            Ok(format!(
                "imported {} into {} of {}\n",
                image.display(),
                channel.name(),
                target.display()
            ))
        }
        Command::Paint {
            file,
            script,
            mesh,
            out,
        } => {
            let commands = read_script(&script)?;
            let mut doc = project::load(&file).map_err(model_error)?;
            if commands.iter().any(model::Command::needs_surface) {
                attach_surface(&mut doc, &file, mesh.as_deref())?;
            }
            let count = commands.len();
            for (i, command) in commands.into_iter().enumerate() {
                doc.apply(command).map_err(|e| {
                    CliError::usage(format!("{}: command {}: {e}", script.display(), i + 1))
                })?;
            }
            doc.apply(model::Command::EndStroke).map_err(model_error)?;
            let target = out.unwrap_or(file);
            project::save(&doc, &target).map_err(model_error)?;
            Ok(format!(
                "applied {count} commands, saved {}\n",
                target.display()
            ))
        }
        Command::Export {
            files,
            preset,
            out,
            report,
            no_padding,
        } => export_command(&files, &preset, &out, report, !no_padding),
        Command::ImportSet {
            manifest,
            out,
            force,
        } => {
            if out.exists() && !force {
                return Err(CliError::usage(format!(
                    "{} exists; pass --force to overwrite it",
                    out.display()
                )));
            }
            let doc = crate::export::set::import(&manifest)
                .map_err(|e| CliError::usage(e.to_string()))?;
            project::save(&doc, &out).map_err(model_error)?;
            Ok(format!(
                "imported {} into {} ({}x{})\n",
                manifest.display(),
                out.display(),
                doc.maps.width(),
                doc.maps.height()
            ))
        }
        Command::EquivalentN { from, n } => {
            let values = n
                .iter()
                .map(|t| parse_n(t, MethodArg::Fast))
                .collect::<Result<Vec<f64>, _>>()?;
            let mut out = String::from("n,equivalent\n");
            for v in values {
                let m = crate::reflectance::equivalent::equivalent_exponent(from.into(), v);
                let _ = writeln!(out, "{v},{m:.6}");
            }
            Ok(out)
        }
        Command::Render(args) => render_command(args),
        Command::MeshInfo { file } => {
            let mesh = mesh::open(&file).map_err(|e| CliError::usage(e.to_string()))?;
            Ok(mesh::info_text(&file, &mesh))
        }
        Command::Bench { size, out, repeats } => {
            if !(16..=16384).contains(&size) {
                return Err(CliError::usage("--size must be in [16, 16384]"));
            }
            if let Some(dir) = &out {
                std::fs::create_dir_all(dir).map_err(|e| {
                    CliError::usage(format!("cannot create {}: {e}", dir.display()))
                })?;
            }
            let rows = bench::run(size, repeats, 48);
            let table = bench::markdown(&rows, size);
            if let Some(dir) = out {
                let csv = dir.join("bench.csv");
                crate::atomic::write_atomic(&csv, bench::csv(&rows).as_bytes()).map_err(|e| {
                    CliError {
                        message: format!("cannot write {}: {e}", csv.display()),
                        code: 1,
                    }
                })?;
                let png = dir.join("bench.png");
                bench::plot(&rows, &png).map_err(|e| CliError {
                    message: e,
                    code: 1,
                })?;
            }
            Ok(table)
        }
    }
}

/// A project's mesh: a built-in name, or its file (a relative path is tried from the
/// project's folder when it does not exist from the current one).
fn project_mesh(settings: &DocumentSettings, project_file: &std::path::Path) -> PathBuf {
    let own = PathBuf::from(settings.mesh.spec());
    match project_file.parent() {
        Some(dir) if own.is_relative() && !own.exists() && dir.join(&own).exists() => dir.join(own),
        _ => own,
    }
}

/// Loads the mesh (`spec`, else the project's own, a relative path taken from the project's
/// folder), bakes it at the map size and attaches it to `doc`.
fn attach_surface(
    doc: &mut Document,
    project_file: &std::path::Path,
    spec: Option<&str>,
) -> Result<(), CliError> {
    let spec = spec.map_or_else(
        || project_mesh(&doc.settings, project_file),
        std::path::PathBuf::from,
    );
    let mesh = mesh::open(&spec).map_err(|e| CliError::usage(e.to_string()))?;
    let surface = model::surface::Surface::new(mesh, doc.maps.width(), doc.maps.height())
        .map_err(|e| CliError::usage(format!("{}: {e}", spec.display())))?;
    doc.set_surface(Some(std::sync::Arc::new(surface)))
        .map_err(model_error)
}

/// The `--report` lines of one exported set.
fn write_report(text: &mut String, m: &crate::export::set::Manifest) {
    let _ = writeln!(text, "  preset: {}", m.preset);
    if m.dilated {
        let _ = writeln!(
            text,
            "  padding: texels outside the UV islands filled from the nearest island"
        );
    }
    match m.n_encoding {
        Some(e) => {
            let _ = writeln!(
                text,
                "  n: {:?} over [{}, {}] in {} bits",
                e.curve, e.lo, e.hi, e.bits
            );
        }
        None => {
            let _ = writeln!(
                text,
                "  n: {}",
                m.constants
                    .n
                    .map_or_else(|| "stored as float".into(), |n| format!("constant {n}"))
            );
        }
    }
    for f in &m.files {
        let _ = write!(
            text,
            "  {}: {} ({} bit, {}, {}), {} bytes",
            f.path,
            f.layout.join(" "),
            f.bit_depth,
            f.colour_space,
            f.compression,
            f.bytes
        );
        if let Some(levels) = f.mip_levels {
            let _ = write!(text, ", {levels} mip levels");
        }
        if let Some(psnr) = &f.psnr {
            let db: Vec<String> = psnr
                .iter()
                .map(|p| p.map_or_else(|| "exact".into(), |p| format!("{p:.1} dB")))
                .collect();
            let _ = write!(text, ", PSNR {}", db.join(" / "));
        }
        text.push('\n');
    }
    let b = m.bytes;
    let _ = writeln!(
        text,
        "  bytes: set {} vs naive k_a+k_d+k_s+n {} ({:.1}x) vs project maps {} ({:.1}x)",
        b.exported,
        b.naive,
        b.naive as f64 / b.exported.max(1) as f64,
        b.project,
        b.project as f64 / b.exported.max(1) as f64
    );
}

/// `kapaint export`: every project into its set; one line each, plus the report.
fn export_command(
    files: &[PathBuf],
    preset: &str,
    out: &std::path::Path,
    report: bool,
    padding: bool,
) -> Result<String, CliError> {
    use std::io::IsTerminal as _;
    let preset = crate::export::preset::find(preset).map_err(|e| CliError::usage(e.to_string()))?;
    // Load (and so validate) every project before writing anything; bake the meshes for
    // padding.
    let mut text = String::new();
    let docs = files
        .iter()
        .map(|f| {
            let mut doc = project::load(f).map_err(model_error)?;
            if padding && let Err(e) = attach_surface(&mut doc, f, None) {
                let _ = writeln!(text, "note: {}: no padding ({})", f.display(), e.message);
            }
            Ok(doc)
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let targets: Vec<PathBuf> = if files.len() == 1 {
        vec![out.to_path_buf()]
    } else {
        files
            .iter()
            .map(|f| out.join(f.file_stem().unwrap_or_default()))
            .collect()
    };
    let terminal = std::io::stderr().is_terminal();
    for (i, ((file, doc), target)) in files.iter().zip(&docs).zip(&targets).enumerate() {
        let progress = crate::task::Progress::default();
        // The export runs on a worker; this thread draws the bar while it works.
        let m = std::thread::scope(|scope| {
            let worker = std::thread::Builder::new()
                .name("kapaint-export".into())
                .spawn_scoped(scope, || {
                    crate::export::set::export_with(doc, &preset, target, &progress)
                })
                .map_err(|e| CliError::usage(format!("cannot start the export: {e}")))?;
            while terminal && !worker.is_finished() {
                let done = (progress.fraction() * 30.0) as usize;
                eprint!(
                    "\r[{}{}] {}/{} {} {:<8}",
                    "#".repeat(done),
                    " ".repeat(30 - done),
                    i + 1,
                    files.len(),
                    file.display(),
                    progress.stage()
                );
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            if terminal {
                eprint!("\r{}\r", " ".repeat(60 + file.display().to_string().len()));
            }
            worker
                .join()
                .map_err(|_| CliError::usage("the export worker panicked"))?
                .map_err(|e| CliError::usage(e.to_string()))
        })?;
        let _ = writeln!(
            text,
            "exported {} to {} ({} files, {} bytes, k_a error max {:.3e} mean {:.3e})",
            file.display(),
            target.display(),
            m.files.len(),
            m.bytes.exported,
            m.ka_error.max,
            m.ka_error.mean
        );
        if report {
            write_report(&mut text, &m);
        }
    }
    Ok(text)
}

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
    /// phong, blinn, compare-split (Phong left, Blinn-Phong right), compare-side (the two
    /// side by side, one camera) or compare-diff (|Phong - Blinn-Phong| heatmap).
    #[arg(long, value_parser = ["phong", "blinn", "compare-split", "compare-side", "compare-diff"])]
    model: String,
    /// shaded, ka, kd, ks, n, diffuse, specular, ambient (or checker, n-false-colour).
    #[arg(long, value_parser = ["shaded", "ka", "kd", "ks", "n", "diffuse", "specular", "ambient", "checker", "n-false-colour"])]
    view: String,
    /// How k_a's chi is computed.
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

/// The maps to render (a project's, or one uniform material) and the mesh they come with.
fn render_material(a: &RenderArgs) -> Result<(model::MaterialMaps, std::path::PathBuf), CliError> {
    if let Some(file) = &a.project {
        let doc = project::load(file).map_err(model_error)?;
        let spec = project_mesh(&doc.settings, file);
        return Ok((doc.maps, spec));
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
    Ok((maps, std::path::PathBuf::from("sphere")))
}

/// Parses `--light X,Y,Z` (not all zero).
fn parse_light(text: &str) -> Result<glam::Vec3, CliError> {
    let bad = || CliError::usage(format!("--light must be a non-zero X,Y,Z, got {text:?}"));
    let v: Vec<f32> = text
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v.as_slice() {
        [x, y, z] => {
            let l = glam::Vec3::new(*x, *y, *z);
            (l.is_finite() && l.length() > 0.0)
                .then_some(l)
                .ok_or_else(bad)
        }
        _ => Err(bad()),
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
    let (maps, own_mesh) = render_material(&a)?;
    let mesh_spec = a.mesh.map_or(own_mesh, std::path::PathBuf::from);
    let mesh = mesh::open(&mesh_spec).map_err(|e| CliError::usage(e.to_string()))?;
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
    let (model, compare) = match a.model.as_str() {
        "phong" => (ShadingModel::Phong, Compare::Single),
        "blinn" => (ShadingModel::BlinnPhong, Compare::Single),
        "compare-split" => (ShadingModel::Phong, Compare::Split),
        "compare-side" => (ShadingModel::Phong, Compare::SideBySide),
        _ => (ShadingModel::Phong, Compare::Difference),
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
            settings,
            compare,
            size: (width, height),
            out: a.out,
        },
    )
    .map_err(|e| CliError::usage(e.to_string()))
}

/// Every model-layer error is reported in one line with exit code 2.
#[allow(clippy::needless_pass_by_value)] // Used as `map_err(model_error)`.
fn model_error(e: ModelError) -> CliError {
    CliError::usage(e.to_string())
}

/// Parses `W` or `WxH`.
fn parse_size(text: &str) -> Result<(u32, u32), CliError> {
    let bad = || {
        CliError::usage(format!(
            "--size must be W or WxH with sides 1 to 8192, got {text:?}"
        ))
    };
    let (w, h) = text.split_once(['x', 'X']).unwrap_or((text, text));
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > model::maps::MAX_SIDE || h > model::maps::MAX_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

/// A paint script: `(commands: [ ... ])` in RON.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaintScript {
    /// Commands applied in order.
    pub commands: Vec<model::Command>,
}

fn read_script(path: &std::path::Path) -> Result<Vec<model::Command>, CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| model_error(ModelError::io(path, e)))?;
    let script: PaintScript = ron::from_str(&text).map_err(|e| {
        model_error(ModelError::Script {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    })?;
    Ok(script.commands)
}

/// `kapaint info` output: `key: value` lines, then one line per channel component.
pub fn info_text(path: &std::path::Path, doc: &Document, file_bytes: u64) -> String {
    let maps = &doc.maps;
    let s = &doc.settings;
    let mut out = String::new();
    let _ = writeln!(out, "file: {}", path.display());
    let _ = writeln!(out, "size: {}x{}", maps.width(), maps.height());
    let _ = writeln!(
        out,
        "tiles: {} ({}x{} of 64x64)",
        maps.tile_count(),
        maps.tiles_x(),
        maps.tiles_y()
    );
    let _ = writeln!(out, "model: {}", s.model.name());
    let _ = writeln!(out, "method: {}", s.approx.name());
    let _ = writeln!(out, "mesh: {}", s.mesh.spec());
    let _ = writeln!(out, "preset: {}", s.preset.as_deref().unwrap_or("-"));
    let expanded = maps.tile_count() * model::tile::TILE_TEXELS * 14;
    let _ = writeln!(
        out,
        "memory: {} bytes in maps ({} bytes if every tile were expanded)",
        maps.heap_bytes(),
        expanded
    );
    let _ = writeln!(out, "file bytes: {file_bytes}");
    let _ = writeln!(out, "channel min mean max");
    for stat in model::stats::channel_stats(maps) {
        let _ = writeln!(
            out,
            "{} {:.6} {:.6} {:.6}",
            stat.label, stat.min, stat.mean, stat.max
        );
    }
    out
}

/// `chi` with 17 significant digits, enough to round-trip an `f64`.
pub fn fmt17(x: f64) -> String {
    format!("{x:.16e}")
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

fn ka_value(model: ShadingModel, method: MethodArg, kd: DVec3, ks: DVec3, n: f64) -> DVec3 {
    match method.approx() {
        None => TWO_OVER_PI * kd + ks * chi_exact(model, n),
        Some(approx) => {
            reflectance::ka(model, approx, kd.as_vec3(), ks.as_vec3(), n as f32).as_dvec3()
        }
    }
}

fn parse_n(text: &str, method: MethodArg) -> Result<f64, CliError> {
    let n: f64 = text
        .trim()
        .parse()
        .map_err(|_| CliError::usage(format!("n must be a number, got {text:?}")))?;
    if !n.is_finite() {
        return Err(CliError::usage(format!("n must be finite, got {text:?}")));
    }
    if n < 0.0 {
        return Err(CliError::usage(format!("n must be >= 0, got {text}")));
    }
    if matches!(method, MethodArg::Exact) && n > EXACT_N_MAX {
        return Err(CliError::usage(format!(
            "n = {text} is above the exact integrator's limit {EXACT_N_MAX:e}"
        )));
    }
    if n > f64::from(f32::MAX) {
        return Err(CliError::usage(format!("n = {text} does not fit in f32")));
    }
    Ok(n)
}

fn read_stdin_values(stdin: &mut dyn BufRead) -> Result<Vec<f64>, CliError> {
    let mut values = Vec::new();
    for (i, line) in stdin.lines().enumerate() {
        let line = line.map_err(|e| CliError::usage(format!("cannot read stdin: {e}")))?;
        if line.trim().is_empty() {
            continue;
        }
        let n = parse_n(&line, MethodArg::Fast)
            .map_err(|e| CliError::usage(format!("stdin line {}: {}", i + 1, e.message)))?;
        values.push(n);
    }
    if values.is_empty() {
        return Err(CliError::usage("no values on stdin"));
    }
    Ok(values)
}

/// Parses `R,G,B` (or a single value when `allow_scalar`), each finite and in `[0, 1]`.
fn parse_rgb(flag: &str, text: &str, allow_scalar: bool) -> Result<DVec3, CliError> {
    let parts: Vec<&str> = text.split(',').collect();
    let values = parts
        .iter()
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|_| CliError::usage(format!("{flag} must be numbers, got {text:?}")))?;
    if let Some(bad) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
        return Err(CliError::usage(format!(
            "{flag} components must be in [0, 1], got {bad}"
        )));
    }
    match values.as_slice() {
        [v] if allow_scalar => Ok(DVec3::splat(*v)),
        [r, g, b] => Ok(DVec3::new(*r, *g, *b)),
        _ if allow_scalar => Err(CliError::usage(format!(
            "{flag} must be S or R,G,B, got {text:?}"
        ))),
        _ => Err(CliError::usage(format!(
            "{flag} must be R,G,B, got {text:?}"
        ))),
    }
}
