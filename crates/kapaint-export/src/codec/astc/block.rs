//! ASTC's 2D block footprints: the fourteen sizes the format defines, by name ("4x4",
//! "6x6", ...) and by their Vulkan formats. A leaf the presets, the block encoder, the KTX2
//! writer and the manifest share.

use serde::{Deserialize, Serialize};

/// An ASTC 2D block footprint, texels across and down. Every block is 16 bytes, so larger
/// footprints store fewer bits per texel (8 at 4x4, 0.89 at 12x12).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct AstcBlock {
    width: u8,
    height: u8,
}

impl AstcBlock {
    /// Every footprint ASTC defines for 2D images, in the Vulkan formats' order.
    pub const ALL: [Self; 14] = [
        Self::new(4, 4),
        Self::new(5, 4),
        Self::new(5, 5),
        Self::new(6, 5),
        Self::new(6, 6),
        Self::new(8, 5),
        Self::new(8, 6),
        Self::new(8, 8),
        Self::new(10, 5),
        Self::new(10, 6),
        Self::new(10, 8),
        Self::new(10, 10),
        Self::new(12, 10),
        Self::new(12, 12),
    ];

    /// The default footprint, 4x4 (8 bits per texel).
    pub const DEFAULT: Self = Self::new(4, 4);

    const fn new(width: u8, height: u8) -> Self {
        Self { width, height }
    }

    /// The footprint `width` x `height`, where ASTC defines it.
    pub fn of(width: u32, height: u32) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|b| u32::from(b.width) == width && u32::from(b.height) == height)
    }

    /// Texels across and down.
    pub fn dims(self) -> (u32, u32) {
        (u32::from(self.width), u32::from(self.height))
    }

    /// Bits per texel (a block is 128 bits).
    pub fn bits_per_texel(self) -> f64 {
        128.0 / f64::from(u32::from(self.width) * u32::from(self.height))
    }

    /// The name presets and manifests spell: `"4x4"`.
    pub fn name(self) -> String {
        format!("{}x{}", self.width, self.height)
    }

    /// The footprint a name spells (`"6x6"`), or why it is not one.
    ///
    /// # Errors
    /// Not `WxH`, or a footprint ASTC does not define.
    pub fn parse(name: &str) -> Result<Self, String> {
        let known = || {
            Self::ALL
                .iter()
                .map(|b| b.name())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (w, h) = name
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("ASTC block {name:?} is not WxH (ASTC's: {})", known()))?;
        let side = |s: &str| s.trim().parse::<u32>().ok();
        side(w)
            .zip(side(h))
            .and_then(|(w, h)| Self::of(w, h))
            .ok_or_else(|| {
                format!(
                    "ASTC block {name:?} is not a footprint ASTC defines ({})",
                    known()
                )
            })
    }

    /// The Vulkan format number (what a KTX2 header's `vkFormat` holds): UNORM, or SRGB.
    pub fn vk_format(self, srgb: bool) -> u32 {
        let index = Self::ALL.iter().position(|b| *b == self).unwrap_or(0) as u32;
        ASTC_4X4_UNORM + 2 * index + u32::from(srgb)
    }

    /// The footprint and sRGB-ness of a Vulkan format number, where it is an ASTC LDR one.
    pub fn of_vk_format(format: u32) -> Option<(Self, bool)> {
        let at = format.checked_sub(ASTC_4X4_UNORM)?;
        let block = Self::ALL.get(usize::try_from(at / 2).ok()?)?;
        Some((*block, at % 2 == 1))
    }
}

/// `VK_FORMAT_ASTC_4x4_UNORM_BLOCK`; the other LDR footprints follow, UNORM then SRGB.
const ASTC_4X4_UNORM: u32 = 157;

impl Default for AstcBlock {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl std::fmt::Display for AstcBlock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl TryFrom<String> for AstcBlock {
    type Error = String;

    fn try_from(name: String) -> Result<Self, String> {
        Self::parse(&name)
    }
}

impl From<AstcBlock> for String {
    fn from(b: AstcBlock) -> Self {
        b.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_vulkan_formats_round_trip() {
        for b in AstcBlock::ALL {
            assert_eq!(AstcBlock::parse(&b.name()), Ok(b));
            for srgb in [false, true] {
                assert_eq!(AstcBlock::of_vk_format(b.vk_format(srgb)), Some((b, srgb)));
            }
        }
        // Vulkan's numbers: 4x4 UNORM 157, SRGB 158; 12x12 SRGB 184.
        assert_eq!(AstcBlock::DEFAULT.vk_format(false), 157);
        assert_eq!(AstcBlock::DEFAULT.vk_format(true), 158);
        assert_eq!(
            AstcBlock::parse("12x12").map(|b| b.vk_format(true)),
            Ok(184)
        );
        assert_eq!(AstcBlock::of_vk_format(185), None);
        assert_eq!(AstcBlock::of_vk_format(156), None);
        for bad in ["7x7", "4x5", "4", "axb", "", "16x16", "4x4x4"] {
            assert!(AstcBlock::parse(bad).is_err(), "{bad}");
        }
    }
}
