//! Block encoders for the KTX2 export: BC7 (three or four components), BC6H (three linear
//! half floats), BC5 (two), BC4 (one), and ASTC LDR (one to four, any footprint: [`astc`]).
//!
//! On `x86_64` the blocks come from Intel's ISPC texture compressor kernels (`intel_tex_2`,
//! which ships them precompiled); elsewhere from `block_compression`'s port of the same
//! encoder. Either runs in parallel over strips of block rows. A caller may bring another
//! encoder behind [`BlockEncoder`] (the GPU crate's compute shaders): an export uses it only
//! when handed one ([`Coder::best`]); nothing here reaches for a device of its own. Decoding
//! (to measure what a consumer sees) is `block_compression`'s CPU decoder for BC7 and BC6H,
//! and kapaint's own for BC4 and BC5 (rounded as the specification says), also in strips.
//! ASTC is encoded and decoded on the CPU by ARM's `astcenc`, whatever encoder is handed in.

use block_compression::decode::{decode_block_bc6h, decompress_blocks_as_rgba8};
use block_compression::{BC6HSettings, BC7Settings, CompressionVariant};
use half::f16;
use rayon::prelude::*;

pub mod astc;
mod bc45;
mod coder;
mod solid;

pub use coder::{BlockEncoder, Coder, Encoder, Interrupted};

use super::preset::Bc7Quality;
use crate::astc_block::AstcBlock;
use kapaint_core::task::Progress;

/// Which blocks a block-compressed image holds: BC (BC7, BC6H, BC5 or BC4 by what it
/// stores), or ASTC LDR of one footprint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockFamily {
    /// Desktop GPUs' BC formats.
    Bc,
    /// ASTC LDR (phones, standalone headsets).
    Astc(AstcBlock),
}

/// What blocks hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockKind {
    /// One component, 8 bytes per block.
    Bc4,
    /// Two components, 16 bytes per block.
    Bc5,
    /// RGB (`alpha` false) or RGBA, 16 bytes per block, at an effort.
    Bc7 {
        /// The fourth component is stored (otherwise the encoder may ignore it).
        alpha: bool,
        /// How hard the encoder searches.
        effort: Bc7Quality,
    },
    /// RGB as unsigned half floats (linear), 16 bytes per block, at an effort (BC7's scale:
    /// both ultra-fast and very-fast are BC6H's very-fast).
    Bc6h {
        /// How hard the encoder searches.
        effort: Bc7Quality,
    },
    /// ASTC LDR: 16 bytes per block of any footprint ASTC defines, `channels` components
    /// (one as luminance, two as luminance and alpha), colour sRGB where `srgb`, at an effort
    /// (BC7's scale, [`astc::preset_of`]).
    Astc {
        /// The footprint.
        block: AstcBlock,
        /// Meaningful components, 1 to 4.
        channels: u8,
        /// RGB is sRGB-encoded (the sRGB profile).
        srgb: bool,
        /// How hard the encoder searches.
        effort: Bc7Quality,
    },
}

impl BlockKind {
    /// The kind for `channels` components (1, 2, 3 or 4) at `effort` (BC7 only).
    pub fn for_channels(channels: usize, effort: Bc7Quality) -> Self {
        match channels {
            1 => Self::Bc4,
            2 => Self::Bc5,
            c => Self::Bc7 {
                alpha: c == 4,
                effort,
            },
        }
    }

    /// Bytes per block.
    pub fn block_bytes(self) -> usize {
        match self {
            Self::Bc4 => 8,
            Self::Bc5 | Self::Bc7 { .. } | Self::Bc6h { .. } | Self::Astc { .. } => 16,
        }
    }

    /// A block's footprint, texels across and down: 4x4, or ASTC's.
    pub fn dims(self) -> (u32, u32) {
        match self {
            Self::Astc { block, .. } => block.dims(),
            _ => (4, 4),
        }
    }

    /// Bytes of the blocks covering a `(width, height)` image (sides multiples of
    /// [`BlockKind::dims`]).
    pub fn blocks_len(self, (width, height): (u32, u32)) -> usize {
        let (bw, bh) = self.dims();
        (width / bw) as usize * (height / bh) as usize * self.block_bytes()
    }

    /// Bytes per texel of the input (and of [`decode`]'s output): 1, 2 or 4 bytes, or four
    /// little-endian half floats (8 bytes) for BC6H.
    pub fn texel_bytes(self) -> usize {
        match self {
            Self::Bc4 => 1,
            Self::Bc5 => 2,
            Self::Bc7 { .. } | Self::Astc { .. } => 4,
            Self::Bc6h { .. } => 8,
        }
    }

