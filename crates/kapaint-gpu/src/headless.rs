//! `kapaint render`: a frame rendered with no window and no display, written as an image.
//! Data views are raw linear values (16-bit PNG, or float EXR) so images can be checked
//! numerically; shaded views are sRGB PNGs (or linear EXR).

use std::path::{Path, PathBuf};

use super::{Gpu, GpuError, Layout, MapTextures, MeshBuffers, Offscreen, Preview, RenderedImage};
use kapaint_core::render::{FrameSettings, ViewMode};
use kapaint_mesh::Mesh;
use kapaint_model::MaterialMaps;
use kapaint_reflectance::ShadingModel;

pub use kapaint_core::render::Compare;

/// One headless render.
pub struct Request<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The maps.
    pub maps: &'a MaterialMaps,
    /// The material's normal map, if it has one.
    pub normal: Option<&'a std::sync::Arc<kapaint_model::normal::NormalMap>>,
    /// Model, approximation, view, lights, camera.
    pub settings: FrameSettings,
    /// Single model or a comparison.
    pub compare: Compare,
    /// The compared models from the left (the first two but for all three).
    pub models: [ShadingModel; 3],
    /// Image size.
    pub size: (u32, u32),
    /// `.png` or `.exr`.
    pub out: PathBuf,
}

/// Image file kinds written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Png,
    Exr,
}

fn kind_of(path: &Path) -> Result<Kind, GpuError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(Kind::Png),
        Some("exr") => Ok(Kind::Exr),
        _ => Err(GpuError(format!(
            "{}: --out must end in .png or .exr",
            path.display()
        ))),
    }
}

/// Renders and writes the image atomically; returns the report line.
///
/// # Errors
/// No adapter, a bad size or output name, or a failed write.
pub fn run(gpu: &Gpu, req: &Request<'_>) -> Result<String, GpuError> {
    let kind = kind_of(&req.out)?;
    let (width, height) = req.size;
    let preview = Preview::new(gpu);
    let mesh = if req.normal.is_some() {
        MeshBuffers::with_tangents(gpu, req.mesh)?
    } else {
        MeshBuffers::new(gpu, req.mesh)?
    };
    let mut maps = MapTextures::new(gpu, req.maps)?;
    maps.set_normal(gpu, req.normal)?;
    let linear = kind == Kind::Exr || req.settings.view.is_data();
    let mut note = String::new();
    let pixels: RenderedImage = if let Some(layout) = Layout::of(req.compare, 0.5, width) {
        preview.render_offscreen(
            gpu,
            &mesh,
            &maps,
            &req.settings,
            Offscreen {
                size: req.size,
                linear,
                layout,
                models: req.models,
            },
        )?
    } else {
        let render = |model| {
            let settings = FrameSettings {
                model,
                ..req.settings
            };
            let offscreen = Offscreen {
                size: req.size,
                linear: true,
                layout: Layout::Single,
                models: req.models,
            };
            preview.render_offscreen(gpu, &mesh, &maps, &settings, offscreen)
        };
        let (a, b) = (render(req.models[0])?, render(req.models[1])?);
        let (RenderedImage::Linear { pixels: a, .. }, RenderedImage::Linear { pixels: b, .. }) =
            (a, b)
        else {
            return Err(GpuError("difference needs linear renders".into()));
        };
        let diff: Vec<f32> = a
            .chunks_exact(4)
            .zip(b.chunks_exact(4))
            .flat_map(|(p, q)| {
                let d = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0_f32, f32::max);
                [d, d, d, p[3].max(q[3])]
            })
            .collect();
        let max = diff.chunks_exact(4).map(|p| p[0]).fold(0.0_f32, f32::max);
        note = format!(
            ", max |{} - {}| {max:.6}",
            req.models[0].name(),
            req.models[1].name()
        );
        if kind == Kind::Exr {
            RenderedImage::Linear {
                width,
                height,
                pixels: diff,
            }
        } else {
            heatmap(&diff, width, height, max)
        }
    };
    note += &write_image(pixels, req.settings.view, &req.out)?;
    Ok(format!(
        "wrote {} ({width}x{height}, view {}, {}{note}, adapter {} ({:?}))\n",
        req.out.display(),
        req.settings.view.name(),
        describe(req),
        gpu.info.name,
        gpu.info.backend,
    ))
}

/// Writes a rendered `image` of `view` to `out` (`.png` or `.exr`) atomically: the view's scale
/// along the bottom rows of a false-colour or heatmap view, `n` on the painting engine's log
/// scale in a PNG. Returns what the report says of the scale (empty for none).
///
/// # Errors
/// A bad output name, or a failed encode or write.
pub fn write_image(
    mut pixels: RenderedImage,
    view: ViewMode,
    out: &Path,
) -> Result<String, GpuError> {
    let kind = kind_of(out)?;
    let note = draw_view_legend(view, &mut pixels).unwrap_or_default();
    if view == ViewMode::N
        && kind == Kind::Png
        && let RenderedImage::Linear { pixels: p, .. } = &mut pixels
    {
        // n does not fit [0, 1]: a PNG holds it on the log scale of the painting engine.
        for px in p.chunks_exact_mut(4) {
            for v in &mut px[..3] {
                *v = kapaint_model::texel::n_to_blend(*v);
            }
        }
    }
    let bytes = encode(&pixels, kind)?;
    kapaint_base::atomic::write_atomic(out, &bytes)
        .map_err(|e| GpuError(format!("cannot write {}: {e}", out.display())))?;
    Ok(note)
}

