//! ETC1S with BasisLZ: Basis Universal's smaller format (about 1 to 2 bits a texel where UASTC
//! takes 8), whose blocks index codebooks of endpoints and selectors that the whole image and
//! all its mips share. It cannot be a strip codec behind [`super::Codec`]: a strip encoded
//! apart would have codebooks of its own, and a KTX2 file holds one set. So it stands beside
//! the trait: a whole image in, its codebooks and slices out ([`kapaint_basis::etc1s`];
//! `crate::ktx::etc1s_file` writes them as KTX2).
//!
//! Every image goes through [`Etc1sCodec`] (a set's, the Basis `.glb`'s base colour, a file
//! read back): its stored components (one as luminance, two as luminance and alpha, three as
//! RGB, four as RGBA, as UASTC takes them) and kapaint's own mips (averaged in each
//! component's space, as every KTX2 file's), encoded together so the codebooks serve every
//! level; levels come back as the BC7 transcode decodes them (the measure's input).
//!
//! **Efforts** map onto ETC1S's quality level (the codebooks' size): 32, 64, 128, 192, 255.

use super::{Bc7, Codec, CodecError, Effort};
use crate::blocks;
use crate::file_kind::Compression;
use kapaint_basis::etc1s::{Etc1s, encode_etc1s_levels, transcode_etc1s};
pub use kapaint_basis::etc1s::{Etc1sImage, Level};

/// ETC1S's quality level for an effort.
pub fn quality_of(effort: Effort) -> u32 {
    match effort {
        Effort::UltraFast => 32,
        Effort::VeryFast => 64,
        Effort::Fast => 128,
        Effort::Basic => 192,
        Effort::Slow => 255,
    }
}

fn library(reason: String) -> CodecError {
    CodecError::Library {
        codec: "ETC1S",
        reason,
    }
}

/// ETC1S for an image of `channels` stored components (1 to 4), sRGB colour where `srgb`:
/// the codec of a `ktx2-etc1s` set's images (`crate::preset::Format::whole_image`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Etc1sCodec {
    channels: usize,
    srgb: bool,
}

/// An image's levels encoded as ETC1S, and each as a runtime decodes it.
pub struct Etc1sLevels {
    /// The image: codebooks, tables and every level's slices.
    pub image: Etc1sImage,
    /// Every level (level 0 first) as the BC7 transcode decodes it, the stored components
    /// of each texel.
    pub decoded: Vec<Vec<u8>>,
    /// The quality level it was encoded at.
    pub quality: u32,
}

impl Etc1sCodec {
    /// ETC1S for `channels` stored components (clamped to 1..=4), sRGB colour where `srgb`.
    pub fn new(channels: usize, srgb: bool) -> Self {
        Self {
            channels: channels.clamp(1, 4),
            srgb,
        }
    }

    /// Whether colour is sRGB-encoded.
    pub fn srgb(self) -> bool {
        self.srgb
    }

    /// The manifest's name for its files.
    pub fn compression(self) -> Compression {
        Compression::Ktx2Etc1s
    }

    /// `stored` texels (`channels` bytes each) as RGBA: one as luminance, two as luminance
    /// and alpha, alpha 255 where there is none.
    fn rgba_of(self, stored: &[u8]) -> Vec<u8> {
        let ch = self.channels;
        let mut out = Vec::with_capacity(stored.len() / ch * 4);
        for t in stored.chunks_exact(ch) {
            out.extend_from_slice(&match ch {
                1 => [t[0], t[0], t[0], 255],
                2 => [t[0], t[0], t[0], t[1]],
                3 => [t[0], t[1], t[2], 255],
                _ => [t[0], t[1], t[2], t[3]],
            });
        }
        out
    }

    /// RGBA texels back to the stored components (the second of two from alpha).
    fn stored_of(self, rgba: &[u8]) -> Vec<u8> {
        let ch = self.channels;
        let mut out = Vec::with_capacity(rgba.len() / 4 * ch);
        for t in rgba.chunks_exact(4) {
            match ch {
                1 => out.push(t[0]),
                2 => out.extend_from_slice(&[t[0], t[3]]),
                3 => out.extend_from_slice(&t[..3]),
                _ => out.extend_from_slice(t),
            }
        }
        out
    }