    /// A whole input texel whose leading bytes a stored texel replaces: the filler of
    /// components the file does not hold (opaque alpha: 255, or half-float 1.0).
    pub fn filler(self) -> [u8; 8] {
        match self {
            Self::Bc6h { .. } => {
                let one = f16::ONE.to_le_bytes();
                [0, 0, 0, 0, 0, 0, one[0], one[1]]
            }
            _ => [0, 0, 0, 255, 0, 0, 0, 0],
        }
    }

    /// `block_compression`'s name and settings for the kind (`None` for ASTC, which it does
    /// not encode).
    pub fn variant(self) -> Option<CompressionVariant> {
        Some(match self {
            Self::Bc4 => CompressionVariant::BC4,
            Self::Bc5 => CompressionVariant::BC5,
            Self::Bc7 { alpha, effort } => CompressionVariant::BC7(portable_bc7(effort, alpha)),
            Self::Bc6h { effort } => CompressionVariant::BC6H(match effort {
                Bc7Quality::UltraFast | Bc7Quality::VeryFast => BC6HSettings::very_fast(),
                Bc7Quality::Fast => BC6HSettings::fast(),
                Bc7Quality::Basic => BC6HSettings::basic(),
                Bc7Quality::Slow => BC6HSettings::slow(),
            }),
            Self::Astc { .. } => return None,
        })
    }
}

