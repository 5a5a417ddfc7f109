//! The `k_a` error of a set as a consumer decodes it, against the texels it was made from.

use rayon::prelude::*;

use super::encode::StoredImage;
use super::manifest::{Comp, Constants};
use super::perceptual::{SrgbError, SrgbLevels, SrgbStats};
use crate::encoding::KaError;
use crate::encoding::NEncoding;
use crate::preset::Format;
use kapaint_model::texel::{
    Texel, decode_n, decode_unorm, n_from_blend, n_to_blend, srgb_to_linear,
};
use kapaint_reflectance::{self as reflectance, AmbientApprox, ShadingModel};

/// Where a consumer's value of one component comes from.
#[derive(Clone, Copy)]
enum Read<'a> {
    /// Through a table per stored 16-bit code (constants, 16-bit and float files).
    Table(&'a [f32]),
    /// A table per byte of an 8-bit file as written (after block compression).
    Bytes {
        data: &'a [u8],
        stride: usize,
        offset: usize,
        table: &'a [f32],
    },
    /// A table per half float (its bits) of a BC6H file as decoded: `stride` and `offset` in
    /// bytes.
    Halves {
        data: &'a [u8],
        stride: usize,
        offset: usize,
        table: &'a [f32],
    },
}

impl Read<'_> {
    fn get(self, i: usize, code: u16) -> f32 {
        match self {
            Self::Table(t) => t[code as usize],
            Self::Bytes {
                data,
                stride,
                offset,
                table,
            } => table[data[i * stride + offset] as usize],
            Self::Halves {
                data,
                stride,
                offset,
                table,
            } => {
                let at = i * stride + offset;
                table[u16::from_le_bytes([data[at], data[at + 1]]) as usize]
            }
        }
    }
}

/// What a stored colour component stands for, in linear light: per byte of an sRGB or a
/// linear 8-bit image, and per half float (by its bits; negatives as 0, what an unsigned
/// BC6H decodes).
struct ColourTables {
    srgb8: Vec<f32>,
    linear8: Vec<f32>,
    halves: Vec<f32>,
}

impl ColourTables {
    fn new() -> Self {
        Self {
            srgb8: (0..=255_u8)
                .map(|b| srgb_to_linear(f32::from(b) / 255.0))
                .collect(),
            linear8: (0..=255_u8).map(|b| f32::from(b) / 255.0).collect(),
            halves: (0..=u16::MAX)
                .map(|b| half::f16::from_bits(b).to_f32().max(0.0))
                .collect(),
        }
    }

    /// The first of `want` that an image holds.
    fn read<'r>(&'r self, stored: &'r [StoredImage<'_>], want: &[Comp]) -> Option<Read<'r>> {
        in_file(stored, want, &self.srgb8, &self.linear8, Some(&self.halves))
    }
}

/// The first of `want` that an image holds: an 8-bit image's through `table` (sRGB image)
/// or `linear`, a BC6H image's through `halves` (colour only).
fn in_file<'r>(
    stored: &'r [StoredImage<'_>],
    want: &[Comp],
    table: &'r [f32],
    linear: &'r [f32],
    halves: Option<&'r [f32]>,
) -> Option<Read<'r>> {
    want.iter().find_map(|w| {
        stored.iter().find_map(|image| {
            let offset = image.comps.iter().position(|c| c == w)?;
            if image.half {
                return Some(Read::Halves {
                    data: &image.data[..],
                    stride: image.comps.len() * 2,
                    offset: offset * 2,
                    table: halves?,
                });
            }
            Some(Read::Bytes {
                data: &image.data[..],
                stride: image.comps.len(),
                offset,
                table: if image.srgb { table } else { linear },
            })
        })
    })
}

/// What a measure needs of a set besides its images: the row length, the constants, and how
/// stored `n` decodes.
#[derive(Clone, Copy)]
pub(super) struct Shape<'a> {
    /// Texels per row of level 0.
    pub width: u32,
    /// Constant channels.
    pub constants: &'a Constants,
    /// `n`'s encoding, where it is stored in an integer image.
    pub n_encoding: Option<NEncoding>,
}

