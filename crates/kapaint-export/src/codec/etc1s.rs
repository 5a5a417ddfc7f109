//! ETC1S with BasisLZ: Basis Universal's smaller format (about 1 to 2 bits a texel where UASTC
//! takes 8), whose blocks index codebooks of endpoints and selectors that the whole image and
//! all its mips share. It cannot be a strip codec behind [`super::Codec`]: a strip encoded
//! apart would have codebooks of its own, and a KTX2 file holds one set. So it stands beside
//! the trait: a whole image in, its codebooks and slices out (with the encoder's mips,
//! [`kapaint_basis::etc1s`]; `crate::ktx::etc1s_file` writes them as KTX2),
//! and level 0 as a runtime decodes it after transcoding to BC7 (the measure's input).
//!
//! **Efforts** map onto ETC1S's quality level (the codebooks' size): 32, 64, 128, 192, 255.

use super::{Bc7, Codec, CodecError, Effort};
use crate::blocks;
use kapaint_basis::etc1s::{Etc1s, encode_etc1s, transcode_etc1s};
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

/// An image encoded as ETC1S.
pub struct Etc1sFile {
    /// The image: codebooks, tables and every level's slices (`crate::ktx::etc1s_file`
    /// writes its KTX2 file).
    pub image: Etc1sImage,
    /// Level 0 as the BC7 transcode decodes it: RGBA8, the image's size.
    pub decoded: Vec<u8>,
    /// The quality level it was encoded at.
    pub quality: u32,
}

fn library(reason: String) -> CodecError {
    CodecError::Library {
        codec: "ETC1S",
        reason,
    }
}

/// `rgba` (`size`, RGBA8, sides multiples of 4) as ETC1S at `effort`, sRGB colour where
/// `srgb`, with its full mip chain.
///
/// # Errors
/// The encoder's or transcoder's failure.
pub fn encode(
    rgba: &[u8],
    size: (u32, u32),
    effort: Effort,
    srgb: bool,
) -> Result<Etc1sFile, CodecError> {
    let quality = quality_of(effort);
    let how = Etc1s {
        quality,
        srgb,
        mips: true,
    };
    let image = encode_etc1s(rgba, size, how).map_err(library)?;
    let decoded = decode_level0(&image, srgb)?;
    Ok(Etc1sFile {
        image,
        decoded,
        quality,
    })
}

/// Level 0 of `image` as a runtime decodes it after transcoding to BC7: RGBA8 at its size
/// padded to whole blocks (alpha 255 where the image has no alpha slice).
///
/// # Errors
/// Codebooks or slices the transcoder cannot read.
pub fn decode_level0(image: &Etc1sImage, srgb: bool) -> Result<Vec<u8>, CodecError> {
    let first = image
        .levels
        .first()
        .ok_or_else(|| library("no levels".into()))?;
    let size = (first.width.div_ceil(4) * 4, first.height.div_ceil(4) * 4);
    let bc7 = transcode_etc1s(image, srgb, kapaint_basis::Target::Bc7).map_err(library)?;
    let level0 = bc7.first().ok_or_else(|| library("no levels".into()))?;
    let codec = Bc7::new(true, srgb);
    if level0.len() != codec.blocks_len(size) {
        return Err(library("level 0 transcodes to the wrong size".into()));
    }
    blocks::decode(&codec, level0, size)
}
