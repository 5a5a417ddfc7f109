//! `chi_view` against the paper's numbers, the head-on closed form, its view mean (which is
//! `chi(n)`) and an independent integration of the vector definition.

use super::*;
use crate::exact::{chi_exact, chi_parts_exact, rho_s};
use crate::model::phong::exact::phong_head_on;
use crate::quadrature::{break_points, graded_from};

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

const MODELS: [ShadingModel; 3] = [
    ShadingModel::Phong,
    ShadingModel::BlinnPhong,
    ShadingModel::CookTorrance,
];

#[test]
fn head_on_phong_is_its_closed_form() {
    assert!(rel(phong_head_on(10.0), 63.0 / 256.0) < 1e-14);
    for n in [0.0, 0.5, 1.0, 10.0, 100.0, 1000.0, 16384.0] {
        let [v, _] = chi_view_exact(ShadingModel::Phong, n, 0.0);
        // The closed form's log-gamma difference holds about 1e-11 at n = 16384.
        assert!(
            rel(v, phong_head_on(n)) < 1e-10,
            "n {n}: {v} vs {}",
            phong_head_on(n)
        );
    }
}

#[test]
fn the_issues_numbers_hold() {
    let chi = chi_exact(ShadingModel::Phong, 100.0);
    let [head_on, _] = chi_view_exact(ShadingModel::Phong, 100.0, 0.0);
    let [sixty, _] = chi_view_exact(ShadingModel::Phong, 100.0, 60f64.to_radians());
    assert!((chi - 0.0173).abs() < 5e-5, "{chi}");
    assert!((head_on - 0.0796).abs() < 5e-5, "{head_on}");
    assert!((sixty - 0.0073).abs() < 5e-5, "{sixty}");
}

/// `(2/pi) Int_0^{pi/2} chi_view(n, phi) dphi`, graded towards the head-on view.
fn view_mean(model: ShadingModel, n: f64) -> [f64; 2] {
    let rule = TanhSinh::new(8);
    let scale = if n > 0.0 { n.sqrt().recip() } else { 1.0 };
    let breaks = break_points(
        0.0,
        FRAC_PI_2,
        graded_from(0.0, 1.0, scale, FRAC_PI_2 / 2.0),
    );
    let parts = rule.integrate_pieces_par_n(&breaks, |phi| chi_view_exact(model, n, phi));
    parts.map(|v| 2.0 / PI * v)
}

#[test]
fn the_view_mean_is_chi() {
    for model in MODELS {
        for n in [0.0, 0.3, 1.0, 10.0, 200.0, 16384.0] {
            let mean = view_mean(model, n);
            let chi = chi_parts_exact(model, n);
            for k in 0..2 {
                if chi[k] == 0.0 {
                    assert!(mean[k].abs() < 1e-15);
                    continue;
                }
                let e = rel(mean[k], chi[k]);
                assert!(
                    e < 1e-9,
                    "{model:?} n {n} part {k}: {} vs {} ({e:e})",
                    mean[k],
                    chi[k]
                );
            }
        }
    }
}

/// The vector definition integrated directly over `t` and the full azimuth, graded towards the
/// mirror direction `(t, g) = (phi, pi)`: shares no reduction with [`chi_view_exact`].
fn independent(model: ShadingModel, n: f64, phi: f64) -> f64 {
    independent_at(model, n, phi, 10)
}

fn independent_at(model: ShadingModel, n: f64, phi: f64, level: u32) -> f64 {
    let rule = TanhSinh::new(level);
    let width = if model == ShadingModel::CookTorrance {
        crate::cook_torrance::alpha(n).max(1e-4)
    } else if n > 0.0 {
        n.sqrt().recip()
    } else {
        1.0
    };
    let t_breaks = break_points(
        0.0,
        FRAC_PI_2,
        graded_from(phi, -1.0, width, FRAC_PI_2)
            .chain(graded_from(phi, 1.0, width, FRAC_PI_2))
            // Past t = pi/2 - phi part of Phong's azimuth faces away (R.V < 0).
            .chain([phi, FRAC_PI_2 - phi]),
    );
    let outer = rule.integrate_pieces(&t_breaks, |t| {
        let across = (t.sin() * phi.sin()).max(1e-300);
        // Phong's R.V = ct cp - st sp cg crosses 0 (a kink, a step at n = 0) where
        // cos g = cot t cot p.
        let kink = (model == ShadingModel::Phong)
            .then(|| (t.cos() * phi.cos() / across).acos())
            .filter(|g| g.is_finite());
        let g_breaks = break_points(
            0.0,
            PI,
            graded_from(PI, -1.0, width / across, PI).chain(kink),
        );
        rule.integrate_pieces(&g_breaks, |g| rho_s(model, n, t, g, phi))
    });
    // Both halves of the azimuth: rho_s is even in g.
    2.0 * outer / (PI * PI)
}

#[test]
fn an_independent_integration_agrees_to_1e9() {
    for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
        for n in [0.0, 1.0, 10.0, 200.0, 1000.0, 16384.0] {
            for deg in [0.0, 10.0, 45.0, 80.0, 89.9] {
                let phi = f64::to_radians(deg);
                let [v, _] = chi_view_exact(model, n, phi);
                let w = independent_at(model, n, phi, 11);
                let e = rel(v, w);
                assert!(e < 1e-9, "{model:?} n {n} view {deg}: {v} vs {w} ({e:e})");
            }
        }
    }
}

#[test]
fn cook_torrance_parts_sum_to_the_independent_integration() {
    for n in [1.0, 10.0, 200.0, 4096.0] {
        for deg in [0.0, 30.0, 75.0] {
            let phi = f64::to_radians(deg);
            let [a, b] = chi_view_exact(ShadingModel::CookTorrance, n, phi);
            let w = independent(ShadingModel::CookTorrance, n, phi);
            let e = rel(a + b, w);
            assert!(e < 1e-9, "n {n} view {deg}: {} vs {w} ({e:e})", a + b);
        }
    }
}

#[test]
fn the_fast_table_follows_the_exact_integral() {
    // Between the nodes, over n in [0, 16384] and views in [0, 89.9] degrees (a fixed
    // low-discrepancy set of points): the table's measured accuracy (docs/reflectance.md).
    let mut worst = [0.0_f64; 3];
    for k in 0..800_u32 {
        let a = (f64::from(k) * 0.618_033_988_749_895).fract();
        let b = (f64::from(k) * 0.754_877_666_246_692_7).fract();
        let n = (a * 14.0).exp2() - 1.0;
        let phi = (b * 89.9).to_radians();
        for (m, model) in MODELS.into_iter().enumerate() {
            let exact = chi_view_exact(model, n, phi);
            let fast = chi_view_fast(model, n as f32, phi as f32).expect("in range");
            for part in 0..2 {
                if exact[part] > 0.0 {
                    worst[m] = worst[m].max(rel(f64::from(fast[part]), exact[part]));
                }
            }
        }
    }
    eprintln!("worst relative error: {worst:?}");
    assert!(worst.iter().all(|&w| w < 1e-4), "{worst:?}");
    assert_eq!(chi_view_fast(ShadingModel::Phong, 16385.0, 0.0), None);
    assert_eq!(chi_view_fast(ShadingModel::Phong, f32::NAN, 0.0), None);
    assert!(chi_view_fast(ShadingModel::Phong, 10.0, f32::NAN).is_some());
}
