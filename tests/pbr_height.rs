//! Issue 43, item 1: the Phong and Blinn-Phong conversions fit the lobe's height as well as its
//! exponent (`k_s = F0 height(r)`, clamped to the energy guard), so the rough end keeps its
//! roughness apart; the export inverts it; `--n-mapping height-fixed` keeps the old mapping.
//! Measured on spot's glTF material (mesh and texture from ../shared/testdata) with a
//! barrel-like metallic-roughness map made here (barrel.glb itself is not in this tree).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use kapaint::model::texel::{MaterialValue, Texel, srgb_to_linear};
use kapaint::pbr::convert::Conversion;
use kapaint::pbr::fit::{LEVEL, LobeSamples};
use kapaint::pbr::round_trip::RoundTrip;
use kapaint::pbr::{NMapping, Pbr};
use kapaint::reflectance::ShadingModel;

#[path = "common/gltf_asset.rs"]
mod gltf_asset;
use gltf_asset::{Asset, dir, kapaint, write_asset};

const FITTED: [ShadingModel; 2] = [ShadingModel::Phong, ShadingModel::BlinnPhong];

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn fitting_the_lobe_height_too_keeps_rough_exponents_apart() {
    let cap = f64::from(kapaint::model::texel::N_MAX);
    for target in FITTED {
        let rows: Vec<(f64, f64, f64, f64, f64)> = [0.5_f64, 0.75, 1.0]
            .iter()
            .map(|&r| {
                let s = LobeSamples::new(r, LEVEL);
                let (n, height) = s.fit_n_and_height(target, cap);
                let (_, distance) = s.height_for(target, n);
                let fixed_n = s.fit_n(target, cap);
                let fixed = s.lobe_distance(target, fixed_n);
                let [m1, m0] = s.ggx_means();
                (n, height, distance / (m1 + m0), fixed_n, fixed / (m1 + m0))
            })
            .collect();
        for (r, row) in [0.5, 0.75, 1.0].iter().zip(&rows) {
            eprintln!(
                "{target:?} roughness {r}: n {:.3} height {:.4} distance {:.3} | height fixed: n {:.3} distance {:.3}",
                row.0, row.1, row.2, row.3, row.4
            );
        }
        for pair in rows.windows(2) {
            assert!(
                pair[0].0 >= 1.25 * pair[1].0 && pair[1].0 > 0.0,
                "{target:?}: n {} then {}",
                pair[0].0,
                pair[1].0
            );
        }
        for row in &rows {
            assert!(row.2 <= row.4 * (1.0 + 1e-9), "{target:?}: {row:?}");
        }
        // The conversion reads the same from its table.
        let c = Conversion::for_model(target, NMapping::HeightFitted);
        assert!(
            c.n(0.5) >= 1.25 * c.n(0.75) && c.n(0.75) >= 1.25 * c.n(1.0),
            "{target:?}: {} {} {}",
            c.n(0.5),
            c.n(0.75),
            c.n(1.0)
        );
    }
}

