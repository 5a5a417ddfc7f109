//! UASTC: Basis Universal's universal 4x4 blocks (16 bytes), which a runtime transcodes to
//! the block format its GPU samples, BC7 on desktops and ASTC 4x4 on phones; encoded by
//! Binomial's encoder ([`kapaint_basis`]) with rate-distortion optimisation, so zstd squeezes
//! them further. A KTX2 file of them has no Vulkan format: its data format descriptor says
//! UASTC ([`Codec::dfd`]).
//!
//! Components go in as RGBA texels: one as luminance (R = G = B, the descriptor's RRR), two
//! as luminance and alpha (RRRG), three as RGB, four as RGBA.
//!
//! **What the export measures.** The blocks as a runtime decodes them after transcoding:
//! ASTC 4x4 holds every UASTC block exactly (transcoding to it is lossless, so it decodes to
//! UASTC's own texels), BC7 approximates some; the decode here is the BC7 transcode's, the
//! worse target, and the tests check that the ASTC transcode's error is not larger.
//!
//! **Efforts** map onto UASTC's quality level and the RDO's quality scalar, cheapest in
//! bytes first: the export's search spends more only while its budget is not met.

use ktx2::dfd;

use super::astc::{Astc, AstcBlock};
use super::{Bc7, Codec, CodecError, Cpu, Effort, check_strip};
use crate::file_kind::Compression;
use kapaint_basis::{Target, Uastc as Settings};

/// UASTC blocks of `channels` meaningful components (1 to 4), colour sRGB where `srgb`.
#[derive(Debug)]
pub struct Uastc {
    channels: usize,
    srgb: bool,
    /// The BC7 decoder of the transcoded blocks.
    bc7: Bc7,
    /// The ASTC 4x4 decoder of the transcoded blocks (the tests' lossless reference).
    astc: Astc,
}

/// UASTC's level and RDO quality scalar for an effort: the cheapest efforts give the smallest
/// files after zstd (strong RDO), the dearest the most accurate blocks (no RDO, level 3).
pub fn settings_of(effort: Effort) -> (u32, Option<f32>) {
    match effort {
        Effort::UltraFast => (1, Some(3.0)),
        Effort::VeryFast => (1, Some(1.5)),
        Effort::Fast => (2, Some(1.0)),
        Effort::Basic => (2, Some(0.5)),
        Effort::Slow => (3, None),
    }
}

impl Uastc {
    /// UASTC for `channels` meaningful components (clamped to 1..=4), sRGB colour where
    /// `srgb`.
    pub fn new(channels: usize, srgb: bool) -> Self {
        let channels = channels.clamp(1, 4);
        Self {
            channels,
            srgb,
            bc7: Bc7::new(true, srgb),
            astc: Astc::new(AstcBlock::DEFAULT, channels, srgb),
        }
    }

    /// The blocks' texels as the ASTC 4x4 transcode decodes them (UASTC's own texels),
    /// stored components first.
    ///
    /// # Errors
    /// Blocks that do not transcode or decode.
    pub fn decode_lossless(
        &self,
        blocks: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        let astc =
            kapaint_basis::transcode_uastc(blocks, size, Target::Astc4x4).map_err(library)?;
        self.astc.decode_strip(&astc, size, out)
    }

    /// The channel the descriptor names for its one sample.
    fn channel_id(&self) -> u8 {
        // KHR_DF_CHANNEL_UASTC_{RGB, RGBA, RRR, RRRG}.
        match self.channels {
            1 => 3,
            2 => 5,
            3 => 0,
            _ => 2,
        }
    }
}

fn library(reason: String) -> CodecError {
    CodecError::Library {
        codec: "UASTC",
        reason,
    }
}

