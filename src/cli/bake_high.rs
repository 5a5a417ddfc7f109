//! `kapaint bake --high`: normals baked from a high-poly mesh onto the project's mesh, kept as
//! the project's normal map (tangent space, one undo step) or written as a 16-bit PNG.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{CliError, model_error};
use crate::mesh::bakes::{HighBake, HighMap, HighOptions, NormalSpace, bake_from_high};
use crate::model::project;

/// The space a normal is baked in.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum SpaceArg {
    /// The project's mesh's MikkTSpace frame (what the preview and the exports read).
    Tangent,
    /// Object space.
    Object,
}

/// The map asked of the high mesh.
#[derive(Clone, Copy, Debug)]
pub enum Made {
    /// Normals, in a space.
    Normal(SpaceArg),
    /// Height.
    Height,
}

/// What `kapaint bake --high` is asked.
pub struct HighRequest<'a> {
    /// The project.
    pub project: &'a Path,
    /// The high mesh.
    pub high: &'a Path,
    /// The map.
    pub map: Made,
    /// Ray distances.
    pub front: Option<f32>,
    /// Ray distances.
    pub rear: Option<f32>,
    /// The PNG to write instead of keeping the map.
    pub out: Option<&'a PathBuf>,
    /// The miss map's PNG, if asked.
    pub misses: Option<&'a PathBuf>,
}

/// Bakes and keeps or writes the normals; returns what the command prints.
///
/// # Errors
/// A project without a mesh, a high mesh that does not load or cannot be baked, distances
/// that are not positive, object space without `--out`, a failed write.
pub fn run(r: &HighRequest<'_>) -> Result<String, CliError> {
    let map = match r.map {
        Made::Normal(SpaceArg::Tangent) => HighMap::Normal(NormalSpace::Tangent),
        Made::Normal(SpaceArg::Object) => HighMap::Normal(NormalSpace::Object),
        Made::Height => HighMap::Height,
    };
    if r.out.is_none() && map != HighMap::Normal(NormalSpace::Tangent) {
        return Err(CliError::usage(
            "--space object and --map height need --out: the project keeps a tangent-space normal map",
        ));
    }
    if let Some(m) = r.misses
        && !m.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(CliError::usage(format!(
            "{}: --misses must end in .png",
            m.display()
        )));
    }
    let (mut doc, surface, on_disk) = open_to_bake(r.project)?;
    let high = crate::mesh::open(r.high)
        .map_err(|e| CliError::usage(format!("{}: {e}", r.high.display())))?;
    let start = Instant::now();
    let progress = crate::task::Progress::default();
    let options = HighOptions {
        map,
        front: r.front,
        rear: r.rear,
    };
    let baked = super::progress::with_bar("bake", &progress, || {
        bake_from_high(
            &surface.mesh,
            &surface.bake,
            &high,
            options,
            Some(&progress),
        )
    })
    .map_err(|e| CliError::usage(e.to_string()))?;
    let mut line = summary(r, &high, &baked, start.elapsed().as_secs_f64());
    if let Some(m) = r.misses {
        let map = image::GrayImage::from_fn(baked.width, baked.height, |x, y| {
            image::Luma([if baked.misses[(y * baked.width + x) as usize] {
                255
            } else {
                0
            }])
        });
        let mut png = std::io::Cursor::new(Vec::new());
        map.write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| CliError::io(e.to_string()))?;
        crate::atomic::write_atomic(m, png.get_ref())
            .map_err(|e| CliError::of_io(format!("{}: {e}", m.display()), &e))?;
        let _ = write!(line, "\nwrote the miss map {}", m.display());
    }
    if let Some(out) = r.out {
        let exr = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let png = if exr { exr32(&baked) } else { png16(&baked) }.map_err(CliError::io)?;
        crate::atomic::write_atomic(out, &png)
            .map_err(|e| CliError::of_io(format!("{}: {e}", out.display()), &e))?;
        return Ok(format!("{line}\nwrote {}\n", out.display()));
    }
    let image = image::RgbImage::from_fn(baked.width, baked.height, |x, y| {
        let i = (y * baked.width + x) as usize * 3;
        image::Rgb([0, 1, 2].map(|c| (baked.data[i + c] >> 8) as u8))
    });
    let normal = crate::model::normal::NormalMap::new(image).map_err(CliError::usage)?;
    doc.apply(crate::model::ImportCommand::SetNormal(
        crate::model::document::AttachedNormal(Some(std::sync::Arc::new(normal))),
    ))
    .map_err(model_error)?;
    project::save_checked(&doc, r.project, on_disk.as_ref()).map_err(model_error)?;
    Ok(format!(
        "{line}\nkept as the normal map of {}\n",
        r.project.display()
    ))
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
    match baked.map {
        HighMap::Height => image::ImageBuffer::<image::Luma<u16>, &[u16]>::from_raw(w, h, data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder),
        HighMap::Normal(_) => image::ImageBuffer::<image::Rgb<u16>, &[u16]>::from_raw(w, h, data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder),
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
fn summary(
    r: &HighRequest<'_>,
    high: &crate::mesh::Mesh,
    baked: &HighBake,
    seconds: f64,
) -> String {
    let share = baked.missed as f64 / baked.covered.max(1) as f64 * 100.0;
    format!(
        "baked {} of {} from {} ({} triangles): {}x{}, {} texels, front {:.4} rear {:.4} (object units{}), missed {} texels ({share:.3} %), {seconds:.2} s",
        match baked.map {
            HighMap::Normal(NormalSpace::Tangent) => "normal (tangent space)".to_string(),
            HighMap::Normal(NormalSpace::Object) => "normal (object space)".to_string(),
            HighMap::Height => format!(
                "height (0 at {:.4} below, 1 at {:.4} above the mesh)",
                baked.rear, baked.front
            ),
        },
        r.project.display(),
        r.high.display(),
        high.triangles.len(),
        baked.width,
        baked.height,
        baked.covered,
        baked.front,
        baked.rear,
        if r.front.is_none() || r.rear.is_none() {
            ", by default 2 % of the meshes' diagonal"
        } else {
            ""
        },
        baked.missed,
    )
}
