//! Block encoding and decoding of whole images, in parallel strips of block rows, over any
//! [`Codec`]: the CPU's encoders (on `x86_64` Intel's ISPC kernels, `intel_tex_2`; elsewhere
//! `block_compression`'s port of the same encoder), or one a caller brings behind
//! [`BlockEncoder`] (the GPU crate's compute shaders) for the codecs it encodes: an export uses
//! it only when handed one ([`Coder::best`]); nothing here reaches for a device of its own.
//! What each format's blocks are, and how one strip is encoded and decoded, is its codec's
//! ([`crate::codec`]).

use rayon::prelude::*;

mod coder;

pub use coder::{BlockEncoder, Coder, Encoder, Interrupted};

use crate::codec::{self, Codec, CodecError, Effort};
use kapaint_base::task::Progress;

/// `src`'s texels of `stored` bytes widened to `to` bytes (at most [`Codec::texel_bytes`])
/// with `codec`'s [`Codec::filler`].
fn widen<'a>(
    codec: &dyn Codec,
    src: &'a [u8],
    stored: usize,
    to: usize,
) -> std::borrow::Cow<'a, [u8]> {
    codec::widen(src, stored, to, codec.filler())
}

/// The encoder a manifest names for blocks of `codec` that `coder` was asked to encode: the
/// codec's own where it has one, the CPU's best where a brought encoder does not encode it
/// (or failed), else `coder`'s.
pub fn encoder_name(coder: Coder<'_>, codec: &dyn Codec) -> Encoder {
    if let Some(own) = codec.own_encoder() {
        return own;
    }
    match coder {
        Coder::Brought(b) if b.failure().is_some() || !b.encodes(codec) => Encoder::best_cpu(),
        c => c.name(),
    }
}

/// Encodes a `(width, height)` image (sides multiples of [`Codec::block_dims`]) of
/// [`Codec::texel_bytes`] bytes per texel as `codec` at `effort`, in parallel strips of block
/// rows. Each strip advances `progress` by its texel rows; once it is cancelled the remaining
/// strips are skipped (the result is then garbage: check [`Progress::is_cancelled`]).
///
/// # Errors
/// The codec failed on a strip (its library could not build its tables).
pub fn encode(
    encoder: Coder<'_>,
    codec: &dyn Codec,
    effort: Effort,
    texels: &[u8],
    size: (u32, u32),
    progress: Option<&Progress>,
) -> Result<Vec<u8>, CodecError> {
    encode_stored(
        encoder,
        codec,
        effort,
        texels,
        codec.texel_bytes(),
        size,
        progress,
    )
}

/// [`encode`] of texels of `stored` bytes (the leading bytes of [`Codec::texel_bytes`]:
/// three colour components without alpha, say), each strip widened with
/// [`Codec::filler`] as it is encoded, so no widened copy of the image is ever whole.
///
/// # Errors
/// As [`encode`].
pub fn encode_stored(
    encoder: Coder<'_>,
    codec: &dyn Codec,
    effort: Effort,
    texels: &[u8],
    stored: usize,
    (width, height): (u32, u32),
    progress: Option<&Progress>,
) -> Result<Vec<u8>, CodecError> {
    let (bw, bh) = codec.block_dims();
    debug_assert!(width % bw == 0 && height % bh == 0);
    let per = codec.texel_bytes();
    let mut blocks = vec![0_u8; codec.blocks_len((width, height))];
    let (encoder, from_row) = match encoder {
        Coder::Brought(b) if b.encodes(codec) => {
            let done = encode_brought(
                b,
                (codec, effort),
                texels,
                stored,
                (width, height),
                progress,
                &mut blocks,
            );
            (Coder::best_cpu(), done)
        }
        // A brought encoder that does not encode this codec: the CPU's.
        Coder::Brought(_) => (Coder::best_cpu(), 0),
        cpu => (cpu, 0),
    };
    // The rows the brought encoder did not encode (all of them, mostly).
    let row_bytes = (width / bw) as usize * codec.block_bytes();
    let first_block = row_bytes * (from_row / bh) as usize;
    let first_texel = from_row as usize * width as usize * stored;
    let strip = codec.strip_block_rows((width / bw) as usize);
    let strip_texels = strip * bh as usize * width as usize * stored;
    blocks[first_block..]
        .par_chunks_mut(row_bytes * strip)
        .zip(texels[first_texel..].par_chunks(strip_texels))
        .try_for_each(|(out, src)| {
            if progress.is_some_and(Progress::is_cancelled) {
                return Ok(());
            }
            let rows = (out.len() / row_bytes) as u32 * bh;
            let wide = widen(codec, src, stored, per);
            codec.encode_strip(encoder.cpu(), effort, &wide, (width, rows), out)?;
            codec.refine(out, &wide, width as usize);
            if let Some(p) = progress {
                p.advance(u64::from(rows));
            }
            Ok(())
        })?;
    // The rows a brought encoder did: refined as the CPU's are.
    if first_block > 0 && !progress.is_some_and(Progress::is_cancelled) {
        blocks[..first_block]
            .par_chunks_mut(row_bytes * strip)
            .zip(texels[..first_texel].par_chunks(strip_texels))
            .for_each(|(out, src)| {
                codec.refine(out, &widen(codec, src, stored, per), width as usize);
            });
    }
    Ok(blocks)
}

