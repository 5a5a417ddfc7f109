//! KTX2 files with a full mip chain: 8-bit components uncompressed, or block-compressed
//! (BC7 for three or four components, BC5 for two, BC4 for one).
//!
//! The container is assembled from the `ktx2` crate's header, level index and data format
//! descriptor types (`container.rs`); blocks come from [`super::blocks`]; mips
//! (`levels.rs`) are 2x2 boxes, each component averaged in its own space ([`Space`]).

mod container;
mod levels;

use ktx2::Format as KtxFormat;
use rayon::prelude::*;

use self::container::container;
pub use self::container::{Decoded, decode};
pub use self::levels::{Space, box_down, level_count, mips, quantise};
use super::blocks::{self, BlockKind, Encoder};
use super::preset::Bc7Quality;
use super::set::Compression;
use crate::task::Progress;

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

/// An image to write: its size, each component's space, level 0 as stored bytes (one per
/// component per texel, row major) and, for the mips, each texel's value in the averaging
/// space (`value(texel, component)`, unquantised).
pub struct Source<'a> {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// One per component (1 to 4).
    pub spaces: &'a [Space],
    /// Level 0: `width * height * spaces.len()` bytes.
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

    fn check(&self) -> Result<(), String> {
        let (w, h, ch) = (self.width, self.height, self.channels());
        if w == 0
            || h == 0
            || !(1..=4).contains(&ch)
            || self.level0.len() != w as usize * h as usize * ch
        {
            return Err(format!("cannot write a {w}x{h} image of {ch} components"));
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
    let mut out = Vec::with_capacity(w as usize * h as usize * channels);
    for y in 0..h as usize {
        for x in 0..w as usize {
            out.extend_from_slice(&bytes[(y * pw as usize + x) * per..][..channels]);
        }
    }
    out
}

/// One level block-compressed: its blocks, and its texels as a consumer decodes them
/// (`channels` bytes per texel, the level's own size).
pub struct Compressed {
    /// The blocks.
    pub blocks: Vec<u8>,
    /// Decoded, cropped to the level.
    pub decoded: Vec<u8>,
}

/// Compresses one level (`channels` bytes per texel) as `kind` with `encoder`. Rows advance
/// `progress`.
pub fn compress_level(
    encoder: Encoder,
    kind: BlockKind,
    bytes: &[u8],
    (w, h): (u32, u32),
    channels: usize,
    progress: Option<&Progress>,
) -> Compressed {
    let per = kind.texel_bytes();
    let padded = (w.div_ceil(4) * 4, h.div_ceil(4) * 4);
    let widened: std::borrow::Cow<'_, [u8]> = if per == channels {
        bytes.into()
    } else {
        bytes
            .chunks_exact(channels)
            .flat_map(|t| {
                let mut px = [0, 0, 0, 255];
                px[..channels].copy_from_slice(t);
                px
            })
            .take(w as usize * h as usize * per)
            .collect::<Vec<u8>>()
            .into()
    };
    let input = if padded == (w, h) {
        widened
    } else {
        pad(&widened, (w, h), per, padded).into()
    };
    let blocks = blocks::encode(encoder, kind, &input, padded, progress);
    let decoded = blocks::decode(kind, &blocks, padded);
    let decoded = if padded == (w, h) && per == channels {
        decoded
    } else {
        crop(&decoded, padded.0, (w, h), per, channels)
    };
    Compressed { blocks, decoded }
}

/// Per component, PSNR (dB) of `decoded` against `reference` (`channels` bytes per texel),
/// `None` where they are identical.
pub fn psnr(reference: &[u8], decoded: &[u8], channels: usize) -> Vec<Option<f64>> {
    (0..channels)
        .map(|k| {
            let sum: u64 = reference
                .par_chunks(channels)
                .zip(decoded.par_chunks(channels))
                .map(|(a, b)| {
                    let d = i64::from(a[k]) - i64::from(b[k]);
                    (d * d) as u64
                })
                .sum();
            let mse = sum as f64 / (reference.len() / channels).max(1) as f64;
            (mse > 0.0).then(|| 10.0 * (255.0_f64 * 255.0 / mse).log10())
        })
        .collect()
}

/// A written KTX2 file.
#[derive(Clone, Debug)]
pub struct Written {
    /// The file.
    pub bytes: Vec<u8>,
    /// Every level as a consumer decodes it, finest first, `channels` bytes per texel.
    pub decoded: Vec<Vec<u8>>,
    /// Per component, PSNR (dB) of the decoded level 0 against the uncompressed 8-bit values,
    /// `None` where they are identical (`None` altogether for uncompressed files).
    pub psnr: Option<Vec<Option<f64>>>,
    /// Mip levels in the file.
    pub levels: u32,
    /// The file's compression: plain KTX2, or BC4, BC5 or BC7 blocks.
    pub compression: Compression,
}

/// The KTX2 format and compression name of `channels` components, block-compressed or not.
fn format_of(channels: usize, srgb: bool, compressed: bool) -> (KtxFormat, Compression) {
    match (compressed, channels) {
        (false, 1) => (KtxFormat::R8_UNORM, Compression::Ktx2),
        (false, 2) => (KtxFormat::R8G8_UNORM, Compression::Ktx2),
        (false, _) if srgb => (KtxFormat::R8G8B8A8_SRGB, Compression::Ktx2),
        (false, _) => (KtxFormat::R8G8B8A8_UNORM, Compression::Ktx2),
        (true, 1) => (KtxFormat::BC4_UNORM_BLOCK, Compression::Ktx2Bc4),
        (true, 2) => (KtxFormat::BC5_UNORM_BLOCK, Compression::Ktx2Bc5),
        (true, _) if srgb => (KtxFormat::BC7_SRGB_BLOCK, Compression::Ktx2Bc7),
        (true, _) => (KtxFormat::BC7_UNORM_BLOCK, Compression::Ktx2Bc7),
    }
}

