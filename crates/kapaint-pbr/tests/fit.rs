//! The PBR fits and their tables (issue 20): the box rule against the exact integrals, the
//! fitted exponent and its inverse, the committed table against the fit, the error between
//! rows and nodes, and an import's error summary. Crate-only: the CLI's import and export of
//! real sets are tested beside the binary (tests/pbr.rs at the top).

use glam::Vec3;
use kapaint_pbr::convert::Conversion;
use kapaint_pbr::fit::{LEVEL, LobeSamples, TARGETS, ks_node};
use kapaint_pbr::import::{PbrSet, Source, import};
use kapaint_pbr::{NMapping, Pbr};
use kapaint_reflectance::{ShadingModel, cook_torrance, exact};

#[test]
fn the_box_rule_agrees_with_the_exact_integrals() {
    for r in [0.25_f64, 0.5, 1.0] {
        let s = LobeSamples::new(r, LEVEL);
        let n = kapaint_pbr::fit::ct_n(r);
        let [m1, m0] = s.ggx_means();
        let [e1, e0] = cook_torrance::chi_exact(n);
        assert!((m1 / e1 - 1.0).abs() < 1e-3, "r {r}: chi1 {m1} vs {e1}");
        assert!((m0 / e0 - 1.0).abs() < 2e-3, "r {r}: chi0 {m0} vs {e0}");
        for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
            let got = s.target_mean(model, 0.5 * n + 1.0);
            let want = exact::chi_exact(model, 0.5 * n + 1.0);
            assert!(
                (got / want - 1.0).abs() < 1e-3,
                "{model:?} r {r}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn the_fitted_exponent_falls_with_roughness_and_inverts() {
    for (model, mapping) in TARGETS
        .into_iter()
        .flat_map(|m| NMapping::ALL.map(|n| (m, n)))
    {
        let c = Conversion::for_model(model, mapping);
        let mut last = f32::INFINITY;
        for i in 0..=1000 {
            let r = i as f32 / 1000.0;
            let n = c.n(r);
            assert!(
                n.is_finite() && (0.0..=16384.0).contains(&n),
                "{model:?} {r}: {n}"
            );
            assert!(n <= last * (1.0 + 1e-6), "{model:?}: n({r}) = {n} > {last}");
            last = n;
        }
        // Where the fitted exponent still falls (everywhere but above 0.48 for the
        // height-fixed Phong and Blinn-Phong), the inverse gives the roughness back.
        let flat = model != ShadingModel::CookTorrance && mapping == NMapping::HeightFixed;
        let falling: &[f32] = if flat {
            &[0.12, 0.2, 0.3, 0.4, 0.45]
        } else {
            &[0.12, 0.2, 0.3, 0.4, 0.45, 0.55, 0.7, 0.85, 0.99]
        };
        for &r in falling {
            let back = c.roughness(c.n(r));
            assert!(
                (back - r).abs() < 2e-3,
                "{model:?}: {r} -> {} -> {back}",
                c.n(r)
            );
        }
    }
    // Cook-Torrance is its own mapping.
    let ct = Conversion::for_model(ShadingModel::CookTorrance, NMapping::default());
    for r in [0.2_f32, 0.5, 0.9] {
        let want = kapaint_pbr::n_of_roughness(r);
        assert!((ct.n(r) - want).abs() <= 1e-3 * want.max(1.0), "{r}");
    }
}

#[test]
fn the_committed_table_is_what_the_fit_gives() {
    // Row 14 (roughness 0.25): the fit there is not capped, so it can be redone alone.
    let r = 0.25;
    let s = LobeSamples::new(r, LEVEL);
    for (k, model) in TARGETS.into_iter().enumerate().take(2) {
        let n = s.fit_n(model, 16384.0);
        let table = Conversion::for_model(model, NMapping::HeightFixed).n(r as f32);
        assert!(
            (f64::from(table) / n - 1.0).abs() < 2e-3,
            "{model:?}: table {table}, fit {n}"
        );
        let errors = s.error_table(model, n);
        let c = Conversion::for_model(model, NMapping::HeightFixed);
        let means = s.ggx_means();
        for j in [0, 3, 8, 16] {
            let ks = ks_node(j) as f32;
            // A texel whose k_d is zero and k_s is the node: the error is the numerator over
            // the Cook-Torrance mean.
            let want = errors[j] / (f64::from(ks) * means[0] + means[1]);
            let got = c.error_of(Vec3::ZERO, Vec3::splat(ks), r as f32);
            assert!(
                (f64::from(got) / want - 1.0).abs() < 5e-3,
                "{model:?} k_s {ks}: {got} vs {want} (column {k})"
            );
        }
    }
}

#[test]
fn the_error_between_rows_and_nodes_is_the_direct_one() {
    // Roughness 0.3 lies between rows; k_s = 0.3 between nodes.
    let (r, ks) = (0.3_f64, 0.3_f64);
    let s = LobeSamples::new(r, LEVEL);
    for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
        let c = Conversion::for_model(model, NMapping::HeightFixed);
        let n = f64::from(c.n(r as f32));
        let direct = s.error_at(model, n, ks);
        let means = s.ggx_means();
        let kd = 0.2;
        let want = direct / (std::f64::consts::FRAC_2_PI * kd + ks * means[0] + means[1]);
        let got = f64::from(c.error_of(Vec3::splat(kd as f32), Vec3::splat(ks as f32), r as f32));
        assert!(
            (got / want - 1.0).abs() < 0.02,
            "{model:?}: {got} vs {want}"
        );
    }
}

#[test]
fn cook_torrance_loses_nothing_above_the_painted_limit() {
    let c = Conversion::for_model(ShadingModel::CookTorrance, NMapping::default());
    for r in [0.11_f32, 0.3, 0.7, 1.0] {
        for ks in [0.0_f32, 0.04, 0.5, 1.0] {
            let e = c.error_of(Vec3::splat(0.3), Vec3::splat(ks), r);
            assert!(e < 1e-4, "r {r} k_s {ks}: {e}");
        }
    }
    // Below it, the painted exponent's limit (16384) is a blunter lobe: measured, not hidden.
    assert!(c.error_of(Vec3::ZERO, Vec3::ONE, 0.05) > 0.3);
}

#[test]
fn the_error_summary_is_the_texels_error() {
    // A set of two halves: the error statistics are those of the two values.
    let set = PbrSet::MetallicRoughness {
        base: Source::constant(Vec3::new(0.8, 0.5, 0.2)),
        metallic: Source::constant(Vec3::ONE),
        roughness: Source::constant(Vec3::splat(0.4)),
    };
    let imported = import(
        &set,
        Some((64, 64)),
        ShadingModel::Phong,
        NMapping::default(),
    )
    .expect("import");
    let c = Conversion::for_model(ShadingModel::Phong, NMapping::default());
    let want = c.error(Pbr {
        base: Vec3::new(0.8, 0.5, 0.2),
        metallic: 1.0,
        roughness: 0.4,
    });
    let e = imported.report.error;
    assert!(
        (e.max - want).abs() < 1e-6 && (e.mean - want).abs() < 1e-5,
        "{e:?} vs {want}"
    );
    assert!((e.p99 / want - 1.0).abs() < 0.01, "{e:?}");
}