/// [`encode_stored`] on a brought encoder into `blocks`, each strip widened as it goes
/// up: the texel rows whose blocks are in place, from the top. Short of `height` where it
/// failed part-way (it is then given up, and the CPU goes on from there: no strip is encoded
/// or counted twice).
fn encode_brought(
    brought: &dyn BlockEncoder,
    (codec, effort): (&dyn Codec, Effort),
    texels: &[u8],
    stored: usize,
    (width, height): (u32, u32),
    progress: Option<&Progress>,
    blocks: &mut [u8],
) -> u32 {
    if brought.failure().is_some() {
        return 0;
    }
    let per = codec.texel_bytes();
    let row_texels = width as usize * stored;
    let mut fill = |row: u32, rows: u32, out: &mut [u8]| {
        let src = &texels[row as usize * row_texels..(row + rows) as usize * row_texels];
        codec::widen_into(src, stored, per, codec.filler(), out);
    };
    let mut strip_done = |rows: u32| {
        progress.is_none_or(|p| {
            p.advance(u64::from(rows));
            !p.is_cancelled()
        })
    };
    match brought.encode(
        codec,
        effort,
        (width, height),
        &mut fill,
        &mut strip_done,
        blocks,
    ) {
        Ok(()) => height,
        Err(stopped) => {
            brought.give_up(&stopped.error);
            stopped.rows_done
        }
    }
}

/// Decodes blocks of `codec` covering `(width, height)` (sides multiples of
/// [`Codec::block_dims`]) into [`Codec::texel_bytes`] bytes per texel, in parallel strips.
///
/// # Errors
/// The codec failed on a strip (its library could not build a decoder).
pub fn decode(codec: &dyn Codec, blocks: &[u8], size: (u32, u32)) -> Result<Vec<u8>, CodecError> {
    decode_stored(codec, blocks, size, codec.texel_bytes())
}

