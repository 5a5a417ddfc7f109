//! Property tests over the whole `f32` range: every input gives a finite, documented output.

use glam::Vec3;
use kapaint_reflectance::{
    AmbientApprox, ShadingModel, chi_f32, chi_f64, chi_parts_f32, chi_parts_f64, ka,
};
use proptest::prelude::*;

fn any_model() -> impl Strategy<Value = ShadingModel> {
    prop_oneof![
        Just(ShadingModel::Phong),
        Just(ShadingModel::BlinnPhong),
        Just(ShadingModel::CookTorrance)
    ]
}

fn paper_model() -> impl Strategy<Value = ShadingModel> {
    prop_oneof![Just(ShadingModel::Phong), Just(ShadingModel::BlinnPhong)]
}

fn any_approx() -> impl Strategy<Value = AmbientApprox> {
    prop_oneof![
        Just(AmbientApprox::PaperPrinted),
        Just(AmbientApprox::PaperCorrected),
        Just(AmbientApprox::Fast)
    ]
}

/// Every f32 bit pattern: NaNs, infinities, subnormals, negatives, huge values.
fn any_f32_bits() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

    #[test]
    fn chi_is_finite_and_in_unit_interval(model in any_model(), approx in any_approx(), n in any_f32_bits()) {
        let chi = chi_f32(model, approx, n);
        prop_assert!(chi.is_finite() && chi > 0.0 && chi <= 1.0, "chi({n}) = {chi}");
        let chi64 = chi_f64(model, approx, f64::from(n));
        prop_assert!(chi64.is_finite() && chi64 > 0.0 && chi64 <= 1.0);
    }

    #[test]
    fn chi_is_non_increasing(model in paper_model(), approx in any_approx(), a in any_f32_bits(), b in any_f32_bits()) {
        let (lo, hi) = if a.max(0.0) <= b.max(0.0) { (a, b) } else { (b, a) };
        let (c_lo, c_hi) = (chi_f32(model, approx, lo), chi_f32(model, approx, hi));
        // Up to f32 rounding of nearly equal arguments.
        prop_assert!(c_hi <= c_lo * (1.0 + 4.0 * f32::EPSILON), "chi({lo}) = {c_lo} < chi({hi}) = {c_hi}");
    }

    #[test]
    fn cook_torrance_parts_are_finite_bounded_and_non_decreasing(approx in any_approx(), a in any_f32_bits(), b in any_f32_bits()) {
        let (lo, hi) = if a.max(0.0) <= b.max(0.0) { (a, b) } else { (b, a) };
        let (p_lo, p_hi) = (
            chi_parts_f32(ShadingModel::CookTorrance, approx, lo),
            chi_parts_f32(ShadingModel::CookTorrance, approx, hi),
        );
        for (k, bound) in [(0, 0.52), (1, 0.0113)] {
            prop_assert!(p_lo[k].is_finite() && p_lo[k] > 0.0 && p_lo[k] <= bound, "part {k} at {lo}: {p_lo:?}");
            // Up to f32 rounding of nearly equal arguments.
            prop_assert!(p_hi[k] >= p_lo[k] * (1.0 - 4.0 * f32::EPSILON), "part {k}: {lo} -> {p_lo:?}, {hi} -> {p_hi:?}");
        }
        let wide = chi_parts_f64(ShadingModel::CookTorrance, approx, f64::from(lo));
        prop_assert!(wide.iter().all(|v| v.is_finite() && *v > 0.0));
    }

    #[test]
    fn ka_is_finite_and_bounded(model in any_model(), approx in any_approx(),
                                kd in prop::array::uniform3(any_f32_bits()),
                                ks in prop::array::uniform3(any_f32_bits()),
                                n in any_f32_bits()) {
        let v = ka(model, approx, Vec3::from(kd), Vec3::from(ks), n);
        prop_assert!(v.is_finite());
        prop_assert!(v.min_element() >= 0.0 && v.max_element() <= 2.0 / std::f32::consts::PI + 1.0 + 1e-6);
    }

    #[test]
    fn f32_and_f64_agree_on_valid_inputs(model in any_model(), approx in any_approx(), n in 0.0f32..1.0e9) {
        let single = f64::from(chi_f32(model, approx, n));
        let double = chi_f64(model, approx, f64::from(n));
        prop_assert!((single / double - 1.0).abs() < 2e-6, "n={n}: {single} vs {double}");
    }
}
