//! Snapshot tests of the preview's main views: the real renderer draws the spot mesh of
//! `../shared/testdata` with its texture as `k_d` (and its luminance as `n`), and each view is
//! compared with the picture committed in `tests/snapshots/` within a stated tolerance, over
//! the mesh's pixels (where either picture is opaque): the mean difference at most 1/255 per
//! channel and at most 1 % of those pixels off by more than 8/255 (rasterisers differ on
//! silhouette pixels and in the last bits of filtering).
//!
//! `KAPAINT_UPDATE_SNAPSHOTS=1 cargo test --release --test snapshots` rewrites the pictures;
//! a failing view writes what it rendered to `target/snapshots/` beside the expected one.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod common;

use common::gpu;
use std::path::{Path, PathBuf};

use glam::Vec3;
use kapaint::gpu::difference::Difference;
use kapaint::gpu::preview::COMPARED_MODELS;
use kapaint::gpu::{Layout, MapTextures, MeshBuffers, Offscreen, Preview, RenderedImage};
use kapaint::model::texel::{MaterialValue, linear_to_srgb8};
use kapaint::model::{Channel, Document, DocumentSettings};
use kapaint::reflectance::{AmbientApprox, ShadingModel};
use kapaint::render::{Camera, FrameSettings, Lighting, ViewMode};

const SIZE: (u32, u32) = (192, 144);

fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot")
        .join(name)
}

/// RGBA8 sRGB bytes of a render (linear data views encoded as the shaded ones are).
fn rgba8(image: RenderedImage) -> Vec<u8> {
    match image {
        RenderedImage::Srgb8 { pixels, .. } => pixels,
        RenderedImage::Linear { pixels, .. } => pixels
            .chunks_exact(4)
            .flat_map(|p| {
                let b = linear_to_srgb8;
                [
                    b(p[0]),
                    b(p[1]),
                    b(p[2]),
                    (p[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                ]
            })
            .collect(),
    }
}

/// Compares `got` with the committed snapshot `name`; returns a failure line or `None`.
fn check(name: &str, got: &[u8]) -> Option<String> {
    let (w, h) = SIZE;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots");
    let path = dir.join(format!("{name}.png"));
    let save = |p: &Path| {
        image::RgbaImage::from_raw(w, h, got.to_vec())
            .expect("size")
            .save(p)
            .expect("write snapshot");
    };
    if std::env::var_os("KAPAINT_UPDATE_SNAPSHOTS").is_some() {
        std::fs::create_dir_all(&dir).expect("snapshot dir");
        save(&path);
        return None;
    }
    let Ok(want) = image::open(&path) else {
        return Some(format!(
            "{name}: no snapshot at {} (KAPAINT_UPDATE_SNAPSHOTS=1 writes it)",
            path.display()
        ));
    };
    let want = want.to_rgba8();
    if want.dimensions() != (w, h) {
        return Some(format!(
            "{name}: snapshot is {:?}, render {w}x{h}",
            want.dimensions()
        ));
    }
    // Measured over the mesh's pixels only (either picture opaque there): the transparent
    // background around it would otherwise dilute a difference on the surface.
    let mut sum = 0_u64;
    let (mut off, mut pixels) = (0_usize, 0_usize);
    for (p, q) in got.chunks_exact(4).zip(want.as_raw().chunks_exact(4)) {
        if p[3] == 0 && q[3] == 0 {
            continue;
        }
        pixels += 1;
        let d = p
            .iter()
            .zip(q)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        sum += p
            .iter()
            .zip(q)
            .map(|(a, b)| u64::from(a.abs_diff(*b)))
            .sum::<u64>();
        off += usize::from(d > 8);
    }
    let mean = sum as f64 / (pixels.max(1) * 4) as f64;
    let off_fraction = off as f64 / pixels.max(1) as f64;
    if pixels == 0 {
        return Some(format!("{name}: nothing was drawn"));
    }
    (mean > 1.0 || off_fraction > 0.01).then(|| {
        let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/snapshots");
        let _ = std::fs::create_dir_all(&out);
        save(&out.join(format!("{name}.png")));
        format!(
            "{name}: mean difference {mean:.2}/255, {:.2} % of pixels off by more than 8/255",
            off_fraction * 100.0
        )
    })
}

#[test]
fn the_main_views_match_their_snapshots() {
    let Some(gpu) = gpu() else { return };
    let mesh = kapaint::mesh::open(&testdata("spot_triangulated.obj")).expect("spot");
    let mut doc = Document::new(
        256,
        256,
        DocumentSettings {
            base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.35), 40.0),
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    let texture = testdata("spot_texture.png");
    doc.import_file(Channel::Kd, &texture).expect("k_d");
    doc.import_file(Channel::N, &texture).expect("n");
    let buffers = MeshBuffers::new(&gpu, &mesh).expect("mesh buffers");
    let maps = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    let preview = Preview::new(&gpu);
    let settings = |model, view| FrameSettings {
        model,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting::default(),
        camera: Camera {
            yaw: 2.3,
            pitch: 0.3,
            ..Camera::default()
        }
        .framing(&mesh.positions),
    };
    let render = |model, view, layout, linear| {
        preview
            .render_offscreen(
                &gpu,
                &buffers,
                &maps,
                &settings(model, view),
                Offscreen {
                    size: SIZE,
                    linear,
                    layout,
                    models: COMPARED_MODELS,
                },
            )
            .expect("render")
    };
    let (phong, blinn) = (ShadingModel::Phong, ShadingModel::BlinnPhong);
    let mut failures = Vec::new();
    for (name, model, view, layout) in [
        ("shaded_phong", phong, ViewMode::Shaded, Layout::Single),
        ("shaded_blinn", blinn, ViewMode::Shaded, Layout::Single),
        ("ka", phong, ViewMode::Ka, Layout::Single),
        (
            "n_false_colour",
            phong,
            ViewMode::NFalseColour,
            Layout::Single,
        ),
        ("specular_blinn", blinn, ViewMode::Specular, Layout::Single),
        (
            "compare_split",
            phong,
            ViewMode::Shaded,
            Layout::Split(SIZE.0 / 2),
        ),
        (
            "compare_side_by_side",
            phong,
            ViewMode::Shaded,
            Layout::SideBySide,
        ),
    ] {
        let image = rgba8(render(model, view, layout, false));
        failures.extend(check(name, &image));
    }
    let (a, b) = (
        render(phong, ViewMode::Shaded, Layout::Single, true),
        render(blinn, ViewMode::Shaded, Layout::Single, true),
    );
    let heat = Difference::new(&gpu)
        .heatmap(&gpu, &a, &b, 0.1)
        .expect("heatmap");
    failures.extend(check("compare_difference", &rgba8(heat)));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
