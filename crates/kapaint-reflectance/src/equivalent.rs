//! The exponent of the other model whose highlight matches: `n_blinn ~ 4 n_phong` is only the
//! narrow-lobe limit, so the mapping is found numerically.
//!
//! With the light along the normal, a viewer at angle `t` from it sees `cos(t)^n` under Phong
//! (R = N) and `cos(t / 2)^m` under Blinn-Phong (H halfway between N and V). The equivalent
//! exponent minimises the squared difference of the two lobes over the hemisphere, weighted by
//! solid angle (`sin t dt`). For narrow lobes both are Gaussians in `t` and `m / n -> 4`
//! (measured: `m = 4 n + 1.5` from n = 20 on); for broad lobes the ratio is larger.
//!
//! Cook-Torrance takes its roughness from `n` by the Beckmann correspondence to the Blinn-Phong
//! lobe (`alpha = sqrt(2 / (n + 2))`), so its highlight is matched as Blinn-Phong's, against
//! Phong.

use super::ShadingModel;

/// Simpson intervals over the lobe.
const INTERVALS: usize = 2000;

/// The highlight lobe of `model` with exponent `n` at angle `t` from the mirror direction
/// (light along the normal).
fn lobe(model: ShadingModel, n: f64, t: f64) -> f64 {
    let c = match model {
        ShadingModel::Phong => t.cos(),
        ShadingModel::BlinnPhong | ShadingModel::CookTorrance => (t / 2.0).cos(),
    };
    if c <= 0.0 { 0.0 } else { c.powf(n) }
}

/// Solid-angle weighted squared difference of the two lobes.
fn mismatch(from: ShadingModel, n: f64, to: ShadingModel, m: f64, t_max: f64) -> f64 {
    let h = t_max / INTERVALS as f64;
    (0..=INTERVALS)
        .map(|i| {
            let t = i as f64 * h;
            let w = if i == 0 || i == INTERVALS {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let d = lobe(from, n, t) - lobe(to, m, t);
            w * d * d * t.sin()
        })
        .sum::<f64>()
        * h
        / 3.0
}

/// The model [`equivalent_exponent`] converts `from`'s exponents into: Phong's counterpart is
/// Blinn-Phong; Blinn-Phong's and Cook-Torrance's is Phong.
pub fn counterpart(from: ShadingModel) -> ShadingModel {
    match from {
        ShadingModel::Phong => ShadingModel::BlinnPhong,
        ShadingModel::BlinnPhong | ShadingModel::CookTorrance => ShadingModel::Phong,
    }
}

/// The exponent of [`counterpart`]`(from)` whose highlight best matches exponent `n` of `from`
/// (0 for 0; NaN and negative `n` count as 0).
pub fn equivalent_exponent(from: ShadingModel, n: f64) -> f64 {
    if n.is_nan() || n <= 0.0 {
        return 0.0;
    }
    let n = n.min(1e9);
    let to = counterpart(from);
    // Integrate where the broader (Blinn) lobe is not negligible.
    let blinn_n = match from {
        ShadingModel::Phong => 4.0 * n,
        ShadingModel::BlinnPhong | ShadingModel::CookTorrance => n,
    };
    let t_max = (12.0 / blinn_n.sqrt()).min(std::f64::consts::FRAC_PI_2);
    // Golden-section search on ln m. A Blinn lobe is broader than a Phong lobe of the same
    // exponent, so the ratio lies in [1, 16] (Phong to Blinn) or [1/16, 1]; it is 4 in the
    // narrow limit and larger for broad lobes (cos(t/2) never drops below cos(pi/4) on the
    // hemisphere, so matching cos(t) near t = pi/2 needs a higher exponent).
    let (lo, hi) = match from {
        ShadingModel::Phong => (n.ln(), (16.0 * n).ln()),
        ShadingModel::BlinnPhong | ShadingModel::CookTorrance => ((n / 16.0).ln(), n.ln()),
    };
    let cost = |ln_m: f64| mismatch(from, n, to, ln_m.exp(), t_max);
    let (lo, hi) = super::geometry::golden_section(cost, (lo, hi), 60);
    f64::midpoint(lo, hi).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_lobes_approach_four_times() {
        let m = equivalent_exponent(ShadingModel::Phong, 10_000.0);
        assert!((m / 10_000.0 - 4.0).abs() < 0.02, "{m}");
        let n = equivalent_exponent(ShadingModel::BlinnPhong, 40_000.0);
        assert!((n / 10_000.0 - 1.0).abs() < 0.02, "{n}");
    }

    #[test]
    fn the_mapping_is_monotone_and_nearly_invertible() {
        let mut last = 0.0;
        for n in [0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0, 1000.0] {
            let m = equivalent_exponent(ShadingModel::Phong, n);
            assert!(m > last, "monotone at {n}");
            assert!(
                m > 3.9 * n && m < 15.9 * n,
                "{n} -> {m}: inside the bracket"
            );
            let back = equivalent_exponent(ShadingModel::BlinnPhong, m);
            assert!((back / n - 1.0).abs() < 0.05, "{n} -> {m} -> {back}");
            last = m;
        }
        assert_eq!(equivalent_exponent(ShadingModel::Phong, 0.0), 0.0);
        assert_eq!(equivalent_exponent(ShadingModel::Phong, f64::NAN), 0.0);
    }

    #[test]
    fn the_match_beats_the_rule_of_thumb() {
        for n in [1.0, 4.0, 20.0] {
            let m = equivalent_exponent(ShadingModel::Phong, n);
            let t_max = std::f64::consts::FRAC_PI_2;
            let best = mismatch(ShadingModel::Phong, n, ShadingModel::BlinnPhong, m, t_max);
            let thumb = mismatch(
                ShadingModel::Phong,
                n,
                ShadingModel::BlinnPhong,
                4.0 * n,
                t_max,
            );
            assert!(best <= thumb, "n = {n}: {best} vs {thumb}");
        }
    }
}
