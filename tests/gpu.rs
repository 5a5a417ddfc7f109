//! The real renderer on a real adapter (Mesa's lavapipe in CI): the shader's chi against the
//! Rust core, the k_a view against the CPU k_a, shaded renders against the CPU reference
//! renderer, dirty-tile uploads, the split compare, finite output on extreme maps.
//!
//! In CI (`CI` or `KAPAINT_REQUIRE_GPU` set) a missing adapter fails the tests; elsewhere
//! they say clearly that they were skipped.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod common;

use common::gpu;
use glam::{Vec2, Vec3};
use kapaint::gpu::preview::COMPARED_MODELS;
use kapaint::gpu::{Gpu, Layout, MapTextures, MeshBuffers, Offscreen, Preview, RenderedImage};
use kapaint::mesh::{self, pick::Bvh};
use kapaint::model::texel::{MaterialValue, linear_to_srgb, linear_to_srgb8};
use kapaint::model::{Document, DocumentSettings, FillRegion, MaterialMaps, StrokeTool};
use kapaint::model::{HistoryCommand, PaintCommand, SettingsCommand, StrokeCommand};
use kapaint::reflectance::{self, AmbientApprox, ShadingModel};
use kapaint::render::reference::{self, Material};
use kapaint::render::{Camera, FrameSettings, Lighting, ViewMode};

fn settings(model: ShadingModel, view: ViewMode, points: &[Vec3]) -> FrameSettings {
    FrameSettings {
        model,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting::default(),
        camera: Camera {
            yaw: 0.5,
            pitch: 0.35,
            ..Camera::default()
        }
        .framing(points),
    }
}

#[test]
fn shader_chi_equals_the_rust_fast_chi() {
    let Some(gpu) = gpu() else { return };
    let mut n: Vec<f32> = (0..=2000)
        .map(|i| (16385.0_f32.ln() * i as f32 / 2000.0).exp() - 1.0)
        .collect();
    n.extend([0.0, 1e-6, 0.5, 1.0, 32766.0, 32768.0, 1e5, 1e9, f32::MAX]);
    for model in ShadingModel::ALL {
        let got =
            kapaint::gpu::check::chi_on_gpu(&gpu, model, AmbientApprox::Fast, &n).expect("compute");
        for (&n, &g) in n.iter().zip(&got) {
            let want = reflectance::chi_f32(model, AmbientApprox::Fast, n);
            let rel = ((g - want) / want).abs();
            assert!(
                rel <= 1e-6 || (g - want).abs() < 1e-30,
                "{model:?} n = {n}: gpu {g} vs rust {want} ({rel:e})"
            );
        }
        for approx in [AmbientApprox::PaperPrinted, AmbientApprox::PaperCorrected] {
            let got = kapaint::gpu::check::chi_on_gpu(&gpu, model, approx, &n).expect("compute");
            for (&n, &g) in n.iter().zip(&got).filter(|(n, _)| **n <= 16384.0) {
                let want = reflectance::chi_f32(model, approx, n);
                assert!(
                    ((g - want) / want).abs() <= 1e-5,
                    "{model:?} {approx:?} n = {n}"
                );
            }
        }
    }
}

fn linear(image: RenderedImage) -> (u32, u32, Vec<f32>) {
    match image {
        RenderedImage::Linear {
            width,
            height,
            pixels,
        } => (width, height, pixels),
        RenderedImage::Srgb8 { .. } => panic!("expected a linear image"),
    }
}

#[test]
fn ka_view_of_a_uniform_sphere_equals_the_cpu_ka() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(64, 32);
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let preview = Preview::new(&gpu);
    for (value, model) in [
        (
            MaterialValue::new(Vec3::new(0.8, 0.3, 0.1), Vec3::splat(0.5), 40.0),
            ShadingModel::Phong,
        ),
        (
            MaterialValue::new(Vec3::new(0.1, 0.2, 0.9), Vec3::new(0.9, 0.6, 0.2), 2000.0),
            ShadingModel::BlinnPhong,
        ),
        (
            MaterialValue::new(Vec3::splat(0.5), Vec3::ZERO, 0.0),
            ShadingModel::Phong,
        ),
        (
            MaterialValue::new(Vec3::new(0.7, 0.2, 0.05), Vec3::new(0.04, 0.5, 0.95), 300.0),
            ShadingModel::CookTorrance,
        ),
        (
            MaterialValue::new(Vec3::splat(0.2), Vec3::ZERO, 0.0),
            ShadingModel::CookTorrance,
        ),
    ] {
        let maps = MaterialMaps::new(32, 32, value).expect("maps");
        let textures = MapTextures::new(&gpu, &maps).expect("map textures");
        let s = settings(model, ViewMode::Ka, &sphere.positions);
        let (_, _, pixels) = linear(
            preview
                .render_offscreen(
                    &gpu,
                    &buffers,
                    &textures,
                    &s,
                    Offscreen {
                        size: (96, 96),
                        linear: true,
                        layout: Layout::Single,
                        models: COMPARED_MODELS,
                    },
                )
                .expect("render"),
        );
        let stored = maps.value(0, 0);
        // The false-colour view of n agrees with the CPU scale too.
        let false_colour = FrameSettings {
            view: ViewMode::NFalseColour,
            ..s
        };
        let (_, _, colours) = linear(
            preview
                .render_offscreen(
                    &gpu,
                    &buffers,
                    &textures,
                    &false_colour,
                    Offscreen {
                        size: (16, 16),
                        linear: true,
                        layout: Layout::Single,
                        models: COMPARED_MODELS,
                    },
                )
                .expect("render"),
        );
        let ramp = kapaint::render::n_false_colour(stored.n);
        for p in colours.chunks_exact(4).filter(|p| p[3] > 0.0) {
            assert!(
                (Vec3::new(p[0], p[1], p[2]) - ramp).length() < 1e-4,
                "{p:?} vs {ramp}"
            );
        }
        let want = reflectance::ka(model, AmbientApprox::Fast, stored.kd, stored.ks, stored.n);
        let mut covered = 0;
        for p in pixels.chunks_exact(4).filter(|p| p[3] > 0.0) {
            covered += 1;
            for c in 0..3 {
                let err = (p[c] - want[c]).abs() / want[c].max(1e-6);
                assert!(err <= 1e-5, "{model:?}: {p:?} vs {want}");
            }
        }
        assert!(
            covered > 96 * 96 / 4,
            "the sphere fills the frame: {covered}"
        );
        if model == ShadingModel::CookTorrance {
            // Against the exact integral: (2/pi) k_d + k_s chi_1(n) + chi_0(n), to 2e-4.
            let [chi1, chi0] = reflectance::cook_torrance::chi_exact(f64::from(stored.n));
            let exact = reflectance::TWO_OVER_PI * stored.kd.as_dvec3()
                + stored.ks.as_dvec3() * chi1
                + glam::DVec3::splat(chi0);
            for p in pixels.chunks_exact(4).filter(|p| p[3] > 0.0) {
                for c in 0..3 {
                    let err = (f64::from(p[c]) - exact[c]).abs() / exact[c];
                    assert!(err <= 2e-4, "{p:?} vs exact {exact}: {err:e}");
                }
            }
        }
    }
}

