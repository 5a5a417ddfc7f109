//! A preset's image format, with the parameters each format has (preset version 2).

use serde::{Deserialize, Serialize};

use super::{AstcBlock, Effort, default_bc6h};
use crate::codec::etc1s::Etc1sCodec;
use crate::codec::{Astc, Bc4, Bc5, Bc6h, Bc7, Codec, Uastc};
use crate::ktx::Space;

/// Image format of the exported files, with the parameters that format has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Format {
    /// 8-bit PNG (colour in sRGB).
    Png8,
    /// 16-bit PNG (linear).
    Png16,
    /// Float OpenEXR (linear; `n` as is).
    Exr,
    /// KTX2, 8 bits per component, uncompressed, with a full mip chain.
    Ktx2,
    /// KTX2 block-compressed with a full mip chain: BC7 for three or four components, BC5
    /// for two, BC4 for one, BC6H for colour where BC7 misses the budget.
    Ktx2Bc {
        /// The most effort the export may spend meeting its budget.
        #[serde(default)]
        max_effort: Effort,
        /// Whether colour may be stored as BC6H (linear half floats) when BC7 misses the
        /// budget; off for consumers that sample only BC7.
        #[serde(default = "default_bc6h")]
        bc6h: bool,
    },
    /// KTX2 with ASTC LDR blocks and a full mip chain (phones, standalone headsets): one
    /// footprint for every image, `k_d` sRGB.
    Ktx2Astc {
        /// The footprint (`"6x6"`; 4x4 by default); the loader refuses one ASTC does not
        /// define.
        #[serde(default)]
        block: AstcBlock,
        /// The most effort (`astcenc`'s search) the export may spend meeting its budget.
        #[serde(default)]
        max_effort: Effort,
    },
    /// KTX2 with Basis Universal's UASTC blocks and a full mip chain, which a runtime
    /// transcodes to BC7 or ASTC 4x4: the quality level and RDO chosen against the budget
    /// as measured after transcoding ([`crate::codec::Uastc`]).
    Ktx2Uastc {
        /// The most effort (level and RDO: [`crate::codec::uastc_settings_of`]) the export
        /// may spend meeting its budget.
        #[serde(default)]
        max_effort: Effort,
    },
    /// KTX2 with Basis Universal's ETC1S blocks and BasisLZ (about 1 to 2 bits a texel, a
    /// fifth of UASTC's bytes), which a runtime transcodes to BC7 or ASTC 4x4: the quality
    /// level chosen against the budget as measured after transcoding
    /// ([`crate::codec::etc1s`]). Its codebooks span a whole image and its mips, so it is
    /// encoded a whole image at a time ([`Format::whole_image`]), not by strips; the normal
    /// map is UASTC (ETC1S's shared endpoints blur directions).
    Ktx2Etc1s {
        /// The most effort (quality level: [`crate::codec::etc1s::quality_of`]) the export
        /// may spend meeting its budget.
        #[serde(default)]
        max_effort: Effort,
    },
    /// glTF's metallic-roughness PNGs (8-bit): base colour (sRGB), metallic-roughness (G
    /// roughness, B metallic), and the normal map where the project has one; converted back
    /// from `k_d`, `k_s`, `n` ([`crate::gltf_pbr`]). `layout`, `n_bits` and `include_ka` do
    /// not apply.
    GltfPbr,
    /// PBR PNGs in the preset's own layout (`textures:`): engine materials (Unreal's ORM,
    /// Unity's mask map, Godot's ORM), converted back from `k_d`, `k_s`, `n` as
    /// [`Self::GltfPbr`] is, occlusion from the AO bake ([`crate::gltf_pbr`]). `layout`,
    /// `n_bits` and `include_ka` do not apply.
    PbrTextures,
}

