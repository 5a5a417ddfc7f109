//! Basis Universal (Binomial's encoder and transcoder, through the `basis-universal` crate)
//! behind a safe API, the one room of kapaint that calls foreign code marked unsafe.
//!
//! - [`encode_uastc`]: RGBA8 texels to UASTC 4x4 blocks (16 bytes each, row-major), at a
//!   quality level (0 fastest to 4 slowest) with optional rate-distortion optimisation (RDO,
//!   a quality scalar: higher is smaller after zstd and lossier).
//! - [`transcode_uastc`]: UASTC blocks to what a runtime uploads: BC7 or ASTC 4x4 (lossless
//!   from UASTC: decoding the ASTC blocks is UASTC's own decode). Texels are not offered: the
//!   bindings' uncompressed transcode sizes its buffer by blocks, not texels, and the
//!   transcoder writes past it.
//!
//! - [`etc1s`]: ETC1S with BasisLZ, the smaller of Basis Universal's two formats: RGBA8
//!   texels (and the caller's mips, or the encoder's) to the codebooks, tables and slices KTX2 stores, and
//!   those back to BC7 or ASTC 4x4.
//!
//! No `.basis` files leave here: kapaint writes its own KTX2 containers; the encoder's `.basis`
//! output is read for its slices (and, for ETC1S, its codebooks), and rebuilt in memory from
//! them to transcode.

pub mod etc1s;

use basis_universal::{
    BasisTextureFormat, ColorSpace, Compressor, CompressorParams, DecodeFlags,
    LowLevelUastcTranscoder, SliceParametersUastc, Transcoder, TranscoderBlockFormat,
};

/// Bytes per UASTC block.
pub const BLOCK_BYTES: usize = 16;

/// The quality levels UASTC has (`basisu -uastc_level`).
pub const UASTC_LEVELS: std::ops::RangeInclusive<u32> = 0..=4;

/// How UASTC blocks are encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uastc {
    /// The quality level, in [`UASTC_LEVELS`].
    pub level: u32,
    /// The RDO quality scalar (`basisu -uastc_rdo_l`), `None` for no RDO.
    pub rdo: Option<f32>,
    /// The texels are sRGB-encoded colour (perceptual error metrics), else linear data.
    pub srgb: bool,
}

/// What UASTC blocks are transcoded to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// BC7 blocks (16 bytes per 4x4).
    Bc7,
    /// ASTC 4x4 blocks (16 bytes per 4x4).
    Astc4x4,
}

/// Encodes `rgba` (`width x height` RGBA8 texels, both sides multiples of 4) as UASTC blocks,
/// row-major.
///
/// # Errors
/// A size that is not whole blocks, settings out of range, or the encoder's failure.
pub fn encode_uastc(
    rgba: &[u8],
    (width, height): (u32, u32),
    how: Uastc,
) -> Result<Vec<u8>, String> {
    whole_blocks(width, height)?;
    if rgba.len() != width as usize * height as usize * 4 {
        return Err(format!(
            "{} bytes are not {width}x{height} RGBA texels",
            rgba.len()
        ));
    }
    if !UASTC_LEVELS.contains(&how.level) {
        return Err(format!("UASTC level {} is outside 0..=4", how.level));
    }
    if how
        .rdo
        .is_some_and(|q| !(q.is_finite() && q > 0.0 && q <= 10.0))
    {
        return Err(format!("the RDO quality {:?} is outside (0, 10]", how.rdo));
    }
    let mut params = CompressorParams::new();
    params.set_basis_format(BasisTextureFormat::UASTC4x4);
    set_uastc_level(&mut params, how.level);
    params.set_rdo_uastc(how.rdo);
    params.set_color_space(if how.srgb {
        ColorSpace::Srgb
    } else {
        ColorSpace::Linear
    });
    params.set_generate_mipmaps(false);
    params.set_print_status_to_stdout(false);
    params.source_image_mut(0).init(rgba, width, height, 4);
    // One thread: the export runs strips in parallel.
    let file = compress(&params, "UASTC", 1)?;
    let file = file.as_slice();
    let info = Transcoder::new()
        .image_level_info(file, 0, 0)
        .ok_or("the encoder's output has no image")?;
    let (at, len) = (info.m_rgb_file_ofs as usize, info.m_rgb_file_len as usize);
    let want = (width / 4) as usize * (height / 4) as usize * BLOCK_BYTES;
    if len != want || at + len > file.len() {
        return Err(format!(
            "the encoder wrote {len} bytes of blocks, {want} expected"
        ));
    }
    Ok(file[at..at + len].to_vec())
}

