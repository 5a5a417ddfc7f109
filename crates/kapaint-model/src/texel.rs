//! Per-texel material values and their storage encodings.
//!
//! In memory every channel is linear. `k_d` and `k_s` are stored as 16-bit unorm (steps of
//! 1/65535: no banding from soft strokes); `n` as IEEE half floats, whose relative step is
//! 2^-11 = 0.049 % over the whole paintable range `[0, N_MAX]` (and which the GPU samples
//! natively). Blending happens in a perceptual space where every channel is in `[0, 1]`:
//! `k_d`, `k_s` as they are, `n` through [`n_to_blend`] (log space).

use glam::Vec3;
use half::f16;
use serde::{Deserialize, Serialize};

/// Clamps into `[lo, hi]`, mapping NaN to `lo` (`f32::clamp` would keep NaN).
#[inline]
pub fn clamp_nan_low(v: f32, lo: f32, hi: f32) -> f32 {
    v.max(lo).min(hi)
}

/// Clamps into `[0, 1]`, NaN to 0.
#[inline]
pub fn unit(v: f32) -> f32 {
    clamp_nan_low(v, 0.0, 1.0)
}

/// Largest paintable Phong exponent (the range the `Fast` approximation is specified on).
pub const N_MAX: f32 = 16384.0;

/// A material at one texel, linear values.
///
/// From a file, every field is checked ([`MaterialValueFile`]): a value out of range is an
/// error, never a clamped surprise.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MaterialValueFile")]
pub struct MaterialValue {
    /// Diffuse coefficient, linear RGB in `[0, 1]`.
    pub kd: Vec3,
    /// Specular coefficient, linear RGB in `[0, 1]` (coloured for metals).
    pub ks: Vec3,
    /// Phong exponent in `[0, N_MAX]`.
    pub n: f32,
}

/// A material value as a file spells it, before its ranges are checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialValueFile {
    kd: [f32; 3],
    ks: [f32; 3],
    n: f32,
}

impl TryFrom<MaterialValueFile> for MaterialValue {
    type Error = String;

    fn try_from(f: MaterialValueFile) -> Result<Self, String> {
        use super::check::{all_in_range, in_range};
        Ok(Self {
            kd: Vec3::from(all_in_range("kd", f.kd, 0.0, 1.0)?),
            ks: Vec3::from(all_in_range("ks", f.ks, 0.0, 1.0)?),
            n: in_range("n", f.n, 0.0, N_MAX)?,
        })
    }
}

impl MaterialValue {
    /// Builds a value, sanitising every field (see [`MaterialValue::sanitized`]).
    pub fn new(kd: Vec3, ks: Vec3, n: f32) -> Self {
        Self { kd, ks, n }.sanitized()
    }

    /// NaN -> 0; `k_d`, `k_s` clamped into `[0, 1]`; `n` into `[0, N_MAX]`.
    #[must_use]
    pub fn sanitized(self) -> Self {
        Self {
            kd: self.kd.map(unit),
            ks: self.ks.map(unit),
            n: clamp_nan_low(self.n, 0.0, N_MAX),
        }
    }

    /// The value as it reads back after storage (quantised).
    #[must_use]
    pub fn quantized(self) -> Self {
        Texel::encode(self).decode()
    }
}

impl Default for MaterialValue {
    /// A neutral grey plastic.
    fn default() -> Self {
        Self {
            kd: Vec3::splat(0.5),
            ks: Vec3::splat(0.25),
            n: 32.0,
        }
    }
}

/// Which channels an operation writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Channels {
    /// Write `k_d`.
    pub kd: bool,
    /// Write `k_s`.
    pub ks: bool,
    /// Write `n`.
    pub n: bool,
}

impl Channels {
    /// Every channel.
    pub const ALL: Self = Self {
        kd: true,
        ks: true,
        n: true,
    };
    /// No channel.
    pub const NONE: Self = Self {
        kd: false,
        ks: false,
        n: false,
    };

    /// True when no channel is enabled.
    pub fn is_empty(self) -> bool {
        !(self.kd || self.ks || self.n)
    }

    /// The channels enabled in either.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self {
            kd: self.kd || other.kd,
            ks: self.ks || other.ks,
            n: self.n || other.n,
        }
    }
}

impl Default for Channels {
    fn default() -> Self {
        Self::ALL
    }
}