/// The `k_a` error of the set described by `manifest` against the texels it was made from,
/// relative per texel and colour channel and in sRGB levels per texel
/// ([`super::perceptual`]): every value goes through what a consumer reads (the bytes an 8-bit
/// file holds after compression, or 16-bit and float codes by table) and back.
pub(super) fn ka_error_of_set(
    texels: &[Texel],
    manifest: Shape<'_>,
    stored: &[StoredImage<'_>],
    format: Format,
    model: ShadingModel,
    approx: AmbientApprox,
) -> (KaError, SrgbError) {
    let lut = kapaint_model::maps::chi_lut(model, approx);
    let tables = SetTables::new(lut, manifest.n_encoding, model, approx);
    let colours = ColourTables::new();
    let reads = tables.reads(&colours, stored, manifest.constants, format);
    let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
    compare(texels, manifest.width, lut, &tables.exact, diffuse, &reads)
}

/// The tables a set's values are read through.
struct SetTables {
    /// Every 16-bit unorm code's value.
    exact: Vec<f32>,
    /// The same, through a 16-bit file.
    sixteen: Vec<f32>,
    /// `[chi_1, chi_0]` of every half-float `n` (`chi_0` = 0 but for Cook-Torrance).
    chi: [Vec<f32>; 2],
    /// The same, of what the set decodes of each `n`.
    chi_of_set: [Vec<f32>; 2],
    /// The same, of each byte of `n`'s 8-bit encoding.
    chi8: [Vec<f32>; 2],
}

/// The three channels' reads: `k_d` and `k_s` per colour component, `[chi_1, chi_0]` of `n`.
type Reads<'a> = ([Read<'a>; 3], [Read<'a>; 3], [Read<'a>; 2]);

impl SetTables {
    fn new(
        lut: &[[f32; 2]],
        n_encoding: Option<NEncoding>,
        model: ShadingModel,
        approx: AmbientApprox,
    ) -> Self {
        let split = |pairs: &[[f32; 2]]| -> [Vec<f32>; 2] {
            [0, 1].map(|k| pairs.iter().map(|p| p[k]).collect())
        };
        let exact: Vec<f32> = (0..=u16::MAX).map(decode_unorm).collect();
        let sixteen = exact
            .iter()
            .map(|v| (v * 65535.0).round() / 65535.0)
            .collect();
        // n: stored half-float bits -> chi of what the set decodes.
        let chi_of_set = split(
            &(0..=u16::MAX)
                .map(|bits| match n_encoding {
                    Some(e) => reflectance::chi_parts_f32(
                        model,
                        approx,
                        e.decode(e.encode(decode_n(bits))),
                    ),
                    None => lut[bits as usize],
                })
                .collect::<Vec<_>>(),
        );
        let chi8 = split(
            &(0..=255_u16)
                .map(|q| {
                    n_encoding.map_or([0.0; 2], |e| {
                        reflectance::chi_parts_f32(
                            model,
                            approx,
                            e.decode(q.min((1 << e.bits) - 1)),
                        )
                    })
                })
                .collect::<Vec<_>>(),
        );
        Self {
            exact,
            sixteen,
            chi: split(lut),
            chi_of_set,
            chi8,
        }
    }

