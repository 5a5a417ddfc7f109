//! PBR interop: glTF's metallic-roughness materials to and from kapaint's
//! `k_d`, `k_s`, `n`.
//!
//! Per texel, in linear light (glTF 2.0's metallic-roughness model):
//!
//! ```text
//! k_d = base (1 - metallic)
//! k_s = F0 = mix(0.04, base, metallic)          per colour channel
//! alpha = roughness^2                            glTF's GGX roughness
//! n = 2 / alpha^2 - 2                            the inverse of alpha = sqrt(2 / (n + 2))
//! ```
//!
//! The last line is the Cook-Torrance model's own mapping ([`kapaint_reflectance::cook_torrance`]),
//! so a PBR material shaded by that model needs no conversion at all. `n` is clamped to the
//! painted range `[0, 16384]` (roughness below 0.105 is a mirror there).
//!
//! The inverse ([`from_material`]) is exact where the forward mapping made the values: since
//! `k_d + k_s = base + 0.04 (1 - metallic)`, metallic solves a quadratic in the channels' means
//! and `base = k_d + k_s - 0.04 (1 - metallic)` follows without a division.

use glam::Vec3;

pub mod convert;
pub mod fit;
pub mod gltf;
mod gltf_check;
pub mod import;
pub mod names;
pub mod round_trip;
mod table;
mod table_height;

pub use kapaint_model::provenance::NMapping;
use kapaint_model::texel::{MaterialValue, N_MAX};

/// The dielectric `F0` of the metallic-roughness model.
pub const DIELECTRIC_F0: f32 = 0.04;

/// How far below the dielectric `F0` a mean `k_s` still reads as a dielectric: a unorm16 step
/// (`k_s` is stored as unorm16, so 0.04 comes back as 0.039994).
const F0_TOLERANCE: f32 = 1.0 / 65535.0;

/// One texel of a metallic-roughness material, linear light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pbr {
    /// Base colour, linear RGB in `[0, 1]`.
    pub base: Vec3,
    /// Metallic factor in `[0, 1]`.
    pub metallic: f32,
    /// Perceptual roughness in `[0, 1]` (`alpha = roughness^2`).
    pub roughness: f32,
}

/// `x` clamped into `[0, 1]`, NaN to 0.
fn unit(x: f32) -> f32 {
    kapaint_reflectance::sanitize_coefficient(x)
}

/// The Phong exponent of a glTF roughness under the Cook-Torrance mapping: `2 / r^4 - 2`,
/// clamped to `[0, N_MAX]`.
pub fn n_of_roughness(roughness: f32) -> f32 {
    let r = unit(roughness);
    let alpha2 = (r * r) * (r * r);
    if alpha2 <= 2.0 / (N_MAX + 2.0) {
        return N_MAX;
    }
    (2.0 / alpha2 - 2.0).clamp(0.0, N_MAX)
}

/// The glTF roughness of a Phong exponent: `(2 / (n + 2))^(1/4)`, the inverse of
/// [`n_of_roughness`] on its range.
pub fn roughness_of_n(n: f32) -> f32 {
    let n = kapaint_reflectance::sanitize_n_f32(n);
    (2.0 / (n + 2.0)).sqrt().sqrt()
}

/// A PBR texel as kapaint's material (the Cook-Torrance mapping of roughness).
pub fn to_material(p: Pbr) -> MaterialValue {
    let base = p.base.map(unit);
    let m = unit(p.metallic);
    MaterialValue::new(
        base * (1.0 - m),
        Vec3::splat(DIELECTRIC_F0).lerp(base, m),
        n_of_roughness(p.roughness),
    )
}

/// The metallic factor from `k_d` and `k_s`: a root in `[0, 1]` of
/// `0.04 m^2 + (D + S - 0.08) m - (S - 0.04) = 0`, with `D`, `S` the channels' means (what
/// `S = 0.04 + m (D / (1 - m) - 0.04)` becomes).
///
/// Where `S >= 0.04` the one non-negative root (0 for a dielectric). Below, only a metal with a
/// dark base reaches `S`, and the two roots are two readings that shade the same (a darker
/// base, less metal): the larger is taken, so a metal comes back a metal. Values no texel of
/// the model has (no real root) take the `m` nearest to one, the vertex.
pub fn metallic_of(kd: Vec3, ks: Vec3) -> f32 {
    metallic_within(kd, ks, F0_TOLERANCE)
}