/// One channel, for tools that act on a single one (fill tolerance, views, import).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Channel {
    /// Diffuse coefficient (RGB).
    Kd,
    /// Specular coefficient (RGB).
    Ks,
    /// Phong exponent.
    N,
}

impl Channel {
    /// All channels in storage order.
    pub const ALL: [Self; 3] = [Self::Kd, Self::Ks, Self::N];

    /// The name people read: `k_d`, `k_s`, `n` (the editor's panels, messages and tools).
    pub fn label(self) -> &'static str {
        match self {
            Self::Kd => "k_d",
            Self::Ks => "k_s",
            Self::N => "n",
        }
    }

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Kd => "kd",
            Self::Ks => "ks",
            Self::N => "n",
        }
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The set holding only this channel.
    pub fn only(self) -> Channels {
        Channels {
            kd: self == Self::Kd,
            ks: self == Self::Ks,
            n: self == Self::N,
        }
    }
}

/// One texel as stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Texel {
    /// `k_d` as unorm16 RGB.
    pub kd: [u16; 3],
    /// `k_s` as unorm16 RGB.
    pub ks: [u16; 3],
    /// `n` as IEEE half-float bits.
    pub n: u16,
}

impl Texel {
    /// Encodes a (sanitised) value.
    pub fn encode(v: MaterialValue) -> Self {
        Self {
            kd: encode_rgb(v.kd),
            ks: encode_rgb(v.ks),
            n: encode_n(v.n),
        }
    }

    /// Decodes to linear values.
    pub fn decode(self) -> MaterialValue {
        MaterialValue {
            kd: decode_rgb(self.kd),
            ks: decode_rgb(self.ks),
            n: decode_n(self.n),
        }
    }
}

/// `[0, 1]` (NaN -> 0) to unorm16, rounding to nearest.
#[inline]
pub fn encode_unorm(v: f32) -> u16 {
    // In range, the same as `as u16`; the u32 holds at most 65535.
    trunc_small(unit(v) * 65535.0 + 0.5) as u16
}

/// `y as u32` for a `y` in `[0, 2^22)`, in plain float arithmetic: no saturating
/// conversion (a compare and branches per value), so loops of it vectorise.
///
/// Adding 2^23 leaves no fraction bits: `(y + 2^23) - 2^23` is `y` rounded to the nearest
/// integer, exactly; one less where that rounded up is the floor, which for `y >= 0` is the
/// truncation; and `floor + 2^23` holds it in its low mantissa bits.
#[inline]
pub fn trunc_small(y: f32) -> u32 {
    const SHIFT: f32 = 8_388_608.0;
    let near = (y + SHIFT) - SHIFT;
    let floor = near - if near > y { 1.0 } else { 0.0 };
    (floor + SHIFT).to_bits() - SHIFT.to_bits()
}

/// unorm16 to `[0, 1]`.
#[inline]
pub fn decode_unorm(q: u16) -> f32 {
    f32::from(q) * (1.0 / 65535.0)
}

/// Encodes an RGB triple.
#[inline]
pub fn encode_rgb(v: Vec3) -> [u16; 3] {
    [encode_unorm(v.x), encode_unorm(v.y), encode_unorm(v.z)]
}

/// Decodes an RGB triple.
#[inline]
pub fn decode_rgb(q: [u16; 3]) -> Vec3 {
    Vec3::new(decode_unorm(q[0]), decode_unorm(q[1]), decode_unorm(q[2]))
}

/// `n` (NaN -> 0, clamped into `[0, N_MAX]`) to half-float bits.
#[inline]
pub fn encode_n(n: f32) -> u16 {
    f16::from_f32(clamp_nan_low(n, 0.0, N_MAX)).to_bits()
}

/// Half-float bits to `n`. Bits that are not a valid stored exponent (negative, NaN, above
/// `N_MAX`) decode to the nearest valid value, so a corrupt map never yields NaN.
#[inline]
pub fn decode_n(bits: u16) -> f32 {
    clamp_nan_low(f16::from_bits(bits).to_f32(), 0.0, N_MAX)
}

/// `ln(1 + N_MAX)`: the top of the perceptual `n` scale.
fn ln_n_span() -> f32 {
    N_MAX.ln_1p()
}

