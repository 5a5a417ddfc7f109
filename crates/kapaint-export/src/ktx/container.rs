//! The KTX2 container: written from the `ktx2` crate's header, level index and data format
//! descriptor types (that crate reads KTX2 but does not assemble files), and level 0 read back.

use ktx2::{Format as KtxFormat, Header, Index, LevelIndex, dfd};

use super::crop;
use crate::blocks;
use crate::codec::{self, Codec};

/// Level 0 of a KTX2 file as decoded texels.
#[derive(Clone, Debug)]
pub struct Decoded {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Meaningful components per texel (1, 2, 3 or 4).
    pub channels: usize,
    /// RGBA per texel (components past `channels` are filler): bytes as fractions of 255,
    /// or BC6H's half floats.
    pub rgba: Vec<f32>,
}

/// What a KTX2 file's header and data format descriptor say its texels are.
pub(crate) struct Described {
    /// The header's `vkFormat` (`None`: UNDEFINED, the descriptor says: UASTC).
    format: Option<KtxFormat>,
    /// The data format descriptor as the file holds it (its total size first).
    dfd: Vec<u8>,
    /// The header's `typeSize`.
    type_size: u32,
    /// Plain level data's alignment: lcm(texel block size, 4).
    align: usize,
}

impl Described {
    /// Texels of `format` (uncompressed, or a block format kapaint reads back).
    pub(crate) fn of_format(format: KtxFormat) -> Result<Self, String> {
        let (basic, type_size) = dfd::Basic::from_format(format)
            .map_err(|e| format!("data format descriptor: {e:?}"))?;
        let align = codec::from_vk_format(format).map_or(4, |c| c.block_bytes().max(4));
        Ok(Self::new(Some(format), &basic, type_size, align))
    }

    /// `codec`'s blocks.
    pub(crate) fn of_codec(codec: &dyn Codec) -> Result<Self, String> {
        let (basic, type_size) = codec.dfd()?;
        Ok(Self::new(
            codec.vk_format(),
            &basic,
            type_size,
            codec.block_bytes().max(4),
        ))
    }

    fn new(format: Option<KtxFormat>, basic: &dfd::Basic, type_size: u32, align: usize) -> Self {
        let block = dfd::Block::Basic(basic.clone()).to_vec();
        let mut dfd = ((block.len() + 4) as u32).to_le_bytes().to_vec();
        dfd.extend_from_slice(&block);
        Self {
            format,
            dfd,
            type_size,
            align,
        }
    }
}

/// Assembles a KTX2 file: header, level index, data format descriptor, the writer's name,
/// then the levels from smallest to largest, each aligned as the specification asks.
pub(super) fn container(described: &Described, size: (u32, u32), levels: &[Vec<u8>]) -> Vec<u8> {
    let stored: Vec<(&[u8], u64)> = levels
        .iter()
        .map(|l| (l.as_slice(), l.len() as u64))
        .collect();
    assemble(described, size, &stored, false)
}

pub use crate::file_kind::ZSTD_LEVELS;

