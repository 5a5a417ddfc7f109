//! KTX2 files with a full mip chain: 8-bit components uncompressed, or block-compressed
//! (BC7 for three or four components, BC5 for two, BC4 for one, BC6H for three linear half
//! floats; or ASTC LDR of any footprint for one to four).
//!
//! The container is assembled from the `ktx2` crate's header, level index and data format
//! descriptor types (`container.rs`); blocks come from [`super::blocks`]; mips
//! (`levels.rs`) are 2x2 boxes, each component averaged in its own space ([`Space`]).

mod assembly;
mod basislz;
mod container;
mod levels;
mod own_levels;

use ktx2::Format as KtxFormat;
use rayon::prelude::*;

use self::assembly::Described;
pub use self::basislz::{etc1s_file, read_etc1s};
use self::container::container;
pub use self::container::{Decoded, ZSTD_LEVELS, decode, decode_image, supercompress};
pub use self::levels::{Space, box_down, level_count, mips, quantise, texel_layout};
pub use self::own_levels::encode_levels;
use super::blocks::{self, Coder};
use super::codec::{Codec, CodecError, Effort};
use crate::file_kind::Compression;
use kapaint_base::task::Progress;

/// Why a KTX2 file could not be written: what a caller acts on (a cancel ends an export
/// quietly; anything else is its error line).
#[derive(Debug, thiserror::Error)]
pub enum KtxError {
    /// The image cannot be stored so: an empty image, a component count outside 1..=4,
    /// levels that are not a full chain.
    #[error("cannot write {0}")]
    Shape(String),
    /// Half floats asked for uncompressed (they are written only as BC6H blocks).
    #[error("half floats are written only as BC6H blocks")]
    HalfUncompressed,
    /// The block codec failed.
    #[error(transparent)]
    Codec(#[from] CodecError),
    /// The container could not describe the format.
    #[error("data format descriptor: {0}")]
    Container(String),
    /// Cancelled through its [`Progress`].
    #[error("cancelled")]
    Cancelled,
}

/// A texel's component in its averaging space (`value(texel, component)`, unquantised).
pub trait Values: Sync {
    /// Texel `i`'s component `k`.
    fn value(&self, i: usize, k: usize) -> f32;
}

impl<F: Fn(usize, usize) -> f32 + Sync> Values for F {
    fn value(&self, i: usize, k: usize) -> f32 {
        self(i, k)
    }
}

/// An image to write: its size, each component's space, level 0 as stored bytes (per
/// component per texel, row major: one byte, or two for a half float) and, for the mips, each texel's value in the averaging
/// space (`value(texel, component)`, unquantised).
pub struct Source<'a> {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// One per component (1 to 4).
    pub spaces: &'a [Space],
    /// Level 0: `width * height` texels of [`texel_layout`] bytes.
    pub level0: &'a [u8],
    /// A texel's component in its averaging space.
    pub value: &'a dyn Values,
}

impl Source<'_> {
    fn channels(&self) -> usize {
        self.spaces.len()
    }

    /// Colour components are sRGB (three or four components whose first is colour).
    pub fn srgb(&self) -> bool {
        self.channels() >= 3 && self.spaces[0].is_colour()
    }

    /// Bytes per stored texel.
    fn texel_bytes(&self) -> usize {
        texel_layout(self.spaces).0
    }

    fn check(&self) -> Result<(), KtxError> {
        let (w, h, ch) = (self.width, self.height, self.channels());
        let half = self.spaces.iter().filter(|s| **s == Space::Half).count();
        if w == 0
            || h == 0
            || !(1..=4).contains(&ch)
            || (half > 0 && (half != ch || ch != 3))
            || self.level0.len() != w as usize * h as usize * self.texel_bytes()
        {
            return Err(KtxError::Shape(format!(
                "a {w}x{h} image of {ch} components"
            )));
        }
        Ok(())
    }
}

/// `bytes` (`per` per texel, `(w, h)`) padded to whole blocks by repeating the last row and
/// column.
fn pad(bytes: &[u8], (w, h): (u32, u32), per: usize, (pw, ph): (u32, u32)) -> Vec<u8> {
    let mut out = vec![0_u8; pw as usize * ph as usize * per];
    out.par_chunks_mut(pw as usize * per)
        .enumerate()
        .for_each(|(y, row)| {
            let sy = y.min(h as usize - 1);
            let src = &bytes[sy * w as usize * per..][..w as usize * per];
            row[..src.len()].copy_from_slice(src);
            for x in w as usize..pw as usize {
                row.copy_within((w as usize - 1) * per..w as usize * per, x * per);
            }
        });
    out
}

/// `channels` of `per` bytes per texel, cropped from `(pw, ph)` to `(w, h)`.
pub(super) fn crop(
    bytes: &[u8],
    pw: u32,
    (w, h): (u32, u32),
    per: usize,
    channels: usize,
) -> Vec<u8> {
    let mut out = vec![0_u8; w as usize * h as usize * channels];
    out.par_chunks_mut(w as usize * channels)
        .enumerate()
        .for_each(|(y, row)| {
            let src = &bytes[y * pw as usize * per..];
            for (x, t) in row.chunks_exact_mut(channels).enumerate() {
                t.copy_from_slice(&src[x * per..x * per + channels]);
            }
        });
    out
}

