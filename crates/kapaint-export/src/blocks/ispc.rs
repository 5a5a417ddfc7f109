//! ISPC's BC encoders (`intel_tex_2`), where the target has them.

use intel_tex_2::{RSurface, RgSurface, RgbaSurface, bc4, bc5, bc6h, bc7};

use super::{Bc7Quality, BlockKind};

fn bc7_settings(effort: Bc7Quality, alpha: bool) -> bc7::EncodeSettings {
    match (effort, alpha) {
        (Bc7Quality::UltraFast, false) => bc7::opaque_ultra_fast_settings(),
        (Bc7Quality::VeryFast, false) => bc7::opaque_very_fast_settings(),
        (Bc7Quality::Fast, false) => bc7::opaque_fast_settings(),
        (Bc7Quality::Basic, false) => bc7::opaque_basic_settings(),
        (Bc7Quality::Slow, false) => bc7::opaque_slow_settings(),
        (Bc7Quality::UltraFast, true) => bc7::alpha_ultra_fast_settings(),
        (Bc7Quality::VeryFast, true) => bc7::alpha_very_fast_settings(),
        (Bc7Quality::Fast, true) => bc7::alpha_fast_settings(),
        (Bc7Quality::Basic, true) => bc7::alpha_basic_settings(),
        (Bc7Quality::Slow, true) => bc7::alpha_slow_settings(),
    }
}

fn bc6h_settings(effort: Bc7Quality) -> bc6h::EncodeSettings {
    match effort {
        Bc7Quality::UltraFast | Bc7Quality::VeryFast => bc6h::very_fast_settings(),
        Bc7Quality::Fast => bc6h::fast_settings(),
        Bc7Quality::Basic => bc6h::basic_settings(),
        Bc7Quality::Slow => bc6h::slow_settings(),
    }
}

/// Encodes `rows` texel rows (a multiple of 4) of a `width`-wide image into `out`.
pub(super) fn encode(kind: BlockKind, data: &[u8], width: u32, rows: u32, out: &mut [u8]) {
    let stride = width * kind.texel_bytes() as u32;
    // BC7 and BC6H read four components (bytes or half floats).
    let rgba = RgbaSurface {
        data,
        width,
        height: rows,
        stride,
    };
    match kind {
        BlockKind::Bc4 => bc4::compress_blocks_into(
            &RSurface {
                data,
                width,
                height: rows,
                stride,
            },
            out,
        ),
        BlockKind::Bc5 => bc5::compress_blocks_into(
            &RgSurface {
                data,
                width,
                height: rows,
                stride,
            },
            out,
        ),
        BlockKind::Bc7 { alpha, effort } => {
            bc7::compress_blocks_into(&bc7_settings(effort, alpha), &rgba, out);
        }
        BlockKind::Bc6h { effort } => {
            bc6h::compress_blocks_into(&bc6h_settings(effort), &rgba, out);
        }
        // astcenc's, in `encode_strip`.
        BlockKind::Astc { .. } => {}
    }
}
