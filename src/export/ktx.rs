//! KTX2 files with a full mip chain: 8-bit components uncompressed, or block-compressed
//! (BC7 for three or four components, BC5 for two, BC4 for one).
//!
//! The container is written by hand from the `ktx2` crate's header, level index and data
//! format descriptor types (that crate reads KTX2 but does not assemble files); blocks come
//! from `block_compression`'s CPU encoders, run in parallel over strips of block rows.

use block_compression::decode::decompress_blocks_as_rgba8;
use block_compression::encode::compress_rgba8;
use block_compression::{BC7Settings, CompressionVariant};
use ktx2::{Format as KtxFormat, Header, Index, LevelIndex, dfd};
use rayon::prelude::*;

use super::preset::Bc7Quality;
use super::set::Compression;
use crate::model::texel::{linear_to_srgb, srgb_to_linear};
use crate::task::Progress;

/// An image in the file's value domain: `channels` components per texel in `[0, 1]`, row
/// major. With `srgb`, the first three components of a three- or four-component image are
/// sRGB-encoded colour (alpha is always linear).
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Components per texel, 1 to 4.
    pub channels: usize,
    /// `width * height * channels` values.
    pub values: &'a [f32],
    /// Colour components are sRGB-encoded.
    pub srgb: bool,
}

