//! `kapaint bake --high`: maps baked from high-poly meshes onto the project's mesh, kept in
//! the project (a tangent-space normal as its normal map, ao, thickness, curvature, position and
//! object-space normal as its bakes; one undo step) or written as a 16-bit PNG (height also
//! as an EXR).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{CliError, model_error};
use crate::gpu::rays::{GpuCaster, RaysOn};
use crate::mesh::Mesh;
use crate::mesh::bakes::{
    CpuCaster, HighBake, HighMap, HighOptions, HighRays, HighSource, IdSource, Matching,
    NormalSpace, RayCaster, bake_from_high_on,
};
use crate::model::project;

/// The space a normal is baked in.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum SpaceArg {
    /// The project's mesh's MikkTSpace frame (what the preview and the exports read).
    Tangent,
    /// Object space.
    Object,
}

/// How the project's parts find the high mesh's (`--match`).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum MatchArg {
    /// `X_low` with `X_high` (OBJ objects and groups, glTF nodes; case aside).
    ByName,
}

/// What an ID map tells apart (`--id-from`).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum IdArg {
    /// Surfaces joined by shared positions.
    Piece,
    /// OBJ objects and groups, glTF nodes.
    Object,
    /// OBJ `usemtl`, glTF primitives' materials.
    Material,
    /// The vertex colours themselves.
    Color,
}

impl IdArg {
    /// The bake's source.
    pub fn source(self) -> IdSource {
        match self {
            Self::Piece => IdSource::Piece,
            Self::Object => IdSource::Object,
            Self::Material => IdSource::Material,
            Self::Color => IdSource::Color,
        }
    }
}

/// Where AO and thickness rays run (`--device`).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum DeviceArg {
    /// A hardware GPU where there is one, else the CPU.
    Auto,
    /// The CPU.
    Cpu,
    /// Any GPU adapter, software ones included.
    Gpu,
}

impl DeviceArg {
    /// The choice.
    pub fn choice(self) -> RaysOn {
        match self {
            Self::Auto => RaysOn::Auto,
            Self::Cpu => RaysOn::Cpu,
            Self::Gpu => RaysOn::Gpu,
        }
    }
}

/// What `kapaint bake --high` is asked.
pub struct HighRequest<'a> {
    /// The project.
    pub project: &'a Path,
    /// The high meshes (baked as one).
    pub high: &'a [PathBuf],
    /// The cage, if any.
    pub cage: Option<&'a Path>,
    /// The map, distances, rays and samples.
    pub options: HighOptions,
    /// The PNG to write instead of keeping the map.
    pub out: Option<&'a PathBuf>,
    /// The miss map's PNG, if asked.
    pub misses: Option<&'a PathBuf>,
    /// The skew view's PNG, if asked.
    pub skew: Option<&'a PathBuf>,
    /// Pair parts by name.
    pub matching: bool,
    /// What an ID map tells apart; `None`: what the high mesh names.
    pub id_from: Option<IdSource>,
    /// Where AO and thickness rays run.
    pub device: RaysOn,
}

