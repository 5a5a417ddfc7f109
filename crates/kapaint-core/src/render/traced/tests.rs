//! The traced view against `k_a` per view where nothing is in the way (a convex mesh, an open
//! plane), and below it where the mesh shadows itself.

use glam::Vec3;

use super::*;
use crate::render::reference;
use crate::render::{Camera, Lighting, Sample};
use kapaint_mesh as mesh;
use kapaint_reflectance::AmbientApprox;

fn settings(model: ShadingModel, view: ViewMode, camera: Camera) -> FrameSettings {
    FrameSettings {
        model,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting::default(),
        camera,
    }
}

/// The traced `k_a` of `mesh` after `samples` samples against the `k_a` per view of the same
/// pixels: the mean and the largest relative difference over the covered pixels.
fn against_per_view(
    mesh: &Mesh,
    camera: Camera,
    model: ShadingModel,
    sample: Sample,
    samples: u32,
) -> (f64, f32, Traced) {
    let (bvh, rays) = (Bvh::build(mesh), RayMesh::new(mesh));
    let material = Material::Uniform(sample);
    let s = settings(model, ViewMode::KaTraced, camera);
    let (w, h) = (64, 64);
    let mut traced = Traced::new((mesh, &bvh, &rays), &material, &s, w, h);
    assert!(traced.pass(&rays, samples, &|| false));
    assert_eq!(traced.samples(), samples);
    let per_view = reference::render(
        mesh,
        &bvh,
        &material,
        &FrameSettings {
            view: ViewMode::KaView,
            ..s
        },
        w,
        h,
    );
    let (mut sum, mut worst, mut count) = (0.0_f64, 0.0_f32, 0);
    for (t, v) in traced.ka().iter().zip(&per_view) {
        if t.w == 0.0 || v.w == 0.0 {
            continue;
        }
        let e = relative_error(t.truncate(), v.truncate());
        sum += f64::from(e);
        worst = worst.max(e);
        count += 1;
    }
    assert!(count > 500, "{count} covered pixels");
    (sum / f64::from(count), worst, traced)
}

fn materials() -> [(ShadingModel, Sample); 5] {
    let s = |kd: Vec3, ks: f32, n: f32| Sample {
        kd,
        ks: Vec3::splat(ks),
        n,
    };
    [
        (ShadingModel::Phong, s(Vec3::new(0.6, 0.3, 0.2), 0.4, 40.0)),
        (ShadingModel::Phong, s(Vec3::splat(0.05), 0.9, 2000.0)),
        (
            ShadingModel::BlinnPhong,
            s(Vec3::new(0.2, 0.5, 0.3), 0.7, 300.0),
        ),
        (ShadingModel::CookTorrance, s(Vec3::splat(0.3), 0.04, 30.0)),
        (ShadingModel::CookTorrance, s(Vec3::splat(0.1), 0.9, 3000.0)),
    ]
}

#[test]
fn on_a_sphere_the_trace_converges_to_ka_per_view() {
    let sphere = mesh::uv_sphere(256, 128);
    let camera = Camera::default().orbit(0.4, 0.3).framing(&sphere.positions);
    for (model, sample) in materials() {
        let (mean, worst, traced) = against_per_view(&sphere, camera, model, sample, 256);
        let error = traced.standard_error().unwrap_or(f32::NAN);
        eprintln!(
            "sphere {model:?} n {}: mean {:.3} %, worst {:.2} %, std. error {:.3} %",
            sample.n,
            mean * 100.0,
            worst * 100.0,
            error * 100.0
        );
        assert!(mean < 0.01, "{model:?} {sample:?}: mean {mean}");
    }
}

#[test]
fn on_an_open_plane_the_trace_converges_to_ka_per_view() {
    let plane = mesh::plane();
    let camera = Camera {
        pitch: 0.6,
        distance: 2.0,
        ..Camera::default()
    };
    for (model, sample) in materials() {
        let (mean, worst, _) = against_per_view(&plane, camera, model, sample, 256);
        eprintln!(
            "plane {model:?} n {}: mean {:.3} %, worst {:.2} %",
            sample.n,
            mean * 100.0,
            worst * 100.0
        );
        assert!(mean < 0.01, "{model:?} {sample:?}: mean {mean}");
    }
}

#[test]
fn a_torus_shadows_its_inner_side() {
    let torus = mesh::torus(1.0, 0.4, 96, 48);
    // Looking down the hole at an angle: the inner side faces the other side of the ring.
    let camera = Camera {
        pitch: 0.9,
        ..Camera::default()
    }
    .framing(&torus.positions);
    let sample = Sample {
        kd: Vec3::splat(0.5),
        ks: Vec3::splat(0.3),
        n: 20.0,
    };
    let (_, worst, traced) = against_per_view(&torus, camera, ShadingModel::BlinnPhong, sample, 64);
    assert!(
        worst > 0.2,
        "the shadow takes a fifth or more somewhere: {worst}"
    );
    // Never above the unshadowed integral by more than the noise.
    let s = settings(ShadingModel::BlinnPhong, ViewMode::KaView, camera);
    let bvh = Bvh::build(&torus);
    let per_view = reference::render(&torus, &bvh, &Material::Uniform(sample), &s, 64, 64);
    let above = traced
        .ka()
        .iter()
        .zip(&per_view)
        .filter(|(t, v)| t.w > 0.0 && v.w > 0.0 && t.x > v.x * 1.05)
        .count();
    assert!(above < 40, "{above} pixels above k_a per view");
}

#[test]
fn a_stopped_pass_keeps_every_pixels_mean_its_own() {
    let sphere = mesh::uv_sphere(32, 16);
    let (bvh, rays) = (Bvh::build(&sphere), RayMesh::new(&sphere));
    let s = settings(
        ShadingModel::Phong,
        ViewMode::KaTraced,
        Camera::default().framing(&sphere.positions),
    );
    let material = Material::Uniform(Sample {
        kd: Vec3::splat(0.5),
        ks: Vec3::ZERO,
        n: 1.0,
    });
    let mut traced = Traced::new((&sphere, &bvh, &rays), &material, &s, 32, 32);
    assert_eq!(traced.standard_error(), None);
    let calls = std::sync::atomic::AtomicU32::new(0);
    let finished = traced.pass(&rays, 4, &|| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 1
    });
    assert!(!finished);
    assert_eq!(traced.samples(), 0, "some pixels got none");
    assert!(traced.pass(&rays, 64, &|| false));
    assert!(traced.samples() >= 64);
    // k_d alone, nothing in the way: (2/pi) k_d.
    for p in traced.ka().iter().filter(|p| p.w > 0.0) {
        assert!(
            (p.x / (0.5 * std::f32::consts::FRAC_2_PI) - 1.0).abs() < 0.05,
            "{p}"
        );
    }
}