/// A painted 256^2 document: a base, a fill of one colour, strokes of others.
fn painted_maps() -> MaterialMaps {
    let mut doc = Document::new(256, 256, DocumentSettings::default()).expect("doc");
    for (i, (kd, ks, n)) in [
        (Vec3::new(0.7, 0.2, 0.1), 0.3, 30.0),
        (Vec3::new(0.1, 0.6, 0.3), 0.6, 300.0),
        (Vec3::new(0.2, 0.2, 0.8), 0.1, 5.0),
    ]
    .into_iter()
    .enumerate()
    {
        doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
            kd,
            Vec3::splat(ks),
            n,
        )))
        .expect("primary");
        if i == 0 {
            doc.apply(PaintCommand::Fill(FillRegion::All))
                .expect("fill");
            continue;
        }
        let y = 60.0 + 80.0 * i as f32;
        brush_stroke(&mut doc, &[Vec2::new(10.0, y), Vec2::new(246.0, y + 20.0)]);
    }
    doc.into_parts().0
}

#[test]
fn shaded_renders_match_the_cpu_reference_renderer() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(64, 32);
    let bvh = Bvh::build(&sphere);
    let maps = painted_maps();
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let textures = MapTextures::new(&gpu, &maps).expect("map textures");
    let preview = Preview::new(&gpu);
    let (w, h) = (192, 192);
    for model in ShadingModel::ALL {
        let s = settings(model, ViewMode::Shaded, &sphere.positions);
        // The reference samples level 0 bilinearly; the GPU picks mip levels where the maps
        // are minified, i.e. towards the silhouette. Compare where the surface faces the
        // camera (N.V > 0.5): there the maps are magnified and both sample level 0.
        let facing: Vec<bool> = (0..w * h)
            .map(|i| {
                let (origin, dir) = s.camera.ray((i % w) as f32, (i / w) as f32, w, h);
                bvh.pick(&sphere, origin, dir)
                    .is_some_and(|hit| hit.normal.dot(-dir) > 0.5)
            })
            .collect();
        let RenderedImage::Srgb8 { pixels: gpu_px, .. } = preview
            .render_offscreen(
                &gpu,
                &buffers,
                &textures,
                &s,
                Offscreen {
                    size: (w, h),
                    linear: false,
                    layout: Layout::Single,
                    models: COMPARED_MODELS,
                },
            )
            .expect("render")
        else {
            panic!("shaded renders are sRGB bytes");
        };
        let cpu = reference::render(&sphere, &bvh, &Material::Maps(&maps), &s, w, h);
        let covered = |x: i32, y: i32| {
            (0..w as i32).contains(&x)
                && (0..h as i32).contains(&y)
                && cpu[(y as u32 * w + x as u32) as usize].w > 0.0
                && gpu_px[((y as u32 * w + x as u32) * 4 + 3) as usize] == 255
        };
        let (mut sum, mut count, mut worst) = (0.0_f64, 0_u32, 0_i32);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                // Interior pixels: edges differ by coverage, not by shading.
                if ![(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]
                    .iter()
                    .all(|(dx, dy)| covered(x + dx, y + dy))
                {
                    continue;
                }
                let i = (y as u32 * w + x as u32) as usize;
                if !facing[i] {
                    continue;
                }
                for c in 0..3 {
                    let want = (linear_to_srgb(cpu[i][c]) * 255.0).round() as i32;
                    let d = (i32::from(gpu_px[i * 4 + c]) - want).abs();
                    sum += f64::from(d);
                    worst = worst.max(d);
                }
                count += 1;
            }
        }
        assert!(count > w * h / 5, "{count} compared pixels");
        let mean = sum / f64::from(count * 3);
        eprintln!("{model:?}: mean {mean:.3}/255, max {worst}/255 over {count} pixels");
        assert!(mean <= 1.0, "{model:?}: mean difference {mean}/255");
        assert!(worst <= 4, "{model:?}: max difference {worst}/255");
    }
}

#[test]
fn sync_uploads_only_dirty_tiles_and_the_render_follows() {
    let Some(gpu) = gpu() else { return };
    let mut doc = Document::new(512, 512, DocumentSettings::default()).expect("doc");
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    assert_eq!(
        textures.sync(&gpu, doc.maps()).expect("sync"),
        0,
        "nothing changed"
    );
    // Unpainted, every channel is one texel: no texture memory for a uniform map.
    assert_eq!(
        textures.kd.size().width,
        1,
        "an unpainted channel is one texel"
    );
    brush_stroke(&mut doc, &[Vec2::new(100.0, 100.0)]);
    // The first stroke gives the channels it paints their full textures, uploaded whole.
    let uploaded = textures.sync(&gpu, doc.maps()).expect("sync");
    assert_eq!(uploaded, doc.maps().tile_count());
    assert_eq!(textures.kd.size().width, 512);
    assert!(textures.uniform.kd.is_none(), "k_d is no longer uniform");
    // A 32 px dab at (300, 300) touches the 4 tiles around it at most.
    brush_stroke(&mut doc, &[Vec2::new(300.0, 300.0)]);
    let uploaded = textures.sync(&gpu, doc.maps()).expect("sync");
    assert!((1..=4).contains(&uploaded), "{uploaded} tiles");
}