impl Format {
    /// The format's name as a preset spells it, without its parameters.
    pub fn name(self) -> &'static str {
        match self {
            Self::Png8 => "Png8",
            Self::Png16 => "Png16",
            Self::Exr => "Exr",
            Self::Ktx2 => "Ktx2",
            Self::Ktx2Bc { .. } => "Ktx2Bc",
            Self::Ktx2Astc { .. } => "Ktx2Astc",
            Self::Ktx2Uastc { .. } => "Ktx2Uastc",
            Self::Ktx2Etc1s { .. } => "Ktx2Etc1s",
            Self::GltfPbr => "GltfPbr",
            Self::PbrTextures => "PbrTextures",
        }
    }

    /// Whether files hold 8-bit components (PNG8, the KTX2 kinds and glTF's PNGs).
    pub fn is_8bit(self) -> bool {
        match self {
            Self::Png8
            | Self::Ktx2
            | Self::Ktx2Bc { .. }
            | Self::Ktx2Astc { .. }
            | Self::Ktx2Uastc { .. }
            | Self::Ktx2Etc1s { .. }
            | Self::GltfPbr
            | Self::PbrTextures => true,
            Self::Png16 | Self::Exr => false,
        }
    }

    /// Whether files are KTX2 containers.
    pub fn is_ktx2(self) -> bool {
        match self {
            Self::Ktx2
            | Self::Ktx2Bc { .. }
            | Self::Ktx2Astc { .. }
            | Self::Ktx2Uastc { .. }
            | Self::Ktx2Etc1s { .. } => true,
            Self::Png8 | Self::Png16 | Self::Exr | Self::GltfPbr | Self::PbrTextures => false,
        }
    }

    /// Whether files are block-compressed (BC or ASTC), their layout and effort chosen
    /// against the preset's budget.
    pub fn is_blocks(self) -> bool {
        self.max_effort().is_some()
    }

    /// Whether this is the glTF metallic-roughness export (a PBR set that may carry a `.glb`).
    pub fn is_gltf_pbr(self) -> bool {
        matches!(self, Self::GltfPbr)
    }

    /// Whether this writes PBR textures (glTF's or a layout's), not a kapaint set.
    pub fn is_pbr(self) -> bool {
        matches!(self, Self::GltfPbr | Self::PbrTextures)
    }

    /// The most effort a block-compressed export may spend (`None` without blocks).
    pub fn max_effort(self) -> Option<Effort> {
        match self {
            Self::Ktx2Bc { max_effort, .. }
            | Self::Ktx2Astc { max_effort, .. }
            | Self::Ktx2Uastc { max_effort }
            | Self::Ktx2Etc1s { max_effort } => Some(max_effort),
            Self::Png8
            | Self::Png16
            | Self::Exr
            | Self::Ktx2
            | Self::GltfPbr
            | Self::PbrTextures => None,
        }
    }

    /// Whether colour may be stored as linear half floats (BC6H) when the 8-bit blocks miss
    /// the budget.
    pub fn half_colour(self) -> bool {
        match self {
            Self::Ktx2Bc { bc6h, .. } => bc6h,
            _ => false,
        }
    }

    /// Whether every block costs the same bytes whatever it holds (ASTC's 16 bytes for one to
    /// four components), so an image of fewer components saves nothing.
    pub fn same_bytes_per_block(self) -> bool {
        matches!(self, Self::Ktx2Astc { .. } | Self::Ktx2Uastc { .. })
    }

    /// The ASTC footprint, for an ASTC format.
    pub fn astc_block(self) -> Option<AstcBlock> {
        match self {
            Self::Ktx2Astc { block, .. } => Some(block),
            _ => None,
        }
    }

    /// Bytes per stored component: 1 (8-bit), 2 (16-bit PNG) or 4 (EXR's floats).
    pub fn component_bytes(self) -> u8 {
        match self {
            Self::Png8
            | Self::Ktx2
            | Self::Ktx2Bc { .. }
            | Self::Ktx2Astc { .. }
            | Self::Ktx2Uastc { .. }
            | Self::Ktx2Etc1s { .. }
            | Self::GltfPbr
            | Self::PbrTextures => 1,
            Self::Png16 => 2,
            Self::Exr => 4,
        }
    }

    /// The files' extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png8 | Self::Png16 | Self::GltfPbr | Self::PbrTextures => "png",
            Self::Exr => "exr",
            Self::Ktx2
            | Self::Ktx2Bc { .. }
            | Self::Ktx2Astc { .. }
            | Self::Ktx2Uastc { .. }
            | Self::Ktx2Etc1s { .. } => "ktx2",
        }
    }

    /// The codec an image of components in `spaces` is written with, the one place that
    /// picks it: ASTC of the format's footprint (sRGB where colour leads three or four
    /// components); BC6H for half floats, else BC by the component count (BC4, BC5, BC7);
    /// `None` for a format without blocks, or whose blocks are encoded a whole image at a
    /// time ([`Format::whole_image`]).
    pub fn codec(self, spaces: &[Space]) -> Option<Box<dyn Codec>> {
        let srgb = spaces.len() >= 3 && spaces[0].is_colour();
        match self {
            Self::Ktx2Astc { block, .. } => Some(Box::new(Astc::new(block, spaces.len(), srgb))),
            Self::Ktx2Uastc { .. } => Some(Box::new(Uastc::new(spaces.len(), srgb))),
            Self::Ktx2Bc { .. } if spaces.first() == Some(&Space::Half) => Some(Box::new(Bc6h)),
            Self::Ktx2Bc { .. } => Some(match spaces.len() {
                1 => Box::new(Bc4),
                2 => Box::new(Bc5),
                c => Box::new(Bc7::new(c == 4, srgb)),
            }),
            Self::Png8
            | Self::Png16
            | Self::Exr
            | Self::Ktx2
            | Self::Ktx2Etc1s { .. }
            | Self::GltfPbr
            | Self::PbrTextures => None,
        }
    }

    /// The codec of an image of components in `spaces` whose blocks are encoded a whole image
    /// at a time (ETC1S: codebooks the image and its mips share), the one place that picks
    /// it; `None` for the other formats.
    pub fn whole_image(self, spaces: &[Space]) -> Option<Etc1sCodec> {
        let srgb = spaces.len() >= 3 && spaces[0].is_colour();
        match self {
            Self::Ktx2Etc1s { .. } => Some(Etc1sCodec::new(spaces.len(), srgb)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_written_codec_reads_back_as_itself() {
        let formats = [
            Format::Ktx2Bc {
                max_effort: Effort::Basic,
                bc6h: true,
            },
            Format::Ktx2Astc {
                block: AstcBlock::DEFAULT,
                max_effort: Effort::Basic,
            },
        ];
        for format in formats {
            for spaces in [
                vec![Space::Linear],
                vec![Space::Linear; 2],
                vec![Space::Srgb; 3],
                vec![Space::Srgb, Space::Srgb, Space::Srgb, Space::Linear],
                vec![Space::Half; 3],
            ] {
                let codec = format.codec(&spaces).expect("a block format");
                let vk = codec.vk_format().expect("a Vulkan format");
                let back = crate::codec::from_vk_format(vk).expect("read back");
                assert_eq!(back.vk_format(), codec.vk_format());
                assert_eq!(back.compression(), codec.compression());
                assert_eq!(back.block_dims(), codec.block_dims());
            }
        }
        assert!(Format::Ktx2.codec(&[Space::Linear]).is_none());
    }
}
