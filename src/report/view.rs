//! What the view average hides, for `kapaint accuracy`: how far `k_a` (the view average) is
//! from `k_a` per view over the views a sphere shows, and on real meshes how far `k_a`, and
//! `k_a` times the AO stand-in, are from the traced reference with the mesh's own shadow.

use std::fmt::Write as _;

use glam::Vec3;

use crate::mesh::Mesh;
use crate::mesh::bakes::RayMesh;
use crate::mesh::pick::Bvh;
use crate::reflectance::view::chi_view_fast;
use crate::reflectance::{AmbientApprox, ShadingModel, exact::chi_parts_exact};
use crate::render::reference::Material;
use crate::render::traced::Traced;
use crate::render::{Camera, FrameSettings, Lighting, Sample, ViewMode};

/// The exponents the view-average table lists.
pub const VIEW_AVERAGE_N: [f64; 8] = [1.0, 10.0, 50.0, 100.0, 500.0, 1000.0, 5000.0, 16384.0];

/// One row of the view-average table: the specular part of `k_a` (`k_d = 0`, `k_s = 1`, the
/// worst case: any `k_d` dilutes it) against its per-view value, over the view angles an
/// orthographic sphere shows (`phi = asin r` at radius `r`, weighted by area, `sin 2 phi`).
#[derive(Clone, Copy, Debug)]
pub struct ViewAverageRow {
    /// Model.
    pub model: ShadingModel,
    /// Exponent.
    pub n: f64,
    /// The largest relative difference, and the view angle (degrees) where it is.
    pub max: (f64, f64),
    /// The area-weighted mean over the disc.
    pub mean: f64,
    /// The relative difference head-on.
    pub head_on: f64,
}

/// The view-average table for `models`: each at [`VIEW_AVERAGE_N`], views sampled at 2048
/// midpoints over `[0, 90)` degrees (the per-view values from the table, within 2e-5).
pub fn view_average_rows(models: &[ShadingModel]) -> Vec<ViewAverageRow> {
    const STEPS: usize = 2048;
    let mut rows = Vec::new();
    for &model in models {
        for n in VIEW_AVERAGE_N {
            let [c1, c0] = chi_parts_exact(model, n);
            let average = c1 + c0;
            let relative = |phi: f64| {
                let [v1, v0] = chi_view_fast(model, n as f32, phi as f32).unwrap_or([0.0; 2]);
                let per_view = f64::from(v1) + f64::from(v0);
                (average - per_view).abs() / per_view
            };
            let (mut max, mut sum, mut weights) = ((0.0_f64, 0.0_f64), 0.0, 0.0);
            for k in 0..STEPS {
                let phi = (k as f64 + 0.5) / STEPS as f64 * std::f64::consts::FRAC_PI_2;
                let e = relative(phi);
                let w = (2.0 * phi).sin();
                sum += e * w;
                weights += w;
                if e > max.0 {
                    max = (e, phi.to_degrees());
                }
            }
            rows.push(ViewAverageRow {
                model,
                n,
                max,
                mean: sum / weights,
                head_on: relative(0.0),
            });
        }
    }
    rows
}

/// The view-average table as markdown.
pub fn view_average_markdown(rows: &[ViewAverageRow]) -> String {
    let mut out = String::from(
        "| view average | model | n | max rel error | at view (deg) | mean over the disc | head-on |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| view average | {} | {} | {:.3e} | {:.1} | {:.3e} | {:.3e} |",
            r.model.name(),
            super::accuracy::format_n(r.n),
            r.max.0,
            r.max.1,
            r.mean,
            r.head_on,
        );
    }
    out.push_str(
        "\nview average: |k_a - k_a per view| / k_a per view for the specular part alone \
         (k_d = 0, k_s = 1), over the views an orthographic sphere shows (area-weighted mean).\n",
    );
    out
}