#[test]
fn split_and_side_by_side_compare_phong_left_and_blinn_right() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(64, 32);
    let maps = MaterialMaps::new(
        16,
        16,
        MaterialValue::new(Vec3::splat(0.4), Vec3::splat(0.6), 20.0),
    )
    .expect("maps");
    let (buffers, textures) = (
        MeshBuffers::new(&gpu, &sphere).expect("mesh buffers"),
        MapTextures::new(&gpu, &maps).expect("map textures"),
    );
    let preview = Preview::new(&gpu);
    let (w, h) = (96_u32, 64_u32);
    let render = |model, size: (u32, u32), layout| {
        let s = settings(model, ViewMode::Shaded, &sphere.positions);
        linear(
            preview
                .render_offscreen(
                    &gpu,
                    &buffers,
                    &textures,
                    &s,
                    Offscreen {
                        size,
                        linear: true,
                        layout,
                        models: COMPARED_MODELS,
                    },
                )
                .expect("render"),
        )
        .2
    };
    let (phong, blinn, split) = (
        render(ShadingModel::Phong, (w, h), Layout::Single),
        render(ShadingModel::BlinnPhong, (w, h), Layout::Single),
        render(ShadingModel::Phong, (w, h), Layout::Split(w / 2)),
    );
    assert_ne!(phong, blinn);
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            let want = if x < w / 2 { &phong } else { &blinn };
            assert_eq!(&split[i..i + 4], &want[i..i + 4], "pixel ({x}, {y})");
        }
    }
    // Side by side: each half is the whole picture of its model at half the width, seen by
    // the same camera (an odd width leaves the middle column empty).
    let w = 97;
    let half = w / 2;
    let side = render(ShadingModel::BlinnPhong, (w, h), Layout::SideBySide);
    let (left, right) = (
        render(ShadingModel::Phong, (half, h), Layout::Single),
        render(ShadingModel::BlinnPhong, (half, h), Layout::Single),
    );
    assert_ne!(left, right);
    for y in 0..h {
        for x in 0..w {
            let got = &side[((y * w + x) * 4) as usize..][..4];
            let want = match x.cmp(&half) {
                std::cmp::Ordering::Less => &left[((y * half + x) * 4) as usize..][..4],
                std::cmp::Ordering::Greater => {
                    &right[((y * half + x - half - 1) * 4) as usize..][..4]
                }
                std::cmp::Ordering::Equal => &[0.0; 4][..],
            };
            // The viewport's offset moves rasterisation by whole pixels: the same pictures,
            // up to float rounding in the interpolants.
            let close = got.iter().zip(want).all(|(a, b)| (a - b).abs() <= 1e-5);
            assert!(close, "pixel ({x}, {y}): {got:?} vs {want:?}");
        }
    }
    // All three: thirds of equal width, the spare pixels between them.
    let third = w / 3;
    let three = render(ShadingModel::Phong, (w, h), Layout::ThreeWay);
    let singles = ShadingModel::ALL.map(|m| render(m, (third, h), Layout::Single));
    assert_ne!(singles[1], singles[2]);
    for (i, single) in singles.iter().enumerate() {
        let x0 = (w - third) * i as u32 / 2;
        for y in 0..h {
            for x in 0..third {
                let got = &three[((y * w + x0 + x) * 4) as usize..][..4];
                let want = &single[((y * third + x) * 4) as usize..][..4];
                let close = got.iter().zip(want).all(|(a, b)| (a - b).abs() <= 1e-5);
                assert!(close, "picture {i} pixel ({x}, {y}): {got:?} vs {want:?}");
            }
        }
    }
}

#[test]
fn extreme_maps_shade_to_finite_colours() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(32, 16);
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let preview = Preview::new(&gpu);
    for value in [
        MaterialValue::new(Vec3::ONE, Vec3::ONE, 0.0),
        MaterialValue::new(Vec3::ONE, Vec3::ONE, 16384.0),
        MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 1e-3),
    ] {
        let maps = MaterialMaps::new(8, 8, value).expect("maps");
        let textures = MapTextures::new(&gpu, &maps).expect("map textures");
        for view in ViewMode::ALL {
            for approx in [
                AmbientApprox::Fast,
                AmbientApprox::PaperPrinted,
                AmbientApprox::PaperCorrected,
            ] {
                let s = FrameSettings {
                    approx,
                    ..settings(ShadingModel::BlinnPhong, view, &sphere.positions)
                };
                let (_, _, px) = linear(
                    preview
                        .render_offscreen(
                            &gpu,
                            &buffers,
                            &textures,
                            &s,
                            Offscreen {
                                size: (32, 32),
                                linear: true,
                                layout: Layout::Single,
                                models: COMPARED_MODELS,
                            },
                        )
                        .expect("render"),
                );
                assert!(px.iter().all(|v| v.is_finite()), "{value:?} {view:?}");
            }
        }
    }
}

