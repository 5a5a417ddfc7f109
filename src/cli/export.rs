//! `kapaint export`: projects into texture sets, with a progress bar and the report.

use std::fmt::Write as _;
use std::path::PathBuf;

use super::{CliError, model_error};
use crate::model::project;

/// The `--report` lines of one exported set.
fn write_report(text: &mut String, m: &crate::export::set::Manifest) {
    let _ = writeln!(text, "  preset: {}", m.preset);
    // A block-compressed set's level 0 numbers are in its verdict line.
    if let Some(e) = m.ka_error_srgb.filter(|_| m.blocks.is_none()) {
        let _ = writeln!(text, "  {}", e.describe());
    }
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
    if let Some(b) = &m.blocks {
        write_blocks(text, b);
    }
    // The budget judges level 0 alone: the levels' lines say so where there is a budget.
    let judged = if m.blocks.is_some() {
        " (not judged: the budget judges level 0 only)"
    } else {
        ""
    };
    if !m.level_ka_error.is_empty() {
        let levels: Vec<String> = m
            .level_ka_error
            .iter()
            .map(|e| format!("{:.2e}", e.max))
            .collect();
        let _ = writeln!(
            text,
            "  k_a error max per mip level: {}{judged}",
            levels.join(" ")
        );
    }
    if !m.level_ka_error_srgb.is_empty() {
        let levels: Vec<String> = m
            .level_ka_error_srgb
            .iter()
            .map(|e| format!("{:.2}", e.p999))
            .collect();
        let _ = writeln!(
            text,
            "  k_a error p99.9 per mip level, levels of 8-bit sRGB: {}{judged}",
            levels.join(" ")
        );
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

/// The `--report` lines of a block-compressed set's choice beyond its verdict (printed with
/// the set's first line): what was kept and why, and every trial.
fn write_blocks(text: &mut String, b: &crate::export::set::BlockChoice) {
    let footprint = b
        .astc_block
        .map_or_else(String::new, |f| format!("ASTC {f}, "));
    let _ = writeln!(
        text,
        "  kept: {footprint}{:?} at {:?} ({:?} encoder); why: {}",
        b.layout, b.bc7_effort, b.encoder, b.reason
    );
    if let Some(f) = &b.uncompressed_ka_error_srgb {
        let _ = writeln!(
            text,
            "  the same files uncompressed: k_a within {:.2} levels for 99.9 % of texels (mean {:.3})",
            f.p999, f.mean
        );
    }
    if let Some(why) = &b.gpu_failed {
        let _ = writeln!(
            text,
            "  the GPU encoder failed part-way ({why}): the CPU finished"
        );
    }
    for t in &b.trials {
        let kept = if (t.layout, t.bc7_effort) == (b.layout, b.bc7_effort) {
            " (kept)"
        } else {
            ""
        };
        let _ = writeln!(
            text,
            "    trial {:?} {:?}{kept}: k_a p99.9 {:.2} mean {:.3} max {:.2} levels, relative max {:.3e} mean {:.3e}, PSNR {}, {:.2} s",
            t.layout,
            t.bc7_effort,
            t.ka_error_srgb.map_or(f64::NAN, |e| e.p999),
            t.ka_error_srgb.map_or(f64::NAN, |e| e.mean),
            t.ka_error_srgb.map_or(f64::NAN, |e| e.max),
            t.ka_error.max,
            t.ka_error.mean,
            t.min_psnr
                .map_or_else(|| "exact".into(), |p| format!("{p:.1} dB")),
            t.seconds
        );
    }
}

/// The lines of one exported glTF PBR set.
fn write_pbr(
    text: &mut String,
    file: &std::path::Path,
    target: &std::path::Path,
    m: &crate::export::gltf_pbr::PbrManifest,
    report: bool,
) {
    let e = m.round_trip;
    let _ = writeln!(
        text,
        "exported {} to {} ({} files, {}, {} bytes)",
        file.display(),
        target.display(),
        m.files.len() + 1,
        m.kind(),
        m.files.iter().map(|f| f.bytes).sum::<u64>()
    );
    let _ = writeln!(
        text,
        "round-trip error (relative, box average): max {:.1} %, mean {:.1} %, p99 {:.1} %",
        100.0 * e.max,
        100.0 * e.mean,
        100.0 * e.p99
    );
    if let Some(o) = &m.occlusion {
        let _ = writeln!(text, "occlusion: {}", o.note);
    }
    if let Some(green) = m.normal_green {
        let _ = writeln!(text, "normal map: {} green", green.name());
    }
    for skipped in &m.skipped {
        let _ = writeln!(text, "not written: {skipped}");
    }
    if let Some(b) = &m.basisu {
        let _ = writeln!(text, "basisu: {}", b.summary());
    }
    if report {
        let _ = writeln!(text, "  preset: {}", m.preset);
        let _ = writeln!(
            text,
            "  n to roughness: {} ({})",
            m.n_mapping,
            m.model.name()
        );
        for f in &m.files {
            let _ = writeln!(
                text,
                "  {}: {}{}, {} bytes",
                f.path,
                f.layout.join(" "),
                f.colour_space
                    .map_or_else(String::new, |c| format!(" ({c})")),
                f.bytes
            );
        }
    }
}

/// Export projects as compact texture sets (images + material.json).
#[derive(Debug, clap::Args)]
#[expect(clippy::struct_excessive_bools, reason = "the command's switches")]
pub struct ExportArgs {
    /// Project files (several: one set per project, in `OUT/<project name>/`).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Export preset: every built-in one (listed from the presets themselves), or a user preset.
    #[arg(long, default_value = "compact", help = preset_help())]
    preset: String,
    /// Target folder (must not exist, or be empty, or with --replace hold an exported set).
    #[arg(long)]
    out: PathBuf,
    /// Replace a set already in the target folder (written beside it, then swapped in); a
    /// folder that holds anything else is never replaced.
    #[arg(long)]
    replace: bool,
    /// Print the memory report, the n encoding and the k_a error.
    #[arg(long)]
    report: bool,
    /// Keep texels outside the mesh's UV islands as painted (by default they are filled
    /// from the nearest island, which needs the project's mesh).
    #[arg(long)]
    no_padding: bool,
    /// With --preset gltf-pbr: also write model.glb, the project's mesh with the material
    /// embedded.
    #[arg(long)]
    glb: bool,
    /// With --glb: the .glb's textures as Basis Universal KTX2 files (KHR_texture_basisu:
    /// UASTC with zstd, its settings the cheapest within the preset's k_a budget) instead of
    /// PNGs.
    #[arg(long)]
    basisu: bool,
    /// With --preset gltf-pbr: how n and k_s become roughness and F0 for Phong and
    /// Blinn-Phong projects (default: the mapping the project was imported with, else
    /// height-fitted).
    #[arg(long, value_enum)]
    n_mapping: Option<super::args::NMappingArg>,
}

impl ExportArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project or preset that does not load, a busy target, a failed export.
    pub fn run(self) -> Result<String, CliError> {
        export_command(&self)
    }
}

/// A loaded project, and its surface where the mesh is wanted for a `.glb`.
type Loaded = (
    crate::model::Document,
    Option<std::sync::Arc<crate::model::surface::Surface>>,
);

/// Loads (and so validates) every project before anything is written, with the mesh baked
/// for padding; the mesh itself where `glb`. Notes go to `text`.
fn load_projects(
    files: &[PathBuf],
    padding: bool,
    glb: bool,
    text: &mut String,
) -> Result<Vec<Loaded>, CliError> {
    files
        .iter()
        .map(|f| {
            if !padding && !glb {
                return super::open_project(f).map(|d| (d, None));
            }
            let (doc, failed) = project::open_with_mesh(f, None).map_err(model_error)?;
            if let Some(e) = &failed
                && doc.needs_mesh()
            {
                return Err(CliError::usage(format!(
                    "{}: its generator masks are laid on its mesh {}, which does not load ({e})",
                    f.display(),
                    doc.settings().mesh.spec()
                )));
            }
            super::require_bakes(f, &doc)?;
            if let Some(e) = failed {
                if glb {
                    return Err(CliError::usage(format!(
                        "{}: --glb needs the project's mesh: {e}",
                        f.display()
                    )));
                }
                let _ = writeln!(text, "note: {}: no padding ({e})", f.display());
            }
            let mesh = glb.then(|| doc.surface().cloned()).flatten();
            if !padding {
                return Ok((doc.with_surface(None).map_err(model_error)?, mesh));
            }
            Ok((doc, mesh))
        })
        .collect()
}

/// `--preset`'s help: every built-in preset by name, from the presets themselves.
fn preset_help() -> String {
    let names: Vec<String> = crate::export::preset::builtin()
        .into_iter()
        .map(|p| p.name)
        .collect();
    format!(
        "Export preset: {} (gltf-pbr writes glTF's metallic-roughness maps, unreal, unity-hdrp, unity-urp and godot each engine's PBR textures; the others kapaint sets), or a user preset",
        names.join(", ")
    )
}

/// `kapaint export`: every project into its set; one line each, plus the report.
fn export_command(args: &ExportArgs) -> Result<String, CliError> {
    use crate::export::set::SetKind;
    let (files, out, report, replace, glb) =
        (&args.files, &args.out, args.report, args.replace, args.glb);
    let preset =
        crate::export::preset::find(&args.preset).map_err(|e| CliError::usage(e.to_string()))?;
    if glb && !preset.format.is_gltf_pbr() {
        return Err(CliError::usage(format!(
            "--glb writes the mesh with a glTF material: use it with --preset gltf-pbr, not {}",
            preset.name
        )));
    }
    if args.basisu && !glb {
        return Err(CliError::usage(
            "--basisu encodes the .glb's textures: use it with --preset gltf-pbr --glb",
        ));
    }
    if args.n_mapping.is_some() && !preset.format.is_pbr() {
        return Err(CliError::usage(format!(
            "--n-mapping chooses how n becomes roughness: use it with --preset gltf-pbr or an engine preset (unreal, unity-hdrp, unity-urp, godot), not {}",
            preset.name
        )));
    }
    let mut text = String::new();
    let mut docs = load_projects(files, !args.no_padding, glb, &mut text)?;
    if let Some(mapping) = args.n_mapping {
        docs = docs
            .into_iter()
            .map(|(doc, mesh)| {
                let mut settings = doc.settings().clone();
                settings.n_mapping = Some(mapping.into());
                (doc.with_settings(settings), mesh)
            })
            .collect();
    }
    let targets: Vec<PathBuf> = if files.len() == 1 {
        vec![out.clone()]
    } else {
        files
            .iter()
            .map(|f| out.join(f.file_stem().unwrap_or_default()))
            .collect()
    };
    check_targets(files, &targets, replace, SetKind::of(&preset))?;
    let gpu = crate::gpu::blocks::for_export(&preset);
    for (i, ((file, (doc, mesh)), target)) in files.iter().zip(&docs).zip(&targets).enumerate() {
        let mesh = mesh.as_ref().map(|s| crate::export::gltf_pbr::Glb {
            mesh: &s.mesh,
            basisu: args.basisu,
        });
        let progress = crate::task::Progress::default();
        // A bar with the stage and an estimate on a terminal while it works.
        let what = format!("export {}/{} {}", i + 1, files.len(), file.display());
        let m = super::progress::with_bar(&what, &progress, || {
            crate::export::run(doc, &preset, target, &progress, replace, mesh, gpu)
        })
        .map_err(super::set_error)?;
        match m {
            crate::export::Exported::Set(m) => {
                let _ = write!(
                    text,
                    "exported {} to {} ({} files, {} bytes",
                    file.display(),
                    target.display(),
                    m.files.len(),
                    m.bytes.exported,
                );
                // A block-compressed set: its numbers with the budget's verdict on them.
                match &m.blocks {
                    Some(b) => {
                        let _ = writeln!(text, ")\n  blocks: {}", b.summary());
                    }
                    None => {
                        let _ = writeln!(
                            text,
                            ", k_a error max {:.3e} mean {:.3e})",
                            m.ka_error.max, m.ka_error.mean
                        );
                    }
                }
                if let Some(normal) = m.normal.as_ref().and_then(|n| n.summary()) {
                    let _ = writeln!(text, "  normal map: {normal}");
                }
                if let Some(saved) = m.supercompression_summary() {
                    let _ = writeln!(text, "  supercompression: {saved}");
                }
                if report {
                    write_report(&mut text, &m);
                }
            }
            crate::export::Exported::Pbr(m) => write_pbr(&mut text, file, target, &m, report),
        }
    }
    Ok(text)
}

/// Every target is free (absent, or an empty folder; with `replace`, a set of the same kind
/// holding only what its export wrote), holds no project, and no two projects share one,
/// before anything is written: a failed batch leaves nothing behind.
fn check_targets(
    files: &[PathBuf],
    targets: &[PathBuf],
    replace: bool,
    kind: crate::export::set::SetKind,
) -> Result<(), CliError> {
    use crate::export::set::{Target, holds, target as target_of};
    for (k, target) in targets.iter().enumerate() {
        if let Some(j) = targets[..k].iter().position(|t| t == target) {
            return Err(CliError::usage(format!(
                "{} and {} would both export to {}; give the projects different names",
                files[j].display(),
                files[k].display(),
                target.display()
            )));
        }
        if let Some(project) = files.iter().find(|f| holds(target, f)) {
            return Err(CliError::usage(format!(
                "{}: holds the project {}; export into another folder",
                target.display(),
                project.display()
            )));
        }
        match target_of(target, kind).map_err(super::set_error)? {
            Target::Free => {}
            Target::Set if replace => {}
            Target::Set => {
                return Err(CliError::usage(format!(
                    "{}: holds an exported set already; pass --replace to replace it",
                    target.display()
                )));
            }
            Target::Taken(why) => {
                return Err(CliError::usage(format!("{}: {why}", target.display())));
            }
        }
    }
    Ok(())
}