/// One row of the traced table: on one mesh with one model, the relative difference of `k_a`
/// and of `k_a` times the AO stand-in from the traced reference, per covered pixel.
#[derive(Clone, Debug)]
pub struct TracedRow {
    /// The mesh's name.
    pub mesh: String,
    /// Model.
    pub model: ShadingModel,
    /// Mean and 99th percentile of `k_a`'s relative error.
    pub ka: (f64, f64),
    /// The same for `k_a` times AO.
    pub ka_ao: (f64, f64),
    /// Pixels measured.
    pub pixels: usize,
    /// Pixels the trace found fully shadowed (no light reaches them, so no relative error is
    /// defined): left out of the means and percentiles.
    pub dark: usize,
    /// The trace's mean relative standard error.
    pub std_error: f64,
}

/// How a traced table is measured: the material, the image and the samples.
#[derive(Clone, Copy, Debug)]
pub struct TracedSetup {
    /// The uniform material.
    pub material: Sample,
    /// Image side (square).
    pub size: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Rays of the AO stand-in per pixel.
    pub ao_rays: u32,
}

impl Default for TracedSetup {
    fn default() -> Self {
        Self {
            material: Sample {
                kd: Vec3::splat(0.5),
                ks: Vec3::splat(0.5),
                n: 50.0,
            },
            size: 256,
            samples: 256,
            ao_rays: 256,
        }
    }
}

/// Mean and 99th percentile of `errors`, leaving out those against a zero reference.
fn mean_p99(errors: Vec<f32>) -> (f64, f64) {
    let mut errors: Vec<f32> = errors.into_iter().filter(|&e| e < f32::MAX).collect();
    if errors.is_empty() {
        return (0.0, 0.0);
    }
    errors.sort_by(f32::total_cmp);
    let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len() as f64;
    let at = ((errors.len() - 1) as f64 * 0.99).round() as usize;
    (mean, f64::from(errors[at]))
}

/// The traced table: every mesh with every model, seen as `kapaint render` sees it by
/// default (yaw 30, pitch 20 degrees, framed).
pub fn traced_rows(
    meshes: &[(String, Mesh)],
    models: &[ShadingModel],
    setup: &TracedSetup,
) -> Vec<TracedRow> {
    let mut rows = Vec::new();
    for (name, mesh) in meshes {
        let (bvh, rays) = (Bvh::build(mesh), RayMesh::new(mesh));
        let camera = Camera {
            yaw: 30f32.to_radians(),
            pitch: 20f32.to_radians(),
            ..Camera::default()
        }
        .framing(&mesh.positions);
        let mut ao = None;
        for &model in models {
            let settings = FrameSettings {
                model,
                approx: AmbientApprox::Fast,
                view: ViewMode::KaTraced,
                lighting: Lighting::default(),
                camera,
            };
            let material = Material::Uniform(setup.material);
            let size = setup.size;
            let mut traced = Traced::new((mesh, &bvh, &rays), &material, &settings, size, size);
            traced.pass(&rays, setup.samples, &|| false);
            let ao = ao.get_or_insert_with(|| traced.ambient_occlusion(&rays, setup.ao_rays));
            let ka = traced.relative_errors(&settings, None);
            let pixels = ka.len();
            let dark = ka.iter().filter(|&&e| e == f32::MAX).count();
            rows.push(TracedRow {
                mesh: name.clone(),
                model,
                ka: mean_p99(ka),
                ka_ao: mean_p99(traced.relative_errors(&settings, Some(ao))),
                pixels,
                dark,
                std_error: f64::from(traced.standard_error().unwrap_or(0.0)),
            });
        }
    }
    rows
}

