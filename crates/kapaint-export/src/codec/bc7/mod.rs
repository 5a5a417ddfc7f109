//! BC7: RGB or RGBA (8-bit, sRGB or linear), 16 bytes per 4x4 block, encoded by ISPC's kernels
//! (`x86_64`) or `block_compression`'s port at five efforts, decoded by `block_compression`'s
//! decoder; blocks of one colour are then stored exactly ([`solid`]).

mod solid;

use block_compression::decode::decompress_blocks_as_rgba8;
use block_compression::{BC7Settings, CompressionVariant};

use super::{Codec, CodecError, Cpu, Effort, check_strip, encode_portable};
use crate::file_kind::Compression;

/// BC7 of three components (`alpha` false: the encoder may ignore the fourth) or four.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bc7 {
    alpha: bool,
    srgb: bool,
}

impl Bc7 {
    /// BC7 storing alpha where `alpha`, its colour sRGB-encoded where `srgb`.
    pub fn new(alpha: bool, srgb: bool) -> Self {
        Self { alpha, srgb }
    }
}

impl Codec for Bc7 {
    fn name(&self) -> &'static str {
        "BC7"
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        Some(if self.srgb {
            ktx2::Format::BC7_SRGB_BLOCK
        } else {
            ktx2::Format::BC7_UNORM_BLOCK
        })
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Bc7
    }

    fn texel_bytes(&self) -> usize {
        4
    }

    fn portable(&self, effort: Effort) -> Option<CompressionVariant> {
        Some(CompressionVariant::BC7(match (effort, self.alpha) {
            (Effort::UltraFast, false) => BC7Settings::opaque_ultra_fast(),
            (Effort::VeryFast, false) => BC7Settings::opaque_very_fast(),
            (Effort::Fast, false) => BC7Settings::opaque_fast(),
            (Effort::Basic, false) => BC7Settings::opaque_basic(),
            (Effort::Slow, false) => BC7Settings::opaque_slow(),
            (Effort::UltraFast, true) => BC7Settings::alpha_ultrafast(),
            (Effort::VeryFast, true) => BC7Settings::alpha_very_fast(),
            (Effort::Fast, true) => BC7Settings::alpha_fast(),
            (Effort::Basic, true) => BC7Settings::alpha_basic(),
            (Effort::Slow, true) => BC7Settings::alpha_slow(),
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
        match (cpu, self.portable(effort)) {
            #[cfg(target_arch = "x86_64")]
            (Cpu::Ispc, _) => {
                use intel_tex_2::bc7;
                let settings = match (effort, self.alpha) {
                    (Effort::UltraFast, false) => bc7::opaque_ultra_fast_settings(),
                    (Effort::VeryFast, false) => bc7::opaque_very_fast_settings(),
                    (Effort::Fast, false) => bc7::opaque_fast_settings(),
                    (Effort::Basic, false) => bc7::opaque_basic_settings(),
                    (Effort::Slow, false) => bc7::opaque_slow_settings(),
                    (Effort::UltraFast, true) => bc7::alpha_ultra_fast_settings(),
                    (Effort::VeryFast, true) => bc7::alpha_very_fast_settings(),
                    (Effort::Fast, true) => bc7::alpha_fast_settings(),
                    (Effort::Basic, true) => bc7::alpha_basic_settings(),
                    (Effort::Slow, true) => bc7::alpha_slow_settings(),
                };
                let surface = intel_tex_2::RgbaSurface {
                    data: texels,
                    width,
                    height: rows,
                    stride: width * 4,
                };
                bc7::compress_blocks_into(&settings, &surface, out);
            }
            (_, Some(variant)) => encode_portable(variant, texels, size, out),
            (_, None) => {}
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
        if let Some(variant) = self.portable(Effort::UltraFast) {
            decompress_blocks_as_rgba8(variant, width, rows, blocks, out);
        }
        Ok(())
    }

    /// Each block of one colour stored exactly where that decodes closer (the module `solid`).
    fn refine(&self, blocks: &mut [u8], texels: &[u8], width: usize) {
        solid::refine(self.alpha, blocks, texels, width);
    }
}
