//! The `kapaint` command line. Output formats here are a contract for scripts.
//!
//! Every failure ends the program with one line on stderr, before any output is written, so
//! a script never sees a partial table. Exit codes: 0 done; [`EXIT_IO`] (1) a file could not
//! be read or written for a reason other than its content (a full disk, no permission, a
//! read-only folder); [`EXIT_USAGE`] (2) bad arguments or bad input (a missing or malformed
//! file, a value out of range); [`crate::crash::EXIT_INTERNAL`] (70) an internal error.

use std::io::{BufRead, Write};

use clap::{Parser, Subcommand};

use crate::mesh;
use crate::model::ModelError;

mod accuracy;
mod args;
mod bake;
mod bake_high;
mod bench;
mod chi;
mod debug_panic;
mod edit;
mod equivalent_n;
mod export;
mod import;
mod import_pbr;
mod import_set;
mod info;
mod ka;
mod layers;
mod mesh_info;
mod new;
mod paint;
mod progress;
mod render;
mod render_traced;
mod unwrap;

pub use accuracy::MAX_ACCURACY_POINTS;
pub use args::{MethodArg, ModelArg, fmt17};
pub use chi::chi_parts_value;
pub use info::info_text;
pub use paint::PaintScript;

/// Exit code for a failed read or write that is not the input's fault.
pub const EXIT_IO: i32 = 1;

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
        // A link that loops (ELOOP) names nothing: the input's fault, like a missing file.
        const LINK_LOOP: i32 = if cfg!(target_os = "macos") { 62 } else { 40 };
        match e.kind() {
            K::NotFound
            | K::NotADirectory
            | K::IsADirectory
            | K::InvalidInput
            | K::InvalidFilename => Self::usage(message),
            _ if cfg!(unix) && e.raw_os_error() == Some(LINK_LOOP) => Self::usage(message),
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
    /// Open the editor, on the project FILE if one is given (`kapaint` alone opens it too).
    Edit(edit::EditArgs),
    /// Print chi(n), the specular part of k_a per unit k_s, as CSV `n,chi`.
    Chi(chi::ChiArgs),
    /// Print k_a = (2/pi) k_d + k_s chi(n) of one texel as `r,g,b`.
    Ka(ka::KaArgs),
    /// Print the error of every approximation against the exact integrator (markdown).
    Accuracy(accuracy::AccuracyArgs),
    /// Create a project of one material everywhere.
    New(new::NewArgs),
    /// Print a project's resolution, per-channel min/mean/max and memory.
    Info(info::InfoArgs),
    /// List a project's layers as CSV.
    Layers(layers::LayersArgs),
    /// Import an image (PNG, JPEG, TGA, EXR) into one channel of a project.
    Import(import::ImportArgs),
    /// Replay a paint script (RON list of commands) on a project and save it.
    Paint(paint::PaintArgs),
    /// Export projects as compact texture sets (images + material.json).
    Export(export::ExportArgs),
    /// Rebuild a project from an exported set.
    ImportSet(import_set::ImportSetArgs),
    /// Convert a PBR texture set (glTF material, metallic-roughness or specular-glossiness
    /// images, or numbers) into a project, and print the conversion error.
    ImportPbr(import_pbr::ImportPbrArgs),
    /// The exponent of the other model whose highlight matches (CSV "n,equivalent").
    EquivalentN(equivalent_n::EquivalentNArgs),
    /// Render the preview headless (no window, no display) into a PNG or EXR.
    Render(render::RenderArgs),
    /// Print a mesh's vertices, triangles, UV islands, bounds, and whether normals and UVs
    /// were present (FILE is an .obj, .gltf or .glb file, or sphere, plane, cube, torus).
    MeshInfo(mesh_info::MeshInfoArgs),
    /// Bake a map of a project's mesh (ao, curvature, thickness, position, normal) at the
    /// project's size into a 16-bit PNG.
    Bake(bake::BakeArgs),
    /// Give a mesh a new UV atlas (charts packed and padded for a map size, no overlap) and
    /// write it as .obj or .glb.
    Unwrap(unwrap::UnwrapArgs),
    /// Panics on purpose, to check what a crash looks like (one line, a report file, exit
    /// code 70).
    #[command(hide = true)]
    DebugPanic(debug_panic::DebugPanicArgs),
    /// Time the k_a derive of a full map per method against its error and a memory copy.
    Bench(bench::BenchArgs),
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
    let command = match cli.command {
        Command::Edit(editor) => return editor.run(),
        command => command,
    };
    crate::crash::install(crate::crash::OnPanic::Exit);
    let stdin = std::io::stdin();
    if let Command::Chi(chi) = command {
        // Rows as they are computed: a long run (an exact integral per value) shows its
        // first rows at once, not all of them hours later.
        return match chi.stream(&mut stdin.lock(), &mut std::io::stdout().lock()) {
            Ok(()) => 0,
            Err(e) => {
                eprintln!("kapaint: {}", one_line(&e.message));
                e.code
            }
        };
    }
    match run(command, &mut stdin.lock()) {
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
///
/// # Errors
/// What the command reports: one line and an exit code.
pub fn run(command: Command, stdin: &mut dyn BufRead) -> Result<String, CliError> {
    match command {
        Command::Edit(_) => Err(CliError::usage(
            "`kapaint edit` opens the editor's window: run it from a terminal",
        )),
        Command::Chi(a) => a.run(stdin),
        Command::Ka(a) => a.run(),
        Command::Accuracy(a) => a.run(),
        Command::New(a) => a.run(),
        Command::Info(a) => a.run(),
        Command::Layers(a) => a.run(),
        Command::Import(a) => a.run(),
        Command::Paint(a) => a.run(),
        Command::Export(a) => a.run(),
        Command::ImportSet(a) => a.run(),
        Command::ImportPbr(a) => a.run(),
        Command::EquivalentN(a) => a.run(),
        Command::Render(a) => a.run(),
        Command::MeshInfo(a) => a.run(),
        Command::Unwrap(a) => a.run(),
        Command::Bake(a) => a.run(),
        Command::DebugPanic(a) => a.run(),
        Command::Bench(a) => a.run(),
    }
}

/// A model-layer error in one line: exit code 1 for a failed read or write that is not the
/// input's fault, 70 for a broken invariant inside kapaint, 2 for bad input.
#[expect(
    clippy::needless_pass_by_value,
    reason = "used as `map_err(model_error)`"
)]
pub(super) fn model_error(e: ModelError) -> CliError {
    match &e {
        ModelError::Io { source, .. } => CliError::of_io(e.to_string(), source),
        ModelError::Conflict { .. } => CliError::io(e.to_string()),
        ModelError::Internal(_) => CliError {
            message: e.to_string(),
            code: crate::crash::EXIT_INTERNAL,
        },
        ModelError::InvalidSize { .. }
        | ModelError::Project { .. }
        | ModelError::Preset { .. }
        | ModelError::UnknownPreset { .. }
        | ModelError::Image { .. }
        | ModelError::Script { .. }
        | ModelError::Unsaveable { .. }
        | ModelError::Command(_) => CliError::usage(e.to_string()),
    }
}