/// What the image shows: the model, or the models compared and how.
fn describe(req: &Request<'_>) -> String {
    let [a, b, c] = req.models.map(ShadingModel::name);
    match req.compare {
        Compare::Single => req.settings.model.name().to_owned(),
        Compare::Split => format!("{a} | {b}"),
        Compare::SideBySide => format!("{a}, {b} side by side"),
        Compare::ThreeWay => format!("{a}, {b}, {c} side by side"),
        Compare::Difference => format!("|{a} - {b}|"),
    }
}

/// Draws the scale of a false-colour or heatmap view along the bottom rows; what the report
/// says about it.
fn draw_view_legend(view: ViewMode, pixels: &mut RenderedImage) -> Option<String> {
    match view {
        ViewMode::NFalseColour => {
            draw_legend(pixels, |t| {
                let span = (1.0 + kapaint_model::texel::N_MAX).ln();
                kapaint_core::render::n_false_colour((span * t).exp() - 1.0)
            });
            Some(", legend: n = 0 (left) to 16384 (right), log scale".into())
        }
        v if v.is_error_heatmap() => {
            draw_legend(pixels, kapaint_core::render::heat_ramp);
            Some(format!(
                ", legend: relative error 0 (left) to {:.0} % (right)",
                kapaint_core::render::VIEW_ERROR_TOP * 100.0
            ))
        }
        _ => None,
    }
}

/// Draws a scale along the bottom rows: `ramp(t)` (linear RGB) for `t` from 0 at the left to
/// 1 at the right.
fn draw_legend(image: &mut RenderedImage, ramp: impl Fn(f32) -> glam::Vec3) {
    let (width, height) = match image {
        RenderedImage::Srgb8 { width, height, .. }
        | RenderedImage::Linear { width, height, .. } => (*width, *height),
    };
    let bar = (height / 24).max(2).min(height);
    for y in height - bar..height {
        for x in 0..width {
            let c = ramp(x as f32 / (width.max(2) - 1) as f32);
            let i = (y * width + x) as usize * 4;
            match image {
                RenderedImage::Srgb8 { pixels, .. } => {
                    let byte = kapaint_model::texel::linear_to_srgb8;
                    pixels[i..i + 4].copy_from_slice(&[byte(c.x), byte(c.y), byte(c.z), 255]);
                }
                RenderedImage::Linear { pixels, .. } => {
                    pixels[i..i + 4].copy_from_slice(&[c.x, c.y, c.z, 1.0]);
                }
            }
        }
    }
}

/// A heatmap of `diff` (black, red, yellow, white up to `max`) with a scale bar along the
/// bottom rows, sRGB bytes.
fn heatmap(diff: &[f32], width: u32, height: u32, max: f32) -> RenderedImage {
    let ramp = kapaint_core::render::heat_ramp;
    let scale = if max > 0.0 { 1.0 / max } else { 0.0 };
    let bar = (height / 24).max(2);
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for (i, p) in diff.chunks_exact(4).enumerate() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        let (c, a) = if y >= height - bar {
            (ramp(x as f32 / (width.max(2) - 1) as f32), 1.0)
        } else {
            (ramp(p[0] * scale), p[3])
        };
        let byte = kapaint_model::texel::linear_to_srgb8;
        pixels.extend_from_slice(&[byte(c.x), byte(c.y), byte(c.z), (a * 255.0 + 0.5) as u8]);
    }
    RenderedImage::Srgb8 {
        width,
        height,
        pixels,
    }
}

/// Encodes an image: sRGB bytes as an 8-bit RGBA PNG; linear data as a 16-bit RGBA PNG
/// (values clamped into [0, 1]; `n` through the log blend scale) or a float RGBA EXR.
fn encode(image: &RenderedImage, kind: Kind) -> Result<Vec<u8>, GpuError> {
    let fail = |e: image::ImageError| GpuError(format!("cannot encode the image: {e}"));
    let mut out = std::io::Cursor::new(Vec::new());
    match (image, kind) {
        (
            RenderedImage::Srgb8 {
                width,
                height,
                pixels,
            },
            Kind::Png,
        ) => {
            image::RgbaImage::from_raw(*width, *height, pixels.clone())
                .ok_or_else(|| GpuError("image size mismatch".into()))?
                .write_to(&mut out, image::ImageFormat::Png)
                .map_err(fail)?;
        }
        (
            RenderedImage::Linear {
                width,
                height,
                pixels,
            },
            Kind::Exr,
        ) => {
            image::Rgba32FImage::from_raw(*width, *height, pixels.clone())
                .ok_or_else(|| GpuError("image size mismatch".into()))?
                .write_to(&mut out, image::ImageFormat::OpenExr)
                .map_err(fail)?;
        }
        (
            RenderedImage::Linear {
                width,
                height,
                pixels,
            },
            Kind::Png,
        ) => {
            let words: Vec<u16> = pixels
                .iter()
                .map(|&v| (v.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16)
                .collect();
            image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(*width, *height, words)
                .ok_or_else(|| GpuError("image size mismatch".into()))?
                .write_to(&mut out, image::ImageFormat::Png)
                .map_err(fail)?;
        }
        (RenderedImage::Srgb8 { .. }, Kind::Exr) => {
            return Err(GpuError("an EXR needs a linear render".into()));
        }
    }
    Ok(out.into_inner())
}
