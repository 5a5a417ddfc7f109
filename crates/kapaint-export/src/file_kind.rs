//! What a set's file is: its container and compression, and how its colour is encoded. A leaf
//! that the KTX2 writer, the set's stages and its manifest share.

use serde::{Deserialize, Serialize};

/// How a file's colour components are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ColourSpace {
    /// sRGB-encoded (colour components of 8-bit images).
    Srgb,
    /// Linear values.
    Linear,
}

impl ColourSpace {
    /// The name a manifest spells.
    pub fn name(self) -> &'static str {
        match self {
            Self::Srgb => "srgb",
            Self::Linear => "linear",
        }
    }

    /// The colour space a manifest names.
    pub fn parse(name: &str) -> Option<Self> {
        [Self::Srgb, Self::Linear]
            .into_iter()
            .find(|c| c.name() == name)
    }
}

impl std::fmt::Display for ColourSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A file's container and compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Compression {
    /// PNG (deflate), 8 or 16 bits.
    #[serde(rename = "png")]
    Png,
    /// OpenEXR, 32-bit float.
    #[serde(rename = "exr")]
    Exr,
    /// KTX2, uncompressed 8-bit texels.
    #[serde(rename = "ktx2")]
    Ktx2,
    /// KTX2 with BC4 blocks (one component).
    #[serde(rename = "ktx2-bc4")]
    Ktx2Bc4,
    /// KTX2 with BC5 blocks (two components).
    #[serde(rename = "ktx2-bc5")]
    Ktx2Bc5,
    /// KTX2 with BC7 blocks (three or four components).
    #[serde(rename = "ktx2-bc7")]
    Ktx2Bc7,
    /// KTX2 with BC6H blocks: three components, linear unsigned half floats.
    #[serde(rename = "ktx2-bc6h")]
    Ktx2Bc6h,
    /// KTX2 with ASTC LDR blocks (one to four components; the footprint is the file's
    /// `vkFormat` and the manifest's `astc_block`).
    #[serde(rename = "ktx2-astc")]
    Ktx2Astc,
    /// KTX2 with Basis Universal's UASTC blocks (one to four components; `vkFormat`
    /// UNDEFINED, the data format descriptor says UASTC), transcoded by the runtime.
    #[serde(rename = "ktx2-uastc")]
    Ktx2Uastc,
    /// KTX2 with Basis Universal's ETC1S blocks and BasisLZ supercompression (one to four
    /// components; `vkFormat` UNDEFINED, supercompression scheme 1, codebooks in the global
    /// data), transcoded by the runtime.
    #[serde(rename = "ktx2-etc1s")]
    Ktx2Etc1s,
}

impl Compression {
    /// Every compression, in the order the docs list them.
    pub const ALL: [Self; 10] = [
        Self::Png,
        Self::Exr,
        Self::Ktx2,
        Self::Ktx2Bc4,
        Self::Ktx2Bc5,
        Self::Ktx2Bc7,
        Self::Ktx2Bc6h,
        Self::Ktx2Astc,
        Self::Ktx2Uastc,
        Self::Ktx2Etc1s,
    ];

    /// The name a manifest spells.
    pub fn name(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Exr => "exr",
            Self::Ktx2 => "ktx2",
            Self::Ktx2Bc4 => "ktx2-bc4",
            Self::Ktx2Bc5 => "ktx2-bc5",
            Self::Ktx2Bc7 => "ktx2-bc7",
            Self::Ktx2Bc6h => "ktx2-bc6h",
            Self::Ktx2Astc => "ktx2-astc",
            Self::Ktx2Uastc => "ktx2-uastc",
            Self::Ktx2Etc1s => "ktx2-etc1s",
        }
    }

    /// Whether two components are stored as luminance and alpha (ASTC's, UASTC's and ETC1S's
    /// blocks), not as red and green.
    pub fn second_in_alpha(self) -> bool {
        matches!(self, Self::Ktx2Astc | Self::Ktx2Uastc | Self::Ktx2Etc1s)
    }

    /// Whether its files carry a supercompression of their own (ETC1S's BasisLZ), so a
    /// preset's zstd does not go over them.
    pub fn has_own_supercompression(self) -> bool {
        matches!(self, Self::Ktx2Etc1s)
    }

    /// The compression a manifest names.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The file name's extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Exr => "exr",
            Self::Ktx2
            | Self::Ktx2Bc4
            | Self::Ktx2Bc5
            | Self::Ktx2Bc7
            | Self::Ktx2Bc6h
            | Self::Ktx2Astc
            | Self::Ktx2Uastc
            | Self::Ktx2Etc1s => "ktx2",
        }
    }

    /// The bits per component a file of this kind has.
    pub fn bit_depths(self) -> &'static [u32] {
        match self {
            Self::Png => &[8, 16],
            Self::Exr => &[32],
            Self::Ktx2
            | Self::Ktx2Bc4
            | Self::Ktx2Bc5
            | Self::Ktx2Bc7
            | Self::Ktx2Astc
            | Self::Ktx2Uastc
            | Self::Ktx2Etc1s => &[8],
            Self::Ktx2Bc6h => &[16],
        }
    }
}

impl std::fmt::Display for Compression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Zstandard levels 1 to 22, as a KTX2 file's supercompression takes them.
pub const ZSTD_LEVELS: std::ops::RangeInclusive<u8> = 1..=22;

/// A KTX2 file's supercompression: Zstandard at a level, each mip level on its own.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Supercompression {
    /// The scheme: [`Supercompression::ZSTD`].
    pub scheme: String,
    /// Its level (1 to 22).
    pub level: u8,
    /// The file's size with its levels as encoded, not supercompressed (so the saving is
    /// `1 - bytes / uncompressed_bytes`).
    pub uncompressed_bytes: u64,
}

impl Supercompression {
    /// Zstandard, each level on its own (KTX2 scheme 2): the one kapaint writes.
    pub const ZSTD: &'static str = "zstd";

    /// Whether it is one kapaint writes and reads: zstd at a level in
    /// [`ZSTD_LEVELS`].
    pub fn is_known(&self) -> bool {
        self.scheme == Self::ZSTD && ZSTD_LEVELS.contains(&self.level)
    }
}