/// [`metallic_of`] with `tolerance` for how far from the dielectric `F0` a grey `F0` still
/// reads as a dielectric.
fn metallic_within(kd: Vec3, ks: Vec3, tolerance: f32) -> f32 {
    let f0 = DIELECTRIC_F0;
    let (d, s) = (
        kd.map(unit).element_sum() / 3.0,
        ks.map(unit).element_sum() / 3.0,
    );
    let b = d + s - 2.0 * f0;
    let c = s - f0;
    let disc = b * b + 4.0 * f0 * c;
    // F0 within storage precision of the dielectric 0.04 in every channel (unorm16 rounds 0.04
    // to 0.039994; a height-fitted k_s divided by its height lands either side) is a
    // dielectric: on a dark base a mean just above 0.04 would otherwise read as a metal (only
    // a metal reaches it there), and the dark-metal reading below is for values clearly under
    // it. A coloured F0 whose mean is near 0.04 is a metal's: the roots below say so.
    let grey = ks
        .map(unit)
        .to_array()
        .iter()
        .all(|k| (k - f0).abs() <= tolerance);
    let m = if c.abs() <= tolerance && grey {
        0.0
    } else if c > 0.0 {
        // The one positive root, in the form without cancellation for the sign of b.
        if b >= 0.0 {
            2.0 * c / (b + disc.sqrt())
        } else {
            (-b + disc.sqrt()) / (2.0 * f0)
        }
    } else if disc >= 0.0 {
        (-b + disc.sqrt()) / (2.0 * f0)
    } else {
        -b / (2.0 * f0)
    };
    unit(m)
}

/// kapaint's material as a PBR texel: the inverse of [`to_material`] (exact where
/// `to_material` made the values; elsewhere the nearest metallic-roughness reading).
pub fn from_material(v: MaterialValue) -> Pbr {
    pbr_of(v.kd, v.ks, roughness_of_n(v.n), F0_TOLERANCE)
}

