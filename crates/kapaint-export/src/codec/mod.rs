//! Block codecs: each block format kapaint writes is one value behind [`Codec`], in one file
//! (BC4, BC5, BC7, BC6H, ASTC LDR, UASTC; ETC1S stands beside the trait, [`etc1s`]); a
//! preset's format picks an image's codec
//! (`preset::Format::codec`). A codec says what its blocks are (the KTX2 format, the
//! footprint and bytes, the manifest's name), which efforts it tells apart, and encodes and
//! decodes one strip of block rows; [`crate::blocks`] runs strips in parallel over any codec,
//! with the CPU's encoders or one a caller brings.
//!
//! A new codec is a file here (and a line in [`from_vk_format`] where kapaint reads its files
//! back), a preset format with its parameters that picks it, a [`Compression`] name, and a
//! preset (ARCHITECTURE.md lists the files).

pub mod astc;
mod bc4;
mod bc5;
mod bc6h;
mod bc7;
pub mod etc1s;
mod uastc;

use serde::{Deserialize, Serialize};

pub use self::astc::{Astc, AstcBlock};
pub use self::bc4::Bc4;
pub use self::bc5::Bc5;
pub use self::bc6h::Bc6h;
pub use self::bc7::Bc7;
pub use self::uastc::{Uastc, settings_of as uastc_settings_of};
use crate::file_kind::Compression;

/// How hard an encoder searches, on one scale every codec maps onto its own settings
/// ([`Codec::effort`], [`Codec::effort_name`]). Ordered from the cheapest.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub enum Effort {
    /// The fewest candidates tried.
    UltraFast,
    /// About 1 dB under `Basic` at a fraction of the time (BC7).
    VeryFast,
    /// More candidates.
    Fast,
    /// The reference encoders' basic profile: the most a preset spends by default.
    #[default]
    Basic,
    /// Exhaustive.
    Slow,
}

impl Effort {
    /// Every effort, cheapest first.
    pub const ALL: [Self; 5] = [
        Self::UltraFast,
        Self::VeryFast,
        Self::Fast,
        Self::Basic,
        Self::Slow,
    ];
}

/// Which code encoded a set's blocks, as a manifest names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Encoder {
    /// Intel's ISPC kernels (`x86_64`).
    Ispc,
    /// `block_compression`'s CPU port.
    Portable,
    /// An encoder the caller brought (a GPU's compute shaders); the CPU's best encoder
    /// wherever it fails.
    Gpu,
    /// ARM's ASTC encoder (`astcenc`), for ASTC blocks.
    Astcenc,
    /// Binomial's Basis Universal encoder, for UASTC blocks.
    Basisu,
}

impl Encoder {
    /// The fastest encoder this CPU has.
    pub fn best_cpu() -> Self {
        if cfg!(target_arch = "x86_64") {
            Self::Ispc
        } else {
            Self::Portable
        }
    }
}

/// Which of the CPU's BC encoders a codec runs where it has two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cpu {
    /// Intel's ISPC kernels (`x86_64` only; elsewhere the portable one).
    Ispc,
    /// `block_compression`'s CPU port.
    Portable,
}

/// Why a codec could not encode or decode a strip.
#[derive(Debug, thiserror::Error)]
pub enum CodecError {
    /// The strip's bytes do not match its size.
    #[error("{codec}: {got} bytes for a {width}x{rows} strip, {want} expected")]
    Size {
        /// The codec's name.
        codec: &'static str,
        /// Texels across.
        width: u32,
        /// Texel rows.
        rows: u32,
        /// Bytes given.
        got: usize,
        /// Bytes expected.
        want: usize,
    },
    /// The encoder or decoder library failed (it could not build its tables: out of memory).
    #[error("{codec}: {reason}")]
    Library {
        /// The codec's name.
        codec: &'static str,
        /// What the library said.
        reason: String,
    },
}

/// A block format: what its blocks are, and the encoding and decoding of one strip of block
/// rows. One value serves one image (its contexts and tables live as long as it does, shared
/// by the strips, mips and effort trials of that image).
pub trait Codec: Send + Sync + std::fmt::Debug {
    /// A short name for errors and reports ("BC7", "ASTC 6x6").
    fn name(&self) -> &'static str;

    /// What its files hold, in words for people ("BC5", "ASTC 6x6 (luminance and alpha)").
    fn describe(&self) -> String {
        self.name().into()
    }

    /// The KTX2 (Vulkan) format of its blocks; `None` for UNDEFINED, where the data format
    /// descriptor alone says what they are (UASTC).
    fn vk_format(&self) -> Option<ktx2::Format>;

    /// Its KTX2 data format descriptor and the header's `typeSize`: by default the one the
    /// `ktx2` crate makes for [`Codec::vk_format`].
    ///
    /// # Errors
    /// A codec without a Vulkan format that does not describe itself.
    fn dfd(&self) -> Result<(ktx2::dfd::Basic, u32), String> {
        let format = self
            .vk_format()
            .ok_or_else(|| format!("{} has no Vulkan format to describe", self.name()))?;
        ktx2::dfd::Basic::from_format(format).map_err(|e| format!("data format descriptor: {e:?}"))
    }

    /// The manifest's name for its files.
    fn compression(&self) -> Compression;

    /// A block's footprint, texels across and down.
    fn block_dims(&self) -> (u32, u32) {
        (4, 4)
    }

    /// Bytes per block.
    fn block_bytes(&self) -> usize {
        16
    }

    /// Block rows per parallel strip, for an image `blocks_across` blocks wide: eight by
    /// default, more for a codec whose encoder works better on more blocks at once.
    fn strip_block_rows(&self, _blocks_across: usize) -> usize {
        8
    }