/// Sets the UASTC pack flags to `level` alone. The crate's `set_uastc_quality_level` ORs the
/// level into the flags the parameters start with (level 2), so levels 0 and 1 came out as 2
/// and 3, and 4 as 6.
fn set_uastc_level(params: &mut CompressorParams, level: u32) {
    let flags = basis_universal::sys::UastcPackFlags::try_from(level).unwrap_or_default();
    #[expect(
        unsafe_code,
        reason = "the bindings mark this setter unsafe: it writes one field of the parameters `params` owns, alive for the call"
    )]
    unsafe {
        basis_universal::sys::compressor_params_set_pack_uastc_flags(params.0, flags);
    }
}

/// Runs Binomial's compressor on `params` (its source images set) with `threads` threads:
/// the `.basis` file.
fn compress(params: &CompressorParams, what: &str, threads: u32) -> Result<Vec<u8>, String> {
    let mut compressor = Compressor::new(threads);
    #[expect(
        unsafe_code,
        reason = "the bindings mark the compressor's init and run unsafe: the parameters they read live in `params` until both return"
    )]
    let run = unsafe {
        if compressor.init(params) {
            compressor
                .process()
                .map_err(|e| format!("the {what} encoder failed: {e:?}"))
        } else {
            Err(format!("the {what} encoder refused its parameters"))
        }
    };
    run?;
    Ok(compressor.basis_file().to_vec())
}

/// Whether `width x height` is whole 4x4 blocks (and not empty).
fn whole_blocks(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 || !width.is_multiple_of(4) || !height.is_multiple_of(4) {
        return Err(format!("{width}x{height} is not whole 4x4 blocks"));
    }
    Ok(())
}