    /// Where each component of the set comes from: an 8-bit file's bytes, else a table.
    fn reads<'a>(
        &'a self,
        colours: &'a ColourTables,
        stored: &'a [StoredImage<'_>],
        constants: &Constants,
        format: Format,
    ) -> Reads<'a> {
        let colour_table: &[f32] = if format == Format::Png16 {
            &self.sixteen
        } else {
            &self.exact
        };
        let kd = std::array::from_fn(|c| {
            if constants.kd.is_some() {
                Read::Table(&self.exact)
            } else {
                colours
                    .read(stored, &[Comp::Kd(c)])
                    .unwrap_or(Read::Table(colour_table))
            }
        });
        let ks = std::array::from_fn(|c| {
            if constants.ks.is_some() {
                Read::Table(&self.exact)
            } else {
                colours
                    .read(stored, &[Comp::Ks(c), Comp::Ks(0)])
                    .unwrap_or(Read::Table(colour_table))
            }
        });
        let n = std::array::from_fn(|k| {
            if constants.n.is_some() {
                Read::Table(&self.chi[k])
            } else {
                in_file(stored, &[Comp::N], &self.chi8[k], &self.chi8[k], None)
                    .unwrap_or(Read::Table(&self.chi_of_set[k]))
            }
        });
        (kd, ks, n)
    }
}

/// What the measures add up as they go: the relative error's max, sum and count (per
/// channel), and the texels' sRGB-level errors.
struct Acc {
    max: f64,
    sum: f64,
    count: u64,
    srgb: SrgbStats,
}

impl Acc {
    fn new() -> Self {
        Self {
            max: 0.0,
            sum: 0.0,
            count: 0,
            srgb: SrgbStats::new(),
        }
    }

    /// One texel: its exact `k_a` and the one read back.
    #[inline]
    fn add(&mut self, levels: &SrgbLevels, want: [f32; 3], got: [f32; 3]) {
        for c in 0..3 {
            let err = if want[c] > 0.0 {
                f64::from((got[c] - want[c]).abs() / want[c])
            } else {
                0.0
            };
            self.max = self.max.max(err);
            self.sum += err;
        }
        self.count += 3;
        self.srgb.add(levels.distance(want, got));
    }

    fn merge(mut self, other: &Self) -> Self {
        self.max = self.max.max(other.max);
        self.sum += other.sum;
        self.count += other.count;
        self.srgb = self.srgb.merge(&other.srgb);
        self
    }

    fn finish(self) -> (KaError, SrgbError) {
        (
            KaError {
                max: self.max,
                mean: if self.count > 0 {
                    self.sum / self.count as f64
                } else {
                    0.0
                },
            },
            self.srgb.summary(),
        )
    }
}

/// The `k_a` error of every texel's components, read through `reads`, against the exact
/// texels: relative (max and mean per channel) and in sRGB levels.
fn compare(
    texels: &[Texel],
    width: u32,
    lut: &[[f32; 2]],
    exact: &[f32],
    diffuse: f32,
    (kd, ks, n): &Reads<'_>,
) -> (KaError, SrgbError) {
    let w = width as usize;
    let levels = SrgbLevels::new();
    texels
        .par_chunks(w)
        .enumerate()
        .fold(Acc::new, |mut acc, (y, row)| {
            for (x, t) in row.iter().enumerate() {
                let i = y * w + x;
                let [chi_t, offset_t] = lut[t.n as usize];
                let (chi_b, offset_b) = (n[0].get(i, t.n), n[1].get(i, t.n));
                let want = std::array::from_fn(|c| {
                    diffuse * exact[t.kd[c] as usize] + exact[t.ks[c] as usize] * chi_t + offset_t
                });
                let got = std::array::from_fn(|c| {
                    diffuse * kd[c].get(i, t.kd[c]) + ks[c].get(i, t.ks[c]) * chi_b + offset_b
                });
                acc.add(&levels, want, got);
            }
            acc
        })
        .reduce(Acc::new, |a, b| a.merge(&b))
        .finish()
}