/// A written KTX2 file.
#[derive(Clone, Debug)]
pub struct Written {
    /// The file.
    pub bytes: Vec<u8>,
    /// Level 0 as a consumer decodes it, `channels` bytes per texel.
    pub level0: Vec<u8>,
    /// Per component, PSNR (dB) of the decoded level 0 against the uncompressed 8-bit values,
    /// `None` where they are identical (`None` altogether for uncompressed files).
    pub psnr: Option<Vec<Option<f64>>>,
    /// Mip levels in the file.
    pub levels: u32,
    /// The file's compression: plain KTX2, or BC4, BC5 or BC7 blocks.
    pub compression: Compression,
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

fn bc7_settings(quality: Bc7Quality, alpha: bool) -> BC7Settings {
    match (quality, alpha) {
        (Bc7Quality::UltraFast, false) => BC7Settings::opaque_ultra_fast(),
        (Bc7Quality::VeryFast, false) => BC7Settings::opaque_very_fast(),
        (Bc7Quality::Fast, false) => BC7Settings::opaque_fast(),
        (Bc7Quality::Basic, false) => BC7Settings::opaque_basic(),
        (Bc7Quality::Slow, false) => BC7Settings::opaque_slow(),
        (Bc7Quality::UltraFast, true) => BC7Settings::alpha_ultrafast(),
        (Bc7Quality::VeryFast, true) => BC7Settings::alpha_very_fast(),
        (Bc7Quality::Fast, true) => BC7Settings::alpha_fast(),
        (Bc7Quality::Basic, true) => BC7Settings::alpha_basic(),
        (Bc7Quality::Slow, true) => BC7Settings::alpha_slow(),
    }
}

/// The next mip level: a 2x2 box (clamped at odd edges), colour averaged in linear light.
fn downsample(values: &[f32], (w, h): (u32, u32), channels: usize, srgb: bool) -> Vec<f32> {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let colour = |k: usize| srgb && channels >= 3 && k < 3;
    let mut out = vec![0.0_f32; nw as usize * nh as usize * channels];
    out.par_chunks_mut(nw as usize * channels)
        .enumerate()
        .for_each(|(y, row)| {
            let ys = [(2 * y).min(h as usize - 1), (2 * y + 1).min(h as usize - 1)];
            for x in 0..nw as usize {
                let xs = [(2 * x).min(w as usize - 1), (2 * x + 1).min(w as usize - 1)];
                for k in 0..channels {
                    let mut sum = 0.0;
                    for sy in ys {
                        for sx in xs {
                            let v = values[(sy * w as usize + sx) * channels + k];
                            sum += if colour(k) { srgb_to_linear(v) } else { v };
                        }
                    }
                    let mean = sum * 0.25;
                    row[x * channels + k] = if colour(k) {
                        linear_to_srgb(mean)
                    } else {
                        mean
                    };
                }
            }
        });
    out
}

fn quantise(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// RGBA8 texels of a level, padded by repeating the last row and column to `(pw, ph)`.
fn rgba8(values: &[f32], (w, h): (u32, u32), channels: usize, (pw, ph): (u32, u32)) -> Vec<u8> {
    let mut out = vec![0_u8; pw as usize * ph as usize * 4];
    out.par_chunks_mut(pw as usize * 4)
        .enumerate()
        .for_each(|(y, row)| {
            let sy = y.min(h as usize - 1);
            for x in 0..pw as usize {
                let sx = x.min(w as usize - 1);
                let src = &values[(sy * w as usize + sx) * channels..][..channels];
                let px = &mut row[x * 4..x * 4 + 4];
                px[3] = 255;
                for (k, v) in src.iter().enumerate() {
                    px[k] = quantise(*v);
                }
            }
        });
    out
}

/// Block-compresses RGBA8 texels (sides multiples of 4) in parallel strips of block rows,
/// advancing `progress` by texel rows (strips are skipped once it is cancelled).
fn compress(
    variant: CompressionVariant,
    rgba: &[u8],
    (w, h): (u32, u32),
    progress: Option<&Progress>,
) -> Vec<u8> {
    const STRIP: u32 = 8; // Block rows per task.
    let row_bytes = variant.blocks_byte_size(w, 4);
    let mut blocks = vec![0_u8; variant.blocks_byte_size(w, h)];
    blocks
        .par_chunks_mut(row_bytes * STRIP as usize)
        .enumerate()
        .for_each(|(i, out)| {
            let rows = (out.len() / row_bytes) as u32 * 4;
            if progress.is_some_and(Progress::is_cancelled) {
                return;
            }
            let first = i * STRIP as usize * 4 * w as usize * 4;
            let src = &rgba[first..first + rows as usize * w as usize * 4];
            compress_rgba8(variant, src, out, w, rows, w * 4);
            if let Some(p) = progress {
                p.advance(u64::from(rows));
            }
        });
    blocks
}

fn psnr(reference: &[u8], decoded: &[u8], channels: usize) -> Vec<Option<f64>> {
    (0..channels)
        .map(|k| {
            let (sum, count) = reference
                .par_chunks(channels)
                .zip(decoded.par_chunks(channels))
                .map(|(a, b)| {
                    let d = f64::from(a[k]) - f64::from(b[k]);
                    (d * d, 1_u64)
                })
                .reduce(|| (0.0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
            let mse = sum / count.max(1) as f64;
            (mse > 0.0).then(|| 10.0 * (255.0_f64 * 255.0 / mse).log10())
        })
        .collect()
}

/// The first `channels` bytes of each RGBA8 texel of a `pw`-wide level, cropped to `(w, h)`.
fn crop(rgba: &[u8], pw: u32, (w, h): (u32, u32), channels: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(w as usize * h as usize * channels);
    for y in 0..h as usize {
        for x in 0..w as usize {
            out.extend_from_slice(&rgba[(y * pw as usize + x) * 4..][..channels]);
        }
    }
    out
}

/// Writes `source` as a KTX2 file with a full mip chain; `compressed` picks block
/// compression and BC7's effort. Level 0's rows advance `progress`; a cancel stops the
/// block encoder between strips.
///
/// # Errors
/// An empty image, a component count outside 1..=4, or cancelled.
pub fn encode(
    source: &Source<'_>,
    compressed: Option<Bc7Quality>,
    progress: &Progress,
) -> Result<Written, String> {
    let (w, h, ch) = (source.width, source.height, source.channels);
    if w == 0
        || h == 0
        || !(1..=4).contains(&ch)
        || source.values.len() != w as usize * h as usize * ch
    {
        return Err(format!("cannot write a {w}x{h} image of {ch} components"));
    }
    let srgb = source.srgb && ch >= 3;
    let levels = 32 - w.max(h).leading_zeros();
    // Level values, finest first.
    let mut chain: Vec<((u32, u32), Vec<f32>)> = vec![((w, h), source.values.to_vec())];
    for _ in 1..levels {
        let (size, values) = chain.last().map(|(s, v)| (*s, v)).ok_or("no level")?;
        let next = downsample(values, size, ch, srgb);
        chain.push((((size.0 / 2).max(1), (size.1 / 2).max(1)), next));
    }
    let (format, variant, compression) = match (compressed, ch) {
        (None, 1) => (KtxFormat::R8_UNORM, None, Compression::Ktx2),
        (None, 2) => (KtxFormat::R8G8_UNORM, None, Compression::Ktx2),
        (None, _) if srgb => (KtxFormat::R8G8B8A8_SRGB, None, Compression::Ktx2),
        (None, _) => (KtxFormat::R8G8B8A8_UNORM, None, Compression::Ktx2),
        (Some(_), 1) => (
            KtxFormat::BC4_UNORM_BLOCK,
            Some(CompressionVariant::BC4),
            Compression::Ktx2Bc4,
        ),
        (Some(_), 2) => (
            KtxFormat::BC5_UNORM_BLOCK,
            Some(CompressionVariant::BC5),
            Compression::Ktx2Bc5,
        ),
        (Some(q), _) => (
            if srgb {
                KtxFormat::BC7_SRGB_BLOCK
            } else {
                KtxFormat::BC7_UNORM_BLOCK
            },
            Some(CompressionVariant::BC7(bc7_settings(q, ch == 4))),
            Compression::Ktx2Bc7,
        ),
    };
    let stored_channels = if variant.is_none() && ch == 3 { 4 } else { ch };
    let mut level_bytes = Vec::with_capacity(chain.len());
    let mut level0 = Vec::new();
    let mut psnr_values = None;
    for (i, ((lw, lh), values)) in chain.iter().enumerate() {
        let (lw, lh) = (*lw, *lh);
        match variant {
            None => {
                let rgba = rgba8(values, (lw, lh), ch, (lw, lh));
                if i == 0 {
                    level0 = crop(&rgba, lw, (lw, lh), ch);
                    progress.advance(u64::from(lh));
                }
                level_bytes.push(crop(&rgba, lw, (lw, lh), stored_channels));
            }
            Some(variant) => {
                let padded = (lw.div_ceil(4) * 4, lh.div_ceil(4) * 4);
                let rgba = rgba8(values, (lw, lh), ch, padded);
                let blocks = compress(variant, &rgba, padded, (i == 0).then_some(progress));
                if progress.is_cancelled() {
                    return Err("cancelled".into());
                }
                if i == 0 {
                    let mut decoded = vec![0_u8; rgba.len()];
                    decompress_blocks_as_rgba8(variant, padded.0, padded.1, &blocks, &mut decoded);
                    level0 = crop(&decoded, padded.0, (lw, lh), ch);
                    let reference = crop(&rgba, padded.0, (lw, lh), ch);
                    psnr_values = Some(psnr(&reference, &level0, ch));
                }
                level_bytes.push(blocks);
            }
        }
    }
    let bytes = container(format, (w, h), &level_bytes)?;
    Ok(Written {
        bytes,
        level0,
        psnr: psnr_values,
        levels,
        compression,
    })
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
            let (variant, ch) = match f {
                KtxFormat::BC4_UNORM_BLOCK => (CompressionVariant::BC4, 1),
                KtxFormat::BC5_UNORM_BLOCK => (CompressionVariant::BC5, 2),
                _ => (CompressionVariant::BC7(BC7Settings::alpha_very_fast()), 4),
            };
            let padded = (w.div_ceil(4) * 4, h.div_ceil(4) * 4);
            let size = variant.blocks_byte_size(padded.0, padded.1);
            if data.len() < size {
                return Err("level 0 is truncated".into());
            }
            let mut rgba = vec![0_u8; padded.0 as usize * padded.1 as usize * 4];
            decompress_blocks_as_rgba8(variant, padded.0, padded.1, &data[..size], &mut rgba);
            (ch, crop(&rgba, padded.0, (w, h), 4))
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

    fn gradient(w: u32, h: u32, ch: usize) -> Vec<f32> {
        (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                (0..ch).map(move |k| ((x + y * 3 + k as u32 * 17) % 64) as f32 / 63.0)
            })
            .collect()
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
            let source = Source {
                width: w,
                height: h,
                channels: ch,
                values: &values,
                srgb: true,
            };
            let written = encode(&source, compressed, &Progress::default()).unwrap();
            assert_eq!(written.levels, 6);
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
            assert_eq!(first, written.level0, "{ch} {compressed:?}");
            if compressed.is_none() {
                let exact: Vec<u8> = values.iter().map(|v| quantise(*v)).collect();
                assert_eq!(written.level0, exact);
            } else {
                let p = written.psnr.unwrap();
                assert!(p.iter().all(|p| p.is_none_or(|p| p > 30.0)), "{p:?}");
            }
        }
    }

    #[test]
    fn mips_average_colour_in_linear_light() {
        // Black and white columns: the sRGB mean of linear 0.5, not 0.5.
        let values: Vec<f32> = (0..4 * 3)
            .map(|i| if (i / 3) % 2 == 0 { 0.0 } else { 1.0 })
            .collect();
        let next = downsample(&values, (2, 2), 3, true);
        assert!((next[0] - linear_to_srgb(0.5)).abs() < 1e-6);
        let linear = downsample(&values, (2, 2), 3, false);
        assert!((linear[0] - 0.5).abs() < 1e-6);
    }

    #[test]
    fn garbage_is_an_error() {
        assert!(decode(b"not a ktx2 file at all").is_err());
        let values = gradient(8, 8, 1);
        let mut bytes = encode(
            &Source {
                width: 8,
                height: 8,
                channels: 1,
                values: &values,
                srgb: false,
            },
            None,
            &Progress::default(),
        )
        .unwrap()
        .bytes;
        bytes.truncate(bytes.len() - 10);
        assert!(decode(&bytes).is_err());
    }
}