/// [`decode`] keeping the leading `stored` bytes of each texel (as [`encode_stored`] took
/// them), strip by strip.
///
/// # Errors
/// As [`decode`].
pub fn decode_stored(
    codec: &dyn Codec,
    blocks: &[u8],
    (width, height): (u32, u32),
    stored: usize,
) -> Result<Vec<u8>, CodecError> {
    let (bw, bh) = codec.block_dims();
    let row_bytes = (width / bw) as usize * codec.block_bytes();
    let whole = codec.texel_bytes();
    let mut out = vec![0_u8; width as usize * height as usize * stored];
    let strip = codec.strip_block_rows((width / bw) as usize);
    out.par_chunks_mut(strip * bh as usize * width as usize * stored)
        .zip(blocks.par_chunks(row_bytes * strip))
        .try_for_each(|(dst, src)| {
            let rows = (src.len() / row_bytes) as u32 * bh;
            // Whole texels as the codec decodes them: into `dst` where it holds them whole,
            // else into a strip narrowed into it.
            if stored == whole {
                return codec.decode_strip(src, (width, rows), dst);
            }
            let mut strip = vec![0; width as usize * rows as usize * whole];
            codec.decode_strip(src, (width, rows), &mut strip)?;
            for (d, s) in dst.chunks_exact_mut(stored).zip(strip.chunks_exact(whole)) {
                d.copy_from_slice(&s[..stored]);
            }
            Ok(())
        })?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::codec::{Astc, AstcBlock, Bc4, Bc5, Bc6h, Bc7};
    use half::f16;

    fn pattern(w: u32, h: u32, per: usize) -> Vec<u8> {
        (0..w as usize * h as usize * per)
            .map(|i| {
                let (t, k) = (i / per, i % per);
                let (x, y) = (t % w as usize, t / w as usize);
                ((x * 7 + y * 3 + k * 50) % 256) as u8
            })
            .collect()
    }

    #[test]
    fn every_encoder_and_codec_round_trips_closely() {
        let (w, h) = (64, 40);
        for encoder in [Coder::best_cpu(), Coder::Portable] {
            // Each codec, its effort, and whether its alpha is opaque.
            let codecs: [(Box<dyn Codec>, Effort, bool); 5] = [
                (Box::new(Bc4), Effort::UltraFast, false),
                (Box::new(Bc5), Effort::UltraFast, false),
                (Box::new(Bc7::new(false, false)), Effort::UltraFast, true),
                (Box::new(Bc7::new(true, false)), Effort::VeryFast, false),
                (
                    Box::new(Astc::new(AstcBlock::DEFAULT, 4, false)),
                    Effort::UltraFast,
                    false,
                ),
            ];
            for (codec, effort, opaque) in codecs {
                let mut src = pattern(w, h, codec.texel_bytes());
                if opaque {
                    src.chunks_exact_mut(4).for_each(|p| p[3] = 255);
                }
                let blocks = encode(encoder, &*codec, effort, &src, (w, h), None).unwrap();
                assert_eq!(blocks.len(), (w * h) as usize / 16 * codec.block_bytes());
                let back = decode(&*codec, &blocks, (w, h)).unwrap();
                let linear = vec![crate::ktx::Space::Linear; codec.texel_bytes()];
                let p = crate::ktx::psnr(&src, &back, &linear);
                assert!(
                    p.iter().all(|p| p.is_none_or(|p| p > 30.0)),
                    "{encoder:?} {codec:?}: {p:?} dB"
                );
            }
        }
    }

    #[test]
    fn a_strip_of_the_wrong_size_is_an_error_not_a_panic() {
        let codecs: [Box<dyn Codec>; 5] = [
            Box::new(Bc4),
            Box::new(Bc5),
            Box::new(Bc6h),
            Box::new(Bc7::new(true, true)),
            Box::new(Astc::new(AstcBlock::DEFAULT, 3, true)),
        ];
        for codec in codecs {
            let mut out = vec![0; codec.blocks_len((8, 4))];
            let short = vec![0; 8 * 4 * codec.texel_bytes() - 1];
            let err = codec.encode_strip(
                Coder::best_cpu().cpu(),
                Effort::UltraFast,
                &short,
                (8, 4),
                &mut out,
            );
            assert!(matches!(err, Err(CodecError::Size { .. })), "{codec:?}");
            let mut texels = vec![0; 8 * 4 * codec.texel_bytes()];
            let err = codec.decode_strip(&out[1..], (8, 4), &mut texels);
            assert!(matches!(err, Err(CodecError::Size { .. })), "{codec:?}");
        }
    }

    #[test]
    fn bc6h_keeps_linear_half_floats_close() {
        let (w, h) = (32, 16);
        // Smooth linear colour, as BC6H's input (RGBA half floats, alpha 1).
        let values: Vec<f32> = (0..w * h * 4)
            .map(|i| {
                let (t, k) = (i / 4, i % 4);
                let (x, y) = (t % w, t / w);
                if k == 3 {
                    1.0
                } else {
                    0.05 + 0.1 * (x + y + k * 5) as f32 / (w + h + 10) as f32
                }
            })
            .collect();
        let src: Vec<u8> = values
            .iter()
            .flat_map(|v| f16::from_f32(*v).to_le_bytes())
            .collect();
        for encoder in [Coder::Portable, Coder::best_cpu()] {
            let size = (w as u32, h as u32);
            let blocks = encode(encoder, &Bc6h, Effort::UltraFast, &src, size, None).unwrap();
            assert_eq!(blocks.len(), w * h / 16 * 16);
            let back = decode(&Bc6h, &blocks, size).unwrap();
            let errors: Vec<(f32, f32)> = back
                .chunks_exact(8)
                .zip(values.chunks_exact(4))
                .flat_map(|(b, v)| {
                    (0..4).map(move |k| {
                        let got = f16::from_le_bytes([b[2 * k], b[2 * k + 1]]).to_f32();
                        ((got - v[k]).abs(), ((got - v[k]) / v[k]).abs())
                    })
                })
                .collect();
            let worst = errors.iter().map(|e| e.0).fold(0.0_f32, f32::max);
            let mean = errors.iter().map(|e| e.1).sum::<f32>() / errors.len() as f32;
            assert!(worst < 0.002 && mean < 0.005, "{encoder:?}: {worst} {mean}");
        }
    }
}
