//! PBR interop (issue 20): the fitted exponent and its error tables, the import of real sets
//! (the spot cow's texture as base colour, in a glTF material written with the `gltf` crate's
//! JSON types, and as loose images), and bad input.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;

use glam::Vec3;
use kapaint::model::texel::srgb_to_linear;
use kapaint::pbr::NMapping;
use kapaint::pbr::convert::Conversion;
use kapaint::pbr::fit::TARGETS;
use kapaint::pbr::import::{PbrSet, Source, import};
use kapaint::reflectance::ShadingModel;

#[path = "common/gltf_asset.rs"]
mod gltf_asset;
use gltf_asset::{Asset, dir, kapaint, spot, write_asset};

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs `kapaint import-pbr --out OUT ARGS...` and checks it is refused: exit 2, one line on
/// stderr that holds `want`, and nothing written at `out`.
fn refused(out: &Path, args: &[String], want: &str) {
    let mut all = vec![
        "import-pbr".to_string(),
        "--out".into(),
        out.display().to_string(),
    ];
    all.extend_from_slice(args);
    let refs: Vec<&str> = all.iter().map(String::as_str).collect();
    let o = kapaint(&refs);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{all:?}: {e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains(want), "{all:?}: {e}");
    assert!(!out.exists(), "{all:?} wrote {}", out.display());
}

// ---------------------------------------------------------------------------------------
// Loose images.

#[test]
fn the_spot_set_round_trips_its_base_colour_where_metallic_is_pure() {
    let d = dir("roundtrip");
    let (base, mr) =
        kapaint::report::typical::write_pbr_set(&d, 256, Some(&spot().join("spot_texture.png")))
            .expect("set");
    let set = PbrSet::MetallicRoughness {
        base: Source::file(&base, None, true),
        metallic: Source::file(&mr, Some(2), false),
        roughness: Source::file(&mr, Some(1), false),
    };
    let out = d.join("spot.kapaint");
    for model in TARGETS {
        let imported = import(&set, None, model, NMapping::default()).expect("import");
        kapaint::model::project::save(&imported.doc, &out).expect("save");
        let doc = kapaint::model::project::load(&out).expect("load");
        let base_png = image::open(&base).expect("base").to_rgb8();
        let mr_png = image::open(&mr).expect("mr").to_rgb8();
        let c = Conversion::for_model(model, NMapping::default());
        let (mut worst, mut clamped) = (0.0_f32, 0);
        for y in 0..256 {
            for x in 0..256 {
                let v = doc.maps().value(x, y);
                let pbr = c.pbr(v);
                let want = base_png.get_pixel(x, y);
                let m = f32::from(mr_png.get_pixel(x, y)[2]) / 255.0;
                let rough = f32::from(mr_png.get_pixel(x, y)[1]) / 255.0;
                // The energy guard clamps k_s where a dielectric's base is near white (red on
                // most of spot's texture); such a dielectric still comes back.
                let linear = Vec3::from_array(want.0.map(|b| srgb_to_linear(f32::from(b) / 255.0)));
                let f0 = Vec3::splat(0.04).lerp(linear, m);
                if ((linear * (1.0 - m) + f0 * c.height(rough)).max_element()) > 1.0 {
                    clamped += 1;
                }
                let got = pbr.base.map(linear_to_srgb);
                for ch in 0..3 {
                    // The byte the export writes.
                    worst = worst.max(((got[ch] * 255.0).round() - f32::from(want[ch])).abs());
                }
                // Within half a byte: the exported byte is the one imported (F0 = k_s /
                // height magnifies the stored k_s's unorm16 step where the height is small).
                assert!(
                    (pbr.metallic - m).abs() < 0.5 / 255.0,
                    "({x}, {y}): {}",
                    pbr.metallic
                );
                // The exponent is the target's for the texel's roughness.
                let n = c.n(rough);
                assert!(
                    (v.n - n).abs() <= 2e-3 * n.max(1.0),
                    "({x}, {y}): {} vs {n}",
                    v.n
                );
            }
        }
        assert!(worst <= 1.0, "{model:?}: base colour off by {worst}/255");
        let report = doc.settings().import.clone().expect("report kept");
        assert_eq!(report.model, model.name());
        assert!(report.error.max >= report.error.p99 && report.error.max >= report.error.mean);
        eprintln!(
            "{model:?}: base colour within {worst}/255 ({clamped} texels clamped by the energy guard); error {:?}",
            report.error
        );
    }
}

fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[test]
fn import_pbr_cli_converts_images_and_numbers_and_prints_the_error() {
    let d = dir("cli");
    let (base, mr) = kapaint::report::typical::write_pbr_set(&d, 128, None).expect("set");
    let out = d.join("a.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--out",
        out.to_str().expect("utf-8"),
        "--base-color",
        base.to_str().expect("utf-8"),
        "--metallic-roughness",
        mr.to_str().expect("utf-8"),
        "--model",
        "blinn",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("(128x128, blinn)"), "{text}");
    assert!(
        text.starts_with("imported base.png, metallic_roughness.png into "),
        "{text}"
    );
    assert!(
        text.lines().any(
            |l| l.starts_with("conversion error (relative, box average): max ")
                && l.contains("mean")
                && l.contains("p99")
        ),
        "{text}"
    );
    let doc = kapaint::model::project::load(&out).expect("load");
    assert_eq!(doc.settings().model, ShadingModel::BlinnPhong);
    // Numbers for every quantity, and the specular-glossiness workflow.
    let o = kapaint(&[
        "import-pbr",
        "--out",
        out.to_str().expect("utf-8"),
        "--force",
        "--size",
        "32",
        "--base-color",
        "0.5",
        "--specular",
        "0.9,0.6,0.2",
        "--glossiness",
        "0.7",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let doc = kapaint::model::project::load(&out).expect("load");
    let v = doc.maps().value(5, 5);
    assert!(
        (v.ks - Vec3::new(0.9, 0.6, 0.2)).abs().max_element() < 1e-3,
        "{v:?}"
    );
    assert!(
        (v.kd - Vec3::splat(0.5 * 0.1)).abs().max_element() < 1e-3,
        "{v:?}"
    );
    let n = Conversion::for_model(ShadingModel::Phong, NMapping::default()).n(0.3);
    assert!((v.n - n).abs() < 2e-3 * n, "{v:?} vs {n}");
}

#[test]
fn images_of_another_size_are_resampled_and_said() {
    let d = dir("sizes");
    let base = d.join("base.png");
    image::RgbImage::from_pixel(64, 64, image::Rgb([200, 100, 50]))
        .save(&base)
        .expect("base");
    let rough = d.join("rough.png");
    image::GrayImage::from_pixel(16, 16, image::Luma([128]))
        .save(&rough)
        .expect("rough");
    let out = d.join("a.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--out",
        out.to_str().expect("utf-8"),
        "--base-color",
        base.to_str().expect("utf-8"),
        "--metallic",
        "0",
        "--roughness",
        rough.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("note: resampled rough.png from 16x16 to 64x64"),
        "{}",
        stdout(&o)
    );
    let doc = kapaint::model::project::load(&out).expect("load");
    let notes = doc.settings().import.clone().expect("report").notes;
    assert!(notes.iter().any(|n| n.contains("resampled")), "{notes:?}");
}

#[test]
fn bad_sets_are_one_clear_error_and_nothing_written() {
    let d = dir("bad");
    let out = d.join("never.kapaint");
    // A 100000^2 PNG header.
    let huge = d.join("huge.png");
    std::fs::write(&huge, png_header(100_000, 100_000)).expect("huge");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "--base-color".into(),
                d.join("missing.png").display().to_string(),
                "--metallic".into(),
                "0".into(),
                "--roughness".into(),
                "0.5".into(),
            ],
            "no such file",
        ),
        (
            vec![
                "--base-color".into(),
                huge.display().to_string(),
                "--metallic".into(),
                "0".into(),
                "--roughness".into(),
                "0.5".into(),
            ],
            "too large",
        ),
        (
            vec![
                "--base-color".into(),
                "0.5".into(),
                "--metallic".into(),
                "0".into(),
            ],
            "--roughness is missing",
        ),
        (
            vec![
                "--base-color".into(),
                "0.5".into(),
                "--metallic".into(),
                "2".into(),
                "--roughness".into(),
                "0.5".into(),
            ],
            "in [0, 1]",
        ),
    ];
    for (args, want) in cases {
        refused(&out, &args, want);
    }
}