/// Opens a project the way every command that reads one does ([`project::load`]: its
/// composite made from its layers, on its own mesh where a generator mask needs it) and
/// refuses one whose generator masks read a bake it lacks.
///
/// # Errors
/// A project that does not load (exit 1 or 2, as [`model_error`]); a missing bake (exit 2,
/// naming the `kapaint bake` that makes it).
///
/// [`project::load`]: crate::model::project::load
pub(super) fn open_project(path: &std::path::Path) -> Result<crate::model::Document, CliError> {
    let doc = crate::model::project::load(path).map_err(model_error)?;
    require_bakes(path, &doc)?;
    Ok(doc)
}

/// An error when a generator mask of `doc` (the project at `path`) reads a bake the project
/// does not keep: the masks would be made of a flat stand-in.
///
/// # Errors
/// The first missing bake, naming the command that makes it.
pub(super) fn require_bakes(
    path: &std::path::Path,
    doc: &crate::model::Document,
) -> Result<(), CliError> {
    match doc.missing_bakes().first() {
        Some((map, layer)) => Err(CliError::usage(format!(
            "{}: the mask of the layer {layer:?} reads the {name} bake, which the project does \
             not have: run `kapaint bake {} --map {name}` first",
            path.display(),
            path.display(),
            name = map.name()
        ))),
        None => Ok(()),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh baked at another size than the maps is kapaint's fault, not the input's: it
    /// exits 70, not 2 (bad input).
    #[test]
    fn a_broken_invariant_in_the_model_is_an_internal_error() {
        use crate::model::{Document, DocumentSettings, surface::Surface};
        let doc = Document::new(8, 8, DocumentSettings::default()).expect("document");
        let sphere = mesh::builtin("sphere").expect("sphere");
        let surface = Surface::new(sphere, 16, 16).expect("bake");
        let e = doc
            .with_surface(Some(std::sync::Arc::new(surface)))
            .expect_err("sizes differ");
        let e = model_error(e);
        assert_eq!(e.code, crate::crash::EXIT_INTERNAL, "{}", e.message);
        assert_eq!(
            model_error(ModelError::Command("pick outside".into())).code,
            EXIT_USAGE
        );
    }
}
