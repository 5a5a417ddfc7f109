//! The `k_a` error of a set as a consumer decodes it, against the texels it was made from.

use rayon::prelude::*;

use super::encode::StoredImage;
use super::manifest::{Comp, Manifest};
use crate::export::encoding::KaError;
use crate::export::preset::Format;
use crate::model::texel::{Texel, decode_n, decode_unorm, srgb_to_linear};
use crate::reflectance::{self, AmbientApprox, ShadingModel};

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
        }
    }
}

/// The first of `want` that an 8-bit image holds, read through `table` (sRGB image) or
/// `linear`.
fn in_file<'r>(
    stored: &'r [StoredImage],
    want: &[Comp],
    table: &'r [f32],
    linear: &'r [f32],
) -> Option<Read<'r>> {
    want.iter().find_map(|w| {
        stored.iter().find_map(|image| {
            let offset = image.comps.iter().position(|c| c == w)?;
            Some(Read::Bytes {
                data: &image.data,
                stride: image.comps.len(),
                offset,
                table: if image.srgb { table } else { linear },
            })
        })
    })
}

/// Relative `k_a` error of the set described by `manifest` against the texels it was made
/// from, per texel and colour channel: every value goes through what a consumer reads (the
/// bytes an 8-bit file holds after compression, or 16-bit and float codes by table) and back.
pub(super) fn ka_error_of_set(
    texels: &[Texel],
    manifest: &Manifest,
    stored: &[StoredImage],
    format: Format,
    model: ShadingModel,
    approx: AmbientApprox,
) -> KaError {
    let lut = crate::model::maps::chi_lut(model, approx);
    // [chi_1, chi_0] as two tables (chi_0 = 0 but for Cook-Torrance).
    let split = |pairs: &[[f32; 2]]| -> [Vec<f32>; 2] {
        [0, 1].map(|k| pairs.iter().map(|p| p[k]).collect())
    };
    let chi = split(lut);
    let diffuse = reflectance::diffuse_factor(approx.for_model(model)) as f32;
    let exact: Vec<f32> = (0..=u16::MAX).map(decode_unorm).collect();
    let sixteen: Vec<f32> = exact
        .iter()
        .map(|v| (v * 65535.0).round() / 65535.0)
        .collect();
    // n: stored half-float bits -> chi of what the set decodes.
    let chi_of_set = split(
        &(0..=u16::MAX)
            .map(|bits| match manifest.n_encoding {
                Some(e) => {
                    reflectance::chi_parts_f32(model, approx, e.decode(e.encode(decode_n(bits))))
                }
                None => lut[bits as usize],
            })
            .collect::<Vec<_>>(),
    );
    let srgb8: Vec<f32> = (0..=255_u8)
        .map(|b| srgb_to_linear(f32::from(b) / 255.0))
        .collect();
    let linear8: Vec<f32> = (0..=255_u8).map(|b| f32::from(b) / 255.0).collect();
    let chi8 = split(
        &(0..=255_u16)
            .map(|q| {
                manifest.n_encoding.map_or([0.0; 2], |e| {
                    reflectance::chi_parts_f32(model, approx, e.decode(q.min((1 << e.bits) - 1)))
                })
            })
            .collect::<Vec<_>>(),
    );
    // The source of each component: an 8-bit file's bytes, else a table.
    let colour_table: &[f32] = if format == Format::Png16 {
        &sixteen
    } else {
        &exact
    };
    let kd: [Read<'_>; 3] = std::array::from_fn(|c| {
        if manifest.constants.kd.is_some() {
            Read::Table(&exact)
        } else {
            in_file(stored, &[Comp::Kd(c)], &srgb8, &linear8).unwrap_or(Read::Table(colour_table))
        }
    });
    let ks: [Read<'_>; 3] = std::array::from_fn(|c| {
        if manifest.constants.ks.is_some() {
            Read::Table(&exact)
        } else {
            in_file(stored, &[Comp::Ks(c), Comp::Ks(0)], &srgb8, &linear8)
                .unwrap_or(Read::Table(colour_table))
        }
    });
    let n: [Read<'_>; 2] = std::array::from_fn(|k| {
        if manifest.constants.n.is_some() {
            Read::Table(&chi[k])
        } else {
            in_file(stored, &[Comp::N], &chi8[k], &chi8[k]).unwrap_or(Read::Table(&chi_of_set[k]))
        }
    });
    let w = manifest.width as usize;
    let (max, sum, count) = texels
        .par_chunks(w)
        .enumerate()
        .map(|(y, row)| {
            let (mut max, mut sum) = (0.0_f64, 0.0_f64);
            for (x, t) in row.iter().enumerate() {
                let i = y * w + x;
                let [chi_t, offset_t] = lut[t.n as usize];
                let (chi_b, offset_b) = (n[0].get(i, t.n), n[1].get(i, t.n));
                for c in 0..3 {
                    let ka = diffuse * exact[t.kd[c] as usize]
                        + exact[t.ks[c] as usize] * chi_t
                        + offset_t;
                    let kb =
                        diffuse * kd[c].get(i, t.kd[c]) + ks[c].get(i, t.ks[c]) * chi_b + offset_b;
                    let err = if ka > 0.0 {
                        f64::from((kb - ka).abs() / ka)
                    } else {
                        0.0
                    };
                    max = max.max(err);
                    sum += err;
                }
            }
            (max, sum, row.len() as u64 * 3)
        })
        .reduce(
            || (0.0, 0.0, 0),
            |x, y| (x.0.max(y.0), x.1 + y.1, x.2 + y.2),
        );
    KaError {
        max,
        mean: if count > 0 { sum / count as f64 } else { 0.0 },
    }
}