fn portable_bc7(effort: Bc7Quality, alpha: bool) -> BC7Settings {
    match (effort, alpha) {
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

#[cfg(target_arch = "x86_64")]
mod ispc;

/// `src`'s texels of `stored` bytes widened to `kind`'s whole texels (`to` bytes, at most
/// [`BlockKind::texel_bytes`]) with its [`BlockKind::filler`], into `out`.
fn widen_into(kind: BlockKind, src: &[u8], stored: usize, to: usize, out: &mut [u8]) {
    let filler = kind.filler();
    for (d, s) in out.chunks_exact_mut(to).zip(src.chunks_exact(stored)) {
        d.copy_from_slice(&filler[..to]);
        d[..stored].copy_from_slice(s);
    }
}

/// `src` as [`widen_into`] widens it: borrowed where it already has `to` bytes per texel.
fn widen(kind: BlockKind, src: &[u8], stored: usize, to: usize) -> std::borrow::Cow<'_, [u8]> {
    if stored == to {
        return src.into();
    }
    let mut out = vec![0; src.len() / stored * to];
    widen_into(kind, src, stored, to, &mut out);
    out.into()
}

/// Encodes one strip with the portable encoder (which reads RGBA8 whatever the kind, RGBA16F
/// for BC6H).
fn encode_portable(kind: BlockKind, data: &[u8], width: u32, rows: u32, out: &mut [u8]) {
    let Some(variant) = kind.variant() else {
        return;
    };
    if let BlockKind::Bc6h { .. } = kind {
        let halves: Vec<f16> = bytemuck::pod_collect_to_vec(data);
        block_compression::encode::compress_rgba16(variant, &halves, out, width, rows, width * 4);
        return;
    }
    let rgba = widen(kind, data, kind.texel_bytes(), 4);
    block_compression::encode::compress_rgba8(variant, &rgba, out, width, rows, width * 4);
}

/// Encodes one strip of whole texels: ASTC with `astcenc`, BC with `encoder`.
fn encode_strip(
    encoder: Coder<'_>,
    kind: BlockKind,
    data: &[u8],
    width: u32,
    rows: u32,
    out: &mut [u8],
) {
    match (kind, encoder) {
        (
            BlockKind::Astc {
                block,
                channels,
                srgb,
                effort,
            },
            _,
        ) => astc::encode(block, channels, srgb, effort, data, (width, rows), out),
        #[cfg(target_arch = "x86_64")]
        (_, Coder::Ispc) => ispc::encode(kind, data, width, rows, out),
        _ => encode_portable(kind, data, width, rows, out),
    }
}

/// Block rows per parallel task.
const STRIP: usize = 8;

/// Encodes a `(width, height)` image (sides multiples of [`BlockKind::dims`]) of
/// [`BlockKind::texel_bytes`] bytes per texel, in parallel strips of block rows. Each strip
/// advances `progress` by its texel rows; once it is cancelled the remaining strips are
/// skipped (the result is then garbage: check [`Progress::is_cancelled`]).
pub fn encode(
    encoder: Coder<'_>,
    kind: BlockKind,
    texels: &[u8],
    size: (u32, u32),
    progress: Option<&Progress>,
) -> Vec<u8> {
    encode_stored(encoder, kind, texels, kind.texel_bytes(), size, progress)
}

/// [`encode`] of texels of `stored` bytes (the leading bytes of [`BlockKind::texel_bytes`]:
/// three colour components without alpha, say), each strip widened with
/// [`BlockKind::filler`] as it is encoded, so no widened copy of the image is ever whole.
pub fn encode_stored(
    encoder: Coder<'_>,
    kind: BlockKind,
    texels: &[u8],
    stored: usize,
    (width, height): (u32, u32),
    progress: Option<&Progress>,
) -> Vec<u8> {
    let (bw, bh) = kind.dims();
    debug_assert!(width % bw == 0 && height % bh == 0);
    let per = kind.texel_bytes();
    let mut blocks = vec![0_u8; kind.blocks_len((width, height))];
    let (encoder, from_row) = match encoder {
        // A brought encoder (a GPU's) encodes BC only.
        Coder::Brought(_) if matches!(kind, BlockKind::Astc { .. }) => (Coder::best_cpu(), 0),
        Coder::Brought(b) => {
            let done = encode_brought(
                b,
                kind,
                texels,
                stored,
                (width, height),
                progress,
                &mut blocks,
            );
            (Coder::best_cpu(), done)
        }
        cpu => (cpu, 0),
    };
    // The rows the GPU did not encode (all of them, mostly).
    let row_bytes = (width / bw) as usize * kind.block_bytes();
    let first_block = row_bytes * (from_row / bh) as usize;
    let first_texel = from_row as usize * width as usize * stored;
    let strip_texels = STRIP * bh as usize * width as usize * stored;
    blocks[first_block..]
        .par_chunks_mut(row_bytes * STRIP)
        .zip(texels[first_texel..].par_chunks(strip_texels))
        .for_each(|(out, src)| {
            if progress.is_some_and(Progress::is_cancelled) {
                return;
            }
            let rows = (out.len() / row_bytes) as u32 * bh;
            let wide = widen(kind, src, stored, per);
            encode_strip(encoder, kind, &wide, width, rows, out);
            solid::refine(kind, out, &wide, width as usize);
            if let Some(p) = progress {
                p.advance(u64::from(rows));
            }
        });
    // The rows a brought encoder did: their blocks of one colour made exact as the CPU's are.
    if first_block > 0 && !progress.is_some_and(Progress::is_cancelled) {
        blocks[..first_block]
            .par_chunks_mut(row_bytes * STRIP)
            .zip(texels[..first_texel].par_chunks(strip_texels))
            .for_each(|(out, src)| {
                solid::refine(kind, out, &widen(kind, src, stored, per), width as usize);
            });
    }
    blocks
}

/// [`encode_stored`] on a brought encoder into `blocks`, each strip widened as it goes
/// up: the texel rows whose blocks are in place, from the top. Short of `height` where it
/// failed part-way (it is then given up, and the CPU goes on from there: no strip is encoded
/// or counted twice).
fn encode_brought(
    brought: &dyn BlockEncoder,
    kind: BlockKind,
    texels: &[u8],
    stored: usize,
    (width, height): (u32, u32),
    progress: Option<&Progress>,
    blocks: &mut [u8],
) -> u32 {
    if brought.failure().is_some() {
        return 0;
    }
    let per = kind.texel_bytes();
    let row_texels = width as usize * stored;
    let mut fill = |row: u32, rows: u32, out: &mut [u8]| {
        let src = &texels[row as usize * row_texels..(row + rows) as usize * row_texels];
        widen_into(kind, src, stored, per, out);
    };
    let mut strip_done = |rows: u32| {
        progress.is_none_or(|p| {
            p.advance(u64::from(rows));
            !p.is_cancelled()
        })
    };
    match brought.encode(kind, (width, height), &mut fill, &mut strip_done, blocks) {
        Ok(()) => height,
        Err(stopped) => {
            brought.give_up(&stopped.error);
            stopped.rows_done
        }
    }
}

/// Decodes a strip of BC6H blocks, `width` texels wide, into RGBA half floats (alpha 1),
/// block by block: `block_compression`'s whole-image RGBA16F helper writes three halves per
/// texel at a four-half pitch.
fn decode_bc6h(blocks: &[u8], width: usize, dst: &mut [u8]) {
    let across = width / 4;
    let one = f16::ONE.to_le_bytes();
    for (b, block) in blocks.chunks_exact(16).enumerate() {
        let mut rgb = [f16::ZERO; 48];
        decode_block_bc6h(block, &mut rgb, 12, false);
        let (bx, by) = (b % across, b / across);
        for y in 0..4 {
            for x in 0..4 {
                let at = ((by * 4 + y) * width + bx * 4 + x) * 8;
                let texel = &mut dst[at..at + 8];
                for c in 0..3 {
                    texel[2 * c..2 * c + 2].copy_from_slice(&rgb[y * 12 + x * 3 + c].to_le_bytes());
                }
                texel[6..].copy_from_slice(&one);
            }
        }
    }
}

/// Decodes blocks of `kind` covering `(width, height)` (sides multiples of
/// [`BlockKind::dims`]) into
/// [`BlockKind::texel_bytes`] bytes per texel, in parallel strips.
pub fn decode(kind: BlockKind, blocks: &[u8], size: (u32, u32)) -> Vec<u8> {
    decode_stored(kind, blocks, size, kind.texel_bytes())
}

/// [`decode`] keeping the leading `stored` bytes of each texel (as [`encode_stored`] took
/// them), strip by strip.
///
/// # Panics
/// Where `astcenc` cannot build an ASTC decoder (out of memory).
pub fn decode_stored(
    kind: BlockKind,
    blocks: &[u8],
    (width, height): (u32, u32),
    stored: usize,
) -> Vec<u8> {
    let (bw, bh) = kind.dims();
    let row_bytes = (width / bw) as usize * kind.block_bytes();
    let mut out = vec![0_u8; width as usize * height as usize * stored];
    let variant = kind.variant();
    out.par_chunks_mut(STRIP * bh as usize * width as usize * stored)
        .zip(blocks.par_chunks(row_bytes * STRIP))
        .for_each(|(dst, src)| {
            let rows = (src.len() / row_bytes) as u32 * bh;
            // Whole texels as the decoder writes them (BC6H's halves, else RGBA8): into `dst`
            // where it holds them whole, else into a strip narrowed into it.
            let whole = if let BlockKind::Bc6h { .. } = kind {
                8
            } else {
                4
            };
            let mut strip = Vec::new();
            let texels: &mut [u8] = if stored == whole {
                &mut *dst
            } else {
                strip.resize(width as usize * rows as usize * whole, 0);
                &mut strip
            };
            match (kind, variant) {
                (
                    BlockKind::Astc {
                        block,
                        channels,
                        srgb,
                        ..
                    },
                    _,
                ) => {
                    if let Err(e) = astc::decode(block, channels, srgb, src, (width, rows), texels)
                    {
                        panic!("{e}");
                    }
                }
                _ if whole == 8 => decode_bc6h(src, width as usize, texels),
                (BlockKind::Bc4, _) => bc45::decode(src, 1, width as usize, texels),
                (BlockKind::Bc5, _) => bc45::decode(src, 2, width as usize, texels),
                (_, Some(variant)) => decompress_blocks_as_rgba8(variant, width, rows, src, texels),
                (_, None) => {}
            }
            if stored != whole {
                for (d, s) in dst.chunks_exact_mut(stored).zip(strip.chunks_exact(whole)) {
                    d.copy_from_slice(&s[..stored]);
                }
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn every_encoder_and_kind_round_trips_closely() {
        let (w, h) = (64, 40);
        for encoder in [Coder::best_cpu(), Coder::Portable] {
            for kind in [
                BlockKind::Bc4,
                BlockKind::Bc5,
                BlockKind::Bc7 {
                    alpha: false,
                    effort: Bc7Quality::UltraFast,
                },
                BlockKind::Bc7 {
                    alpha: true,
                    effort: Bc7Quality::VeryFast,
                },
            ] {
                let mut src = pattern(w, h, kind.texel_bytes());
                if kind
                    == (BlockKind::Bc7 {
                        alpha: false,
                        effort: Bc7Quality::UltraFast,
                    })
                {
                    src.chunks_exact_mut(4).for_each(|p| p[3] = 255);
                }
                let blocks = encode(encoder, kind, &src, (w, h), None);
                assert_eq!(blocks.len(), (w * h) as usize / 16 * kind.block_bytes());
                let back = decode(kind, &blocks, (w, h));
                let linear = vec![crate::ktx::Space::Linear; kind.texel_bytes()];
                let p = crate::ktx::psnr(&src, &back, &linear);
                assert!(
                    p.iter().all(|p| p.is_none_or(|p| p > 30.0)),
                    "{encoder:?} {kind:?}: {p:?} dB"
                );
            }
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
            let kind = BlockKind::Bc6h {
                effort: Bc7Quality::UltraFast,
            };
            let blocks = encode(encoder, kind, &src, (w as u32, h as u32), None);
            assert_eq!(blocks.len(), w * h / 16 * 16);
            let back = decode(kind, &blocks, (w as u32, h as u32));
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
