//! Issue 43, item 1: the Phong and Blinn-Phong conversions fit the lobe's height as well as its
//! exponent (`k_s = F0 height(r)`, clamped to the energy guard), so the rough end keeps its
//! roughness apart; the export inverts it; the height-fixed mapping is the old one. Crate-only:
//! the CLI's `--n-mapping` on a real glTF is tested beside the binary (tests/pbr_height.rs).

use glam::Vec3;
use kapaint_model::texel::{MaterialValue, Texel, srgb_to_linear};
use kapaint_pbr::convert::Conversion;
use kapaint_pbr::fit::{LEVEL, LobeSamples};
use kapaint_pbr::round_trip::RoundTrip;
use kapaint_pbr::{NMapping, Pbr};
use kapaint_reflectance::ShadingModel;

const FITTED: [ShadingModel; 2] = [ShadingModel::Phong, ShadingModel::BlinnPhong];

#[test]
fn fitting_the_lobe_height_too_keeps_rough_exponents_apart() {
    let cap = f64::from(kapaint_model::texel::N_MAX);
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
    let mut settings = kapaint_model::document::DocumentSettings::default();
    assert_eq!(settings.n_mapping(), NMapping::HeightFitted);
    settings.import = Some(kapaint_model::provenance::ImportReport {
        source: "old.glb".into(),
        model: "phong".into(),
        n_mapping: "fitted".into(),
        error: kapaint_model::provenance::ErrorSummary {
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
