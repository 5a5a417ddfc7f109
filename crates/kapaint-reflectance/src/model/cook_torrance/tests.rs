use super::*;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn the_reduced_integrand_is_the_vector_definition() {
    let mut worst: f64 = 0.0;
    for n in [0.0, 1.0, 37.0, 900.0, 16384.0] {
        let a = alpha(n);
        for i in 1..12 {
            for j in 0..12 {
                for k in 1..24 {
                    let t = FRAC_PI_2 * f64::from(i) / 12.0;
                    let g = FRAC_PI_2 * f64::from(j) / 12.0;
                    let p = -FRAC_PI_2 + PI * f64::from(k) / 24.0 + 1e-3;
                    let want = rho_s_parts(n, t, g, p);
                    let (sp, cp) = p.sin_cos();
                    let got = integrand(a, t.sin_cos(), g, (p, sp, cp), t);
                    for (w, g) in want.iter().zip(got) {
                        let scale = want[0].abs() + want[1].abs();
                        if scale > 1e-300 {
                            worst = worst.max((w - g).abs() / scale);
                        }
                    }
                }
            }
        }
    }
    assert!(worst < 1e-9, "worst relative difference {worst:e}");
}

#[test]
fn at_n_zero_the_sum_is_one_over_four_pi() {
    let [c1, c0] = chi_exact(0.0);
    assert!(
        rel(c1 + c0, SUM_AT_ZERO) < 1e-11,
        "{} vs {SUM_AT_ZERO}",
        c1 + c0
    );
}

#[test]
fn doubling_the_nodes_moves_the_result_by_less_than_1e_10() {
    for n in [3.0, 16384.0] {
        let coarse = chi_exact(n);
        let fine = chi_exact_at_level(n, DEFAULT_LEVEL + 2);
        for (c, f) in coarse.iter().zip(fine) {
            assert!(rel(*c, f) < 1e-10, "n = {n}: {c} vs {f}");
        }
    }
}

#[test]
fn monte_carlo_from_the_vector_definition_agrees() {
    for n in [0.0, 8.0, 120.0] {
        let exact = chi_exact(n);
        let mc = chi_monte_carlo(n, 2_000_000, 7 + n as u64);
        for (e, (m, err)) in exact.iter().zip(mc) {
            assert!(
                (e - m).abs() < 5.0 * err,
                "n = {n}: exact {e}, Monte Carlo {m} +- {err}"
            );
        }
    }
}

#[test]
fn large_n_follows_the_derived_limits() {
    let [a1, a0] = chi_exact(1.0e4);
    let [b1, b0] = chi_exact(1.0e6);
    // chi_0 converges to its limit (the gap shrinks with alpha, 10x here).
    let limit = chi0_limit();
    assert!(
        (b0 - limit).abs() < 0.2 * (a0 - limit).abs(),
        "{a0} {b0} {limit}"
    );
    assert!(rel(b0, limit) < 0.02, "{b0} vs {limit}");
    // chi_1 + chi_0 grows as ln(n) / pi^3.
    let slope = ((b1 + b0) - (a1 + a0)) / (1.0e6_f64.ln() - 1.0e4_f64.ln());
    assert!(
        rel(slope, SUM_LOG_SLOPE) < 0.02,
        "slope {slope} vs {SUM_LOG_SLOPE}"
    );
}