/// The traced table as markdown.
pub fn traced_markdown(rows: &[TracedRow], setup: &TracedSetup) -> String {
    let mut out = String::from(
        "| traced | model | k_a mean | k_a p99 | k_a x AO mean | k_a x AO p99 | pixels | fully shadowed | trace std. error |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {} | {} | {:.2} % |",
            r.mesh,
            r.model.name(),
            r.ka.0 * 100.0,
            r.ka.1 * 100.0,
            r.ka_ao.0 * 100.0,
            r.ka_ao.1 * 100.0,
            r.pixels,
            r.dark,
            r.std_error * 100.0,
        );
    }
    let m = setup.material;
    let _ = writeln!(
        out,
        "\ntraced: |live k_a - traced k_a| / traced k_a per pixel, the traced reference masking \
         each light direction by a ray against the mesh ({} samples per pixel, {}^2 pixels, \
         yaw 30, pitch 20 degrees); k_a x AO multiplies by the AO stand-in ({} cosine-weighted \
         rays about the triangle's normal, the AO bake's definition). Fully shadowed pixels (no \
         light reaches them in the trace) have no relative error and are left out of the \
         statistics. Material k_d {}, k_s {}, \
         n {}.",
        setup.samples, setup.size, setup.ao_rays, m.kd.x, m.ks.x, m.n
    );
    out
}

/// The exponents the figure of `chi_view` draws.
pub const PLOT_N: [f64; 4] = [1.0, 10.0, 100.0, 1000.0];

/// Draws `chi_view(n, phi) / chi(n)` against the view angle for Phong (solid) and Blinn-Phong
/// (dashed) at [`PLOT_N`], exact integrals at 90 views each, and writes it as a PNG: the
/// figure of docs/reflectance.md.
///
/// # Errors
/// A failed draw, encode or write.
pub fn plot_chi_view(path: &std::path::Path) -> Result<(), String> {
    const SIZE: (u32, u32) = (960, 560);
    let mut rgb = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw_chi_view(&mut rgb, SIZE).map_err(|e| format!("cannot draw the plot: {e}"))?;
    super::bench::write_png(rgb, SIZE, path)
}

fn draw_chi_view(rgb: &mut [u8], size: (u32, u32)) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    use rayon::prelude::*;
    let font = super::bench::FONT;
    super::bench::register_font()?;
    let root = BitMapBackend::with_buffer(rgb, size).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "chi_view(n, phi) / chi(n): the view average hides a factor of ten",
            (font, 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..90.0_f64, -2.0..1.0_f64)?;
    chart
        .configure_mesh()
        .x_desc("view angle phi (degrees)")
        .y_desc("chi_view / chi, log scale")
        .y_label_formatter(&|y| {
            // Decades only: 0.01, 0.1, 1, 10.
            if (y - y.round()).abs() < 1e-9 {
                format!("{}", 10f64.powi(y.round() as i32))
            } else {
                String::new()
            }
        })
        .label_style((font, 14))
        .axis_desc_style((font, 15))
        .draw()?;
    for (i, n) in PLOT_N.into_iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        for (solid, model) in [
            (true, ShadingModel::Phong),
            (false, ShadingModel::BlinnPhong),
        ] {
            let chi = chi_parts_exact(model, n)[0];
            let points: Vec<(f64, f64)> = (0..90)
                .into_par_iter()
                .map(|k| {
                    let deg = f64::from(k) + 0.5;
                    let v = crate::reflectance::view::chi_view_exact(model, n, deg.to_radians());
                    (deg, (v[0] / chi).max(1e-2).log10())
                })
                .collect();
            let style = ShapeStyle::from(colour).stroke_width(2);
            if solid {
                chart
                    .draw_series(LineSeries::new(points, style))?
                    .label(format!("n = {n} (Phong solid, Blinn-Phong dashed)"))
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
            } else {
                chart.draw_series(DashedLineSeries::new(points, 8, 6, style))?;
            }
        }
    }
    chart
        .draw_series(LineSeries::new([(0.0, 0.0), (90.0, 0.0)], BLACK.mix(0.5)))?
        .label("1: the view average")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.mix(0.5)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((font, 14))
        .draw()?;
    root.present()?;
    Ok(())
}