/// A KTX2 file kapaint wrote (no supercompression) with each of its levels compressed by
/// Zstandard at `level`, independently (supercompression scheme 2), in parallel; the data
/// format descriptor as it was (`bytesPlane` kept, as KTX 2.0.4 asks).
///
/// # Errors
/// A file that does not read, one supercompressed already, a level out of [`ZSTD_LEVELS`].
pub fn supercompress(bytes: &[u8], level: u8) -> Result<Vec<u8>, String> {
    use rayon::prelude::*;
    if !ZSTD_LEVELS.contains(&level) {
        return Err(format!(
            "zstd level {level} is outside {}..={}",
            ZSTD_LEVELS.start(),
            ZSTD_LEVELS.end()
        ));
    }
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a KTX2 file: {e}"))?;
    let header = reader.header();
    if header.supercompression_scheme.is_some() {
        return Err("the file is supercompressed already".into());
    }
    let (at, len) = (
        header.index.dfd_byte_offset as usize,
        header.index.dfd_byte_length as usize,
    );
    let dfd = bytes
        .get(at..at + len)
        .ok_or("the data format descriptor is outside the file")?;
    let described = Described {
        format: header.format,
        dfd: dfd.to_vec(),
        type_size: header.type_size,
        align: 1,
    };
    let raw: Vec<&[u8]> = reader.levels().map(|l| l.data).collect();
    let packed: Vec<Vec<u8>> = raw
        .par_iter()
        .map(|data| zstd::bulk::compress(data, i32::from(level)).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let stored: Vec<(&[u8], u64)> = packed
        .iter()
        .zip(&raw)
        .map(|(p, r)| (p.as_slice(), r.len() as u64))
        .collect();
    Ok(assemble(
        &described,
        (header.pixel_width, header.pixel_height),
        &stored,
        true,
    ))
}

/// The file of `levels` (each its stored bytes and its length uncompressed), supercompressed
/// by Zstandard or not: a supercompressed level is aligned to 1, a plain one to lcm(texel
/// block size, 4).
fn assemble(
    described: &Described,
    (w, h): (u32, u32),
    levels: &[(&[u8], u64)],
    zstd: bool,
) -> Vec<u8> {
    let dfd_bytes = &described.dfd;
    let mut kvd = Vec::new();
    let entry = format!("KTXwriter\0kapaint {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    kvd.extend_from_slice(entry.as_bytes());
    kvd.resize(kvd.len().div_ceil(4) * 4, 0);
    // Level data alignment: lcm(texel block size, 4); 1 when supercompressed.
    let block_bytes = if zstd { 1 } else { described.align };
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
    for (i, &(level, uncompressed)) in levels.iter().enumerate().rev() {
        let aligned = at.div_ceil(block_bytes) * block_bytes;
        body.resize(body.len() + (aligned - at), 0);
        index[i] = LevelIndex {
            byte_offset: aligned as u64,
            byte_length: level.len() as u64,
            uncompressed_byte_length: uncompressed,
        };
        body.extend_from_slice(level);
        at = aligned + level.len();
    }
    let header = Header {
        format: described.format,
        type_size: described.type_size,
        pixel_width: w,
        pixel_height: h,
        pixel_depth: 0,
        layer_count: 0,
        face_count: 1,
        level_count: levels.len() as u32,
        supercompression_scheme: zstd.then_some(ktx2::SupercompressionScheme::Zstandard),
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
    out.extend_from_slice(dfd_bytes);
    out.extend_from_slice(&kvd);
    out.extend_from_slice(&body);
    out
}

/// Reads level 0 of a KTX2 file kapaint writes (the formats above, plain or supercompressed
/// by Zstandard).
/// ASTC files come back as RGBA, luminance in RGB and the second of two components in alpha.
///
/// # Errors
/// A malformed file or a format kapaint does not write.
pub fn decode(bytes: &[u8]) -> Result<Decoded, String> {
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a KTX2 file: {e}"))?;
    let header = reader.header();
    let (w, h) = (header.pixel_width, header.pixel_height.max(1));
    if w > kapaint_model::maps::MAX_SIDE || h > kapaint_model::maps::MAX_SIDE {
        return Err(format!("{w}x{h} is larger than kapaint's maps"));
    }
    let level = reader.levels().next().ok_or("the file has no levels")?;
    let inflated;
    let data = match header.supercompression_scheme {
        None => level.data,
        Some(ktx2::SupercompressionScheme::Zstandard) => {
            // At most what level 0 of the largest map can hold: a bomb stops there.
            let most = (w as usize * h as usize * 16).min(level.uncompressed_byte_length as usize);
            inflated = zstd::bulk::decompress(level.data, most)
                .map_err(|e| format!("level 0 does not inflate: {e}"))?;
            &inflated[..]
        }
        Some(other) => return Err(format!("supercompression {other:?} is not supported")),
    };
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
        None if reader.color_model() == Some(ktx2::ColorModel::UASTC) => {
            return decode_uastc(data, (w, h));
        }
        other => {
            let Some(codec) = other.and_then(codec::from_vk_format) else {
                return Err(format!("KTX2 format {other:?} is not one kapaint writes"));
            };
            return decode_blocks(&*codec, data, (w, h));
        }
    };
    let rgba = rgba.iter().map(|b| f32::from(*b) / 255.0).collect();
    Ok(Decoded {
        width: w,
        height: h,
        channels,
        rgba,
    })
}

/// Level 0 of a KTX2 file kapaint reads ([`decode`]) as an image: 8-bit luminance,
/// luminance and alpha, RGB or RGBA by its components (BC6H's floats clamped to `[0, 1]`). The
/// reader a glTF's `KHR_texture_basisu` images go through (`kapaint_pbr::gltf`).
///
/// # Errors
/// [`decode`]'s.
pub fn decode_image(bytes: &[u8]) -> Result<image::DynamicImage, String> {
    use image::DynamicImage as D;
    let d = decode(bytes)?;
    let (w, h) = (d.width, d.height);
    let wrong = || "the decoded level does not match its size".to_string();
    let byte = |v: &f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let pick = |k: usize| -> Vec<u8> {
        d.rgba
            .chunks_exact(4)
            .flat_map(|t| t[..k].iter().map(byte).collect::<Vec<u8>>())
            .collect()
    };
    Ok(match d.channels {
        1 => D::ImageLuma8(image::GrayImage::from_raw(w, h, pick(1)).ok_or_else(wrong)?),
        2 => {
            let la: Vec<u8> = d
                .rgba
                .chunks_exact(4)
                .flat_map(|t| [byte(&t[0]), byte(&t[1])])
                .collect();
            D::ImageLumaA8(image::GrayAlphaImage::from_raw(w, h, la).ok_or_else(wrong)?)
        }
        3 => D::ImageRgb8(image::RgbImage::from_raw(w, h, pick(3)).ok_or_else(wrong)?),
        _ => D::ImageRgba8(image::RgbaImage::from_raw(w, h, pick(4)).ok_or_else(wrong)?),
    })
}

/// Level 0 of a UASTC file as RGBA, as its ASTC 4x4 transcode decodes (UASTC's own texels):
/// luminance in RGB and the second of two components in alpha, as ASTC's.
fn decode_uastc(data: &[u8], (w, h): (u32, u32)) -> Result<Decoded, String> {
    let padded = (w.div_ceil(4) * 4, h.div_ceil(4) * 4);
    let size = padded.0 as usize / 4 * padded.1 as usize / 4 * 16;
    if data.len() < size {
        return Err("level 0 is truncated".into());
    }
    let uastc = codec::Uastc::new(4, false);
    let mut texels = vec![0_u8; padded.0 as usize * padded.1 as usize * 4];
    uastc
        .decode_lossless(&data[..size], padded, &mut texels)
        .map_err(|e| e.to_string())?;
    let tight = crop(&texels, padded.0, (w, h), 4, 4);
    Ok(Decoded {
        width: w,
        height: h,
        channels: 4,
        rgba: tight.iter().map(|b| f32::from(*b) / 255.0).collect(),
    })
}

/// Level 0 of a block-compressed file of `codec`, as RGBA (BC6H: three linear floats).
fn decode_blocks(codec: &dyn Codec, data: &[u8], (w, h): (u32, u32)) -> Result<Decoded, String> {
    let (bw, bh) = codec.block_dims();
    let padded = (w.div_ceil(bw) * bw, h.div_ceil(bh) * bh);
    let size = codec.blocks_len(padded);
    if data.len() < size {
        return Err("level 0 is truncated".into());
    }
    let per = codec.texel_bytes();
    let texels = blocks::decode(codec, &data[..size], padded).map_err(|e| e.to_string())?;
    let tight = crop(&texels, padded.0, (w, h), per, per);
    if per == 8 {
        let rgba = tight
            .chunks_exact(2)
            .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
            .collect();
        return Ok(Decoded {
            width: w,
            height: h,
            channels: 3,
            rgba,
        });
    }
    let mut rgba = vec![255_u8; w as usize * h as usize * 4];
    for (px, t) in rgba.chunks_exact_mut(4).zip(tight.chunks_exact(per)) {
        px[..per].copy_from_slice(t);
    }
    Ok(Decoded {
        width: w,
        height: h,
        channels: per,
        rgba: rgba.iter().map(|b| f32::from(*b) / 255.0).collect(),
    })
}
