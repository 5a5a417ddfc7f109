//! Mip levels: each component averaged in its own space ([`Space`]), colour in linear
//! light, `n` in the log space the brushes blend it in, and stored through exact byte
//! boundaries (or as half floats).

use half::f16;
use rayon::prelude::*;

use super::{Source, Values};
use crate::encoding::NEncoding;
use kapaint_model::texel::{n_to_blend, srgb_to_linear};

/// How a component is averaged into the next mip level, and stored as a byte.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Space {
    /// Colour: averaged in linear light, stored sRGB-encoded.
    Srgb,
    /// Averaged and stored as is (`[0, 1]`).
    Linear,
    /// `n`: averaged in the brushes' log space ([`n_to_blend`]), stored as the 8-bit code of
    /// its encoding.
    N(NEncoding),
    /// Colour: averaged in linear light, stored as a linear half float (two bytes,
    /// little-endian; BC6H's input).
    Half,
}

impl Space {
    /// Bytes a stored component takes.
    pub fn bytes(self) -> usize {
        if self == Self::Half { 2 } else { 1 }
    }

    /// The 255 boundaries between consecutive bytes, in the averaging space: a value's byte
    /// is the number of boundaries at or below it (rounding to the nearest stored value).
    /// Half floats round by themselves: none.
    pub fn boundaries(self) -> Vec<f32> {
        if self == Self::Half {
            return Vec::new();
        }
        (0..255)
            .map(|b| {
                let mid = (f64::from(b) + 0.5) / 255.0;
                match self {
                    Self::Srgb => srgb_to_linear(mid as f32),
                    Self::Linear | Self::Half => mid as f32,
                    Self::N(e) if e.lo >= e.hi => f32::INFINITY,
                    Self::N(e) => n_to_blend(e.decode_fraction(mid)),
                }
            })
            .collect()
    }

    /// The value in the averaging space that a stored byte stands for (for
    /// [`Space::Half`], the byte as a fraction of 255).
    pub fn value_of(self, byte: u8) -> f32 {
        let v = f32::from(byte) / 255.0;
        match self {
            Self::Srgb => srgb_to_linear(v),
            Self::Linear | Self::Half => v,
            Self::N(e) => n_to_blend(e.decode(u16::from(byte))),
        }
    }

    /// Stores `v` (in the averaging space) at the start of `out`: a byte between
    /// `boundaries`, or a half float.
    #[inline]
    pub fn store(self, boundaries: &[f32], v: f32, out: &mut [u8]) {
        if self == Self::Half {
            out[..2].copy_from_slice(&f16::from_f32(v.max(0.0)).to_le_bytes());
        } else {
            out[0] = quantise(boundaries, v);
        }
    }

    pub(crate) fn is_colour(self) -> bool {
        self == Self::Srgb
    }
}

/// Bytes per texel of components in `spaces`, and each component's offset in it.
pub fn texel_layout(spaces: &[Space]) -> (usize, Vec<usize>) {
    let mut at = 0;
    let offsets = spaces
        .iter()
        .map(|s| {
            let o = at;
            at += s.bytes();
            o
        })
        .collect();
    (at, offsets)
}

/// The byte of `v` between `boundaries` ([`Space::boundaries`]).
#[inline]
pub fn quantise(boundaries: &[f32], v: f32) -> u8 {
    boundaries.partition_point(|b| *b <= v) as u8
}

/// Mip levels in a full chain for a `w x h` image.
pub fn level_count(w: u32, h: u32) -> u32 {
    32 - w.max(h).leading_zeros()
}

/// The size of the level after `(w, h)`.
pub(super) fn half((w, h): (u32, u32)) -> (u32, u32) {
    ((w / 2).max(1), (h / 2).max(1))
}

/// One 2x2 box of the level `(w, h)`, clamped at odd edges: the four source indices of
/// output texel `(x, y)`.
fn footprint((w, h): (u32, u32), x: usize, y: usize) -> [usize; 4] {
    let (w, h) = (w as usize, h as usize);
    let xs = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
    let ys = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
    [
        ys[0] * w + xs[0],
        ys[0] * w + xs[1],
        ys[1] * w + xs[0],
        ys[1] * w + xs[1],
    ]
}