/// One level block-compressed: its blocks, and its texels as a consumer decodes them
/// (`channels` bytes per texel, the level's own size).
pub struct Compressed {
    /// The blocks.
    pub blocks: Vec<u8>,
    /// Decoded, cropped to the level.
    pub decoded: Vec<u8>,
    /// Per component, [`psnr`] of `decoded` against the level, once measured
    /// ([`Compressed::psnr`]).
    psnr: Option<Vec<Option<f64>>>,
}

impl Compressed {
    /// Per component, [`psnr`] of the decoded blocks against `level` (the texels they were
    /// encoded from, of components in `spaces`), measured once.
    pub fn psnr(&mut self, level: &[u8], spaces: &[Space]) -> &[Option<f64>] {
        self.psnr
            .get_or_insert_with(|| psnr(level, &self.decoded, spaces))
    }
}

/// Compresses one level (`channels` bytes per stored texel) as `codec` at `effort` with
/// `encoder`. Rows advance `progress`.
///
/// # Errors
/// The codec failed.
pub fn compress_level(
    encoder: Coder<'_>,
    (codec, effort): (&dyn Codec, Effort),
    bytes: &[u8],
    (w, h): (u32, u32),
    channels: usize,
    progress: Option<&Progress>,
) -> Result<Compressed, CodecError> {
    let (bw, bh) = codec.block_dims();
    let padded = (w.div_ceil(bw) * bw, h.div_ceil(bh) * bh);
    let input: std::borrow::Cow<'_, [u8]> = if padded == (w, h) {
        bytes.into()
    } else {
        pad(bytes, (w, h), channels, padded).into()
    };
    let blocks = blocks::encode_stored(encoder, codec, effort, &input, channels, padded, progress)?;
    let decoded = blocks::decode_stored(codec, &blocks, padded, channels)?;
    let decoded = if padded == (w, h) {
        decoded
    } else {
        crop(&decoded, padded.0, (w, h), channels, channels)
    };
    Ok(Compressed {
        blocks,
        decoded,
        psnr: None,
    })
}

/// Per component, PSNR (dB) of `decoded` against `reference` (texels of components in
/// `spaces`), `None` where they are identical. Bytes compare as stored (peak 255); half
/// floats compare sRGB-encoded, on the same scale, so a BC6H image's PSNR reads like a BC7
/// image's.
pub fn psnr(reference: &[u8], decoded: &[u8], spaces: &[Space]) -> Vec<Option<f64>> {
    /// Texels per parallel run: a run of both images stays in cache while each component's
    /// differences are summed.
    const RUN: usize = 1 << 14;
    let (per, offsets) = texel_layout(spaces);
    let n = spaces.len();
    let sums = reference
        .par_chunks(per * RUN)
        .zip(decoded.par_chunks(per * RUN))
        .map(|(a, b)| {
            let pairs = || a.chunks_exact(per).zip(b.chunks_exact(per));
            (0..n)
                .map(|k| {
                    let o = offsets[k];
                    if spaces[k] == Space::Half {
                        let level = |t: &[u8]| {
                            f64::from(
                                HALF_LEVELS[usize::from(u16::from_le_bytes([t[o], t[o + 1]]))],
                            )
                        };
                        pairs().map(|(x, y)| (level(x) - level(y)).powi(2)).sum()
                    } else {
                        // Whole bytes: exact integer sums.
                        let sum: u64 = pairs()
                            .map(|(x, y)| u64::from(x[o].abs_diff(y[o])).pow(2))
                            .sum();
                        sum as f64
                    }
                })
                .collect::<Vec<f64>>()
        })
        .reduce(
            || vec![0.0; n],
            |x, y| x.iter().zip(&y).map(|(x, y)| x + y).collect(),
        );
    let texels = (reference.len() / per).max(1) as f64;
    sums.into_iter()
        .map(|sum| {
            let mse = sum / texels;
            (mse > 0.0).then(|| 10.0 * (255.0_f64 * 255.0 / mse).log10())
        })
        .collect()
}

/// Every half float's bits as the byte-scale level [`psnr`] compares: clamped to `[0, 1]`
/// (NaN as 0) and sRGB-encoded.
static HALF_LEVELS: std::sync::LazyLock<Vec<f32>> = std::sync::LazyLock::new(|| {
    (0..=u16::MAX)
        .map(|b| {
            let v = half::f16::from_bits(b).to_f32();
            let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
            kapaint_model::texel::linear_to_srgb(v) * 255.0
        })
        .collect()
});

