//! Issue 43, item 1: the Phong and Blinn-Phong conversions fit the lobe's height as well as its
//! exponent (`k_s = F0 height(r)`, clamped to the energy guard), so the rough end keeps its
//! roughness apart; the export inverts it; `--n-mapping height-fixed` keeps the old mapping.
//! The fits themselves are tested in their crate (crates/kapaint-pbr/tests/height.rs).
//! Measured on spot's glTF material (mesh and texture from ../shared/testdata) with a
//! barrel-like metallic-roughness map made here (barrel.glb itself is not in this tree).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use kapaint::model::texel::srgb_to_linear;
use kapaint::pbr::convert::Conversion;
use kapaint::pbr::{NMapping, Pbr};
use kapaint::reflectance::ShadingModel;

#[path = "common/gltf_asset.rs"]
mod gltf_asset;
use gltf_asset::{Asset, dir, kapaint, write_asset};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A deterministic stream of numbers in `[0, 1)`.
fn stream(seed: u64) -> impl FnMut() -> f32 {
    let mut x = seed;
    move || {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (x >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Spot's glTF asset (its mesh) with a barrel-like material made here in place of its
/// textures: bands of rough dark wood (a dielectric, base colour brown, roughness 0.55 to 0.9)
/// and smoother iron (a metal, dark grey, roughness 0.35 to 0.6), both noisy along the band.
/// Returns the glTF's path.
fn barrel_like(d: &Path) -> PathBuf {
    let gltf = write_asset(d, &Asset::default());
    let (w, h) = image::image_dimensions(d.join("mr.png")).expect("mr size");
    let mut next = stream(7);
    let grain: Vec<f32> = (0..w).map(|_| next()).collect();
    let iron = |y: u32| (y * 10 / h) % 3 == 1;
    let wobble =
        |x: u32, y: u32| 0.5 * grain[x as usize] + 0.5 * (y as f32 / h as f32 * 10.0).fract();
    image::RgbImage::from_fn(w, h, |x, y| {
        let shade = 0.7 + 0.3 * wobble(x, y);
        let colour: [f32; 3] = if iron(y) {
            [70.0, 70.0, 75.0]
        } else {
            [120.0, 80.0, 45.0]
        };
        image::Rgb(colour.map(|c| (c * shade).round() as u8))
    })
    .save(d.join("spot_texture.png"))
    .expect("barrel base colour");
    image::RgbImage::from_fn(w, h, |x, y| {
        let (m, r) = if iron(y) {
            (255, 0.35 + 0.25 * wobble(x, y))
        } else {
            (0, 0.55 + 0.35 * wobble(x, y))
        };
        image::Rgb([0, (r * 255.0).round() as u8, m])
    })
    .save(d.join("mr.png"))
    .expect("barrel metallic-roughness");
    gltf
}

/// `kapaint import-pbr --gltf GLTF --model MODEL --out OUT` with `flags`.
fn import(gltf: &Path, model: &str, out: &Path, flags: &[&str]) -> std::process::Output {
    let mut args = vec![
        "import-pbr",
        "--gltf",
        s(gltf),
        "--model",
        model,
        "--out",
        s(out),
    ];
    args.extend_from_slice(flags);
    kapaint(&args)
}

#[test]
fn a_barrel_like_material_keeps_its_roughness_bands_and_lowers_its_error() {
    let d = dir("barrel");
    let gltf = barrel_like(&d);
    let mr = image::open(d.join("mr.png")).expect("mr").to_rgb8();
    let base = image::open(d.join("spot_texture.png"))
        .expect("base")
        .to_rgb8();
    for (model, name) in [
        (ShadingModel::Phong, "phong"),
        (ShadingModel::BlinnPhong, "blinn"),
    ] {
        let mut results = Vec::new();
        for mapping in NMapping::ALL {
            let out = d.join(format!("{name}-{}.kapaint", mapping.name()));
            let o = import(&gltf, name, &out, &["--n-mapping", mapping.name()]);
            assert!(o.status.success(), "{}", text(&o.stderr));
            let said = text(&o.stdout);
            assert!(
                said.contains(&format!("n mapping: {}", mapping.name())),
                "{said}"
            );
            let doc = kapaint::model::project::load(&out).expect("load");
            let report = doc.settings().import.clone().expect("report");
            assert_eq!(report.n_mapping, mapping.name());
            assert_eq!(doc.settings().n_mapping(), mapping);
            // The exponents per roughness byte: distinct and falling where the map's
            // roughness is.
            let mut by_rough = std::collections::BTreeMap::new();
            for (x, y, px) in mr.enumerate_pixels() {
                by_rough.insert(px[1], doc.maps().value(x, y).n);
            }
            let n: Vec<f32> = by_rough.values().copied().collect();
            let distinct = n.windows(2).filter(|p| p[1] < p[0] * (1.0 - 1e-4)).count() + 1;
            // The error of the wood and the iron apart (each texel's, as the import measures
            // it).
            let c = Conversion::for_model(model, mapping);
            let mut bands = [(0.0_f64, 0_u32); 2];
            for (x, y, px) in mr.enumerate_pixels() {
                let p = Pbr {
                    base: Vec3::from_array(
                        base.get_pixel(x, y)
                            .0
                            .map(|b| srgb_to_linear(f32::from(b) / 255.0)),
                    ),
                    metallic: f32::from(px[2]) / 255.0,
                    roughness: f32::from(px[1]) / 255.0,
                };
                let band = &mut bands[usize::from(px[2] == 255)];
                band.0 += f64::from(c.error(p));
                band.1 += 1;
            }
            eprintln!(
                "{model:?} {}: conversion error mean {:.1} % (wood {:.1} %, iron {:.1} %), p99 {:.1} %, max {:.1} %; {distinct} exponents for {} roughness values ({:.2} to {:.2})",
                mapping.name(),
                100.0 * report.error.mean,
                100.0 * bands[0].0 / f64::from(bands[0].1),
                100.0 * bands[1].0 / f64::from(bands[1].1),
                100.0 * report.error.p99,
                100.0 * report.error.max,
                n.len(),
                n[0],
                n[n.len() - 1]
            );
            results.push((report.error, distinct, n.len()));
        }
        let (fitted, fixed) = (&results[0], &results[1]);
        assert_eq!(fitted.1, fitted.2, "{model:?}: every roughness its own n");
        assert!(fixed.1 * 2 < fixed.2, "{model:?}: the old mapping flattens");
        // The target (mean at most 16 %, half the old) was set on barrel.glb, which is
        // not in this tree. Here the wood's error halves (31 to 17 %); the smoother iron (a metal
        // at roughness 0.35 to 0.6, where the height is at its cap of 1) keeps its lobe-shape
        // error, so the whole falls by a quarter (docs/pbr.md).
        assert!(
            fitted.0.mean <= 0.8 * fixed.0.mean
                && fitted.0.p99 <= fixed.0.p99 * 1.001
                && fitted.0.max <= fixed.0.max * 1.001,
            "{model:?}: {:?} vs {:?}",
            fitted.0,
            fixed.0
        );
    }
}

#[test]
fn an_unknown_n_mapping_is_refused_with_the_choices() {
    let d = dir("mapping-flag");
    let gltf = write_asset(&d, &Asset::default());
    let out = d.join("p.kapaint");
    let o = import(&gltf, "phong", &out, &["--n-mapping", "lobe"]);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("height-fitted") && e.contains("height-fixed"),
        "{e}"
    );
    assert!(!out.exists());
    // The export: the same, and only with the glTF preset.
    let o = import(&gltf, "phong", &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for (flags, want) in [
        (
            vec!["--preset", "gltf-pbr", "--n-mapping", "flat"],
            "height-fixed",
        ),
        (
            vec!["--preset", "compact", "--n-mapping", "height-fixed"],
            "--preset gltf-pbr",
        ),
    ] {
        let set = d.join("set");
        let mut args = vec!["export", s(&out), "--out", s(&set)];
        args.extend(flags.iter().copied());
        let o = kapaint(&args);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flags:?}: {e}");
        assert!(e.contains(want), "{flags:?}: {e}");
        assert!(!set.exists(), "{flags:?}");
    }
    // Given, it is what the manifest names; not given, the project's.
    for (flags, want) in [
        (vec!["--n-mapping", "height-fixed"], "height-fixed"),
        (vec![], "height-fitted"),
    ] {
        let set = d.join(format!("set-{want}"));
        let mut args = vec![
            "export",
            s(&out),
            "--preset",
            "gltf-pbr",
            "--no-padding",
            "--out",
            s(&set),
        ];
        args.extend(flags.iter().copied());
        let o = kapaint(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(set.join("material.json")).expect("manifest"))
                .expect("json");
        assert_eq!(m["n_mapping"], want, "{flags:?}");
    }
}