/// Bakes and keeps or writes the map; returns what the command prints.
///
/// # Errors
/// A project without a mesh, a high mesh or cage that does not load or cannot be baked,
/// distances that are not positive, height or id without `--out`, a failed write.
pub fn run(r: &HighRequest<'_>) -> Result<String, CliError> {
    let map = r.options.map;
    if r.out.is_none() && matches!(map, HighMap::Height | HighMap::Id(_)) {
        return Err(CliError::usage(
            "--map height and --map id need --out: a project keeps normals, ao, thickness, curvature and position",
        ));
    }
    for (flag, file) in [("--misses", r.misses), ("--skew", r.skew)] {
        if let Some(m) = file
            && !m.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            return Err(CliError::usage(format!(
                "{}: {flag} must end in .png",
                m.display()
            )));
        }
    }
    let (mut doc, surface, on_disk) = open_to_bake(r.project)?;
    let open = |p: &Path| {
        crate::mesh::open(p).map_err(|e| CliError::usage(format!("{}: {e}", p.display())))
    };
    let high = Mesh::merged(r.high.iter().map(|p| open(p)).collect::<Result<_, _>>()?)
        .map_err(CliError::usage)?;
    let cage = r.cage.map(open).transpose()?;
    let options = HighOptions {
        map: match map {
            HighMap::Id(_) => HighMap::Id(r.id_from.unwrap_or_else(|| IdSource::for_mesh(&high))),
            other => other,
        },
        ..r.options
    };
    let start = Instant::now();
    let matching = if r.matching {
        Matching::ByName
    } else {
        Matching::All
    };
    // A GPU only for the maps that cast rays from the point met, through one BVH.
    let device = if options.map.casts_rays() && matching == Matching::All {
        r.device
            .open()
            .map_err(|e| CliError::usage(format!("--device: {e}")))?
    } else {
        None
    };
    let progress = crate::task::Progress::default();
    let (baked, rays) = super::progress::with_bar("bake", &progress, || {
        let rays = HighRays::new(&surface.mesh, &high, matching)?;
        let on_gpu = match (&device, rays.single()) {
            (Some(gpu), Some(one)) => Some(GpuCaster::new(gpu, one).map_err(|e| e.to_string())?),
            _ => None,
        };
        let cpu = CpuCaster(rays.meshes());
        let caster: &dyn RayCaster = on_gpu.as_ref().map_or(&cpu, |g| g);
        let mut baked = bake_from_high_on(
            &surface.mesh,
            &surface.bake,
            (&high, &rays),
            cage.as_ref(),
            options,
            caster,
            Some(&progress),
        )?;
        baked.bvh_seconds = rays.bvh_seconds;
        Ok::<_, crate::mesh::bakes::BakeError>((baked, rays))
    })
    .map_err(|e| CliError::usage(e.to_string()))?;
    let mut line = summary(r, &high, &baked, start.elapsed().as_secs_f64());
    if r.matching {
        let _ = write!(
            line,
            "\nmatched by name: {} pair{} ({}); {} triangles of the project's mesh and {} of the high mesh in no pair",
            rays.pairs.len(),
            if rays.pairs.len() == 1 { "" } else { "s" },
            rays.pairs.join(", "),
            rays.unpaired_low,
            rays.unpaired_high
        );
    }
    drop(rays);
    write_views(r, &baked, &mut line)?;
    if let Some(out) = r.out {
        let exr = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let png = if exr { exr32(&baked) } else { png16(&baked) }.map_err(CliError::io)?;
        crate::atomic::write_atomic(out, &png)
            .map_err(|e| CliError::of_io(format!("{}: {e}", out.display()), &e))?;
        return Ok(format!("{line}\nwrote {}\n", out.display()));
    }
    let kept = match map.kept_as() {
        Some(_) => format!("kept as the {} bake of", map.name()),
        None => "kept as the normal map of".to_string(),
    };
    let source = HighSource::of(&high, cage.as_ref());
    let keep = crate::model::ImportCommand::keep_high(vec![baked], surface.mesh_hash, &source)
        .map_err(CliError::usage)?;
    doc.apply(keep).map_err(model_error)?;
    project::save_checked(&doc, r.project, on_disk.as_ref()).map_err(model_error)?;
    Ok(format!("{line}\n{kept} {}\n", r.project.display()))
}

/// Writes the miss map and the skew view where asked, a line each onto `line`.
fn write_views(r: &HighRequest<'_>, baked: &HighBake, line: &mut String) -> Result<(), CliError> {
    let misses: Vec<u8> = baked.misses.iter().map(|&m| u8::from(m) * 255).collect();
    for (what, file, on) in [
        ("the miss map", r.misses, misses.as_slice()),
        ("the skew view", r.skew, baked.skew.as_slice()),
    ] {
        let Some(file) = file else { continue };
        let grey =
            image::ImageBuffer::<image::Luma<u8>, &[u8]>::from_raw(baked.width, baked.height, on)
                .ok_or_else(|| CliError::io("bake size mismatch"))?;
        let mut png = std::io::Cursor::new(Vec::new());
        grey.write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| CliError::io(e.to_string()))?;
        crate::atomic::write_atomic(file, png.get_ref())
            .map_err(|e| CliError::of_io(format!("{}: {e}", file.display()), &e))?;
        let _ = write!(*line, "\nwrote {what} {}", file.display());
    }
    Ok(())
}

/// The project, opened with its mesh attached, that mesh's surface, and the file as read (a
/// save finds out if another run saved over it meanwhile).
///
/// # Errors
/// A project that does not open, a mesh that does not load, no mesh.
pub(super) fn open_to_bake(
    path: &std::path::Path,
) -> Result<
    (
        crate::model::Document,
        std::sync::Arc<crate::model::surface::Surface>,
        Option<project::OnDisk>,
    ),
    CliError,
