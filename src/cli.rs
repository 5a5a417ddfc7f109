//! The `kapaint` command line. Output formats here are a contract for scripts.
//!
//! Every bad argument ends the program with one line on stderr and exit code 2, before any
//! output is written, so a script never sees a partial table.

use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use glam::DVec3;

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
                write_atomic(&dir.join("bench.csv"), bench::csv(&rows).as_bytes())?;
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

/// Writes a file atomically: a temporary file beside it, flushed to disk, then renamed.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError {
        message: format!("cannot write {}: {e}", path.display()),
        code: 1,
    };
    let tmp = path.with_extension("tmp-kapaint");
    let result = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail(e));
    }
    Ok(())
}
