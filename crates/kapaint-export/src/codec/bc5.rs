//! BC5: two components (red, then green, each a BC4 half of 8 bytes), 16 bytes per 4x4 block,
//! encoded by ISPC's kernels (`x86_64`) or `block_compression`'s port, decoded as BC4's halves
//! are ([`super::bc4`]: rounded as the Direct3D specification says).

use block_compression::CompressionVariant;

use super::{Codec, CodecError, Cpu, Effort, check_strip, encode_portable, widen};
use crate::file_kind::Compression;

/// BC5: two components.
#[derive(Clone, Copy, Debug, Default)]
pub struct Bc5;

impl Codec for Bc5 {
    fn name(&self) -> &'static str {
        "BC5"
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        Some(ktx2::Format::BC5_UNORM_BLOCK)
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Bc5
    }

    fn texel_bytes(&self) -> usize {
        2
    }

    /// One speed.
    fn effort(&self, _asked: Effort) -> Effort {
        Effort::UltraFast
    }

    fn effort_name(&self, _effort: Effort) -> &'static str {
        "the one"
    }

    fn portable(&self, _effort: Effort) -> Option<CompressionVariant> {
        Some(CompressionVariant::BC5)
    }

    fn encode_strip(
        &self,
        cpu: Cpu,
        _effort: Effort,
        texels: &[u8],
        (width, rows): (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        let size = (width, rows);
        check_strip(self, size, texels.len(), out.len())?;
        match cpu {
            #[cfg(target_arch = "x86_64")]
            Cpu::Ispc => {
                let surface = intel_tex_2::RgSurface {
                    data: texels,
                    width,
                    height: rows,
                    stride: width * 2,
                };
                intel_tex_2::bc5::compress_blocks_into(&surface, out);
            }
            _ => encode_portable(
                CompressionVariant::BC5,
                &widen(texels, 2, 4, self.filler()),
                size,
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
        let size = (width, rows);
        check_strip(self, size, out.len(), blocks.len())?;
        super::bc4::decode(blocks, 2, width as usize, out);
        Ok(())
    }
}