> {
    let on_disk = project::OnDisk::of(path);
    let (doc, failed) = project::open_with_mesh(path, None).map_err(model_error)?;
    if let Some(e) = failed {
        return Err(CliError::usage(format!(
            "{}: its mesh cannot be baked: {e}",
            path.display()
        )));
    }
    let surface = doc
        .surface()
        .cloned()
        .ok_or_else(|| CliError::usage(format!("{}: no mesh to bake", path.display())))?;
    Ok((doc, surface, on_disk))
}

/// The bake as a 16-bit PNG (RGB normals, grey height).
fn png16(baked: &HighBake) -> Result<Vec<u8>, String> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Up);
    let (w, h, data) = (baked.width, baked.height, baked.data.as_slice());
    if baked.map.channels() == 1 {
        image::ImageBuffer::<image::Luma<u16>, &[u16]>::from_raw(w, h, data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder)
    } else {
        image::ImageBuffer::<image::Rgb<u16>, &[u16]>::from_raw(w, h, data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder)
    }
    .map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// The bake as a 32-bit float OpenEXR (the samples in `[0, 1]`, grey as RGB).
fn exr32(baked: &HighBake) -> Result<Vec<u8>, String> {
    let c = baked.map.channels();
    let rgb: Vec<f32> = baked
        .data
        .chunks_exact(c)
        .flat_map(|px| [0, 1, 2].map(|k| f32::from(px[k.min(c - 1)]) / 65535.0))
        .collect();
    let image =
        image::Rgb32FImage::from_raw(baked.width, baked.height, rgb).ok_or("bake size mismatch")?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgb32F(image)
        .write_to(&mut bytes, image::ImageFormat::OpenExr)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

/// One line on what was baked: the meshes, the distances and what the rays missed.
fn summary(r: &HighRequest<'_>, high: &Mesh, baked: &HighBake, seconds: f64) -> String {
    let share = baked.missed as f64 / baked.covered.max(1) as f64 * 100.0;
    let what = match baked.map {
        HighMap::Normal(NormalSpace::Tangent) => "normal (tangent space)".to_string(),
        HighMap::Normal(NormalSpace::Object) => "normal (object space)".to_string(),
        HighMap::Height => format!(
            "height (0 at {:.4} below, 1 at {:.4} above the mesh)",
            baked.rear, baked.front
        ),
        map if map.casts_rays() => format!("{} ({} rays a sample)", map.name(), baked.rays),
        HighMap::Id(source) => format!("id (by {})", source.name()),
        map => map.name().to_string(),
    };
    let rays = if baked.map.casts_rays() {
        let cast = baked.covered * u64::from(baked.samples) * u64::from(baked.rays);
        let tracing = (seconds - baked.bvh_seconds).max(1e-9);
        format!(
            " (the BVH {:.2} s), {cast} rays ({:.2} M rays/s after the BVH) on {}",
            baked.bvh_seconds,
            cast as f64 / tracing / 1e6,
            baked.cast_on
        )
    } else {
        String::new()
    };
    let mean = if baked.map.channels() == 1 {
        let sum: f64 = baked.data.iter().map(|&v| f64::from(v) / 65535.0).sum();
        format!(", mean {:.4}", sum / baked.covered.max(1) as f64)
    } else {
        String::new()
    };
    let highs: Vec<String> = r.high.iter().map(|p| p.display().to_string()).collect();
    let defaults = r.options.front.is_none() || r.options.rear.is_none();
    format!(
        "baked {what} of {} from {} ({} triangles): {}x{}, {} texels{mean}, {} sample{} a texel, {}front {:.4} rear {:.4} (object units{}), missed {} texels ({share:.3} %), {seconds:.2} s{rays}",
        r.project.display(),
        highs.join(" + "),
        high.triangles.len(),
        baked.width,
        baked.height,
        baked.covered,
        baked.samples,
        if baked.samples == 1 { "" } else { "s" },
        r.cage
            .map(|c| format!("from the cage {}, ", c.display()))
            .unwrap_or_default(),
        baked.front,
        baked.rear,
        if defaults {
            ", by default 2 % of the meshes' diagonal"
        } else {
            ""
        },
        baked.missed,
    )
}
