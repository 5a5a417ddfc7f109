//! BC4: one component, 8 bytes per 4x4 block, encoded by ISPC's kernels (`x86_64`) or
//! `block_compression`'s port.
//!
//! Its blocks (and BC5's halves) are decoded as the Direct3D specification interpolates them: each palette
//! value is a weighted mean of the two endpoints in real arithmetic, so its byte rounds to the
//! nearest. `block_compression`'s decoder truncates the mean instead and reads up to one level
//! low, which is not what a GPU samples (nor the independent `bcdec`): a normal map's x or y a
//! level off is about half a degree.

use block_compression::CompressionVariant;

use super::{Codec, CodecError, Cpu, Effort, check_strip, encode_portable, widen};
use crate::file_kind::Compression;

/// The eight values a BC4 block's 3-bit indices select: the two endpoints, then six means
/// between them where the first is larger, else four means, 0 and 255.
fn palette(e0: u8, e1: u8) -> [u8; 8] {
    let (a, b) = (u32::from(e0), u32::from(e1));
    let mean = |wa: u32, wb: u32, den: u32| ((wa * a + wb * b + den / 2) / den) as u8;
    let mut p = [e0, e1, 0, 0, 0, 0, 0, 255];
    if e0 > e1 {
        for k in 1..=6 {
            p[k + 1] = mean(7 - k as u32, k as u32, 7);
        }
    } else {
        for k in 1..=4 {
            p[k + 1] = mean(5 - k as u32, k as u32, 5);
        }
    }
    p
}

/// One BC4 block (8 bytes) as 16 values, row-major.
fn bc4_block(block: &[u8]) -> [u8; 16] {
    let p = palette(block[0], block[1]);
    let bits = block[2..8]
        .iter()
        .rev()
        .fold(0_u64, |acc, b| (acc << 8) | u64::from(*b));
    std::array::from_fn(|t| p[((bits >> (3 * t)) & 7) as usize])
}

/// Decodes a strip of BC4 (`channels` 1) or BC5 (2: red, then green, 8 bytes each) blocks,
/// `width` texels wide, into texels of `channels` bytes.
pub(super) fn decode(blocks: &[u8], channels: usize, width: usize, dst: &mut [u8]) {
    let across = width / 4;
    for (b, block) in blocks.chunks_exact(8 * channels).enumerate() {
        let (bx, by) = (b % across, b / across);
        let mut values = [[0_u8; 16]; 2];
        for (v, half) in values.iter_mut().zip(block.chunks_exact(8)) {
            *v = bc4_block(half);
        }
        for t in 0..16 {
            let at = ((by * 4 + t / 4) * width + bx * 4 + t % 4) * channels;
            for (c, v) in values[..channels].iter().enumerate() {
                dst[at + c] = v[t];
            }
        }
    }
}

/// BC4: one component.
#[derive(Clone, Copy, Debug, Default)]
pub struct Bc4;

impl Codec for Bc4 {
    fn name(&self) -> &'static str {
        "BC4"
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        Some(ktx2::Format::BC4_UNORM_BLOCK)
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Bc4
    }

    fn block_bytes(&self) -> usize {
        8
    }

    fn texel_bytes(&self) -> usize {
        1
    }

    /// One speed.
    fn effort(&self, _asked: Effort) -> Effort {
        Effort::UltraFast
    }

    fn effort_name(&self, _effort: Effort) -> &'static str {
        "the one"
    }

    fn portable(&self, _effort: Effort) -> Option<CompressionVariant> {
        Some(CompressionVariant::BC4)
    }

    fn encode_strip(
        &self,
        cpu: Cpu,
        _effort: Effort,
        texels: &[u8],
        (width, rows): (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        check_strip(self, (width, rows), texels.len(), out.len())?;
        match cpu {
            #[cfg(target_arch = "x86_64")]
            Cpu::Ispc => {
                let surface = intel_tex_2::RSurface {
                    data: texels,
                    width,
                    height: rows,
                    stride: width,
                };
                intel_tex_2::bc4::compress_blocks_into(&surface, out);
            }
            _ => encode_portable(
                CompressionVariant::BC4,
                &widen(texels, 1, 4, self.filler()),
                (width, rows),
                out,
            ),
        }
        Ok(())
    }

    fn decode_strip(
        &self,
        blocks: &[u8],
        (width, rows): (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        check_strip(self, (width, rows), out.len(), blocks.len())?;
        decode(blocks, 1, width as usize, out);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palettes_round_to_the_nearest_byte() {
        // 6/7 * 255 + 1/7 * 0 = 218.57: 219, where a truncating decoder reads 218.
        let p = palette(255, 0);
        assert_eq!(p, [255, 0, 219, 182, 146, 109, 73, 36]);
        // The other ordering: four means, then 0 and 255.
        let p = palette(0, 255);
        assert_eq!(p, [0, 255, 51, 102, 153, 204, 0, 255]);
        // Index k of texel t sits at bits 3t of the 48 after the endpoints.
        let mut block = [255, 0, 0, 0, 0, 0, 0, 0];
        block[2] = 0b0000_0010; // texel 0: index 2
        block[7] = 0b1110_0000; // texel 15: index 7
        let v = bc4_block(&block);
        assert_eq!((v[0], v[1], v[15]), (219, 255, 36));
    }
}
