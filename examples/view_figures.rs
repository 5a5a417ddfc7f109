//! Draws the figures of docs/reflectance.md's section on what the view average hides:
//! `tests/screenshots/chi_view.png` (`chi_view / chi` against the view angle) and
//! `tests/screenshots/spot_three_views.png` (the spot cow of `../shared/testdata`: `k_a per
//! view`, the view-average error and the traced error at 64 samples per pixel, left to right;
//! CPU renders, so no GPU is needed).
//!
//! Usage: `cargo run --release --example view_figures`

use std::path::Path;

use glam::{Vec3, Vec4};
use kapaint::mesh::{self, bakes::RayMesh, pick::Bvh};
use kapaint::reflectance::{AmbientApprox, ShadingModel};
use kapaint::render::reference::{self, Material};
use kapaint::render::traced::Traced;
use kapaint::render::{Camera, FrameSettings, Lighting, Sample, ViewMode};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shots = root.join("tests/screenshots");
    if let Err(e) = kapaint::report::view::plot_chi_view(&shots.join("chi_view.png")) {
        eprintln!("view_figures: {e}");
        std::process::exit(1);
    }
    let spot = match mesh::load(&root.join("../shared/testdata/spot/spot_triangulated.obj")) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("view_figures: spot: {e}");
            std::process::exit(1);
        }
    };
    let side = 512;
    let settings = |view| FrameSettings {
        model: ShadingModel::BlinnPhong,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting::default(),
        camera: Camera {
            yaw: 30f32.to_radians(),
            pitch: 20f32.to_radians(),
            ..Camera::default()
        }
        .framing(&spot.positions),
    };
    let material = Material::Uniform(Sample {
        kd: Vec3::new(0.6, 0.5, 0.4),
        ks: Vec3::splat(0.4),
        n: 80.0,
    });
    let (bvh, rays) = (Bvh::build(&spot), RayMesh::new(&spot));
    let per_view = reference::render(
        &spot,
        &bvh,
        &material,
        &settings(ViewMode::KaView),
        side,
        side,
    );
    let error = reference::render(
        &spot,
        &bvh,
        &material,
        &settings(ViewMode::KaViewError),
        side,
        side,
    );
    let s = settings(ViewMode::TracedError);
    let mut traced = Traced::new((&spot, &bvh, &rays), &material, &s, side, side);
    traced.pass(&rays, 64, &|| false);
    let traced_error = traced.error(&s);
    let panels: [&[Vec4]; 3] = [&per_view, &error, &traced_error];
    let mut out = image::RgbImage::from_pixel(side * 3, side, image::Rgb([40, 40, 40]));
    let byte = kapaint::model::texel::linear_to_srgb8;
    for (k, panel) in panels.iter().enumerate() {
        for (i, p) in panel.iter().enumerate() {
            if p.w > 0.0 {
                let (x, y) = (i as u32 % side, i as u32 / side);
                out.put_pixel(
                    k as u32 * side + x,
                    y,
                    image::Rgb([byte(p.x), byte(p.y), byte(p.z)]),
                );
            }
        }
    }
    // The heat scale under the two error panels.
    for k in 1..3 {
        for x in 0..side {
            let c = kapaint::render::heat_ramp(x as f32 / (side - 1) as f32);
            for y in side - 12..side {
                out.put_pixel(
                    k * side + x,
                    y,
                    image::Rgb([byte(c.x), byte(c.y), byte(c.z)]),
                );
            }
        }
    }
    if let Err(e) = out.save(shots.join("spot_three_views.png")) {
        eprintln!("view_figures: {e}");
        std::process::exit(1);
    }
    println!(
        "wrote chi_view.png and spot_three_views.png in {}",
        shots.display()
    );
}
