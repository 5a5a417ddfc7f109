//! KTX2 files with a full mip chain: 8-bit components uncompressed, or block-compressed
//! (BC7 for three or four components, BC5 for two, BC4 for one).
//!
//! The container is written by hand from the `ktx2` crate's header, level index and data
//! format descriptor types (that crate reads KTX2 but does not assemble files); blocks come
//! from [`super::blocks`]. Mips are 2x2 boxes, each component averaged in its own space
//! ([`Space`]): colour in linear light, `n` in the log space the brushes blend it in.

use ktx2::{Format as KtxFormat, Header, Index, LevelIndex, dfd};
use rayon::prelude::*;

use super::blocks::{self, BlockKind, Encoder};
use super::encoding::NEncoding;
use super::preset::Bc7Quality;
use super::set::Compression;
use crate::model::texel::{n_to_blend, srgb_to_linear};
use crate::task::Progress;

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
}

impl Space {
    /// The 255 boundaries between consecutive bytes, in the averaging space: a value's byte
    /// is the number of boundaries at or below it (rounding to the nearest stored value).
    pub fn boundaries(self) -> Vec<f32> {
        (0..255)
            .map(|b| {
                let mid = (f64::from(b) + 0.5) / 255.0;
                match self {
                    Self::Srgb => srgb_to_linear(mid as f32),
                    Self::Linear => mid as f32,
                    Self::N(e) if e.lo >= e.hi => f32::INFINITY,
                    Self::N(e) => n_to_blend(e.decode_fraction(mid)),
                }
            })
            .collect()
    }

    /// The value in the averaging space that a stored byte stands for.
    pub fn value_of(self, byte: u8) -> f32 {
        let v = f32::from(byte) / 255.0;
        match self {
            Self::Srgb => srgb_to_linear(v),
            Self::Linear => v,
            Self::N(e) => n_to_blend(e.decode(u16::from(byte))),
        }
    }

    fn is_colour(self) -> bool {
        self == Self::Srgb
    }
}

