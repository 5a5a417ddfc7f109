//! The `kapaint` command line. Output formats here are a contract for scripts.
//!
//! Every failure ends the program with one line on stderr, before any output is written, so
//! a script never sees a partial table. Exit codes: 0 done; [`EXIT_IO`] (1) a file could not
//! be read or written for a reason other than its content (a full disk, no permission, a
//! read-only folder); [`EXIT_USAGE`] (2) bad arguments or bad input (a missing or malformed
//! file, a value out of range); [`crate::crash::EXIT_INTERNAL`] (70) an internal error.

use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use glam::DVec3;

use crate::mesh;
use crate::model::{self, Channel, Document, DocumentSettings, ModelError, import, project};
use crate::reflectance::{self, AmbientApprox, ShadingModel, TWO_OVER_PI, exact::chi_exact};
use crate::report::{accuracy, bench};

mod args;
mod export;
mod render;

use args::{parse_n, parse_rgb, parse_size, read_stdin_values};
pub use render::RenderArgs;

/// Exit code for a failed read or write that is not the input's fault.
pub const EXIT_IO: i32 = 1;

/// Exit code for bad arguments or input.
pub const EXIT_USAGE: i32 = 2;

/// Most sample points `kapaint accuracy` takes per range (each costs an exact integral per
/// model: 256 points take about a minute on 2 cores).
pub const MAX_ACCURACY_POINTS: usize = 256;

/// A failure to report: one line of text and an exit code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// What went wrong, as one line for stderr.
    pub message: String,
    /// The process exit code.
    pub code: i32,
}

impl CliError {
    /// A bad-argument or bad-input error (exit code 2).
    pub fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: EXIT_USAGE,
        }
    }

    /// A failed read or write that is not the input's fault (exit code 1).
    pub fn io(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: EXIT_IO,
        }
    }

    /// An I/O error on a file: a path that names nothing, or the wrong kind of thing, is bad
    /// input; anything else (no space, no permission, a read-only disk) the system's.
    pub fn of_io(message: impl Into<String>, e: &std::io::Error) -> Self {
        use std::io::ErrorKind as K;
        match e.kind() {
            K::NotFound | K::NotADirectory | K::IsADirectory | K::InvalidInput => {
                Self::usage(message)
            }
            _ => Self::io(message),
        }
    }
}

/// `text` as one line: every run of whitespace, line breaks included, becomes one space.
pub fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
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
        /// Sample points per n range (2 to 256, spaced evenly in ln(n + 1)).
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
        /// Script of commands (see docs/cli.md).
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
        /// Project files (several: one set per project, in `OUT/<project name>/`).
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
    /// Panics on purpose, to check what a crash looks like (one line, a report file, exit
    /// code 70).
    #[command(hide = true)]
    DebugPanic {
        /// Panic in every worker thread at once instead of the main thread.
        #[arg(long)]
        workers: bool,
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
            eprintln!("kapaint: {}", clap_message(&e.render().to_string()));
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
            eprintln!("kapaint: {}", one_line(&e.message));
            e.code
        }
    }
}

/// Clap's error as one line: its first paragraph (what is wrong, and the arguments it names
/// on the lines below), without the usage and help lines.
pub fn clap_message(rendered: &str) -> String {
    let first: Vec<&str> = rendered
        .lines()
        .take_while(|l| !l.trim().is_empty() && !l.starts_with("Usage:"))
        .collect();
    let text = one_line(&first.join(" "));
    let text = text.trim_start_matches("error: ").trim_end_matches(':');
    if text.is_empty() {
        "bad arguments (see kapaint --help)".into()
    } else {
        text.to_string()
    }
}