    /// Bytes per texel of the input and of a decoded strip: 1, 2 or 4 bytes, or four
    /// little-endian half floats (8).
    fn texel_bytes(&self) -> usize;

    /// A whole input texel whose leading bytes a stored texel replaces: the filler of the
    /// components a file does not hold (opaque alpha: 255).
    fn filler(&self) -> [u8; 8] {
        [0, 0, 0, 255, 0, 0, 0, 0]
    }

    /// The effort it runs when asked for `asked` (efforts it does not tell apart map to one):
    /// two efforts with the same answer give the same blocks.
    fn effort(&self, asked: Effort) -> Effort {
        asked
    }

    /// Its own name for an effort (ASTC's "thorough"), for reports.
    fn effort_name(&self, effort: Effort) -> &'static str {
        match self.effort(effort) {
            Effort::UltraFast => "ultra fast",
            Effort::VeryFast => "very fast",
            Effort::Fast => "fast",
            Effort::Basic => "basic",
            Effort::Slow => "slow",
        }
    }

    /// The encoder it always uses, whatever the caller brings (ASTC's `astcenc`): the manifest
    /// then names it.
    fn own_encoder(&self) -> Option<Encoder> {
        None
    }

    /// `block_compression`'s name and settings for it at `effort`, where that crate (its CPU
    /// port, and the GPU's compute shaders built on it) encodes it.
    fn portable(&self, _effort: Effort) -> Option<block_compression::CompressionVariant> {
        None
    }

    /// Encodes `rows` texel rows (a multiple of the footprint's height) of a `width`-wide
    /// strip of [`Codec::texel_bytes`] bytes per texel into `out`, with the CPU encoder
    /// `cpu` where it has more than one.
    ///
    /// # Errors
    /// Sizes that do not match, or the encoder library failed.
    fn encode_strip(
        &self,
        cpu: Cpu,
        effort: Effort,
        texels: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError>;

    /// Decodes the blocks of `rows` texel rows of a `width`-wide strip into
    /// [`Codec::texel_bytes`] bytes per texel, the stored components first.
    ///
    /// # Errors
    /// Sizes that do not match, or the decoder library failed.
    fn decode_strip(
        &self,
        blocks: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError>;

    /// Improves encoded blocks where the codec knows better than its encoder (BC7's blocks of
    /// one colour, stored exactly); `texels` are the strip's whole input texels.
    fn refine(&self, _blocks: &mut [u8], _texels: &[u8], _width: usize) {}

    /// Bytes of the blocks covering a `(width, height)` image (sides multiples of
    /// [`Codec::block_dims`]).
    fn blocks_len(&self, (width, height): (u32, u32)) -> usize {
        let (bw, bh) = self.block_dims();
        (width / bw) as usize * (height / bh) as usize * self.block_bytes()
    }
}

/// Checks a strip of `(width, rows)` texels as `codec` takes them: `texels` bytes of its
/// whole texels and `blocks` bytes of its blocks.
pub(crate) fn check_strip(
    codec: &dyn Codec,
    (width, rows): (u32, u32),
    texels: usize,
    blocks: usize,
) -> Result<(), CodecError> {
    let size_error = |got, want| CodecError::Size {
        codec: codec.name(),
        width,
        rows,
        got,
        want,
    };
    let want = width as usize * rows as usize * codec.texel_bytes();
    if texels != want {
        return Err(size_error(texels, want));
    }
    let want = codec.blocks_len((width, rows));
    if blocks != want {
        return Err(size_error(blocks, want));
    }
    Ok(())
}

/// The codec of a KTX2 file's blocks, to read them back (ASTC as four components), where
/// kapaint writes that format.
pub fn from_vk_format(format: ktx2::Format) -> Option<Box<dyn Codec>> {
    if let Some((block, srgb)) = AstcBlock::of_vk_format(format.value()) {
        return Some(Box::new(Astc::new(block, 4, srgb)));
    }
    Some(match format {
        ktx2::Format::BC4_UNORM_BLOCK => Box::new(Bc4),
        ktx2::Format::BC5_UNORM_BLOCK => Box::new(Bc5),
        ktx2::Format::BC6H_UFLOAT_BLOCK => Box::new(Bc6h),
        ktx2::Format::BC7_UNORM_BLOCK => Box::new(Bc7::new(true, false)),
        ktx2::Format::BC7_SRGB_BLOCK => Box::new(Bc7::new(true, true)),
        _ => return None,
    })
}

/// `src`'s texels of `stored` bytes widened to `to` bytes each (at most eight), the rest of
/// each taken from `filler`, into `out`.
pub(crate) fn widen_into(src: &[u8], stored: usize, to: usize, filler: [u8; 8], out: &mut [u8]) {
    for (d, s) in out.chunks_exact_mut(to).zip(src.chunks_exact(stored)) {
        d.copy_from_slice(&filler[..to]);
        d[..stored].copy_from_slice(s);
    }
}

/// `src` as [`widen_into`] widens it: borrowed where it already has `to` bytes per texel.
pub(crate) fn widen(
    src: &[u8],
    stored: usize,
    to: usize,
    filler: [u8; 8],
) -> std::borrow::Cow<'_, [u8]> {
    if stored == to {
        return src.into();
    }
    let mut out = vec![0; src.len() / stored * to];
    widen_into(src, stored, to, filler, &mut out);
    out.into()
}

/// `block_compression`'s CPU encoder for `variant` over a strip (RGBA8 input, or RGBA16F for
/// BC6H): the portable path of the BC codecs.
pub(crate) fn encode_portable(
    variant: block_compression::CompressionVariant,
    rgba: &[u8],
    (width, rows): (u32, u32),
    out: &mut [u8],
) {
    block_compression::encode::compress_rgba8(variant, rgba, out, width, rows, width * 4);
}
