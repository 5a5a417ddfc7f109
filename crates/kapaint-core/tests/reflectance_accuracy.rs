//! Acceptance tests of the approximations against the exact integrator.

use kapaint_core::report::accuracy::{ExactSamples, Grid, error_stats};
use kapaint_reflectance::exact::chi_exact;
use kapaint_reflectance::fit::{self, power_law_max_error};
use kapaint_reflectance::{
    AmbientApprox, PAPER_BLINN, PAPER_BLINN_CORRECTED_EXPONENT, PAPER_PHONG, ShadingModel, chi_f32,
    chi_f64,
};

fn samples(model: ShadingModel, lo: f64, hi: f64, count: usize) -> ExactSamples {
    ExactSamples::compute(model, &Grid::log_spaced(lo, hi, count))
}

#[test]
fn fast_is_within_1e4_on_0_to_16384_for_both_models() {
    for model in ShadingModel::PAPER {
        // Points between the fit's interpolation nodes, where a polynomial's error peaks.
        let exact = samples(model, 0.0, 16384.0, 97);
        let stats = error_stats(AmbientApprox::Fast, &exact);
        assert!(stats.max_rel <= 1e-4, "{model:?}: {stats:?}");
        // The shipped degree leaves a wide margin: 2e-5 is the fit's own target.
        assert!(stats.max_rel <= 2e-5, "{model:?}: {stats:?}");
    }
}

#[test]
fn paper_errors_are_as_the_notes_report() {
    let phong = samples(ShadingModel::Phong, 1.0, 200.0, 60);
    let printed = error_stats(AmbientApprox::PaperPrinted, &phong);
    // Eq. (8): 0.79 % max on [1, 200], the paper's own claim of 0.8 %.
    assert!((printed.max_rel - 0.0079).abs() < 0.0003, "{printed:?}");

    let blinn = samples(ShadingModel::BlinnPhong, 1.0, 200.0, 60);
    let printed = error_stats(AmbientApprox::PaperPrinted, &blinn);
    // Eq. (11) as printed: about 9 % at n = 200.
    assert!(
        printed.max_rel > 0.08 && printed.max_rel < 0.10,
        "{printed:?}"
    );
    assert_eq!(printed.max_at_n, 200.0);
    let corrected = error_stats(AmbientApprox::PaperCorrected, &blinn);
    assert!(corrected.max_rel < 0.007, "{corrected:?}");
}

#[test]
fn corrected_exponent_is_the_minimax_of_our_integrator() {
    let exact = samples(ShadingModel::BlinnPhong, 1.0, 200.0, 60);
    let (c, err) =
        fit::paper_exponent_minimax(PAPER_BLINN.0, PAPER_BLINN.1, &exact.samples, (-0.95, -0.8));
    // The shipped value is the minimax rounded to the paper's three decimals.
    assert!(
        (c - PAPER_BLINN_CORRECTED_EXPONENT).abs() < 0.0006,
        "minimax c = {c}"
    );
    assert!(err < 0.007, "{err}");
    // And Phong's printed exponent is already (close to) its minimax.
    let phong = samples(ShadingModel::Phong, 1.0, 200.0, 60);
    let (c_phong, _) =
        fit::paper_exponent_minimax(PAPER_PHONG.0, PAPER_PHONG.1, &phong.samples, (-0.95, -0.8));
    assert!((c_phong - PAPER_PHONG.2).abs() < 0.002, "{c_phong}");
    let printed = power_law_max_error(PAPER_BLINN.0, PAPER_BLINN.1, PAPER_BLINN.2, &exact.samples);
    assert!(printed > 10.0 * err);
}

#[test]
fn fast_is_continuous_across_octaves_and_the_tail() {
    for model in ShadingModel::PAPER {
        for octave in 1..=fit::FIT_OCTAVES {
            let x = (1u64 << octave) as f32;
            let at = x - 1.0;
            let below = chi_f32(model, AmbientApprox::Fast, f32::from_bits(at.to_bits() - 1));
            let above = chi_f32(model, AmbientApprox::Fast, at);
            // Adjacent floats: the only change is the true slope (< 1e-6 relative here)
            // plus rounding; no jump between pieces.
            let jump = (below / above - 1.0).abs();
            assert!(jump < 1e-6, "{model:?} at n={at}: jump {jump:e}");
        }
    }
}

#[test]
fn chi_is_monotone_and_within_0_1() {
    // Cook-Torrance's chi_1 grows with n instead: tests/cook_torrance.rs.
    for model in ShadingModel::PAPER {
        for approx in AmbientApprox::ALL {
            let mut last = chi_f32(model, approx, 0.0);
            assert!(last > 0.0 && last <= 1.0);
            // A grid fine enough to cross every piece, coarse enough that the true decrease
            // exceeds f32 rounding.
            let mut n = 0.0_f32;
            while n < 3.0e38 {
                n = if n < 1.0 { n + 1.0 / 64.0 } else { n * 1.001 };
                let chi = chi_f32(model, approx, n);
                assert!(
                    chi > 0.0 && chi <= last,
                    "{model:?} {approx:?} n={n}: {chi} > {last}"
                );
                last = chi;
            }
        }
    }
}

#[test]
fn f32_and_f64_paths_agree() {
    for model in ShadingModel::ALL {
        for approx in AmbientApprox::ALL {
            for i in 0..4000 {
                let n = (f64::from(i) * 0.008).exp() - 1.0;
                let single = f64::from(chi_f32(model, approx, n as f32));
                let double = chi_f64(model, approx, f64::from(n as f32));
                assert!(
                    (single / double - 1.0).abs() < 2e-6,
                    "{model:?} {approx:?} n={n}"
                );
            }
        }
    }
}

#[test]
fn exact_large_n_agrees_with_fast_tail() {
    // Above 16384 Fast switches to the derived log law; it stays close to exact.
    for model in ShadingModel::PAPER {
        for n in [40_000.0, 100_000.0, 1.0e6] {
            let exact = chi_exact(model, n);
            let fast = chi_f64(model, AmbientApprox::Fast, n);
            assert!(
                (fast / exact - 1.0).abs() < 1e-4,
                "{model:?} n={n}: {fast} vs {exact}"
            );
        }
    }
}

#[test]
fn committed_fast_constants_are_what_the_fit_produces() {
    let phong = fit::fit_exact(ShadingModel::Phong, 5);
    let blinn = fit::fit_exact(ShadingModel::BlinnPhong, 5);
    let fresh = fit::render_rust(&phong, &blinn);
    let committed = include_str!("../../kapaint-reflectance/src/fast_coeffs.rs");
    // Compare numerically: libm differences across machines may move a last digit.
    let numbers = |text: &str| -> Vec<f64> {
        text.split(|c: char| !(c.is_ascii_digit() || "eE.-+".contains(c)))
            .filter_map(|t| t.parse::<f64>().ok())
            .collect()
    };
    let (a, b) = (numbers(&fresh), numbers(committed));
    assert_eq!(
        a.len(),
        b.len(),
        "regenerate with `cargo run --release --example fit_fast`"
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() <= 1e-6 * x.abs().max(1e-3),
            "{x} vs {y}: regenerate the constants"
        );
    }
}
