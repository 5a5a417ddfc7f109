//! The KTX2 container: block or plain levels put in a file (`assembly`), supercompressed by
//! zstd, and level 0 read back, whatever kapaint writes.

use ktx2::Format as KtxFormat;

use super::assembly::{Described, assemble};
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

/// Assembles a KTX2 file: header, level index, data format descriptor, the writer's name,
/// then the levels from smallest to largest, each aligned as the specification asks.
pub(super) fn container(described: &Described, size: (u32, u32), levels: &[Vec<u8>]) -> Vec<u8> {
    let stored: Vec<(&[u8], u64)> = levels
        .iter()
        .map(|l| (l.as_slice(), l.len() as u64))
        .collect();
    assemble(described, size, &stored, None)
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
        Some((ktx2::SupercompressionScheme::Zstandard, &[])),
    ))
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
    if header.supercompression_scheme == Some(ktx2::SupercompressionScheme::BasisLZ) {
        return decode_etc1s(&reader, (w, h));
    }
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
            .flat_map(|t| t[..k].iter().map(byte))
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

/// Level 0 of an ETC1S file (BasisLZ) as RGBA, as its BC7 transcode decodes: colour in RGB,
/// the alpha slice (where there is one) in alpha.
fn decode_etc1s(reader: &ktx2::Reader<&[u8]>, (w, h): (u32, u32)) -> Result<Decoded, String> {
    if reader.color_model() != Some(ktx2::ColorModel::ETC1S) {
        return Err("a BasisLZ file that is not ETC1S".into());
    }
    let (image, srgb) = super::basislz::read_etc1s(reader)?;
    let alpha = image.has_alpha();
    let first = image.levels.first().ok_or("the file has no levels")?;
    if (first.width, first.height) != (w, h) {
        return Err("level 0 is not the header's size".into());
    }
    let tight = codec::etc1s::Etc1sCodec::new(4, srgb)
        .decode(&image, 1)
        .map_err(|e| e.to_string())?
        .swap_remove(0);
    Ok(Decoded {
        width: w,
        height: h,
        channels: if alpha { 4 } else { 3 },
        rgba: tight.iter().map(|b| f32::from(*b) / 255.0).collect(),
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
