//! `kapaint render --view ka-traced|ka-traced-error`: the traced reference of the ambient term
//! on the CPU ([`crate::render::traced`]), `--samples` samples per pixel.

use std::path::Path;
use std::time::Instant;

use super::CliError;
use crate::gpu::RenderedImage;
use crate::mesh::{self, bakes::Baked, bakes::RayMesh, pick::Bvh};
use crate::render::reference::Material;
use crate::render::traced::{self, Traced};
use crate::render::{FrameSettings, ViewMode};

/// Samples per pixel when `--samples` is not given.
pub const DEFAULT_SAMPLES: u32 = 64;

/// Renders a traced view (`settings.view`) of one model (`single`) with `samples` (or
/// [`DEFAULT_SAMPLES`]); `None` for another view, which takes no `--samples`. `mesh_hash` is
/// the mesh's as loaded (its AO bake's), before [`mesh::Mesh::viewable`] moved it.
///
/// # Errors
/// As [`render`]; `--samples` with another view, or a traced view of a comparison.
pub fn route(
    samples: Option<u32>,
    single: bool,
    (mesh, mesh_hash, maps, ao): (
        &mesh::Mesh,
        u64,
        &crate::model::MaterialMaps,
        Option<&Baked>,
    ),
    settings: &FrameSettings,
    size: (u32, u32),
    out: &Path,
) -> Result<Option<String>, CliError> {
    let view = settings.view;
    if !view.is_traced() {
        return match samples {
            Some(_) => Err(CliError::usage(
                "--samples is for the traced views: --view ka-traced or ka-traced-error",
            )),
            None => Ok(None),
        };
    }
    if !single {
        return Err(CliError::usage(format!(
            "--view {} traces one model: --model phong, blinn or cook-torrance",
            view.name()
        )));
    }
    let samples = samples.unwrap_or(DEFAULT_SAMPLES);
    let ao = match ao {
        _ if !view.needs_ao_bake() => None,
        Some(bake) if bake.mesh_hash == mesh_hash => Some(bake),
        Some(_) => {
            return Err(CliError::usage(format!(
                "--view {}: the project's AO bake is of its own mesh, not of --mesh",
                view.name()
            )));
        }
        None => {
            return Err(CliError::usage(format!(
                "--view {} needs the project's AO bake: kapaint bake PROJECT --map ao",
                view.name()
            )));
        }
    };
    render((mesh, maps, ao), settings, size, samples, out).map(Some)
}

/// Renders the traced view of `settings` over `maps` on `mesh` and writes it to `out`; returns
/// the report line.
///
/// # Errors
/// A mesh whose tracing does not fit in memory (exit 2, pointing at the untraced view), or a
/// failed write.
pub fn render(
    (mesh, maps, ao): (&mesh::Mesh, &crate::model::MaterialMaps, Option<&Baked>),
    settings: &FrameSettings,
    (width, height): (u32, u32),
    samples: u32,
    out: &Path,
) -> Result<String, CliError> {
    let bytes = traced::ray_mesh_bytes(mesh.triangles.len())
        + u64::from(width) * u64::from(height) * traced::bytes_per_pixel();
    crate::memory::check_fits("tracing this mesh", bytes).map_err(|e| {
        CliError::usage(format!(
            "{e}; --view {} shows the untraced view",
            settings.view.untraced().name()
        ))
    })?;
    let start = Instant::now();
    let (bvh, rays) = (Bvh::build(mesh), RayMesh::new(mesh));
    let mut traced = Traced::new(
        (mesh, &bvh, &rays),
        &Material::Maps(maps),
        settings,
        width,
        height,
    );
    if let Some(bake) = ao {
        traced.set_ao_bake(bake);
    }
    // Passes of a hundredth of the samples each (they accumulate), so a terminal shows how
    // far the trace is and how long it has left.
    let progress = crate::task::Progress::default();
    progress.start("trace", u64::from(samples));
    super::progress::with_bar("render", &progress, || {
        let step = samples.div_ceil(100);
        let mut done = 0;
        while done < samples {
            let now = step.min(samples - done);
            traced.pass(&rays, now, &|| false);
            done += now;
            progress.advance(u64::from(now));
        }
    });
    let seconds = start.elapsed().as_secs_f64();
    let image = traced
        .image(settings.view, settings)
        .unwrap_or_else(|| traced.ka());
    let pixels = if settings.view == ViewMode::KaTraced
        || out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        RenderedImage::Linear {
            width,
            height,
            pixels: image.iter().flat_map(glam::Vec4::to_array).collect(),
        }
    } else {
        let byte = crate::model::texel::linear_to_srgb8;
        RenderedImage::Srgb8 {
            width,
            height,
            pixels: image
                .iter()
                .flat_map(|p| [byte(p.x), byte(p.y), byte(p.z), (p.w * 255.0) as u8])
                .collect(),
        }
    };
    let note = crate::gpu::headless::write_image(pixels, settings.view, out)
        .map_err(|e| CliError::io(e.to_string()))?;
    let error = traced
        .standard_error()
        .map_or_else(|| "n/a".to_owned(), |e| format!("{:.2} %", e * 100.0));
    Ok(format!(
        "wrote {} ({width}x{height}, view {}, {}, {samples} samples per pixel, std. error \
         {error}{note}, traced on the CPU ({} threads) in {seconds:.2} s)\n",
        out.display(),
        settings.view.name(),
        settings.model.name(),
        rayon::current_num_threads(),
    ))
}
