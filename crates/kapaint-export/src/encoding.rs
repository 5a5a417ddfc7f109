//! How `n` is stored in an exported set: linear, square-root or logarithmic over the range the
//! maps actually use, at 8 or 16 bits, chosen by the error it causes where it matters, in
//! `k_a` (and in the highlight's exponent).
//!
//! `k_a = (2/pi) k_d + k_s chi(n)` is recomputed by the consumer from the decoded `n`, so the
//! quantisation of `n` shows up as an error in `k_a`, weighted by each texel's `k_s` and
//! diluted by its `k_d`. The error is measured per texel against the unquantised maps.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use kapaint_model::MaterialMaps;
use kapaint_model::maps::chi_lut;
use kapaint_model::texel::{N_MAX, decode_n};
use kapaint_model::tile::TILE_TEXELS;
use kapaint_reflectance::{AmbientApprox, ShadingModel, diffuse_factor};

/// The curve `n` is quantised along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NCurve {
    /// Even steps in `n`.
    Linear,
    /// Even steps in `sqrt(n)`.
    Sqrt,
    /// Even steps in `ln(1 + n)`.
    Log,
}

impl NCurve {
    /// Every curve.
    pub const ALL: [Self; 3] = [Self::Linear, Self::Sqrt, Self::Log];

    fn forward(self, n: f64) -> f64 {
        match self {
            Self::Linear => n,
            Self::Sqrt => n.sqrt(),
            Self::Log => n.ln_1p(),
        }
    }

    fn inverse(self, v: f64) -> f64 {
        match self {
            Self::Linear => v,
            Self::Sqrt => v * v,
            Self::Log => v.exp_m1(),
        }
    }
}

/// A complete encoding of `n`: curve, range and bit depth. A consumer decodes a stored code
/// `q` as `inverse(f(lo) + q / (2^bits - 1) * (f(hi) - f(lo)))`.
///
/// Read from a manifest only through its checks: bits 8 or 16 (what kapaint writes), and
/// `0 <= lo <= hi <= N_MAX`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "NEncodingFile")]
pub struct NEncoding {
    /// The curve.
    pub curve: NCurve,
    /// Smallest `n` represented (code 0).
    pub lo: f32,
    /// Largest `n` represented (the top code).
    pub hi: f32,
    /// Bits per code (8 or 16).
    pub bits: u8,
}

/// An encoding as a manifest spells it, before it is checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NEncodingFile {
    curve: NCurve,
    lo: f32,
    hi: f32,
    bits: u8,
}

impl TryFrom<NEncodingFile> for NEncoding {
    type Error = String;

    fn try_from(f: NEncodingFile) -> Result<Self, String> {
        use kapaint_model::check::in_range;
        if !matches!(f.bits, 8 | 16) {
            return Err(format!(
                "n_encoding.bits must be 8 or 16 (what kapaint writes), got {}",
                f.bits
            ));
        }
        let lo = in_range("n_encoding.lo", f.lo, 0.0, N_MAX)?;
        let hi = in_range("n_encoding.hi", f.hi, lo, N_MAX)?;
        Ok(Self {
            curve: f.curve,
            lo,
            hi,
            bits: f.bits,
        })
    }
}

impl NEncoding {
    fn max_code(self) -> f64 {
        f64::from((1_u32 << self.bits) - 1)
    }

    /// The code of `n` (clamped into the range).
    pub fn encode(self, n: f32) -> u16 {
        let (a, b) = (
            self.curve.forward(f64::from(self.lo)),
            self.curve.forward(f64::from(self.hi)),
        );
        if b <= a {
            return 0;
        }
        let v = self
            .curve
            .forward(f64::from(n).clamp(f64::from(self.lo), f64::from(self.hi)));
        ((v - a) / (b - a) * self.max_code()).round() as u16
    }

    /// The `n` at `t` of the way along the code range (`decode(q)` is
    /// `decode_fraction(q / (2^bits - 1))`).
    pub fn decode_fraction(self, t: f64) -> f32 {
        let (a, b) = (
            self.curve.forward(f64::from(self.lo)),
            self.curve.forward(f64::from(self.hi)),
        );
        self.curve.inverse(a + t.clamp(0.0, 1.0) * (b - a)) as f32
    }

    /// The `n` a code stands for.
    pub fn decode(self, q: u16) -> f32 {
        let (a, b) = (
            self.curve.forward(f64::from(self.lo)),
            self.curve.forward(f64::from(self.hi)),
        );
        let t = (f64::from(q) / self.max_code()).min(1.0);
        self.curve.inverse(a + t * (b - a)) as f32
    }
}

/// Relative `k_a` error of an encoding over a set of maps (per colour channel, per texel).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KaError {
    /// Largest relative error.
    pub max: f64,
    /// Mean relative error.
    pub mean: f64,
}

/// The range of `n` the maps use (smallest and largest stored value).
pub fn n_range(maps: &MaterialMaps) -> (f32, f32) {
    let mut used = vec![false; 1 << 16];
    for id in 0..maps.tile_count() {
        match &maps.tile(id).n {
            kapaint_model::tile::Plane::Uniform(v) => used[*v as usize] = true,
            kapaint_model::tile::Plane::Data(d) => {
                for &v in d {
                    used[v as usize] = true;
                }
            }
        }
    }
    let values = used
        .iter()
        .enumerate()
        .filter(|(_, u)| **u)
        .map(|(bits, _)| decode_n(bits as u16));
    values.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), n| {
        (lo.min(n), hi.max(n))
    })
}