/// The `k_a` error of one mip level as a consumer decodes it (`stored`: the level's images,
/// decoded) against `reference` ([`reference_levels`]): relative per texel and colour
/// channel, and in sRGB levels per texel.
pub(super) fn ka_error_of_level(
    shape: Shape<'_>,
    stored: &[StoredImage<'_>],
    reference: &[[f32; 3]],
    model: ShadingModel,
    approx: AmbientApprox,
) -> (KaError, SrgbError) {
    let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
    let tables = ColourTables::new();
    let chi_of = |n: f32| reflectance::chi_parts_f32(model, approx, n);
    let chi8: [Vec<f32>; 2] = [0, 1].map(|k| {
        (0..=255_u16)
            .map(|q| shape.n_encoding.map_or(0.0, |e| chi_of(e.decode(q))[k]))
            .collect()
    });
    let kd_const = shape.constants.kd.map(|v| v.map(|c| [c]));
    let ks_const = shape.constants.ks.map(|v| v.map(|c| [c]));
    let n_const = shape.constants.n.map(|n| chi_of(n).map(|c| [c]));
    let zero = [0.0_f32];
    let kd: [Read<'_>; 3] = std::array::from_fn(|c| match &kd_const {
        Some(v) => Read::Table(&v[c]),
        None => tables
            .read(stored, &[Comp::Kd(c)])
            .unwrap_or(Read::Table(&zero)),
    });
    let ks: [Read<'_>; 3] = std::array::from_fn(|c| match &ks_const {
        Some(v) => Read::Table(&v[c]),
        None => tables
            .read(stored, &[Comp::Ks(c), Comp::Ks(0)])
            .unwrap_or(Read::Table(&zero)),
    });
    let n: [Read<'_>; 2] = std::array::from_fn(|k| match &n_const {
        Some(v) => Read::Table(&v[k]),
        None => in_file(stored, &[Comp::N], &chi8[k], &chi8[k], None).unwrap_or(Read::Table(&zero)),
    });
    let levels = SrgbLevels::new();
    reference
        .par_iter()
        .enumerate()
        .fold(Acc::new, |mut acc, (i, want)| {
            let (chi, offset) = (n[0].get(i, 0), n[1].get(i, 0));
            let got =
                std::array::from_fn(|c| diffuse * kd[c].get(i, 0) + ks[c].get(i, 0) * chi + offset);
            acc.add(&levels, *want, got);
            acc
        })
        .reduce(Acc::new, |a, b| a.merge(&b))
        .finish()
}

/// The reference of every mip level past 0 (see [`ka_error_of_level`]): the `k_a` of what
/// the level should hold before it is stored, the exact texels averaged as the mips average
/// them (`k_d` and `k_s` in linear light, `n` in the brushes' log space), level after level
/// (2x2 boxes, clamped at odd edges). So a level's error is what storing it costs, as at
/// level 0, and not the filter's own choice of `n`.
pub(super) fn reference_levels(
    texels: &[Texel],
    (w, h): (u32, u32),
    model: ShadingModel,
    approx: AmbientApprox,
) -> Vec<Vec<[f32; 3]>> {
    let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
    // k_d, k_s (linear), n in blend space.
    let exact = |t: &Texel| -> [f32; 7] {
        let mut v = [0.0; 7];
        for c in 0..3 {
            v[c] = decode_unorm(t.kd[c]);
            v[3 + c] = decode_unorm(t.ks[c]);
        }
        v[6] = n_to_blend(decode_n(t.n));
        v
    };
    let mut out: Vec<Vec<[f32; 3]>> = Vec::new();
    let mut size = (w, h);
    let mut prev: Option<Vec<[f32; 7]>> = None;
    for _ in 1..crate::ktx::level_count(w, h) {
        let next = crate::ktx::box_down(size, |i| match &prev {
            None => exact(&texels[i]),
            Some(p) => p[i],
        });
        size = ((size.0 / 2).max(1), (size.1 / 2).max(1));
        out.push(
            next.par_iter()
                .map(|v| {
                    let [chi, offset] =
                        reflectance::chi_parts_f32(model, approx, n_from_blend(v[6]));
                    std::array::from_fn(|c| diffuse * v[c] + v[3 + c] * chi + offset)
                })
                .collect(),
        );
        prev = Some(next);
    }
    out
}