/// A PNG signature and header for `w x h` RGB8, and nothing else.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut header = w.to_be_bytes().to_vec();
    header.extend_from_slice(&h.to_be_bytes());
    header.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend_from_slice(&13u32.to_be_bytes());
    out.extend_from_slice(b"IHDR");
    out.extend_from_slice(&header);
    out.extend_from_slice(&crc32fast::hash(&[b"IHDR".as_slice(), &header].concat()).to_be_bytes());
    out
}

#[test]
fn a_gltf_material_imports_with_its_mesh_textures_and_transform() {
    let d = dir("gltf");
    let gltf = write_asset(&d, &Asset::default());
    // The file is valid for the gltf crate (its validation runs on open).
    gltf::Gltf::open(&gltf).expect("valid glTF");
    let out = d.join("cow.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--out",
        out.to_str().expect("utf-8"),
        "--gltf",
        gltf.to_str().expect("utf-8"),
        "--material",
        "cow",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let doc = kapaint::model::project::load(&out).expect("load");
    assert!(
        doc.settings().mesh.spec().ends_with("spot.gltf"),
        "{:?}",
        doc.settings().mesh
    );
    let texture = image::open(spot().join("spot_texture.png"))
        .expect("png")
        .to_rgb8();
    let (w, h) = texture.dimensions();
    assert_eq!((doc.maps().width(), doc.maps().height()), (w, h));
    // Left half dielectric: k_d is the texture; right half metal: k_s is.
    let (x, y) = (w / 4, h / 3);
    let want = Vec3::from_array(
        texture
            .get_pixel(x, y)
            .0
            .map(|c| srgb_to_linear(f32::from(c) / 255.0)),
    );
    let v = doc.maps().value(x, y);
    assert!((v.kd - want).abs().max_element() < 2e-3, "{v:?} vs {want}");
    let v = doc.maps().value(3 * w / 4, y);
    let want = Vec3::from_array(
        texture
            .get_pixel(3 * w / 4, y)
            .0
            .map(|c| srgb_to_linear(f32::from(c) / 255.0)),
    );
    assert!((v.ks - want).abs().max_element() < 2e-3, "{v:?} vs {want}");
    assert!(v.kd.max_element() < 1e-4);

    // A texture transform: scale 2 repeats the texture twice across.
    let d2 = dir("gltf-transform");
    let gltf2 = write_asset(
        &d2,
        &Asset {
            transform: Some(([0.0, 0.0], 0.0, [2.0, 2.0])),
            ..Asset::default()
        },
    );
    let out2 = d2.join("cow.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--out",
        out2.to_str().expect("utf-8"),
        "--gltf",
        gltf2.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let doc2 = kapaint::model::project::load(&out2).expect("load");
    // Texel (x, y) samples the texture at (2x + 0.5, 2y + 0.5) texel centres, wrapped.
    let (x, y) = (w / 8 + 3, h / 5 + 1);
    let a = doc2.maps().value(x, y).kd;
    let sx = (2 * x) % w;
    let sy = (2 * y) % h;
    let mut want = Vec3::ZERO;
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let p = texture.get_pixel((sx + dx) % w, (sy + dy) % h).0;
        want += 0.25 * Vec3::from_array(p.map(|c| srgb_to_linear(f32::from(c) / 255.0)));
    }
    assert!((a - want).abs().max_element() < 3e-3, "{a} vs {want}");
}

#[test]
fn bad_gltf_materials_are_one_clear_error_and_nothing_written() {
    let cases: Vec<(Asset, Option<&str>, &str)> = vec![
        (
            Asset::default(),
            Some("velvet"),
            "has no material \"velvet\" (its materials: cow)",
        ),
        (
            Asset {
                base_uri: "gone.png".into(),
                ..Asset::default()
            },
            None,
            "baseColorTexture",
        ),
        (
            Asset {
                base_uri: "spot.ktx2".into(),
                base_mime: Some("image/ktx2"),
                ..Asset::default()
            },
            None,
            "KTX2",
        ),
        (
            Asset {
                tex_coord: 1,
                ..Asset::default()
            },
            None,
            "TEXCOORD_1",
        ),
    ];
    for (k, (asset, material, want)) in cases.into_iter().enumerate() {
        let d = dir(&format!("badgltf{k}"));
        let gltf = write_asset(&d, &asset);
        let mut args = vec!["--gltf".to_string(), gltf.display().to_string()];
        if let Some(m) = material {
            args.extend(["--material".to_string(), m.to_string()]);
        }
        refused(&d.join("never.kapaint"), &args, want);
    }
}