/// The relative `k_a` error that storing `n` with `encoding` causes, against the maps as
/// they are (the same `chi` approximation on both sides, so only quantisation counts).
pub fn ka_error(
    maps: &MaterialMaps,
    model: ShadingModel,
    approx: AmbientApprox,
    encoding: NEncoding,
) -> KaError {
    let chi = chi_lut(model, approx);
    // [chi_1, chi_0] after a round trip through the encoding, per stored n code.
    let quantised: Vec<[f32; 2]> = (0..=u16::MAX)
        .map(|bits| {
            let n = decode_n(bits);
            kapaint_reflectance::chi_parts_f32(model, approx, encoding.decode(encoding.encode(n)))
        })
        .collect();
    let diffuse = diffuse_factor(approx.for_model(model)) as f32;
    let (max, sum, count) = (0..maps.tile_count())
        .into_par_iter()
        .map(|id| {
            let kapaint_model::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
            let tile = maps.tile(id);
            let (mut max, mut sum, mut count) = (0.0_f64, 0.0_f64, 0_u64);
            for i in 0..TILE_TEXELS {
                let (x, y) = (x0 + (i % 64) as u32, y0 + (i / 64) as u32);
                if x >= x1 || y >= y1 {
                    continue;
                }
                let t = tile.texel(i);
                let ([c0, z0], [c1, z1]) = (chi[t.n as usize], quantised[t.n as usize]);
                for c in 0..3 {
                    let kd = kapaint_model::texel::decode_unorm(t.kd[c]);
                    let ks = kapaint_model::texel::decode_unorm(t.ks[c]);
                    let ka = diffuse * kd + ks * c0 + z0;
                    let err = if ka > 0.0 {
                        f64::from((ks * (c1 - c0) + (z1 - z0)).abs() / ka)
                    } else {
                        0.0
                    };
                    max = max.max(err);
                    sum += err;
                    count += 1;
                }
            }
            (max, sum, count)
        })
        .reduce(
            || (0.0, 0.0, 0),
            |a, b| (a.0.max(b.0), a.1 + b.1, a.2 + b.2),
        );
    KaError {
        max,
        mean: if count > 0 { sum / count as f64 } else { 0.0 },
    }
}

/// Every curve at `bits` over the maps' own range of `n`, with its `k_a` error, best first
/// (smallest maximum error, then mean).
pub fn rank_encodings(
    maps: &MaterialMaps,
    model: ShadingModel,
    approx: AmbientApprox,
    bits: u8,
) -> Vec<(NEncoding, KaError)> {
    let (lo, hi) = n_range(maps);
    let mut ranked: Vec<(NEncoding, KaError)> = NCurve::ALL
        .iter()
        .map(|&curve| {
            let e = NEncoding {
                curve,
                lo,
                hi,
                bits,
            };
            (e, ka_error(maps, model, approx, e))
        })
        .collect();
    ranked.sort_by(|a, b| {
        a.1.max
            .total_cmp(&b.1.max)
            .then(a.1.mean.total_cmp(&b.1.mean))
    });
    ranked
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use kapaint_model::texel::MaterialValue;

    #[test]
    fn codes_round_trip_at_the_ends_and_stay_monotone() {
        for curve in NCurve::ALL {
            let e = NEncoding {
                curve,
                lo: 2.0,
                hi: 5000.0,
                bits: 8,
            };
            assert_eq!(e.encode(2.0), 0);
            assert_eq!(e.encode(5000.0), 255);
            assert_eq!(e.encode(1e9), 255, "clamped");
            assert!((e.decode(0) - 2.0).abs() < 1e-4);
            assert!((e.decode(255) - 5000.0).abs() < 1e-1);
            let mut last = 0;
            for k in 0..200 {
                let q = e.encode(2.0 + 25.0 * k as f32);
                assert!(q >= last);
                last = q;
            }
        }
    }

    #[test]
    fn uniform_n_costs_nothing_and_log_wins_on_wide_ranges() {
        let maps = MaterialMaps::new(
            64,
            64,
            MaterialValue::new(Vec3::splat(0.3), Vec3::splat(0.5), 40.0),
        )
        .unwrap();
        let ranked = rank_encodings(&maps, ShadingModel::Phong, AmbientApprox::Fast, 8);
        assert!(ranked.iter().all(|(_, e)| e.max < 1e-6), "{ranked:?}");

        // n spread over 1..10000 in a gradient: the log curve's relative steps are even.
        let mut maps = MaterialMaps::new(256, 1, MaterialValue::default()).unwrap();
        for x in 0..256 {
            let n = (10000.0_f32.ln() * x as f32 / 255.0).exp();
            let (id, i) = maps.locate(x, 0);
            maps.tile_mut(id).set_texel(
                i,
                kapaint_model::texel::Texel::encode(MaterialValue::new(
                    Vec3::splat(0.2),
                    Vec3::splat(0.8),
                    n,
                )),
            );
        }
        let ranked = rank_encodings(&maps, ShadingModel::BlinnPhong, AmbientApprox::Fast, 8);
        assert_eq!(ranked[0].0.curve, NCurve::Log, "{ranked:?}");
        assert!(ranked[0].1.max < 0.02, "{ranked:?}");
        let sixteen = rank_encodings(&maps, ShadingModel::BlinnPhong, AmbientApprox::Fast, 16);
        assert!(sixteen[0].1.max < 1e-3, "{sixteen:?}");
    }
}
