//! BC6H: three linear unsigned half floats, 16 bytes per 4x4 block, encoded by ISPC's kernels
//! (`x86_64`) or `block_compression`'s port, decoded by `block_compression`'s decoder.

use block_compression::decode::decode_block_bc6h;
use block_compression::{BC6HSettings, CompressionVariant};
use half::f16;

use super::{Codec, CodecError, Cpu, Effort, check_strip};
use crate::file_kind::Compression;

/// BC6H: RGB as unsigned half floats (linear); its input and decoded texels are RGBA half
/// floats (alpha 1).
#[derive(Clone, Copy, Debug, Default)]
pub struct Bc6h;

impl Codec for Bc6h {
    fn name(&self) -> &'static str {
        "BC6H"
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        Some(ktx2::Format::BC6H_UFLOAT_BLOCK)
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Bc6h
    }

    fn texel_bytes(&self) -> usize {
        8
    }

    /// Half-float alpha 1.0.
    fn filler(&self) -> [u8; 8] {
        let one = f16::ONE.to_le_bytes();
        [0, 0, 0, 0, 0, 0, one[0], one[1]]
    }

    /// Both ultra-fast and very-fast are BC6H's very-fast.
    fn effort(&self, asked: Effort) -> Effort {
        asked.max(Effort::VeryFast)
    }

    fn portable(&self, effort: Effort) -> Option<CompressionVariant> {
        Some(CompressionVariant::BC6H(match self.effort(effort) {
            Effort::UltraFast | Effort::VeryFast => BC6HSettings::very_fast(),
            Effort::Fast => BC6HSettings::fast(),
            Effort::Basic => BC6HSettings::basic(),
            Effort::Slow => BC6HSettings::slow(),
        }))
    }

    fn encode_strip(
        &self,
        cpu: Cpu,
        effort: Effort,
        texels: &[u8],
        (width, rows): (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        let size = (width, rows);
        check_strip(self, size, texels.len(), out.len())?;
        match cpu {
            #[cfg(target_arch = "x86_64")]
            Cpu::Ispc => {
                use intel_tex_2::bc6h;
                let settings = match self.effort(effort) {
                    Effort::UltraFast | Effort::VeryFast => bc6h::very_fast_settings(),
                    Effort::Fast => bc6h::fast_settings(),
                    Effort::Basic => bc6h::basic_settings(),
                    Effort::Slow => bc6h::slow_settings(),
                };
                let surface = intel_tex_2::RgbaSurface {
                    data: texels,
                    width,
                    height: rows,
                    stride: width * 8,
                };
                bc6h::compress_blocks_into(&settings, &surface, out);
            }
            _ => {
                if let Some(variant) = self.portable(effort) {
                    let halves: Vec<f16> = bytemuck::pod_collect_to_vec(texels);
                    block_compression::encode::compress_rgba16(
                        variant,
                        &halves,
                        out,
                        width,
                        rows,
                        width * 4,
                    );
                }
            }
        }
        Ok(())
    }

    /// Block by block: `block_compression`'s whole-image RGBA16F helper writes three halves
    /// per texel at a four-half pitch.
    fn decode_strip(
        &self,
        blocks: &[u8],
        (width, rows): (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        let size = (width, rows);
        let width = width as usize;
        check_strip(self, size, out.len(), blocks.len())?;
        let across = width / 4;
        let one = f16::ONE.to_le_bytes();
        for (b, block) in blocks.chunks_exact(16).enumerate() {
            let mut rgb = [f16::ZERO; 48];
            decode_block_bc6h(block, &mut rgb, 12, false);
            let (bx, by) = (b % across, b / across);
            for y in 0..4 {
                for x in 0..4 {
                    let at = ((by * 4 + y) * width + bx * 4 + x) * 8;
                    let texel = &mut out[at..at + 8];
                    for c in 0..3 {
                        texel[2 * c..2 * c + 2]
                            .copy_from_slice(&rgb[y * 12 + x * 3 + c].to_le_bytes());
                    }
                    texel[6..].copy_from_slice(&one);
                }
            }
        }
        Ok(())
    }
}