/// The byte of `v` between `boundaries` ([`Space::boundaries`]).
#[inline]
pub fn quantise(boundaries: &[f32], v: f32) -> u8 {
    boundaries.partition_point(|b| *b <= v) as u8
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

/// Mip levels in a full chain for a `w x h` image.
pub fn level_count(w: u32, h: u32) -> u32 {
    32 - w.max(h).leading_zeros()
}

/// The size of the level after `(w, h)`.
fn half((w, h): (u32, u32)) -> (u32, u32) {
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

/// The 2x2 box mean (clamped at odd edges) of a level of `(w, h)` triples given by `value`.
pub fn box_down(size: (u32, u32), value: impl Fn(usize) -> [f32; 3] + Sync) -> Vec<[f32; 3]> {
    let (nw, nh) = half(size);
    (0..nw as usize * nh as usize)
        .into_par_iter()
        .map(|j| {
            let f = footprint(size, j % nw as usize, j / nw as usize);
            let mut sum = [0.0_f32; 3];
            for i in f {
                let v = value(i);
                for c in 0..3 {
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
    let mut size = (source.width, source.height);
    let mut values: Option<Vec<f32>> = None;
    let mut out = Vec::new();
    for _ in 1..level_count(source.width, source.height) {
        let next = match &values {
            None => downsample(source.value, size, ch),
            Some(v) => downsample(&|i, k| v[i * ch + k], size, ch),
        };
        size = half(size);
        let bytes: Vec<u8> = next
            .par_iter()
            .enumerate()
            .map(|(j, v)| quantise(&bounds[j % ch], *v))
            .collect();
        out.push((size, bytes));
        values = Some(next);
    }
    out
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
fn crop(bytes: &[u8], pw: u32, (w, h): (u32, u32), per: usize, channels: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(w as usize * h as usize * channels);
    for y in 0..h as usize {
        for x in 0..w as usize {
            out.extend_from_slice(&bytes[(y * pw as usize + x) * per..][..channels]);
        }
    }
    out
}

/// The block kind for `channels` components at `effort`.
pub fn block_kind(channels: usize, effort: Bc7Quality) -> BlockKind {
    BlockKind::for_channels(channels, effort)
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
            let kind = block_kind(ch, effort);
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

/// Level 0 of a KTX2 file as decoded texels.
#[derive(Clone, Debug)]
pub struct Decoded {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Meaningful components per texel (1, 2 or 4).
    pub channels: usize,
    /// RGBA8 per texel (components past `channels` are filler).
    pub rgba: Vec<u8>,
}

/// Assembles a KTX2 file: header, level index, data format descriptor, the writer's name,
/// then the levels from smallest to largest, each aligned as the specification asks.
fn container(format: KtxFormat, (w, h): (u32, u32), levels: &[Vec<u8>]) -> Result<Vec<u8>, String> {
    let (basic, type_size) =
        dfd::Basic::from_format(format).map_err(|e| format!("data format descriptor: {e:?}"))?;
    let block = dfd::Block::Basic(basic).to_vec();
    let mut dfd_bytes = ((block.len() + 4) as u32).to_le_bytes().to_vec();
    dfd_bytes.extend_from_slice(&block);
    let mut kvd = Vec::new();
    let entry = format!("KTXwriter\0kapaint {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    kvd.extend_from_slice(entry.as_bytes());
    kvd.resize(kvd.len().div_ceil(4) * 4, 0);
    // Level data alignment: lcm(texel block size, 4).
    let block_bytes = match format {
        KtxFormat::BC4_UNORM_BLOCK => 8,
        KtxFormat::BC5_UNORM_BLOCK | KtxFormat::BC7_SRGB_BLOCK | KtxFormat::BC7_UNORM_BLOCK => 16,
        _ => 4,
    };
    let index_at = Header::LENGTH;
    let dfd_at = index_at + levels.len() * LevelIndex::LENGTH;
    let kvd_at = dfd_at + dfd_bytes.len();
    let mut at = kvd_at + kvd.len();
    let mut index = vec![
        LevelIndex {
            byte_offset: 0,
            byte_length: 0,
            uncompressed_byte_length: 0,
        };
        levels.len()
    ];
    let mut body = Vec::new();
    for (i, level) in levels.iter().enumerate().rev() {
        let aligned = at.div_ceil(block_bytes) * block_bytes;
        body.resize(body.len() + (aligned - at), 0);
        index[i] = LevelIndex {
            byte_offset: aligned as u64,
            byte_length: level.len() as u64,
            uncompressed_byte_length: level.len() as u64,
        };
        body.extend_from_slice(level);
        at = aligned + level.len();
    }
    let header = Header {
        format: Some(format),
        type_size,
        pixel_width: w,
        pixel_height: h,
        pixel_depth: 0,
        layer_count: 0,
        face_count: 1,
        level_count: levels.len() as u32,
        supercompression_scheme: None,
        index: Index {
            dfd_byte_offset: dfd_at as u32,
            dfd_byte_length: dfd_bytes.len() as u32,
            kvd_byte_offset: kvd_at as u32,
            kvd_byte_length: kvd.len() as u32,
            sgd_byte_offset: 0,
            sgd_byte_length: 0,
        },
    };
    let mut out = Vec::with_capacity(at);
    out.extend_from_slice(&header.as_bytes());
    for entry in &index {
        out.extend_from_slice(&entry.as_bytes());
    }
    out.extend_from_slice(&dfd_bytes);
    out.extend_from_slice(&kvd);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Reads level 0 of a KTX2 file kapaint writes (the formats above, no supercompression).
///
/// # Errors
/// A malformed file or a format kapaint does not write.
pub fn decode(bytes: &[u8]) -> Result<Decoded, String> {
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a KTX2 file: {e}"))?;
    let header = reader.header();
    if header.supercompression_scheme.is_some() {
        return Err("supercompressed KTX2 is not supported".into());
    }
    let (w, h) = (header.pixel_width, header.pixel_height.max(1));
    if w > crate::model::maps::MAX_SIDE || h > crate::model::maps::MAX_SIDE {
        return Err(format!("{w}x{h} is larger than kapaint's maps"));
    }
    let level = reader.levels().next().ok_or("the file has no levels")?;
    let data = level.data;
    let texels = w as usize * h as usize;
    let (channels, rgba) = match header.format {
        Some(KtxFormat::R8_UNORM | KtxFormat::R8G8_UNORM) => {
            let ch = if header.format == Some(KtxFormat::R8_UNORM) {
                1
            } else {
                2
            };
            if data.len() < texels * ch {
                return Err("level 0 is truncated".into());
            }
            let mut rgba = vec![255_u8; texels * 4];
            for (px, src) in rgba.chunks_mut(4).zip(data.chunks(ch)) {
                px[..ch].copy_from_slice(src);
            }
            (ch, rgba)
        }
        Some(KtxFormat::R8G8B8A8_UNORM | KtxFormat::R8G8B8A8_SRGB) => {
            if data.len() < texels * 4 {
                return Err("level 0 is truncated".into());
            }
            (4, data[..texels * 4].to_vec())
        }
        Some(
            f @ (KtxFormat::BC4_UNORM_BLOCK
            | KtxFormat::BC5_UNORM_BLOCK
            | KtxFormat::BC7_UNORM_BLOCK
            | KtxFormat::BC7_SRGB_BLOCK),
        ) => {
            let kind = match f {
                KtxFormat::BC4_UNORM_BLOCK => BlockKind::Bc4,
                KtxFormat::BC5_UNORM_BLOCK => BlockKind::Bc5,
                _ => BlockKind::for_channels(4, Bc7Quality::UltraFast),
            };
            let padded = (w.div_ceil(4) * 4, h.div_ceil(4) * 4);
            let size = (padded.0 as usize / 4) * (padded.1 as usize / 4) * kind.block_bytes();
            if data.len() < size {
                return Err("level 0 is truncated".into());
            }
            let per = kind.texel_bytes();
            let texels = blocks::decode(kind, &data[..size], padded);
            let tight = crop(&texels, padded.0, (w, h), per, per);
            let mut rgba = vec![255_u8; w as usize * h as usize * 4];
            for (px, t) in rgba.chunks_exact_mut(4).zip(tight.chunks_exact(per)) {
                px[..per].copy_from_slice(t);
            }
            (per, rgba)
        }
        other => return Err(format!("KTX2 format {other:?} is not one kapaint writes")),
    };
    Ok(Decoded {
        width: w,
        height: h,
        channels,
        rgba,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::encoding::NCurve;
    use crate::model::texel::n_from_blend;

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

    #[test]
    fn garbage_is_an_error() {
        assert!(decode(b"not a ktx2 file at all").is_err());
        let values = gradient(8, 8, 1);
        let mut bytes = write((8, 8), &[Space::Linear], &values, None).bytes;
        bytes.truncate(bytes.len() - 10);
        assert!(decode(&bytes).is_err());
    }
}