/// A written KTX2 file.
#[derive(Clone, Debug)]
pub struct Written {
    /// The file.
    pub bytes: Vec<u8>,
    /// Every level as a consumer decodes it, finest first, texels as the source stores them.
    pub decoded: Vec<Vec<u8>>,
    /// Per component, PSNR (dB) of the decoded level 0 against the uncompressed 8-bit values,
    /// `None` where they are identical (`None` altogether for uncompressed files).
    pub psnr: Option<Vec<Option<f64>>>,
    /// Mip levels in the file.
    pub levels: u32,
    /// The file's compression: plain KTX2, or BC4, BC5, BC7, BC6H or ASTC blocks.
    pub compression: Compression,
}

/// What the KTX2 file of `spaces` components holds, and its compression's name: the codec's
/// blocks where block-compressed, else 8-bit components.
fn format_of(
    spaces: &[Space],
    srgb: bool,
    codec: Option<&dyn Codec>,
) -> Result<(Described, Compression), String> {
    if let Some(codec) = codec {
        return Ok((Described::of_codec(codec)?, codec.compression()));
    }
    let format = match spaces.len() {
        1 => KtxFormat::R8_UNORM,
        2 => KtxFormat::R8G8_UNORM,
        _ if srgb => KtxFormat::R8G8B8A8_SRGB,
        _ => KtxFormat::R8G8B8A8_UNORM,
    };
    Ok((Described::of_format(format)?, Compression::Ktx2))
}

/// How an image's blocks are made: the encoder, the codec and its effort.
pub type Blocks<'a> = (Coder<'a>, &'a dyn Codec, Effort);

/// Writes `source` as a KTX2 file with a full mip chain: uncompressed, or with
/// `compressed = Some((encoder, codec, effort))` block-compressed. `level0`, when given, is
/// level 0 already compressed (the export's effort search keeps the one it chose). Level 0's
/// rows advance `progress`; a cancel stops the block encoder between strips.
///
/// # Errors
/// An empty image, a component count outside 1..=4, half floats uncompressed or not as
/// three components ([`KtxError::Shape`], [`KtxError::HalfUncompressed`]), the codec's
/// failure, or [`KtxError::Cancelled`].
pub fn encode(
    source: &Source<'_>,
    compressed: Option<Blocks<'_>>,
    level0: Option<Compressed>,
    progress: &Progress,
) -> Result<Written, KtxError> {
    source.check()?;
    let chain = mips(source);
    let image = Image {
        spaces: source.spaces,
        size: (source.width, source.height),
        level0: source.level0,
        chain: &chain,
    };
    write_levels(&image, compressed, level0, progress)
}

/// An image's levels as stored bytes: level 0 and the chain after it.
struct Image<'a> {
    spaces: &'a [Space],
    size: (u32, u32),
    level0: &'a [u8],
    chain: &'a [((u32, u32), Vec<u8>)],
}

/// The KTX2 file of `image`'s levels, uncompressed or block-compressed (`level0`: level 0
/// already compressed).
fn write_levels(
    image: &Image<'_>,
    compressed: Option<Blocks<'_>>,
    level0: Option<Compressed>,
    progress: &Progress,
) -> Result<Written, KtxError> {
    let ((w, h), spaces, chain) = (image.size, image.spaces, image.chain);
    let ch = spaces.len();
    let per = texel_layout(spaces).0;
    let srgb = ch >= 3 && spaces[0].is_colour();
    if compressed.is_none() && per != ch {
        return Err(KtxError::HalfUncompressed);
    }
    let (described, compression) =
        format_of(spaces, srgb, compressed.map(|c| c.1)).map_err(KtxError::Container)?;
    let mut level_bytes = Vec::with_capacity(chain.len() + 1);
    let mut decoded = Vec::with_capacity(chain.len() + 1);
    let mut psnr_values = None;
    match compressed {
        None => {
            let widen = |bytes: &[u8]| -> Vec<u8> {
                if ch == 3 {
                    bytes
                        .chunks_exact(3)
                        .flat_map(|t| [t[0], t[1], t[2], 255])
                        .collect()
                } else {
                    bytes.to_vec()
                }
            };
            progress.advance(u64::from(h));
            level_bytes.push(widen(image.level0));
            decoded.push(image.level0.to_vec());
            for (_, bytes) in chain {
                level_bytes.push(widen(bytes));
                decoded.push(bytes.clone());
            }
        }
        Some((encoder, codec, effort)) => {
            let blocks = (codec, effort);
            let mut first = match level0 {
                Some(c) => {
                    progress.advance(u64::from(h));
                    c
                }
                None => compress_level(encoder, blocks, image.level0, (w, h), per, Some(progress))?,
            };
            if progress.is_cancelled() {
                return Err(KtxError::Cancelled);
            }
            psnr_values = Some(first.psnr(image.level0, spaces).to_vec());
            level_bytes.push(first.blocks);
            decoded.push(first.decoded);
            for (size, bytes) in chain {
                let c = compress_level(encoder, blocks, bytes, *size, per, None)?;
                level_bytes.push(c.blocks);
                decoded.push(c.decoded);
            }
        }
    }
    let bytes = container(&described, (w, h), &level_bytes);
    Ok(Written {
        bytes,
        decoded,
        psnr: psnr_values,
        levels: level_count(w, h),
        compression,
    })
}

#[cfg(test)]
mod tests;