impl Codec for Uastc {
    fn name(&self) -> &'static str {
        "UASTC"
    }

    fn describe(&self) -> String {
        match self.channels {
            1 => "UASTC (luminance)".into(),
            2 => "UASTC (luminance and alpha)".into(),
            _ => "UASTC".into(),
        }
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        None
    }

    fn dfd(&self) -> Result<(dfd::Basic, u32), String> {
        // KHR_DF_MODEL_UASTC: one 128-bit sample over a 4x4 block, 16 bytes in plane 0.
        let four = std::num::NonZeroU8::new(4).ok_or("a block of four")?;
        let one = std::num::NonZeroU8::MIN;
        let basic = dfd::Basic {
            color_model: Some(ktx2::ColorModel::UASTC),
            color_primaries: Some(ktx2::ColorPrimaries::BT709),
            transfer_function: Some(if self.srgb {
                ktx2::TransferFunction::SRGB
            } else {
                ktx2::TransferFunction::Linear
            }),
            flags: dfd::DataFormatFlags::STRAIGHT_ALPHA,
            texel_block_dimensions: [four, four, one, one],
            bytes_planes: [16, 0, 0, 0, 0, 0, 0, 0],
            sample_information: vec![dfd::SampleInformation {
                bit_offset: 0,
                bit_length: std::num::NonZeroU8::new(128).ok_or("128 bits")?,
                channel_type: self.channel_id(),
                channel_type_qualifiers: dfd::ChannelTypeQualifiers::empty(),
                sample_positions: [0; 4],
                lower: 0,
                upper: u32::MAX,
            }],
        };
        Ok((basic, 1))
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Uastc
    }

    fn texel_bytes(&self) -> usize {
        4
    }

    /// About 16,384 blocks a strip: the RDO conditions a run of blocks for the LZ coder, and a
    /// short strip starts its run afresh too often (basisu's own runs are as long).
    fn strip_block_rows(&self, blocks_across: usize) -> usize {
        (16_384 / blocks_across.max(1)).max(8)
    }

    fn effort_name(&self, effort: Effort) -> &'static str {
        match effort {
            Effort::UltraFast => "level 1, RDO 3.0",
            Effort::VeryFast => "level 1, RDO 1.5",
            Effort::Fast => "level 2, RDO 1.0",
            Effort::Basic => "level 2, RDO 0.5",
            Effort::Slow => "level 3, no RDO",
        }
    }

    fn own_encoder(&self) -> Option<super::Encoder> {
        Some(super::Encoder::Basisu)
    }

    fn encode_strip(
        &self,
        _cpu: Cpu,
        effort: Effort,
        texels: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        check_strip(self, size, texels.len(), out.len())?;
        let rgba: Vec<u8> = texels
            .chunks_exact(4)
            .flat_map(|t| match self.channels {
                1 => [t[0], t[0], t[0], 255],
                2 => [t[0], t[0], t[0], t[1]],
                3 => [t[0], t[1], t[2], 255],
                _ => [t[0], t[1], t[2], t[3]],
            })
            .collect();
        let (level, rdo) = settings_of(effort);
        let how = Settings {
            level,
            rdo,
            srgb: self.srgb,
        };
        let blocks = kapaint_basis::encode_uastc(&rgba, size, how).map_err(library)?;
        out.copy_from_slice(&blocks);
        Ok(())
    }

    fn decode_strip(
        &self,
        blocks: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        check_strip(self, size, out.len(), blocks.len())?;
        let bc7 = kapaint_basis::transcode_uastc(blocks, size, Target::Bc7).map_err(library)?;
        let mut rgba = vec![0_u8; out.len()];
        self.bc7.decode_strip(&bc7, size, &mut rgba)?;
        for (d, s) in out.chunks_exact_mut(4).zip(rgba.chunks_exact(4)) {
            match self.channels {
                1 => d.copy_from_slice(&[s[0], 0, 0, 255]),
                2 => d.copy_from_slice(&[s[0], s[3], 0, 255]),
                _ => d.copy_from_slice(s),
            }
        }
        Ok(())
    }
}