#[test]
fn render_cli_writes_numerically_checkable_data_views() {
    let Some(_gpu) = gpu() else { return };
    let dir = std::env::temp_dir().join(format!("kapaint-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .output()
            .expect("runs")
    };
    let exr = dir.join("ka.exr");
    let material = ["--kd", "0.6,0.3,0.2", "--ks", "0.4", "--n", "80"];
    let mut args = vec![
        "render", "--model", "blinn", "--view", "ka", "--size", "48x32",
    ];
    args.extend(material);
    args.extend(["--out", exr.to_str().expect("path")]);
    let o = run(&args);
    assert!(o.status.success(), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("wrote "));
    let image = image::open(&exr).expect("EXR decodes").to_rgba32f();
    assert_eq!(image.dimensions(), (48, 32));
    let want = reflectance::ka(
        ShadingModel::BlinnPhong,
        AmbientApprox::Fast,
        MaterialValue::new(Vec3::new(0.6, 0.3, 0.2), Vec3::splat(0.4), 80.0).kd,
        Vec3::splat(0.4),
        80.0,
    );
    let covered: Vec<_> = image.pixels().filter(|p| p[3] > 0.0).collect();
    assert!(!covered.is_empty());
    for p in covered {
        for c in 0..3 {
            assert!((p[c] - want[c]).abs() <= 1e-4 * want[c], "{p:?} vs {want}");
        }
    }
    // A 16-bit PNG of k_d, and a shaded sRGB PNG of the split compare.
    let png = dir.join("kd.png");
    let mut args = vec!["render", "--model", "phong", "--view", "kd", "--size", "40"];
    args.extend(material);
    args.extend(["--out", png.to_str().expect("path")]);
    assert!(run(&args).status.success());
    let kd = image::open(&png).expect("PNG decodes").to_rgba16();
    let p = kd.pixels().find(|p| p[3] > 0).expect("covered");
    assert!((f32::from(p[0]) / 65535.0 - 0.6).abs() < 1e-4, "{p:?}");
    let split = dir.join("split.png");
    let mut args = vec!["render", "--model", "compare-split", "--view", "shaded"];
    args.extend(material);
    args.extend(["--out", split.to_str().expect("path")]);
    assert!(run(&args).status.success());
    // Side by side: each half holds a whole sphere, Phong left and Blinn-Phong right.
    let side = dir.join("side.png");
    let mut args = vec![
        "render",
        "--model",
        "compare-side",
        "--view",
        "shaded",
        "--size",
        "96x48",
    ];
    args.extend(material);
    args.extend(["--out", side.to_str().expect("path")]);
    let o = run(&args);
    assert!(o.status.success(), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("side by side"));
    let side = image::open(&side).expect("PNG decodes").to_rgba8();
    let covered = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (0..48).map(move |y| (x, y)))
            .filter(|&(x, y)| side.get_pixel(x, y)[3] > 0)
            .count()
    };
    let (left, right) = (covered(0, 48), covered(48, 96));
    assert!(
        left > 300 && right > 300,
        "a sphere in each half: {left}, {right}"
    );
    assert!(
        left.abs_diff(right) * 20 < left,
        "the same sphere: {left} vs {right}"
    );
    assert_eq!(side.get_pixel(47, 24)[3], 0, "nothing crosses the middle");
    // Errors: one line, exit 2, nothing written.
    let bad = dir.join("x.jpg");
    let mut args = vec!["render", "--model", "phong", "--view", "ka"];
    args.extend(["--out", bad.to_str().expect("path")]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(!bad.exists());
    let o = run(&[
        "render", "--model", "phong", "--view", "ka", "--light", "0,0,0", "--out", "y.png",
    ]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint render` of one uniform test material with `args`, written to `out`.
fn render_material(args: &[&str], out: &std::path::Path) -> std::process::Output {
    let mut all = vec!["render", "--kd", "0.6,0.3,0.2", "--ks", "0.4", "--n", "80"];
    all.extend(args);
    all.extend(["--out", out.to_str().expect("path")]);
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(&all)
        .output()
        .expect("runs")
}

/// `kapaint render --model cook-torrance`: its k_a view, a difference against Phong chosen by
/// `--sides`, and all three models side by side.
#[test]
fn render_cli_draws_cook_torrance_and_all_three_models() {
    let Some(_gpu) = gpu() else { return };
    let dir = std::env::temp_dir().join(format!("kapaint-render-ct-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let ct = dir.join("ct.exr");
    let o = render_material(
        &["--model", "cook-torrance", "--view", "ka", "--size", "32"],
        &ct,
    );
    assert!(o.status.success(), "{o:?}");
    let value = MaterialValue::new(Vec3::new(0.6, 0.3, 0.2), Vec3::splat(0.4), 80.0);
    let want = reflectance::ka(
        ShadingModel::CookTorrance,
        AmbientApprox::Fast,
        value.kd,
        value.ks,
        value.n,
    );
    let image = image::open(&ct).expect("EXR decodes").to_rgba32f();
    let p = image.pixels().find(|p| p[3] > 0.0).expect("covered");
    assert!((p[0] - want[0]).abs() <= 1e-4 * want[0], "{p:?} vs {want}");
    let o = render_material(
        &[
            "--model",
            "compare-diff",
            "--sides",
            "phong,cook-torrance",
            "--view",
            "shaded",
            "--size",
            "32",
        ],
        &dir.join("diff.png"),
    );
    let says =
        |o: &std::process::Output, what: &str| String::from_utf8_lossy(&o.stdout).contains(what);
    assert!(says(&o, "|phong - cook-torrance|"), "{o:?}");
    let three = dir.join("three.png");
    let o = render_material(
        &[
            "--model",
            "compare-three",
            "--view",
            "shaded",
            "--size",
            "96x32",
        ],
        &three,
    );
    assert!(
        says(&o, "phong, blinn, cook-torrance side by side"),
        "{o:?}"
    );
    let three = image::open(&three).expect("PNG decodes").to_rgba8();
    for x0 in [0, 32, 64] {
        let covered = (x0..x0 + 32)
            .flat_map(|x| (0..32).map(move |y| (x, y)))
            .filter(|&(x, y)| three.get_pixel(x, y)[3] > 0)
            .count();
        assert!(covered > 200, "a sphere in the third at {x0}: {covered}");
    }
    let o = render_material(
        &[
            "--model",
            "compare-side",
            "--sides",
            "phong,cook",
            "--view",
            "ka",
        ],
        &dir.join("z.png"),
    );
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn mips_follow_the_dirty_tiles() {
    let Some(gpu) = gpu() else { return };
    let mut doc = Document::new(512, 512, DocumentSettings::default()).expect("doc");
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    brush_stroke(&mut doc, &[Vec2::new(90.0, 100.0), Vec2::new(300.0, 140.0)]);
    assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 0);
    // Level 2 holds the 4 x 4 box means; the 1 x 1 level the mean of the whole map.
    assert_box_means(&gpu, &textures, doc.maps(), 2);
    assert_box_means(&gpu, &textures, doc.maps(), 9);
}

#[test]
fn every_mip_level_is_the_box_mean_on_maps_of_any_size() {
    let Some(gpu) = gpu() else { return };
    // Not a multiple of the tile size: edge tiles are partial, levels round down.
    let (w, h) = (200_usize, 120_usize);
    let mut doc = Document::new(w as u32, h as u32, DocumentSettings::default()).expect("doc");
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.2, 0.1),
        Vec3::splat(0.7),
        900.0,
    )))
    .expect("primary");
    brush_stroke(&mut doc, &[Vec2::new(20.0, 30.0), Vec2::new(190.0, 110.0)]);
    assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 0);
    for level in 1..textures.kd.mip_level_count() {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
}

#[test]
fn without_16_bit_norm_textures_the_maps_upload_as_half_floats() {
    let Some(mut gpu) = gpu() else { return };
    // As on an adapter without 16-bit normalised textures.
    gpu.unorm16 = false;
    let (w, h) = (200_u32, 120_u32);
    let mut doc = Document::new(w, h, DocumentSettings::default()).expect("doc");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.2, 0.001),
        Vec3::splat(0.7),
        900.0,
    )))
    .expect("primary");
    brush_stroke(&mut doc, &[Vec2::new(20.0, 30.0), Vec2::new(190.0, 110.0)]);
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    assert_eq!(textures.kd.format(), wgpu::TextureFormat::Rgba16Float);
    for level in 0..textures.kd.mip_level_count() {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
    // A later stroke updates its tiles and the levels over them.
    brush_stroke(&mut doc, &[Vec2::new(150.0, 10.0), Vec2::new(10.0, 100.0)]);
    assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 0);
    for level in 0..textures.kd.mip_level_count() {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
}

/// Paints one brush stroke through `points` at full pressure.
fn brush_stroke(doc: &mut Document, points: &[Vec2]) {
    let points = points
        .iter()
        .map(|&pos| kapaint::model::brush::StrokePoint { pos, pressure: 1.0 })
        .collect();
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points,
    })
    .expect("stroke");
}

/// Mip `level` of the `k_d` and `n` textures holds the box means of `maps` (2/65535 for
/// `k_d` in unorm16, or to half-float precision; 1e-3 relative for `n`); level 0 holds `k_d`,
/// `k_s` and `n` exactly (as the texture's format stores them).
fn assert_box_means(gpu: &Gpu, textures: &MapTextures, maps: &MaterialMaps, level: u32) {
    use kapaint::gpu::maps::MapChannel;
    let (w, h) = (maps.width() as usize, maps.height() as usize);
    let texel = |x: usize, y: usize| maps.texel(x as u32, y as u32);
    let span = 1_usize << level;
    let (lw, lh) = ((w >> level).max(1), (h >> level).max(1));
    let kd = textures
        .read_level(gpu, MapChannel::Kd, level)
        .expect("read");
    let n = textures
        .read_level(gpu, MapChannel::N, level)
        .expect("read");
    assert_eq!((kd.len(), n.len()), (lw * lh * 4, lw * lh), "level {level}");
    // The texture's code for a unorm16 code, and back to unorm16 steps.
    let stored = |c: u16| {
        if gpu.unorm16 {
            c
        } else {
            half::f16::from_f32(kapaint::model::texel::decode_unorm(c)).to_bits()
        }
    };
    let steps = |c: u16| {
        if gpu.unorm16 {
            f64::from(c)
        } else {
            f64::from(half::f16::from_bits(c).to_f32()) * 65535.0
        }
    };
    if level == 0 {
        let ks = textures.read_level(gpu, MapChannel::Ks, 0).expect("read");
        for y in 0..h {
            for x in 0..w {
                let t = texel(x, y);
                let i = y * w + x;
                assert_eq!(kd[i * 4..i * 4 + 3], t.kd.map(stored), "k_d at ({x}, {y})");
                assert_eq!(ks[i * 4..i * 4 + 3], t.ks.map(stored), "k_s at ({x}, {y})");
                assert_eq!(n[i], t.n, "n at ({x}, {y})");
            }
        }
        return;
    }
    for y in 0..lh {
        for x in 0..lw {
            let block: Vec<_> = (y * span..((y + 1) * span).min(h))
                .flat_map(|v| (x * span..((x + 1) * span).min(w)).map(move |u| (u, v)))
                .map(|(u, v)| texel(u, v))
                .collect();
            let count = block.len() as f64;
            for c in 0..3 {
                let mean = block.iter().map(|t| f64::from(t.kd[c])).sum::<f64>() / count;
                let got = steps(kd[(y * lw + x) * 4 + c]);
                // Half floats keep 11 significant bits.
                let tolerance = if gpu.unorm16 {
                    2.0
                } else {
                    2.0 + mean / 1024.0
                };
                assert!(
                    (got - mean).abs() <= tolerance,
                    "level {level} ({x}, {y}): {got} vs {mean}"
                );
            }
            let mean = block
                .iter()
                .map(|t| f64::from(kapaint::model::texel::decode_n(t.n)))
                .sum::<f64>()
                / count;
            let got = f64::from(half::f16::from_bits(n[y * lw + x]).to_f32());
            assert!(
                (got - mean).abs() <= 1e-3 * mean.max(1.0),
                "level {level} ({x}, {y}): n {got} vs {mean}"
            );
        }
    }
}

#[test]
fn large_uploads_in_several_batches_and_scattered_tiles_mirror_the_maps() {
    let Some(gpu) = gpu() else { return };
    // 2048 x 1536 with mips stages about 75 MB: the first upload takes two batches.
    let mut doc = Document::new(2048, 1536, DocumentSettings::default()).expect("doc");
    let stroke = |doc: &mut Document, value: MaterialValue, from: Vec2, to: Vec2| {
        doc.apply(SettingsCommand::SetPrimary(value))
            .expect("primary");
        brush_stroke(doc, &[from, to]);
    };
    let red = MaterialValue::new(Vec3::new(0.9, 0.2, 0.1), Vec3::splat(0.3), 40.0);
    stroke(
        &mut doc,
        red,
        Vec2::new(10.0, 10.0),
        Vec2::new(2040.0, 1500.0),
    );
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    for level in [0, 3, 9] {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
    // A stroke the other way: its tiles make many small rectangles, not one.
    let blue = MaterialValue::new(Vec3::new(0.1, 0.3, 0.8), Vec3::splat(0.05), 2000.0);
    stroke(
        &mut doc,
        blue,
        Vec2::new(2000.0, 30.0),
        Vec2::new(30.0, 1400.0),
    );
    assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 50);
    for level in [0, 1, 6, 7, 10] {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
}

#[test]
fn a_stroke_on_some_channels_stages_only_those() {
    use kapaint::model::Channels;
    let Some(gpu) = gpu() else { return };
    let mut doc = Document::new(512, 384, DocumentSettings::default()).expect("doc");
    let mut textures = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    let mut dab = |doc: &mut Document, channels: Channels, value: MaterialValue| {
        doc.apply(SettingsCommand::SetChannels(channels))
            .expect("channels");
        doc.apply(SettingsCommand::SetPrimary(value))
            .expect("primary");
        brush_stroke(doc, &[Vec2::new(200.0, 150.0)]);
        assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 0);
        for level in [0, 1, 3, 7] {
            assert_box_means(&gpu, &textures, doc.maps(), level);
        }
        textures.staged_bytes()
    };
    let value = |k: f32| {
        MaterialValue::new(
            Vec3::new(k, 0.5, 1.0 - k),
            Vec3::splat(k * 0.5),
            10.0 + 900.0 * k,
        )
    };
    let all = dab(&mut doc, Channels::ALL, value(0.2));
    let kd = dab(
        &mut doc,
        Channels {
            kd: true,
            ks: false,
            n: false,
        },
        value(0.9),
    );
    let n = dab(
        &mut doc,
        Channels {
            kd: false,
            ks: false,
            n: true,
        },
        value(0.5),
    );
    // k_d is 8 of the 18 bytes a texel, n 2 of them (and the same for the levels above).
    assert!(kd * 10 < all * 5, "k_d only staged {kd} of {all} bytes");
    assert!(n * 10 < all * 2, "n only staged {n} of {all} bytes");
    // Undo recomposites: the composite's changed planes (only n here) are staged again,
    // and the mirror stays exact.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(textures.sync(&gpu, doc.maps()).expect("sync") > 0);
    assert_eq!(textures.staged_bytes(), n);
    for level in [0, 2, 8] {
        assert_box_means(&gpu, &textures, doc.maps(), level);
    }
}

/// A 64 x 8 project whose `n` runs from 1 to 5000, exported as a `compact` set into `dir` so
/// that the set stores `n` on a curve in 8 bits.
fn n_gradient_set(dir: &std::path::Path) -> (Document, kapaint::export::set::Manifest) {
    use kapaint::export::{preset, set};
    let _ = std::fs::remove_dir_all(dir);
    let mut doc = Document::new(64, 8, DocumentSettings::default()).expect("doc");
    doc.apply(SettingsCommand::SetChannels(kapaint::model::Channels {
        kd: false,
        ks: false,
        n: true,
    }))
    .expect("channels");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::ONE,
        Vec3::ONE,
        1.0,
    )))
    .expect("primary");
    doc.apply(SettingsCommand::SetSecondary(MaterialValue::new(
        Vec3::ONE,
        Vec3::ONE,
        5000.0,
    )))
    .expect("secondary");
    doc.apply(PaintCommand::Gradient {
        shape: kapaint::model::paint::GradientShape::Linear,
        start: Vec2::new(0.0, 0.0),
        end: Vec2::new(64.0, 0.0),
    })
    .expect("gradient");
    let m = set::export(&doc, &preset::find("compact").expect("preset"), dir).expect("export");
    (doc, m)
}

/// Checks a kernel's `(n, k_a)` pairs for the 256 codes of `m`'s `n` against the CPU: the
/// decoded `n` within 2e-5 relative (absolute below 1), `k_a` with `k_d = 0.3`, `k_s = 0.5`
/// within 1e-5 relative.
fn check_decoded_pairs(got: &[f32], doc: &Document, m: &kapaint::export::set::Manifest) {
    let e = m.n_encoding.expect("n on a curve");
    assert_eq!(got.len(), 512);
    for (c, pair) in got.chunks_exact(2).enumerate() {
        let n = e.decode(c as u16);
        assert!(
            (pair[0] - n).abs() <= 2e-5 * n.max(1.0),
            "code {c}: {} vs {n}",
            pair[0]
        );
        let ka = reflectance::ka(
            doc.settings().model,
            doc.settings().approx,
            Vec3::splat(0.3),
            Vec3::splat(0.5),
            n,
        )
        .x;
        assert!(
            (pair[1] - ka).abs() <= 1e-5 * ka,
            "code {c}: k_a {} vs {ka}",
            pair[1]
        );
    }
}

#[test]
fn the_exported_wgsl_snippet_decodes_like_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let dir = std::env::temp_dir().join(format!("kapaint-snippet-{}", std::process::id()));
    let (doc, m) = n_gradient_set(&dir);
    let snippet = std::fs::read_to_string(dir.join("material.wgsl")).expect("snippet");
    let kernel = format!(
        "{snippet}\n@group(0) @binding(0) var<storage, read> codes: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> out: array<f32>;\n\
         @compute @workgroup_size(64)\nfn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         let i = id.x;\n    if i < arrayLength(&codes) {{\n\
         let n = kapaint_decode_n(codes[i] / 255.0);\n\
         out[2u * i] = n;\n\
         out[2u * i + 1u] = kapaint_ka(vec3<f32>(0.3), vec3<f32>(0.5), n).x;\n    }}\n}}\n"
    );
    let codes: Vec<f32> = (0..=255).map(|c| c as f32).collect();
    let got = kapaint::gpu::check::run_kernel(&gpu, &kernel, &[], &codes, 512).expect("kernel");
    check_decoded_pairs(&got, &doc, &m);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Compiles a GLSL 4.50 compute shader with naga's GLSL frontend and writes it back out as
/// WGSL (naga's WGSL backend), with its entry point renamed to the `cs_main` that
/// `run_kernel` calls: wgpu takes WGSL, so this is how the GLSL snippet runs here.
fn glsl_to_wgsl(source: &str) -> String {
    let mut module = naga::front::glsl::Frontend::default()
        .parse(&naga::ShaderStage::Compute.into(), source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    assert_eq!(module.entry_points.len(), 1);
    module.entry_points[0].name = "cs_main".into();
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{e:?}"));
    naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
        .expect("WGSL out")
}

/// The GLSL snippet, run: it decodes every code like the CPU, and its `ambient_ka` gives the
/// CPU's `k_a` for every model and approximation, NaN, infinities and negative inputs
/// included.
#[test]
fn the_exported_glsl_snippet_decodes_like_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let dir = std::env::temp_dir().join(format!("kapaint-glsl-snippet-{}", std::process::id()));
    let (doc, m) = n_gradient_set(&dir);
    let snippet = std::fs::read_to_string(dir.join("material.glsl")).expect("snippet");
    let buffers = "layout(local_size_x = 64) in;\n\
         layout(std430, binding = 0) readonly buffer Values { float values[]; };\n\
         layout(std430, binding = 1) buffer Results { float results[]; };\n";

    // The 256 codes of the set's n, as an engine would use the snippet.
    let kernel = glsl_to_wgsl(&format!(
        "#version 450\n{snippet}\n{buffers}\
         void main() {{\n    uint i = gl_GlobalInvocationID.x;\n\
         if (i < uint(values.length())) {{\n\
         float n = kapaint_decode_n(values[i] / 255.0);\n\
         results[2u * i] = n;\n\
         results[2u * i + 1u] = kapaint_ka(vec3(0.3), vec3(0.5), n).x;\n    }}\n}}\n"
    ));
    let codes: Vec<f32> = (0..=255).map(|c| c as f32).collect();
    let got = kapaint::gpu::check::run_kernel(&gpu, &kernel, &[], &codes, 512).expect("kernel");
    check_decoded_pairs(&got, &doc, &m);

    // Every model and approximation (slots 3 model + approx), Cook-Torrance's chi_0 alone
    // (slot 9: k_d = k_s = 0), and the sanitizing of k_d and k_s (slot 10), over awkward values
    // of n.
    let kernel = glsl_to_wgsl(&format!(
        "#version 450\n{snippet}\n{buffers}\
         void main() {{\n    uint i = gl_GlobalInvocationID.x;\n\
         if (i < uint(values.length())) {{\n\
         float v = values[i];\n\
         for (uint model = 0u; model < 3u; model++) {{\n\
         for (uint approx = 0u; approx < 3u; approx++) {{\n\
         results[11u * i + 3u * model + approx] = ambient_ka(model, approx, vec3(0.3), vec3(0.5), v).x;\n\
         }}\n}}\n\
         results[11u * i + 9u] = ambient_ka(MODEL_COOK_TORRANCE, APPROX_FAST, vec3(0.0), vec3(0.0), v).x;\n\
         results[11u * i + 10u] = kapaint_ka(vec3(v), vec3(1.0 - v), 10.0).x;\n    }}\n}}\n"
    ));
    let mut values = vec![
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -0.0,
        -1.0,
        0.0,
        1e-6,
        0.3,
        0.5,
        1.0,
        2.0,
        16384.0,
        32767.0,
        32768.0,
        1e5,
        1e9,
        f32::MAX,
    ];
    values.extend((0..=300).map(|i| (1e6_f32.ln() * i as f32 / 300.0).exp() - 1.0));
    let got = kapaint::gpu::check::run_kernel(&gpu, &kernel, &[], &values, 11 * values.len())
        .expect("kernel");
    let close = |got: f32, want: f32| (got - want).abs() <= 1e-5 * want.abs();
    for (&v, row) in values.iter().zip(got.chunks_exact(11)) {
        let chi0 =
            reflectance::chi_parts_f32(ShadingModel::CookTorrance, AmbientApprox::Fast, v)[1];
        assert!(close(row[9], chi0), "chi_0({v}): {} vs {chi0}", row[9]);
        for (m, model) in ShadingModel::ALL.into_iter().enumerate() {
            for (a, approx) in AmbientApprox::ALL.into_iter().enumerate() {
                let want = reflectance::ka(model, approx, Vec3::splat(0.3), Vec3::splat(0.5), v).x;
                let g = row[3 * m + a];
                assert!(
                    close(g, want),
                    "{model:?} {approx:?} n = {v}: {g} vs {want}"
                );
            }
        }
        let want = reflectance::ka(
            doc.settings().model,
            doc.settings().approx,
            Vec3::splat(v),
            Vec3::splat(1.0 - v),
            10.0,
        )
        .x;
        assert!(close(row[10], want), "k_d = {v}: {} vs {want}", row[10]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn difference_heatmap_on_the_gpu_matches_the_cpu_ramp() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(48, 24);
    let maps = MaterialMaps::new(
        16,
        16,
        MaterialValue::new(Vec3::new(0.5, 0.3, 0.2), Vec3::splat(0.5), 12.0),
    )
    .expect("maps");
    let (buffers, textures) = (
        MeshBuffers::new(&gpu, &sphere).expect("mesh buffers"),
        MapTextures::new(&gpu, &maps).expect("map textures"),
    );
    let preview = Preview::new(&gpu);
    let (w, h) = (80_u32, 60_u32);
    let render = |model| {
        let s = settings(model, ViewMode::Shaded, &sphere.positions);
        preview
            .render_offscreen(
                &gpu,
                &buffers,
                &textures,
                &s,
                Offscreen {
                    size: (w, h),
                    linear: true,
                    layout: Layout::Single,
                    models: COMPARED_MODELS,
                },
            )
            .expect("render")
    };
    let (phong, blinn) = (
        render(ShadingModel::Phong),
        render(ShadingModel::BlinnPhong),
    );
    let max = 0.05;
    let heat = kapaint::gpu::difference::Difference::new(&gpu)
        .heatmap(&gpu, &phong, &blinn, max)
        .expect("heatmap");
    let (RenderedImage::Srgb8 { pixels: got, .. }, (_, _, a), (_, _, b)) =
        (heat, linear(phong), linear(blinn))
    else {
        panic!("an sRGB heatmap");
    };
    let mut hot = 0;
    for (i, (p, q)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
        let d = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0_f32, f32::max);
        hot += usize::from(d > max / 3.0);
        let c = kapaint::render::heat_ramp(d / max);
        let byte = |v: f32| i32::from(linear_to_srgb8(v));
        let want = [
            byte(c.x),
            byte(c.y),
            byte(c.z),
            (p[3].max(q[3]) * 255.0 + 0.5) as i32,
        ];
        for k in 0..4 {
            let g = i32::from(got[i * 4 + k]);
            assert!(
                (g - want[k]).abs() <= 1,
                "pixel {i} component {k}: {g} vs {}",
                want[k]
            );
        }
    }
    assert!(hot > 0, "the two models differ somewhere on the sphere");
}

/// A device like a smaller GPU's: textures up to 1024 texels a side, buffers up to 8 MiB.
fn small_gpu() -> Option<Gpu> {
    gpu()?;
    let adapter = Gpu::adapter().expect("adapter");
    let limits = wgpu::Limits {
        max_texture_dimension_2d: 1024,
        max_buffer_size: 8 << 20,
        ..adapter.limits()
    };
    Some(Gpu::from_adapter_with_limits(&adapter, limits).expect("device"))
}

#[test]
fn what_does_not_fit_the_gpu_is_an_error_not_a_panic() {
    let Some(gpu) = small_gpu() else { return };
    let sphere = mesh::uv_sphere(32, 16);
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("a small mesh fits");
    // Maps beyond the largest texture.
    let big = MaterialMaps::new(2048, 2048, MaterialValue::default()).expect("maps");
    let err = MapTextures::new(&gpu, &big).expect_err("2048^2 does not fit");
    assert!(err.to_string().contains("does not fit this GPU"), "{err}");
    // A read-back beyond the largest buffer: 1024^2 linear RGBA floats are 16 MiB, caught by
    // the error scope around the render.
    let small = MaterialMaps::new(64, 64, MaterialValue::default()).expect("maps");
    let textures = MapTextures::new(&gpu, &small).expect("64^2 fits");
    let settings = settings(ShadingModel::Phong, ViewMode::Ka, &sphere.positions);
    let preview = Preview::new(&gpu);
    let offscreen = |size| Offscreen {
        size,
        linear: true,
        layout: Layout::Single,
        models: COMPARED_MODELS,
    };
    let rendered = preview.render_offscreen(
        &gpu,
        &buffers,
        &textures,
        &settings,
        offscreen((1024, 1024)),
    );
    let Err(err) = rendered else {
        panic!("a read-back larger than the largest buffer rendered");
    };
    assert!(
        err.to_string().starts_with("rendering the preview"),
        "{err}"
    );
    assert!(!err.to_string().contains('\n'), "one line: {err}");
    // The device still works after both.
    let image = preview
        .render_offscreen(&gpu, &buffers, &textures, &settings, offscreen((64, 64)))
        .expect("a small render");
    assert!(matches!(image, RenderedImage::Linear { .. }));
}

#[test]
fn a_lost_device_is_an_error_not_a_panic() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(32, 16);
    let maps = MaterialMaps::new(64, 64, MaterialValue::default()).expect("maps");
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh");
    let mut textures = MapTextures::new(&gpu, &maps).expect("maps");
    let preview = Preview::new(&gpu);
    gpu.device.destroy();
    gpu.wait();
    let settings = settings(ShadingModel::Phong, ViewMode::Shaded, &sphere.positions);
    let offscreen = Offscreen {
        size: (32, 32),
        linear: false,
        layout: Layout::Single,
        models: COMPARED_MODELS,
    };
    assert!(MapTextures::new(&gpu, &maps).is_err());
    assert!(MeshBuffers::new(&gpu, &sphere).is_err());
    assert!(
        preview
            .render_offscreen(&gpu, &buffers, &textures, &settings, offscreen)
            .is_err()
    );
    let mut doc = Document::new(64, 64, DocumentSettings::default()).expect("doc");
    doc.apply(PaintCommand::Fill(FillRegion::All))
        .expect("fill");
    assert!(textures.sync(&gpu, doc.maps()).is_err());
}

/// Steady frames make no GPU object: the preview's uniform buffer and bind group (and the
/// heatmap's) are reused while the maps' textures are the same, the uniforms rewritten in
/// place; a new mirror of the maps makes one new bind group and keeps the buffer. A frame
/// drawn through the reused bindings is the image a one-off render gives.
#[test]
fn steady_frames_reuse_their_buffers_and_bind_groups() {
    use kapaint::gpu::difference::{Difference, DifferenceBindings};
    use kapaint::gpu::preview::{
        DEPTH_FORMAT, DrawPart, FrameBindings, PipelineKey, PreviewDrawData, begin_pass,
    };
    use kapaint::gpu::readback::read_texture;
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(32, 16);
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let preview = Preview::new(&gpu);
    let maps = painted_maps();
    let textures = MapTextures::new(&gpu, &maps).expect("map textures");
    let size = (48, 40);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::TEXTURE_BINDING;
    let color = gpu.texture_2d("test", size, format, usage);
    let view = color.create_view(&wgpu::TextureViewDescriptor::default());
    let depth = gpu
        .texture_2d(
            "test",
            size,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&wgpu::TextureViewDescriptor::default());
    let mut bindings = FrameBindings::default();
    let frame = |textures: &MapTextures, yaw: f32, bindings: &mut FrameBindings| {
        let mut s = settings(ShadingModel::Phong, ViewMode::Shaded, &sphere.positions);
        s.camera.yaw = yaw;
        bindings.begin_frame();
        let parts = [DrawPart::whole(
            PipelineKey::for_frame(&s, &textures.uniform, format),
            size,
        )];
        let data = PreviewDrawData::new(&preview, &gpu, (&buffers, textures), &s, &parts, bindings);
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = begin_pass(&mut encoder, &view, &depth);
            preview.draw(&mut pass, &data);
        }
        (s, encoder)
    };
    for k in 0..5 {
        let (_, encoder) = frame(&textures, 0.1 * k as f32, &mut bindings);
        gpu.queue.submit([encoder.finish()]);
        assert_eq!(
            bindings.made(),
            6,
            "frame {k}: one buffer, four views, one group"
        );
    }
    // The last steady frame is what a one-off render of its settings gives.
    let (s, encoder) = frame(&textures, 0.9, &mut bindings);
    let drawn = read_texture(&gpu, encoder, &color, 4, 0).expect("read back");
    let RenderedImage::Srgb8 { pixels, .. } = preview
        .render_offscreen(
            &gpu,
            &buffers,
            &textures,
            &s,
            Offscreen {
                size,
                linear: false,
                layout: Layout::Single,
                models: COMPARED_MODELS,
            },
        )
        .expect("render")
    else {
        panic!("an sRGB image");
    };
    assert_eq!(
        drawn, pixels,
        "the reused uniforms hold this frame's camera"
    );
    assert_eq!(bindings.made(), 6);
    // A new mirror of the maps: a new bind group (four views), the buffer kept.
    let again = MapTextures::new(&gpu, &maps).expect("map textures");
    let _ = frame(&again, 0.3, &mut bindings);
    assert_eq!(bindings.made(), 11);

    // The heatmap: its buffer and group once, while the sides stay the same views.
    let difference = Difference::new(&gpu);
    let mut heat = DifferenceBindings::default();
    let side = || {
        gpu.texture_2d(
            "side",
            size,
            kapaint::gpu::difference::SIDE_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&wgpu::TextureViewDescriptor::default())
    };
    let (a, b) = (side(), side());
    for max in [0.1, 0.2, 0.3] {
        let _ = difference.draw_data(&gpu, [&a, &b], format, max, &mut heat);
        assert_eq!(heat.made(), 2);
    }
    let c = side();
    let _ = difference.draw_data(&gpu, [&a, &c], format, 0.1, &mut heat);
    assert_eq!(heat.made(), 3, "new sides: a new group, the buffer kept");
}
