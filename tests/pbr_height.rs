//! Issue 43, item 1, its first step: fitting the lobe's height as well as its exponent keeps
//! the roughness apart where the height-fixed fit flattens it (measured at the rows the issue
//! names; the conversion still uses the height-fixed table).

use kapaint::pbr::fit::{LEVEL, LobeSamples};
use kapaint::reflectance::ShadingModel;

#[test]
fn fitting_the_lobe_height_too_keeps_rough_exponents_apart() {
    let cap = f64::from(kapaint::model::texel::N_MAX);
    for target in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
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
    }
}
