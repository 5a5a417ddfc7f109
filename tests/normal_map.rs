//! The normal map in the preview (issue 20): lit in the MikkTSpace frame with the right
//! orientation (red along the tangent, +u; green along the bitangent, +v, the image's up),
//! and never in `k_a`.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

mod common;

use common::gpu;
use glam::Vec3;
use kapaint::gpu::preview::COMPARED_MODELS;
use kapaint::gpu::{Gpu, Layout, MapTextures, MeshBuffers, Offscreen, Preview, RenderedImage};
use kapaint::model::MaterialMaps;
use kapaint::model::normal::NormalMap;
use kapaint::model::texel::MaterialValue;
use kapaint::reflectance::{AmbientApprox, ShadingModel};
use kapaint::render::{Camera, FrameSettings, Lighting, ViewMode};

/// A uniform normal map whose one normal is `n` (unit, tangent frame).
fn uniform_normal(n: Vec3) -> Arc<NormalMap> {
    let c = n.to_array().map(|c| ((c + 1.0) * 127.5).round() as u8);
    Arc::new(NormalMap::new(image::RgbImage::from_pixel(8, 8, image::Rgb(c))).expect("map"))
}

/// The centre pixel of `view` of the plane lit from `light`, with `normal` as its normal map.
fn centre(gpu: &Gpu, view: ViewMode, light: Vec3, normal: Option<&Arc<NormalMap>>) -> [f32; 3] {
    let plane = kapaint::mesh::builtin("plane").expect("plane");
    let buffers = MeshBuffers::with_tangents(gpu, &plane).expect("mesh");
    let maps = MaterialMaps::new(
        16,
        16,
        MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.3), 20.0),
    )
    .expect("maps");
    let mut textures = MapTextures::new(gpu, &maps).expect("textures");
    textures.set_normal(gpu, normal).expect("normal");
    let settings = FrameSettings {
        model: ShadingModel::BlinnPhong,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting {
            light,
            ..Lighting::default()
        },
        // Straight down at the plane (y up): its centre fills the middle of the picture.
        camera: Camera {
            yaw: 0.0,
            pitch: 1.5,
            ..Camera::default()
        }
        .framing(&plane.positions),
    };
    let image = Preview::new(gpu)
        .render_offscreen(
            gpu,
            &buffers,
            &textures,
            &settings,
            Offscreen {
                size: (33, 33),
                linear: true,
                layout: Layout::Single,
                models: COMPARED_MODELS,
            },
        )
        .expect("render");
    let RenderedImage::Linear { width, pixels, .. } = image else {
        panic!("expected a linear image");
    };
    let i = ((16 * width + 16) * 4) as usize;
    [pixels[i], pixels[i + 1], pixels[i + 2]]
}

#[test]
fn the_normal_map_tilts_the_lighting_along_the_tangent_frame_and_never_ka() {
    let Some(gpu) = gpu() else { return };
    // The plane's tangent frame, checked against the mesh's own dP/du and dP/dv.
    let plane = kapaint::mesh::builtin("plane").expect("plane");
    let t = kapaint::mesh::tangents::generate(&plane).expect("tangents");
    let tan = t.tangents[0];
    let (n, u) = (t.mesh.normals[0], Vec3::new(tan[0], tan[1], tan[2]));
    let b = tan[3] * n.cross(u);
    // The tangent is dP/du and the bitangent dP/dv of the mesh's UVs.
    let uvs = plane.uvs.as_deref().expect("uvs");
    let [i, j, k] = plane.triangles[0].map(|i| i as usize);
    let (e1, e2) = (
        plane.positions[j] - plane.positions[i],
        plane.positions[k] - plane.positions[i],
    );
    let (d1, d2) = (uvs[j] - uvs[i], uvs[k] - uvs[i]);
    let det = d1.x * d2.y - d2.x * d1.y;
    let dpdu = ((e1 * d2.y - e2 * d1.y) / det).normalize();
    let dpdv = ((e2 * d1.x - e1 * d2.x) / det).normalize();
    assert!(
        u.dot(dpdu) > 0.999 && b.dot(dpdv) > 0.999,
        "{u} {b} vs {dpdu} {dpdv}"
    );

    let tilt = 0.6_f32;
    let c = (1.0 - tilt * tilt).sqrt();
    for (axis, name) in [
        (Vec3::X, "red, along the tangent"),
        (Vec3::Y, "green, along the bitangent"),
    ] {
        let map = uniform_normal(axis * tilt + Vec3::Z * c);
        let world = if axis == Vec3::X { u } else { b };
        let toward = (world * tilt + n * c).normalize();
        let away = (-world * tilt + n * c).normalize();
        let lit = centre(&gpu, ViewMode::Diffuse, toward, Some(&map))[0];
        let flat = centre(&gpu, ViewMode::Diffuse, toward, None)[0];
        let dark = centre(&gpu, ViewMode::Diffuse, away, Some(&map))[0];
        eprintln!("{name}: toward {lit}, flat {flat}, away {dark}");
        // Diffuse = I_l k_d (N'.L): 1 when the mapped normal faces the light, c there without
        // the map, cos(2 asin(tilt)) away from it.
        let full = 0.8 * 0.5;
        assert!((lit - full).abs() < 0.02 * full, "{name}: {lit} vs {full}");
        assert!((flat - full * c).abs() < 0.02 * full, "{name}: {flat}");
        let away_cos = (2.0 * tilt.asin()).cos();
        assert!(
            (dark - full * away_cos).abs() < 0.03 * full,
            "{name}: {dark}"
        );
        // k_a is the same with the map or without it, whatever the light.
        let ka_with = centre(&gpu, ViewMode::Ka, toward, Some(&map));
        let ka_without = centre(&gpu, ViewMode::Ka, away, None);
        assert_eq!(ka_with, ka_without, "{name}: k_a moved with the normal map");
    }
}