/// The 2x2 box mean (clamped at odd edges) of a level of `(w, h)` tuples given by `value`.
pub fn box_down<const N: usize>(
    size: (u32, u32),
    value: impl Fn(usize) -> [f32; N] + Sync,
) -> Vec<[f32; N]> {
    let (nw, nh) = half(size);
    (0..nw as usize * nh as usize)
        .into_par_iter()
        .map(|j| {
            let f = footprint(size, j % nw as usize, j / nw as usize);
            let mut sum = [0.0_f32; N];
            for i in f {
                let v = value(i);
                for c in 0..N {
                    sum[c] += v[c];
                }
            }
            sum.map(|s| s * 0.25)
        })
        .collect()
}

/// The next level of values (in the averaging space) from `value` over level `size`.
fn downsample(value: &dyn Values, size: (u32, u32), channels: usize) -> Vec<f32> {
    let (nw, nh) = half(size);
    let mut out = vec![0.0_f32; nw as usize * nh as usize * channels];
    out.par_chunks_mut(nw as usize * channels)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..nw as usize {
                let f = footprint(size, x, y);
                for k in 0..channels {
                    row[x * channels + k] =
                        f.iter().map(|i| value.value(*i, k)).sum::<f32>() * 0.25;
                }
            }
        });
    out
}

/// Levels 1 and on, as stored bytes (level 0 is the source's).
pub fn mips(source: &Source<'_>) -> Vec<((u32, u32), Vec<u8>)> {
    let ch = source.channels();
    let bounds: Vec<Vec<f32>> = source.spaces.iter().map(|s| s.boundaries()).collect();
    let (per, offsets) = texel_layout(source.spaces);
    let mut size = (source.width, source.height);
    let mut values: Option<Vec<f32>> = None;
    let mut out = Vec::new();
    for _ in 1..level_count(source.width, source.height) {
        let next = match &values {
            None => downsample(source.value, size, ch),
            Some(v) => downsample(&|i, k| v[i * ch + k], size, ch),
        };
        size = half(size);
        let mut bytes = vec![0_u8; next.len() / ch * per];
        bytes
            .par_chunks_mut(per)
            .zip(next.par_chunks(ch))
            .for_each(|(out, v)| {
                for (k, space) in source.spaces.iter().enumerate() {
                    space.store(&bounds[k], v[k], &mut out[offsets[k]..]);
                }
            });
        out.push((size, bytes));
        values = Some(next);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encoding::NCurve;
    use kapaint_model::texel::n_from_blend;

    #[test]
    fn quantising_by_boundaries_rounds_to_the_nearest_stored_value() {
        let e = NEncoding {
            curve: NCurve::Sqrt,
            lo: 2.0,
            hi: 3000.0,
            bits: 8,
        };
        for space in [Space::Srgb, Space::Linear, Space::N(e)] {
            let bounds = space.boundaries();
            for b in 0..=255_u8 {
                assert_eq!(quantise(&bounds, space.value_of(b)), b, "{space:?} {b}");
            }
        }
        // The same byte as the encodings' own rounding.
        let bounds = Space::N(e).boundaries();
        for n in [2.0, 2.5, 17.0, 400.0, 2999.0, 3000.0] {
            assert_eq!(
                u16::from(quantise(&bounds, n_to_blend(n))),
                e.encode(n),
                "{n}"
            );
        }
    }

    #[test]
    fn mips_average_colour_in_linear_light_and_n_in_log_space() {
        let e = NEncoding {
            curve: NCurve::Linear,
            lo: 1.0,
            hi: 3001.0,
            bits: 8,
        };
        // Black and white columns of k_d, n = 1 and 3001 likewise.
        let values: Vec<f32> = (0..4)
            .flat_map(|i| {
                let on = i % 2 == 1;
                [
                    if on { 1.0 } else { 0.0 },
                    n_to_blend(if on { 3001.0 } else { 1.0 }),
                ]
            })
            .collect();
        let value = |i: usize, k: usize| values[i * 2 + k];
        let next = downsample(&value, (2, 2), 2);
        assert!((next[0] - 0.5).abs() < 1e-6, "linear light");
        // The log-space mean of n: sqrt(2 * 3002) - 1, not 1501.
        let n = n_from_blend(next[1]);
        assert!((n - ((2.0_f32 * 3002.0).sqrt() - 1.0)).abs() < 0.05, "{n}");
        let bounds = Space::N(e).boundaries();
        assert_eq!(quantise(&bounds, next[1]), e.encode(n) as u8);
        assert!(Space::Srgb.boundaries()[127] > 0.2 && Space::Srgb.boundaries()[127] < 0.22);
    }
}
