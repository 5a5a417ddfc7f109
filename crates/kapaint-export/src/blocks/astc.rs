//! ASTC LDR blocks with ARM's own encoder and decoder (`astcenc`, through `astcenc-rs`).
//!
//! Strips of block rows run in parallel, each on a single-threaded `astcenc` context taken
//! from a small pool (a context holds the footprint's partition and weight tables, which cost
//! more to build than a strip takes to encode), so mips and effort trials reuse them.
//!
//! Components go in as `astcenc`'s swizzles put them: one as luminance (R = G = B), two as
//! luminance and alpha (the second in A), three as RGB (A one), four as RGBA. Decoded
//! texels come back with the stored components first (luminance and alpha as its first two
//! bytes), so the export measures what a consumer sampling `.r`/`.ra`/`.rgb`/`.rgba` gets.

use std::sync::Mutex;

use astcenc_rs::{
    ConfigBuilder, Context, Extents, Flags, Image, PRESET_FAST, PRESET_FASTEST, PRESET_MEDIUM,
    PRESET_THOROUGH, PRESET_VERY_THOROUGH, Preset, Profile, Selector, Swizzle,
};

use super::Bc7Quality;
use crate::astc_block::AstcBlock;

/// `astcenc`'s search preset for an effort on BC7's scale.
pub fn preset_of(effort: Bc7Quality) -> (&'static str, Preset) {
    match effort {
        Bc7Quality::UltraFast => ("fastest", PRESET_FASTEST),
        Bc7Quality::VeryFast => ("fast", PRESET_FAST),
        Bc7Quality::Fast => ("medium", PRESET_MEDIUM),
        Bc7Quality::Basic => ("thorough", PRESET_THOROUGH),
        Bc7Quality::Slow => ("very thorough", PRESET_VERY_THOROUGH),
    }
}

/// What a context is built for: a footprint, the colour profile, and an effort (`None`:
/// decoding only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Key {
    block: AstcBlock,
    srgb: bool,
    effort: Option<Bc7Quality>,
}

/// Contexts not in use, most recently returned last.
static POOL: Mutex<Vec<(Key, Context)>> = Mutex::new(Vec::new());

/// The most contexts kept between uses.
const POOL_MAX: usize = 16;

fn context(key: Key) -> Result<Context, String> {
    let mut config = ConfigBuilder::new()
        .with_profile(if key.srgb {
            Profile::LdrSrgb
        } else {
            Profile::LdrRgba
        })
        .with_block_size(Extents::new(key.block.dims().0, key.block.dims().1));
    // Consumers decode LDR blocks to 8 bits: the encoder rounds as they do.
    let mut flags = Flags::DECODE_UNORM8;
    if let Some(effort) = key.effort {
        config = config.with_preset(preset_of(effort).1);
    } else {
        config = config.with_preset(PRESET_FASTEST);
        flags |= Flags::DECOMPRESS_ONLY;
    }
    let config = config
        .with_flags(flags)
        .build()
        .map_err(|e| format!("astcenc configuration for {}: {e:?}", key.block))?;
    Context::with_threads(1, config).map_err(|e| format!("astcenc context: {e:?}"))
}

/// Runs `f` on a context for `key`: a pooled one where there is one, else a new one, put
/// back afterwards.
fn with_context<R>(key: Key, f: impl FnOnce(&mut Context) -> R) -> Result<R, String> {
    let pooled = {
        let mut pool = POOL
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        pool.iter()
            .rposition(|(k, _)| *k == key)
            .map(|i| pool.remove(i).1)
    };
    let mut ctx = match pooled {
        Some(ctx) => ctx,
        None => context(key)?,
    };
    let out = f(&mut ctx);
    let mut pool = POOL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if pool.len() >= POOL_MAX {
        pool.remove(0);
    }
    pool.push((key, ctx));
    Ok(out)
}

fn swizzle(channels: u8) -> Swizzle {
    match channels {
        1 => Swizzle::rrr1(),
        2 => Swizzle::rrrg(),
        3 => Swizzle::rgb1(),
        _ => Swizzle::rgba(),
    }
}

/// Encodes `rows` texel rows (a multiple of the footprint's height) of a `width`-wide RGBA8
/// image (`width` a multiple of its width) of `channels` meaningful components into `out`.
///
/// # Panics
/// Where `astcenc` refuses a footprint it defines, or runs out of memory.
pub(super) fn encode(
    block: AstcBlock,
    channels: u8,
    srgb: bool,
    effort: Bc7Quality,
    rgba: &[u8],
    (width, rows): (u32, u32),
    out: &mut [u8],
) {
    let key = Key {
        block,
        srgb,
        effort: Some(effort),
    };
    let image = Image {
        extents: Extents::new(width, rows),
        data: vec![rgba],
    };
    let blocks = with_context(key, |ctx| ctx.compress(&image, swizzle(channels)))
        .and_then(|r| r.map_err(|e| format!("astcenc: {e:?}")));
    match blocks {
        Ok(blocks) => out.copy_from_slice(&blocks),
        Err(e) => panic!("ASTC {block} encode of {width}x{rows}: {e}"),
    }
}

/// Decodes the blocks of `rows` texel rows of a `width`-wide image into RGBA8 `out`, each
/// texel's stored components first (luminance and alpha as its first two bytes where
/// `channels` is 2).
///
/// # Errors
/// Where `astcenc` cannot build a decoder for the footprint.
pub(super) fn decode(
    block: AstcBlock,
    channels: u8,
    srgb: bool,
    blocks: &[u8],
    (width, rows): (u32, u32),
    out: &mut [u8],
) -> Result<(), String> {
    let key = Key {
        block,
        srgb,
        effort: None,
    };
    let mut image = Image {
        extents: Extents::new(width, rows),
        data: vec![&mut out[..]],
    };
    // Luminance and alpha: alpha into the second byte.
    let swz = if channels == 2 {
        Swizzle {
            r: Selector::Red,
            g: Selector::Alpha,
            b: Selector::Blue,
            a: Selector::Green,
        }
    } else {
        Swizzle::rgba()
    };
    with_context(key, |ctx| ctx.decompress_into(blocks, &mut image, swz))?
        .map_err(|e| format!("astcenc decode: {e:?}"))
}