/// Writes `source` as a KTX2 file with a full mip chain: uncompressed, or with
/// `compressed = Some((encoder, effort))` block-compressed. `level0`, when given, is level 0
/// already compressed (the export's effort search keeps the one it chose). Level 0's rows
/// advance `progress`; a cancel stops the block encoder between strips.
///
/// # Errors
/// An empty image, a component count outside 1..=4, or cancelled.
pub fn encode(
    source: &Source<'_>,
    compressed: Option<(Encoder, Bc7Quality)>,
    level0: Option<Compressed>,
    progress: &Progress,
) -> Result<Written, String> {
    source.check()?;
    let (w, h, ch) = (source.width, source.height, source.channels());
    let srgb = source.srgb();
    let (format, compression) = format_of(ch, srgb, compressed.is_some());
    let chain = mips(source);
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
            level_bytes.push(widen(source.level0));
            decoded.push(source.level0.to_vec());
            for (_, bytes) in &chain {
                level_bytes.push(widen(bytes));
                decoded.push(bytes.clone());
            }
        }
        Some((encoder, effort)) => {
            let kind = BlockKind::for_channels(ch, effort);
            let first = match level0 {
                Some(c) => {
                    progress.advance(u64::from(h));
                    c
                }
                None => compress_level(encoder, kind, source.level0, (w, h), ch, Some(progress)),
            };
            if progress.is_cancelled() {
                return Err("cancelled".into());
            }
            psnr_values = Some(psnr(source.level0, &first.decoded, ch));
            level_bytes.push(first.blocks);
            decoded.push(first.decoded);
            for (size, bytes) in &chain {
                let c = compress_level(encoder, kind, bytes, *size, ch, None);
                level_bytes.push(c.blocks);
                decoded.push(c.decoded);
            }
        }
    }
    let bytes = container(format, (w, h), &level_bytes)?;
    Ok(Written {
        bytes,
        decoded,
        psnr: psnr_values,
        levels: level_count(w, h),
        compression,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32, ch: usize) -> Vec<f32> {
        (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                (0..ch).map(move |k| ((x + y * 3 + k as u32 * 17) % 64) as f32 / 63.0)
            })
            .collect()
    }

    /// Writes `values` (in the averaging space of `spaces`) as a KTX2 file.
    fn write(
        (w, h): (u32, u32),
        spaces: &[Space],
        values: &[f32],
        compressed: Option<Bc7Quality>,
    ) -> Written {
        let ch = spaces.len();
        let bounds: Vec<Vec<f32>> = spaces.iter().map(|s| s.boundaries()).collect();
        let level0: Vec<u8> = values
            .iter()
            .enumerate()
            .map(|(j, v)| quantise(&bounds[j % ch], *v))
            .collect();
        let value = |i: usize, k: usize| values[i * ch + k];
        let source = Source {
            width: w,
            height: h,
            spaces,
            level0: &level0,
            value: &value,
        };
        encode(
            &source,
            compressed.map(|q| (Encoder::best(), q)),
            None,
            &Progress::default(),
        )
        .unwrap()
    }

    #[test]
    fn files_read_back_through_the_ktx2_crate() {
        for (ch, compressed) in [
            (1, None),
            (2, None),
            (3, None),
            (4, None),
            (1, Some(Bc7Quality::VeryFast)),
            (2, Some(Bc7Quality::VeryFast)),
            (4, Some(Bc7Quality::UltraFast)),
        ] {
            let (w, h) = (37, 20);
            let values = gradient(w, h, ch);
            let spaces = [Space::Srgb, Space::Srgb, Space::Srgb, Space::Linear];
            let spaces = if ch >= 3 {
                &spaces[..ch]
            } else {
                &[Space::Linear; 2][..ch]
            };
            let written = write((w, h), spaces, &values, compressed);
            assert_eq!(written.levels, 6);
            assert_eq!(written.decoded.len(), 6);
            let reader = ktx2::Reader::new(&written.bytes[..]).unwrap();
            assert_eq!(reader.header().level_count, 6);
            assert_eq!(reader.levels().count(), 6);
            let decoded = decode(&written.bytes).unwrap();
            assert_eq!((decoded.width, decoded.height), (w, h));
            // What decode reads is what encode says a consumer gets.
            let first: Vec<u8> = decoded
                .rgba
                .chunks(4)
                .flat_map(|p| p[..ch].to_vec())
                .collect();
            assert_eq!(first, written.decoded[0], "{ch} {compressed:?}");
            if compressed.is_none() {
                let exact: Vec<u8> = values
                    .iter()
                    .enumerate()
                    .map(|(j, v)| quantise(&spaces[j % ch].boundaries(), *v))
                    .collect();
                assert_eq!(written.decoded[0], exact);
            } else {
                let p = written.psnr.unwrap();
                assert!(p.iter().all(|p| p.is_none_or(|p| p > 30.0)), "{p:?}");
            }
        }
    }

    #[test]
    fn garbage_is_an_error() {
        assert!(decode(b"not a ktx2 file at all").is_err());
        let values = gradient(8, 8, 1);
        let mut bytes = write((8, 8), &[Space::Linear], &values, None).bytes;
        bytes.truncate(bytes.len() - 10);
        assert!(decode(&bytes).is_err());
    }
}