    /// `levels` (level 0 first, each `(size, stored texels)`; level 0's sides multiples of
    /// 4, each next level halved) encoded at `effort`'s quality with shared codebooks, and
    /// every level decoded as the BC7 transcode gives it.
    ///
    /// # Errors
    /// Sizes that do not follow, or the encoder's or transcoder's failure.
    pub fn encode(
        self,
        levels: &[((u32, u32), &[u8])],
        effort: Effort,
    ) -> Result<Etc1sLevels, CodecError> {
        let quality = quality_of(effort);
        let rgba: Vec<Vec<u8>> = levels.iter().map(|(_, t)| self.rgba_of(t)).collect();
        let given: Vec<(&[u8], (u32, u32))> = rgba
            .iter()
            .zip(levels)
            .map(|(t, (size, _))| (&t[..], *size))
            .collect();
        let how = Etc1s {
            quality,
            srgb: self.srgb,
            mips: false,
        };
        let image = encode_etc1s_levels(&given, how).map_err(library)?;
        let decoded = self.decode(&image, image.levels.len())?;
        Ok(Etc1sLevels {
            image,
            decoded,
            quality,
        })
    }

    /// The first `levels` levels of `image` as the BC7 transcode decodes them, stored
    /// components only (alpha 255 where the image has no alpha slice), each at its own size.
    ///
    /// # Errors
    /// Codebooks or slices the transcoder cannot read.
    pub fn decode(self, image: &Etc1sImage, levels: usize) -> Result<Vec<Vec<u8>>, CodecError> {
        let bc7 = transcode_etc1s(image, self.srgb, kapaint_basis::Target::Bc7).map_err(library)?;
        let codec = Bc7::new(true, self.srgb);
        image
            .levels
            .iter()
            .zip(&bc7)
            .take(levels)
            .map(|(level, blocks)| {
                let (w, h) = (level.width, level.height);
                let padded = (w.div_ceil(4) * 4, h.div_ceil(4) * 4);
                if blocks.len() != codec.blocks_len(padded) {
                    return Err(library(format!(
                        "a {w}x{h} level transcodes to the wrong size"
                    )));
                }
                let rgba = blocks::decode(&codec, blocks, padded)?;
                let row = padded.0 as usize * 4;
                let cropped: Vec<u8> = rgba
                    .chunks_exact(row)
                    .take(h as usize)
                    .flat_map(|r| &r[..w as usize * 4])
                    .copied()
                    .collect();
                Ok(self.stored_of(&cropped))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn components_go_in_and_come_back_where_uastc_puts_them() {
        for channels in 1..=4 {
            let codec = Etc1sCodec::new(channels, false);
            let stored: Vec<u8> = (0..channels as u8).map(|c| 40 + 50 * c).collect();
            let rgba = codec.rgba_of(&stored);
            assert_eq!(codec.stored_of(&rgba), stored, "{channels}");
        }
        assert_eq!(Etc1sCodec::new(2, false).rgba_of(&[7, 9]), [7, 7, 7, 9]);
    }

    #[test]
    fn a_level_chain_decodes_at_every_size_near_its_texels() {
        // 12x8 (whole blocks) down to 1x1: levels 6x4, 3x2 and 1x1 are cropped from padded
        // blocks.
        let codec = Etc1sCodec::new(2, false);
        let mut levels = Vec::new();
        let mut size = (12_u32, 8_u32);
        loop {
            let texels: Vec<u8> = (0..size.0 * size.1)
                .flat_map(|i| [(i * 9) as u8, 200])
                .collect();
            levels.push((size, texels));
            if size == (1, 1) {
                break;
            }
            size = ((size.0 / 2).max(1), (size.1 / 2).max(1));
        }
        let given: Vec<((u32, u32), &[u8])> = levels.iter().map(|(s, t)| (*s, &t[..])).collect();
        let out = codec.encode(&given, Effort::Slow).expect("encode");
        assert_eq!(out.quality, 255);
        assert_eq!(out.decoded.len(), levels.len());
        for ((size, want), got) in levels.iter().zip(&out.decoded) {
            assert_eq!(got.len(), want.len(), "{size:?}");
            let worst = want.iter().zip(got).map(|(a, b)| a.abs_diff(*b)).max();
            assert!(worst.is_some_and(|w| w <= 40), "{size:?}: {worst:?}");
        }
    }
}