/// Runs a parsed command and returns everything it prints, or the error to report.
#[expect(clippy::too_many_lines, reason = "one arm per subcommand, each short")]
pub fn run(command: Command, stdin: &mut dyn BufRead) -> Result<String, CliError> {
    match command {
        Command::Chi { model, method, n } => {
            let values = if n.len() == 1 && n[0] == "-" {
                read_stdin_values(stdin, method)?
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
            if !(2..=MAX_ACCURACY_POINTS).contains(&points) {
                return Err(CliError::usage(format!(
                    "--points must be 2 to {MAX_ACCURACY_POINTS}, got {points}"
                )));
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
            mesh::open(std::path::Path::new(&mesh)).map_err(mesh_error)?;
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
                let spec = mesh.unwrap_or_else(|| doc.settings().mesh.spec().to_string());
                project::attach_mesh(&mut doc, std::path::Path::new(&spec)).map_err(model_error)?;
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
        } => export::export_command(&files, &preset, &out, report, !no_padding),
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
            let doc = crate::export::set::import(&manifest).map_err(set_error)?;
            project::save(&doc, &out).map_err(model_error)?;
            Ok(format!(
                "imported {} into {} ({}x{})\n",
                manifest.display(),
                out.display(),
                doc.maps().width(),
                doc.maps().height()
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
        Command::Render(args) => render::render_command(args),
        Command::MeshInfo { file } => {
            let mesh = mesh::open(&file).map_err(mesh_error)?;
            Ok(mesh::info_text(&file, &mesh))
        }
        Command::DebugPanic { workers } => {
            if workers {
                use rayon::prelude::*;
                (0..64_u32).into_par_iter().for_each(|i| {
                    std::thread::sleep(std::time::Duration::from_millis(5));
                    panic!("deliberate panic in worker task {i}");
                });
            }
            panic!("deliberate panic on the main thread");
        }
        Command::Bench { size, out, repeats } => {
            if !(16..=16384).contains(&size) {
                return Err(CliError::usage("--size must be in [16, 16384]"));
            }
            crate::memory::check_fits(&format!("--size {size}"), bench::bytes_needed(size))
                .map_err(|e| CliError::usage(format!("{e}: use a smaller --size")))?;
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

/// A model-layer error in one line: exit code 1 for a failed read or write that is not the
/// input's fault, 2 for everything else.
#[expect(
    clippy::needless_pass_by_value,
    reason = "used as `map_err(model_error)`"
)]
pub(super) fn model_error(e: ModelError) -> CliError {
    match &e {
        ModelError::Io { source, .. } => CliError::of_io(e.to_string(), source),
        _ => CliError::usage(e.to_string()),
    }
}

/// A mesh error in one line (exit codes as [`model_error`]).
#[expect(
    clippy::needless_pass_by_value,
    reason = "used as `map_err(mesh_error)`"
)]
pub(super) fn mesh_error(e: mesh::MeshError) -> CliError {
    match &e {
        mesh::MeshError::Io { source, .. } => CliError::of_io(e.to_string(), source),
        mesh::MeshError::Invalid { .. } => CliError::usage(e.to_string()),
    }
}

/// An export or set-import error in one line: 1 when writing or reading failed, 2 for a bad
/// set or target.
#[expect(
    clippy::needless_pass_by_value,
    reason = "used as `map_err(set_error)`"
)]
pub(super) fn set_error(e: crate::export::set::SetError) -> CliError {
    use crate::export::set::SetError;
    match &e {
        SetError::Io { .. } => CliError::io(e.to_string()),
        SetError::Invalid { .. } | SetError::Target { .. } | SetError::Cancelled => {
            CliError::usage(e.to_string())
        }
    }
}

/// Largest paint script read (bytes).
const MAX_SCRIPT_BYTES: u64 = 256 << 20;

/// A paint script: `(commands: [ ... ])` in RON.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaintScript {
    /// Commands applied in order.
    pub commands: Vec<model::Command>,
}

fn read_script(path: &std::path::Path) -> Result<Vec<model::Command>, CliError> {
    let bytes = crate::file_check::read_limited(path, MAX_SCRIPT_BYTES).map_err(|e| {
        if e.is_io() {
            CliError::io(format!("{}: {e}", path.display()))
        } else {
            CliError::usage(format!("{}: {e}", path.display()))
        }
    })?;
    let text = String::from_utf8(bytes).map_err(|_| {
        model_error(ModelError::Script {
            path: path.to_path_buf(),
            reason: "not UTF-8 text".into(),
        })
    })?;
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
    let maps = doc.maps();
    let s = doc.settings();
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
