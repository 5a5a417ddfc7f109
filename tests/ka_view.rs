//! The per-view ambient views (issue 42, item 2): `k_a per view` and the view-average error,
//! on the real renderer (Mesa's lavapipe in CI) against the exact per-view integral, the CPU
//! reference renderer, and through `kapaint render`.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod common;

use common::gpu;
use glam::Vec3;
use kapaint::gpu::preview::COMPARED_MODELS;
use kapaint::gpu::{Layout, MapTextures, MeshBuffers, Offscreen, Preview, RenderedImage};
use kapaint::mesh::{self, pick::Bvh};
use kapaint::model::MaterialMaps;
use kapaint::model::texel::{MaterialValue, Texel, linear_to_srgb};
use kapaint::reflectance::view::chi_view_exact;
use kapaint::reflectance::{self, AmbientApprox, ShadingModel};
use kapaint::render::reference::{self, Material};
use kapaint::render::{Camera, FrameSettings, Lighting, ViewMode};

fn run(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("runs")
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    dir
}

/// The target: the `k_a per view` data view (16-bit linear PNG) of a uniform sphere at
/// its centre pixel, seen head-on, is `(2/pi) k_d + k_s chi_view(n, 0)` (and Cook-Torrance's
/// `+ chi_view_0`) to 2e-4, against the exact integral.
#[test]
fn the_ka_view_of_a_uniform_sphere_at_its_centre_is_the_head_on_integral() {
    let Some(_gpu) = gpu() else { return };
    let dir = temp_dir("ka-view");
    let kd = Vec3::new(0.5, 0.4, 0.3);
    let ks = 0.6_f32;
    for (model, arg) in [
        (ShadingModel::Phong, "phong"),
        (ShadingModel::BlinnPhong, "blinn"),
        (ShadingModel::CookTorrance, "cook-torrance"),
    ] {
        // (Cook-Torrance's head-on k_a per view passes 1 above n = 100, where a PNG clamps.)
        let exponents: &[f32] = if model == ShadingModel::CookTorrance {
            &[10.0, 60.0]
        } else {
            &[10.0, 100.0, 2000.0]
        };
        for &n in exponents {
            let out = dir.join(format!("{arg}-{n}.png"));
            let n_text = n.to_string();
            // An odd size: the centre pixel's ray passes through the sphere's centre, so its
            // surface point faces the eye (the interpolated normal of a sphere's flat triangle
            // points from the centre through the point).
            let o = run(&[
                "render",
                "--model",
                arg,
                "--view",
                "ka-view",
                "--size",
                "65",
                "--kd",
                "0.5,0.4,0.3",
                "--ks",
                "0.6",
                "--n",
                &n_text,
                "--out",
                out.to_str().expect("path"),
            ]);
            assert!(o.status.success(), "{o:?}");
            let image = image::open(&out).expect("PNG decodes");
            assert_eq!(
                image.color(),
                image::ColorType::Rgba16,
                "a 16-bit data view"
            );
            let p = image.to_rgba16().get_pixel(32, 32).0;
            let [chi1, chi0] = chi_view_exact(model, f64::from(n), 0.0);
            for c in 0..3 {
                let want =
                    reflectance::TWO_OVER_PI * f64::from(kd[c]) + f64::from(ks) * chi1 + chi0;
                let got = f64::from(p[c]) / 65535.0;
                let err = (got / want - 1.0).abs();
                assert!(err <= 2e-4, "{model:?} n {n}: {got} vs {want} ({err:e})");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 128^2 map with a ramp of `n` across it and colours down it, so every pixel differs.
fn ramp_maps() -> MaterialMaps {
    let mut maps = MaterialMaps::new(128, 128, MaterialValue::default()).expect("maps");
    for y in 0..128 {
        for x in 0..128 {
            let t = x as f32 / 127.0;
            let s = y as f32 / 127.0;
            let value = MaterialValue::new(
                Vec3::new(0.1 + 0.6 * s, 0.3, 0.7 - 0.5 * s),
                Vec3::new(0.9 - 0.5 * s, 0.2 + 0.6 * t, 0.5),
                (t * 12.0).exp2() - 1.0,
            );
            let (tile, i) = maps.locate(x, y);
            maps.tile_mut(tile).set_texel(i, Texel::encode(value));
        }
    }
    maps
}

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

/// The GPU's per-view views (the table as a texture, the shader's spline) against the CPU
/// reference renderer (the same table in Rust), pixel by pixel where the surface faces the
/// camera and both sample the maps' first level.
#[test]
fn the_gpu_per_view_views_match_the_cpu_reference() {
    let Some(gpu) = gpu() else { return };
    let sphere = mesh::uv_sphere(64, 32);
    let bvh = Bvh::build(&sphere);
    let maps = ramp_maps();
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let textures = MapTextures::new(&gpu, &maps).expect("map textures");
    let preview = Preview::new(&gpu);
    let (w, h) = (128, 128);
    for model in ShadingModel::ALL {
        let data = settings(model, ViewMode::KaView, &sphere.positions);
        let facing: Vec<bool> = (0..w * h)
            .map(|i| {
                let (origin, dir) = data.camera.ray((i % w) as f32, (i / w) as f32, w, h);
                bvh.pick(&sphere, origin, dir)
                    .is_some_and(|hit| hit.normal.dot(-dir) > 0.5)
            })
            .collect();
        let render = |s: &FrameSettings, linear| {
            preview
                .render_offscreen(
                    &gpu,
                    &buffers,
                    &textures,
                    s,
                    Offscreen {
                        size: (w, h),
                        linear,
                        layout: Layout::Single,
                        models: COMPARED_MODELS,
                    },
                )
                .expect("render")
        };
        let RenderedImage::Linear { pixels: got, .. } = render(&data, true) else {
            panic!("a data view renders linear");
        };
        let cpu = reference::render(&sphere, &bvh, &Material::Maps(&maps), &data, w, h);
        let (mut worst, mut sum, mut count) = (0.0_f32, 0.0_f64, 0);
        for (i, want) in cpu.iter().enumerate() {
            if !facing[i] || got[i * 4 + 3] == 0.0 || want.w == 0.0 {
                continue;
            }
            for c in 0..3 {
                let e = (got[i * 4 + c] / want[c] - 1.0).abs();
                worst = worst.max(e);
                sum += f64::from(e);
            }
            count += 3;
        }
        let mean = sum / f64::from(count);
        eprintln!("{model:?} k_a per view: GPU vs CPU mean {mean:.2e}, worst {worst:.2e}");
        assert!(count > (w * h) as i32, "{count} compared values");
        assert!(
            mean < 2e-4 && worst < 5e-3,
            "{model:?}: {mean:e} / {worst:e}"
        );

        let heat = FrameSettings {
            view: ViewMode::KaViewError,
            ..data
        };
        let RenderedImage::Srgb8 { pixels: got, .. } = render(&heat, false) else {
            panic!("the error view is a picture");
        };
        let cpu = reference::render(&sphere, &bvh, &Material::Maps(&maps), &heat, w, h);
        let mut off = 0;
        let mut total = 0;
        for (i, want) in cpu.iter().enumerate() {
            if !facing[i] || want.w == 0.0 {
                continue;
            }
            total += 1;
            let d = (0..3)
                .map(|c| {
                    let want = (linear_to_srgb(want[c]) * 255.0).round() as i32;
                    (i32::from(got[i * 4 + c]) - want).abs()
                })
                .max()
                .unwrap_or(0);
            if d > 2 {
                off += 1;
            }
        }
        assert!(
            off * 200 < total,
            "{model:?}: {off} of {total} pixels differ"
        );
    }
}

/// `kapaint render --view ka-view-error` writes an sRGB picture with its scale along the
/// bottom and says so; the centre pixel of a uniform sphere seen head-on is the heat of
/// `|k_a - k_a per view| / k_a per view` there.
#[test]
fn the_render_cli_draws_the_view_average_error_with_its_scale() {
    let Some(_gpu) = gpu() else { return };
    let dir = temp_dir("ka-view-error");
    let out = dir.join("error.png");
    let o = run(&[
        "render",
        "--model",
        "phong",
        "--view",
        "ka-view-error",
        "--size",
        "65",
        "--kd",
        "0.2,0.2,0.2",
        "--ks",
        "0.8",
        "--n",
        "100",
        "--out",
        out.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(
        line.contains("view ka-view-error") && line.contains("0 (left) to 100 % (right)"),
        "{line}"
    );
    let image = image::open(&out).expect("PNG decodes").to_rgba8();
    let kd = Vec3::splat(0.2);
    let ks = Vec3::splat(0.8);
    let ka = reflectance::ka(ShadingModel::Phong, AmbientApprox::Fast, kd, ks, 100.0);
    let per_view = reflectance::view::ka_view(ShadingModel::Phong, kd, ks, 100.0, 0.0);
    let e = kapaint::render::relative_error(ka, per_view);
    // Head-on, chi_view is 4.6 times chi: k_a falls short by a quarter.
    assert!(e > 0.2, "{e}");
    let want = kapaint::render::heat_ramp(e / kapaint::render::VIEW_ERROR_TOP);
    let p = image.get_pixel(32, 32).0;
    for c in 0..3 {
        let want = (linear_to_srgb(want[c]) * 255.0).round() as i32;
        assert!((i32::from(p[c]) - want).abs() <= 2, "{p:?} vs {want}");
    }
    // The scale: black at the left end of the bottom row, white at the right.
    let (w, h) = image.dimensions();
    assert_eq!(image.get_pixel(0, h - 1).0, [0, 0, 0, 255]);
    assert_eq!(image.get_pixel(w - 1, h - 1).0, [255, 255, 255, 255]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint render --view ka-traced`: the traced `k_a` on the CPU (no GPU needed), a 16-bit
/// linear PNG whose centre pixel of a uniform sphere seen head-on converges to `k_a` per view
/// there (nothing on a sphere shadows itself); its error view with the scale; the report names
/// the samples, the standard error and the CPU.
#[test]
fn the_render_cli_traces_on_the_cpu() {
    let dir = temp_dir("ka-traced");
    let out = dir.join("traced.png");
    let o = run(&[
        "render",
        "--model",
        "phong",
        "--view",
        "ka-traced",
        "--samples",
        "512",
        "--size",
        "33",
        "--kd",
        "0.5,0.4,0.3",
        "--ks",
        "0.6",
        "--n",
        "100",
        "--out",
        out.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(
        line.contains("view ka-traced")
            && line.contains("512 samples per pixel")
            && line.contains("std. error")
            && line.contains("on the CPU"),
        "{line}"
    );
    let image = image::open(&out).expect("PNG decodes");
    assert_eq!(
        image.color(),
        image::ColorType::Rgba16,
        "a 16-bit data view"
    );
    let p = image.to_rgba16().get_pixel(16, 16).0;
    let [chi, _] = chi_view_exact(ShadingModel::Phong, 100.0, 0.0);
    for (c, kd) in [0.5, 0.4, 0.3].into_iter().enumerate() {
        let want = reflectance::TWO_OVER_PI * kd + 0.6 * chi;
        let got = f64::from(p[c]) / 65535.0;
        assert!((got / want - 1.0).abs() < 0.02, "{got} vs {want}");
    }
    let out = dir.join("traced-error.png");
    let o = run(&[
        "render",
        "--model",
        "blinn",
        "--view",
        "ka-traced-error",
        "--samples",
        "16",
        "--mesh",
        "torus",
        "--size",
        "48",
        "--out",
        out.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("0 (left) to 100 % (right)"));
    let image = image::open(&out).expect("PNG decodes");
    assert_eq!(image.color(), image::ColorType::Rgba8, "a picture");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad input: `--samples` 0 or above 1,048,576, `--samples` on an untraced view, a traced
/// comparison, and a trace that does not fit in memory each exit 2 with one line and write
/// nothing; the last names the untraced view.
#[test]
fn the_traced_render_refuses_bad_input() {
    let dir = temp_dir("ka-traced-bad");
    let out = dir.join("x.png");
    let path = out.to_str().expect("path");
    for args in [
        &["--model", "phong", "--view", "ka-traced", "--samples", "0"][..],
        &[
            "--model",
            "phong",
            "--view",
            "ka-traced",
            "--samples",
            "1048577",
        ],
        &["--model", "phong", "--view", "ka-traced", "--samples", "-3"],
        &["--model", "phong", "--view", "ka", "--samples", "4"],
        &["--model", "compare-split", "--view", "ka-traced"],
    ] {
        let mut all = vec!["render"];
        all.extend(args);
        all.extend(["--out", path]);
        let o = run(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {o:?}");
        assert_eq!(
            String::from_utf8_lossy(&o.stderr).lines().count(),
            1,
            "{o:?}"
        );
        assert!(!out.exists());
    }
    // A 8192^2 trace under a 2 GB address-space limit: refused before anything is built.
    let o = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2000000; exec '{}' render --model blinn --view ka-traced --size 8192 \
             --out '{path}'",
            env!("CARGO_BIN_EXE_kapaint")
        ))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(
        err.contains("memory") && err.contains("--view ka-view"),
        "{err}"
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint accuracy` adds what the view average hides: the view-average table (every model
/// and exponent) and the traced table per mesh, where on a sphere (nothing shadows) the AO
/// stand-in changes nothing and on a torus it brings `k_a` closer to the trace.
#[test]
fn accuracy_reports_the_view_average_and_the_traced_error() {
    let o = run(&[
        "accuracy",
        "--points",
        "2",
        "--model",
        "blinn",
        "--samples",
        "32",
        "--mesh",
        "sphere",
        "--mesh",
        "torus",
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8_lossy(&o.stdout);
    let rows = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    // The approximations' rows (3 methods, 2 ranges), then the view-average rows (8 exponents)
    // under their own first column, so the first table's rows stay the only `| blinn` ones.
    assert_eq!(rows("| blinn | "), 3 * 2, "{text}");
    assert_eq!(rows("| view average | blinn | "), 8, "{text}");
    let cell = |line: &str, k: usize| -> f64 {
        line.split('|')
            .nth(k)
            .and_then(|c| c.trim().trim_end_matches('%').trim().parse().ok())
            .unwrap_or(f64::NAN)
    };
    let row = |mesh: &str| {
        text.lines()
            .find(|l| l.starts_with(&format!("| {mesh} | blinn |")))
            .unwrap_or_else(|| panic!("no {mesh} row in {text}"))
            .to_owned()
    };
    let (sphere, torus) = (row("sphere"), row("torus"));
    assert!(
        (cell(&sphere, 3) - cell(&sphere, 5)).abs() < 0.05,
        "AO is 1 on a sphere: {sphere}"
    );
    assert!(
        cell(&torus, 5) < cell(&torus, 3),
        "AO helps on a torus: {torus}"
    );
    for bad in [
        &["accuracy", "--samples", "0"][..],
        &["accuracy", "--mesh", "nowhere.obj"],
    ] {
        let o = run(bad);
        assert_ne!(o.status.code(), Some(0), "{bad:?}: {o:?}");
        assert_eq!(
            String::from_utf8_lossy(&o.stderr).lines().count(),
            1,
            "{o:?}"
        );
    }
}

/// The AO stand-in's error view: on the spot cow with its AO baked, `k_a` times AO is nearer
/// the trace than `k_a` where the mesh shadows itself (the mean heat is lower); without an AO
/// bake, or with another mesh than the bake's, the view exits 2 and names what to do.
#[test]
fn the_ao_stand_in_view_needs_the_bake_and_beats_k_a() {
    let dir = temp_dir("ka-ao");
    let project = dir.join("spot.kapaint");
    let p = project.to_str().expect("path");
    let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_triangulated.obj");
    let o = run(&[
        "new",
        "--size",
        "256",
        "--mesh",
        spot.to_str().expect("path"),
        "--out",
        p,
    ]);
    assert!(o.status.success(), "{o:?}");
    let no_bake = dir.join("none.png");
    let args = |view: &'static str, out: &std::path::Path| -> Vec<String> {
        [
            "render",
            "--project",
            p,
            "--model",
            "blinn",
            "--view",
            view,
            "--samples",
            "64",
            "--size",
            "96",
            "--out",
        ]
        .iter()
        .map(|s| (*s).to_owned())
        .chain([out.to_string_lossy().into_owned()])
        .collect()
    };
    let run_owned = |a: Vec<String>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        run(&refs)
    };
    let o = run_owned(args("ka-ao-traced-error", &no_bake));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--map ao"),
        "{o:?}"
    );
    assert!(!no_bake.exists());
    let o = run(&["bake", p, "--map", "ao", "--rays", "64"]);
    assert!(o.status.success(), "{o:?}");
    let mean_heat = |view: &'static str| {
        let out = dir.join(format!("{view}.png"));
        let o = run_owned(args(view, &out));
        assert!(o.status.success(), "{o:?}");
        let image = image::open(&out).expect("PNG decodes").to_rgba8();
        let covered: Vec<_> = image
            .pixels()
            .take((96 - 4) * 96)
            .filter(|p| p[3] > 0)
            .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
            .collect();
        assert!(covered.len() > 500, "{view}: {} pixels", covered.len());
        covered.iter().sum::<f64>() / covered.len() as f64
    };
    let (k_a, k_a_ao) = (
        mean_heat("ka-traced-error"),
        mean_heat("ka-ao-traced-error"),
    );
    assert!(k_a_ao < k_a, "k_a x AO {k_a_ao} vs k_a {k_a}");
    let mut other = args("ka-ao-traced-error", &dir.join("other.png"));
    other.extend(["--mesh".to_owned(), "torus".to_owned()]);
    let o = run_owned(other);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