/// The PBR texel of `k_d`, `F0` and roughness: metallic by [`metallic_within`] (`tolerance`
/// below the dielectric `F0` still a dielectric), then `base = k_d + F0 - 0.04 (1 - m)`.
fn pbr_of(kd: Vec3, f0: Vec3, roughness: f32, tolerance: f32) -> Pbr {
    let (kd, f0) = (kd.map(unit), f0.map(unit));
    let m = metallic_within(kd, f0, tolerance);
    Pbr {
        base: (kd + f0 - Vec3::splat(DIELECTRIC_F0 * (1.0 - m))).map(unit),
        metallic: m,
        roughness,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use kapaint_reflectance::ShadingModel;

    #[test]
    fn the_height_fit_falls_strictly_over_the_whole_table() {
        use super::table::ROWS;
        use super::table_height::HEIGHT_FIT;
        for (k, target) in [ShadingModel::Phong, ShadingModel::BlinnPhong]
            .into_iter()
            .enumerate()
        {
            for i in 1..ROWS {
                let (n, h) = (HEIGHT_FIT[i][k][0], HEIGHT_FIT[i][k][1]);
                // Falling at least MIN_FALL a row: the stored exponent tells every 8-bit
                // roughness apart.
                let cap = HEIGHT_FIT[i - 1][k][0] * (1.0 - fit::MIN_FALL as f32);
                assert!(n <= cap * (1.0 + 1e-6), "{target:?}, row {i}: n {n}");
                assert!(h > 0.0 && h <= 1.0, "{target:?}, row {i}: height {h}");
            }
            // The issue's target: roughness 0.5, 0.75 and 1.0 each at least 1.25 times the next.
            let n = |r: f32| HEIGHT_FIT[(r * 64.0).round() as usize - 2][k][0];
            assert!(
                n(0.5) >= 1.25 * n(0.75) && n(0.75) >= 1.25 * n(1.0),
                "{target:?}: {} {} {}",
                n(0.5),
                n(0.75),
                n(1.0)
            );
        }
        // The conversion's lookup: the rows at their roughness, between them in between, and
        // strictly falling over the whole dense table.
        let c = convert::Conversion::for_model(ShadingModel::Phong, NMapping::HeightFitted);
        assert!((c.n(0.75) / HEIGHT_FIT[46][0][0] - 1.0).abs() < 1e-5);
        assert!((c.height(0.75) - HEIGHT_FIT[46][0][1]).abs() < 1e-6);
        let mid = c.n(0.75 + 0.5 / 64.0);
        assert!(mid < c.n(0.75) && mid > c.n(0.75 + 1.0 / 64.0), "{mid}");
        assert_eq!(c.n(f32::NAN), c.n(0.0));
        for target in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
            let c = convert::Conversion::for_model(target, NMapping::HeightFitted);
            for i in 1..=4096 {
                let (a, b) = (c.n((i - 1) as f32 / 4096.0), c.n(i as f32 / 4096.0));
                assert!(b < a, "{target:?} at {i}: {a} then {b}");
            }
        }
    }

    #[test]
    fn the_inverse_gives_back_the_material_and_pure_dielectrics_and_metals() {
        for base in [
            Vec3::new(0.8, 0.3, 0.1),
            Vec3::splat(0.5),
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::new(0.02, 0.9, 0.4),
        ] {
            for metallic in [0.0, 1.0, 0.5, 0.2] {
                for roughness in [1.0, 0.6, 0.3, 0.12] {
                    let p = Pbr {
                        base,
                        metallic,
                        roughness,
                    };
                    let v = to_material(p);
                    let back = from_material(MaterialValue::new(v.kd, v.ks, v.n));
                    let what = format!("{p:?} -> {v:?} -> {back:?}");
                    assert!((back.roughness - roughness).abs() < 1e-4, "{what}");
                    // Always the same k_d and k_s again: the same shading.
                    let again = to_material(back);
                    assert!((again.kd - v.kd).abs().max_element() < 1e-5, "{what}");
                    assert!((again.ks - v.ks).abs().max_element() < 1e-5, "{what}");
                    // Pure dielectrics and metals come back as they were (a dark base with
                    // metallic in between has a twin reading, a darker base and less metal,
                    // that shades the same).
                    if metallic == 0.0 || metallic == 1.0 {
                        assert!((back.base - base).abs().max_element() < 1e-5, "{what}");
                        assert!((back.metallic - metallic).abs() < 1e-5, "{what}");
                    }
                }
            }
        }
    }

    /// A dark dielectric as the project stores it (unorm16 rounds `k_s = 0.04` down to
    /// 0.039994) was read as a metal with a dark base, metallic 0.93 (found on the spot cow's
    /// texture).
    #[test]
    fn a_stored_dark_dielectric_stays_a_dielectric() {
        use kapaint_model::texel::{decode_rgb, encode_rgb};
        for base in [
            Vec3::splat(0.0),
            Vec3::splat(0.004),
            Vec3::new(0.01, 0.002, 0.0),
        ] {
            let v = to_material(Pbr {
                base,
                metallic: 0.0,
                roughness: 0.5,
            });
            let stored = MaterialValue::new(
                decode_rgb(encode_rgb(v.kd)),
                decode_rgb(encode_rgb(v.ks)),
                v.n,
            );
            let back = from_material(stored);
            assert!(back.metallic < 1e-3, "{base}: {back:?}");
            assert!(
                (back.base - base).abs().max_element() < 1e-4,
                "{base}: {back:?}"
            );
        }
    }

    #[test]
    fn roughness_maps_onto_the_cook_torrance_alpha() {
        for r in [0.2_f32, 0.5, 0.9, 1.0] {
            let n = n_of_roughness(r);
            let alpha = kapaint_reflectance::cook_torrance::alpha(f64::from(n));
            assert!(
                (alpha - f64::from(r * r)).abs() < 1e-5,
                "r = {r}: alpha {alpha}"
            );
        }
        // A mirror is the painted range's end; hostile values are finite.
        assert_eq!(n_of_roughness(0.0), N_MAX);
        assert_eq!(n_of_roughness(f32::NAN), N_MAX);
        assert_eq!(n_of_roughness(7.0), 0.0);
        let v = to_material(Pbr {
            base: Vec3::splat(f32::NAN),
            metallic: f32::INFINITY,
            roughness: -1.0,
        });
        assert!(
            v.kd.is_finite() && v.ks.is_finite() && v.n.is_finite(),
            "{v:?}"
        );
    }
}