/// The conversion's error, clamped by the energy guard or not and between the table's rows
/// and nodes, is the box average computed directly.
#[test]
fn the_height_mappings_error_is_the_direct_one_clamp_counted() {
    // (roughness, k_d, F0): a rough dielectric, a rough metal, and two the guard clamps (a
    // near-white dielectric and a half metal on a bright base, both where the height is 1).
    let cases = [
        (0.8 + 0.5 / 64.0, 0.2, 0.04),
        (0.9 + 0.3 / 64.0, 0.0, 0.7),
        (0.3 + 0.5 / 64.0, 0.985, 0.04),
        (0.35 + 0.5 / 64.0, 0.48, 0.55),
    ];
    for &(r, kd, f0) in &cases {
        let samples = LobeSamples::new(r, LEVEL);
        let [m1, m0] = samples.ggx_means();
        for target in FITTED {
            let c = Conversion::for_model(target, NMapping::HeightFitted);
            let v = c.convert(Vec3::splat(kd as f32), Vec3::splat(f0 as f32), r as f32);
            // The energy guard holds, and clamps only where it must.
            assert!(v.kd.x + v.ks.x <= 1.0 + 1e-6, "{target:?} {r}: {v:?}");
            let ks = f64::from(v.ks.x);
            let unclamped = f0 * f64::from(c.height(r as f32));
            let clamped = kd + unclamped > 1.0;
            assert_eq!(
                (ks - unclamped).abs() > 1e-6,
                clamped,
                "{target:?} {r}: {v:?}"
            );
            let direct = samples.error_at_height(target, f64::from(v.n), f0, ks)
                / (std::f64::consts::FRAC_2_PI * kd + f0 * m1 + m0);
            let got =
                f64::from(c.error_of(Vec3::splat(kd as f32), Vec3::splat(f0 as f32), r as f32));
            eprintln!(
                "{target:?} r {r:.4} k_d {kd} F0 {f0}: k_s {ks:.4} (clamped {clamped}), error {got:.4} vs direct {direct:.4}"
            );
            assert!(
                (got / direct - 1.0).abs() < 0.03,
                "{target:?} r {r} k_d {kd} F0 {f0}: {got} vs {direct}"
            );
        }
    }
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

/// 8-bit PBR texels made into a project's texels and exported again come back within one
/// level where the texel survives: the energy guard left it whole, or it is a dielectric (the
/// inverse gives a clamped channel back the dielectric F0). A metallic in between on a base
/// so dark that F0 falls below 0.04 has two readings, and is counted apart.
#[test]
fn the_export_inverts_the_height_mapping_within_one_level() {
    for (seed, target) in (43..).zip(FITTED) {
        let c = Conversion::for_model(target, NMapping::HeightFitted);
        let round_trip = RoundTrip::for_model(target, NMapping::HeightFitted);
        let mut next = stream(seed);
        let (mut checked, mut clamped, mut twins) = (0, 0, 0);
        let mut worst = [0_i32; 3];
        for _ in 0..20_000 {
            let mut byte = || (next() * 256.0) as u8;
            let base = [byte(), byte(), byte()];
            let metallic = match byte() % 4 {
                0 => 0,
                1 => 255,
                _ => byte(),
            };
            let rough = byte().max(8);
            let p = Pbr {
                base: Vec3::from_array(base.map(|b| srgb_to_linear(f32::from(b) / 255.0))),
                metallic: f32::from(metallic) / 255.0,
                roughness: f32::from(rough) / 255.0,
            };
            let v = c.material(p);
            let f0 = Vec3::splat(0.04).lerp(p.base, p.metallic);
            if (v.ks - f0 * c.height(p.roughness)).abs().max_element() > 1e-6 {
                // The guard took some of F0: a dielectric comes back (the inverse reads the
                // dielectric F0 in the clamped channels); anything else does not survive.
                clamped += 1;
                if metallic != 0 {
                    continue;
                }
            }
            let (b, mr, _) = round_trip.texel(&Texel::encode(v));
            let off = |a: u8, b: u8| (i32::from(a) - i32::from(b)).abs();
            worst[0] = worst[0].max(off(mr[1], rough));
            assert!(
                off(mr[1], rough) <= 1,
                "{target:?} {p:?}: roughness {}",
                mr[1]
            );
            // A metallic in between on a dark base is ill-posed, counted and not checked:
            // where F0 falls below the dielectric 0.04 there are two readings with the same
            // means (the inverse takes the metal one, which does not keep the channels'
            // split), and where the base's mean is near 0.04 a level of metallic moves F0 by
            // less than the inverse's tolerance (the stored k_s's step and the height's
            // uncertainty, over the height: the same without the height, over a band the
            // height widens).
            let f0_mean = f0.element_sum() / 3.0;
            let step = 2.0 * c.f0_tolerance(p.roughness);
            let resolved = (p.base.element_sum() / 3.0 - 0.04).abs() / 255.0 > step;
            if metallic != 0 && metallic != 255 && (f0_mean < 0.04 || !resolved) {
                twins += 1;
                continue;
            }
            worst[1] = worst[1].max(off(mr[2], metallic));
            for k in 0..3 {
                worst[2] = worst[2].max(off(b[k], base[k]));
            }
            assert!(
                off(mr[2], metallic) <= 1 && (0..3).all(|k| off(b[k], base[k]) <= 1),
                "{target:?} {p:?}: base {b:?} metallic {}",
                mr[2]
            );
            checked += 1;
        }
        eprintln!(
            "{target:?}: {checked} texels within (roughness, metallic, base) {worst:?} levels; {twins} ill-posed (dark, partly metal); {clamped} clamped by the energy guard"
        );
        assert!(checked > 10_000, "{checked}");
    }
}

/// The height-fixed mapping is the conversion before the height fit: `k_s = F0`, the old
/// exponents; and a project imported before it (its report says `fitted`) exports with it.
#[test]
fn the_height_fixed_mapping_is_the_old_one() {
    let p = Pbr {
        base: Vec3::new(0.7, 0.5, 0.3),
        metallic: 0.0,
        roughness: 0.8,
    };
    for target in FITTED {
        let fixed = Conversion::for_model(target, NMapping::HeightFixed).material(p);
        assert_eq!(fixed.ks, Vec3::splat(0.04));
        let fitted = Conversion::for_model(target, NMapping::HeightFitted).material(p);
        assert!(fitted.ks.x < 0.04 && fitted.n < 0.5 * fixed.n, "{fitted:?}");
    }
    assert_eq!(
        NMapping::from_name("fitted"),
        Some(NMapping::HeightFixed),
        "reports written before the height fit"
    );
    let mut settings = kapaint::model::document::DocumentSettings::default();
    assert_eq!(settings.n_mapping(), NMapping::HeightFitted);
    settings.import = Some(kapaint::model::provenance::ImportReport {
        source: "old.glb".into(),
        model: "phong".into(),
        n_mapping: "fitted".into(),
        error: kapaint::model::provenance::ErrorSummary {
            max: 0.0,
            mean: 0.0,
            p99: 0.0,
        },
        notes: Vec::new(),
        double_sided: false,
    });
    assert_eq!(settings.n_mapping(), NMapping::HeightFixed);
    settings.n_mapping = Some(NMapping::HeightFitted);
    assert_eq!(settings.n_mapping(), NMapping::HeightFitted);
    // A stored texel reads back by its own mapping.
    let v = MaterialValue::new(Vec3::splat(0.3), Vec3::splat(0.04), 8.0);
    let back = Conversion::for_model(ShadingModel::Phong, NMapping::HeightFixed).pbr(v);
    assert!(
        (back.base.x - 0.3).abs() < 1e-4 && back.metallic < 1e-4,
        "{back:?}"
    );
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