/// Transcodes UASTC `blocks` of a `width x height` image (sides multiples of 4) to `target`.
///
/// # Errors
/// Blocks that are not the size's, or blocks the transcoder cannot read.
pub fn transcode_uastc(
    blocks: &[u8],
    (width, height): (u32, u32),
    target: Target,
) -> Result<Vec<u8>, String> {
    whole_blocks(width, height)?;
    let (bx, by) = (width / 4, height / 4);
    if blocks.len() != bx as usize * by as usize * BLOCK_BYTES {
        return Err(format!(
            "{} bytes are not {bx}x{by} UASTC blocks",
            blocks.len()
        ));
    }
    let format = match target {
        Target::Bc7 => TranscoderBlockFormat::BC7,
        Target::Astc4x4 => TranscoderBlockFormat::ASTC_4x4,
    };
    let slice = SliceParametersUastc {
        num_blocks_x: bx,
        num_blocks_y: by,
        has_alpha: true,
        original_width: width,
        original_height: height,
    };
    LowLevelUastcTranscoder::new()
        .transcode_slice(blocks, slice, DecodeFlags::HIGH_QUALITY, format)
        .map_err(|e| format!("UASTC blocks do not transcode: {e:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each level is the level asked: the encoder's blocks at levels 0, 1 and 2 all differ
    /// (with the level ORed into the default 2, 0 and 2 gave the same blocks, and 1 gave 3's).
    #[test]
    fn each_uastc_level_is_the_level_asked() {
        let (w, h) = (32_u32, 32_u32);
        let rgba: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [(x * 8) as u8, (y * 8) as u8, ((x * y * 7) % 256) as u8, 255]
            })
            .collect();
        let at = |level| {
            let how = Uastc {
                level,
                rdo: None,
                srgb: true,
            };
            encode_uastc(&rgba, (w, h), how).expect("encode")
        };
        let blocks: Vec<Vec<u8>> = (0..=3).map(at).collect();
        assert_ne!(blocks[0], blocks[2], "level 0 is not level 2");
        assert_ne!(blocks[1], blocks[3], "level 1 is not level 3");
        assert_ne!(blocks[0], blocks[1], "level 0 is not level 1");
    }

    fn gradient(w: u32, h: u32) -> Vec<u8> {
        (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [
                    (x * 255 / w) as u8,
                    (y * 255 / h) as u8,
                    ((x + y) % 256) as u8,
                    200,
                ]
            })
            .collect()
    }

    /// The blocks as independent decoders read them: ASTC 4x4 (texture2ddecoder) and BC7
    /// (bcdec), RGBA8 each.
    fn decoded(blocks: &[u8], (w, h): (u32, u32)) -> [Vec<u8>; 2] {
        let astc = transcode_uastc(blocks, (w, h), Target::Astc4x4).expect("ASTC");
        let mut words = vec![0_u32; (w * h) as usize];
        texture2ddecoder::decode_astc(&astc, w as usize, h as usize, 4, 4, &mut words)
            .expect("decode ASTC");
        // texture2ddecoder writes BGRA words.
        let from_astc = words
            .iter()
            .flat_map(|p| {
                let [b, g, r, a] = p.to_le_bytes();
                [r, g, b, a]
            })
            .collect();
        let bc7 = transcode_uastc(blocks, (w, h), Target::Bc7).expect("BC7");
        let mut from_bc7 = vec![0_u8; (w * h * 4) as usize];
        for (i, block) in bc7.chunks_exact(16).enumerate() {
            let (bx, by) = (i as u32 % (w / 4), i as u32 / (w / 4));
            let at = ((by * 4 * w + bx * 4) * 4) as usize;
            bcdec_rs::bc7(block, &mut from_bc7[at..], (w * 4) as usize);
        }
        [from_astc, from_bc7]
    }

    #[test]
    fn uastc_blocks_transcode_to_astc_and_bc7_close_to_the_texels() {
        let (w, h) = (32, 16);
        let rgba = gradient(w, h);
        for how in [
            Uastc {
                level: 2,
                rdo: None,
                srgb: false,
            },
            Uastc {
                level: 0,
                rdo: Some(2.0),
                srgb: true,
            },
        ] {
            let blocks = encode_uastc(&rgba, (w, h), how).expect("encode");
            assert_eq!(blocks.len(), 8 * 4 * 16);
            for (target, texels) in ["ASTC", "BC7"].into_iter().zip(decoded(&blocks, (w, h))) {
                let worst = rgba.iter().zip(&texels).map(|(a, b)| a.abs_diff(*b)).max();
                assert!(
                    worst.is_some_and(|d| d <= 16),
                    "{how:?} {target}: {worst:?}"
                );
            }
        }
    }

    #[test]
    fn bad_sizes_and_settings_are_refused() {
        let rgba = gradient(8, 8);
        let ok = Uastc {
            level: 1,
            rdo: Some(1.0),
            srgb: true,
        };
        assert!(encode_uastc(&rgba, (8, 6), ok).is_err());
        assert!(encode_uastc(&rgba[4..], (8, 8), ok).is_err());
        assert!(encode_uastc(&rgba, (8, 8), Uastc { level: 5, ..ok }).is_err());
        assert!(
            encode_uastc(
                &rgba,
                (8, 8),
                Uastc {
                    rdo: Some(f32::NAN),
                    ..ok
                }
            )
            .is_err()
        );
        assert!(transcode_uastc(&[0; 15], (4, 4), Target::Bc7).is_err());
    }
}