/// `n` to the perceptual blend space `[0, 1]`: `ln(1 + n) / ln(1 + N_MAX)`.
#[inline]
pub fn n_to_blend(n: f32) -> f32 {
    n.max(0.0).ln_1p() / ln_n_span()
}

/// The inverse of [`n_to_blend`].
#[inline]
pub fn n_from_blend(u: f32) -> f32 {
    (unit(u) * ln_n_span()).exp_m1().min(N_MAX)
}

/// sRGB-encoded component to linear (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear component to sRGB encoding (IEC 61966-2-1).
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = unit(c);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear component to an 8-bit sRGB code, rounded.
pub fn linear_to_srgb8(c: f32) -> u8 {
    (linear_to_srgb(c) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trunc_small_is_the_conversion_it_replaces() {
        // Every float bit pattern in [0, 2^22) at a prime stride, and every integer, half and
        // neighbour of them up to 2^18 + 1 (the largest argument the encoders pass).
        let top = (1u32 << 22) as f32;
        let strided = (0..top.to_bits()).step_by(7919).map(f32::from_bits);
        let near_integers = (0..=(1u32 << 18) + 1).flat_map(|i| {
            let f = i as f32;
            [
                f,
                f + 0.5,
                f.next_down().max(0.0),
                f.next_up(),
                (f + 0.5).next_down(),
            ]
        });
        for y in strided.chain(near_integers) {
            assert_eq!(trunc_small(y), y as u32, "{y}");
        }
        // encode_unorm as it was written before: through a saturating conversion.
        for bits in (0..=1.0f32.to_bits() + 1).step_by(101) {
            let v = f32::from_bits(bits);
            assert_eq!(encode_unorm(v), (unit(v) * 65535.0 + 0.5) as u16, "{v}");
        }
        for q in 0..=u16::MAX {
            assert_eq!(encode_unorm(decode_unorm(q)), q);
        }
        assert_eq!(encode_unorm(f32::NAN), 0);
        assert_eq!(encode_unorm(f32::INFINITY), u16::MAX);
        assert_eq!(encode_unorm(-1.0), 0);
    }

    #[test]
    fn n_step_is_below_a_tenth_of_a_percent() {
        // Walk every stored code from the smallest normal half float (6.1e-5) to N_MAX: the
        // relative step between neighbours.
        let mut worst = 0.0_f32;
        let mut bits = half::f16::MIN_POSITIVE.to_bits();
        while decode_n(bits) < N_MAX {
            let (a, b) = (decode_n(bits), decode_n(bits + 1));
            worst = worst.max((b - a) / a);
            bits += 1;
        }
        assert!(worst <= 0.001, "worst relative step {worst}");
        // The step is 2^-10 at the bottom of each binade.
        assert!((worst - 2.0_f32.powi(-10)).abs() < 1e-6, "{worst}");
        // Below the normal range the absolute step is 6e-8.
        assert!(decode_n(1) < 1e-7);
        assert_eq!(decode_n(encode_n(0.0)), 0.0);
        assert_eq!(decode_n(encode_n(N_MAX)), N_MAX);
    }

    #[test]
    fn encodings_round_trip_and_sanitize() {
        for q in [0u16, 1, 2, 32767, 65534, 65535] {
            assert_eq!(encode_unorm(decode_unorm(q)), q);
        }
        assert_eq!(encode_unorm(f32::NAN), 0);
        assert_eq!(encode_unorm(7.0), 65535);
        assert_eq!(encode_n(f32::NAN), 0);
        assert_eq!(decode_n(encode_n(1e9)), N_MAX);
        // Corrupt bits decode to something valid.
        assert_eq!(decode_n(0xFC00), 0.0); // -inf
        assert_eq!(decode_n(0x7E00), 0.0); // NaN
        assert_eq!(decode_n(0x7C00), N_MAX); // +inf
    }

    #[test]
    fn blend_space_round_trips() {
        for n in [0.0, 0.5, 1.0, 32.0, 1000.0, N_MAX] {
            let back = n_from_blend(n_to_blend(n));
            assert!((back - n).abs() <= 1e-3 * (1.0 + n), "{n} -> {back}");
        }
        assert_eq!(n_to_blend(0.0), 0.0);
        assert!((n_to_blend(N_MAX) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn srgb_round_trips() {
        for i in 0..=255 {
            let c = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
    }
}
