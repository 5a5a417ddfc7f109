//! ASTC LDR blocks with ARM's own encoder and decoder (`astcenc`, through `ctt-astcenc`).
//!
//! Strips of block rows run in parallel, each on a single-threaded `astcenc` context taken
//! from a small pool (a context holds the footprint's partition and weight tables, which cost
//! more to build than a strip takes to encode), so mips and effort trials reuse them.
//!
//! Components go in as `astcenc`'s swizzles put them: one as luminance (R = G = B), two as
//! luminance and alpha (the second in A), three as RGB (A one), four as RGBA. Decoded
//! texels come back with the stored components first (luminance and alpha as its first two
//! bytes), so the export measures what a consumer sampling `.r`/`.ra`/`.rgb`/`.rgba` gets.

use std::ffi::c_void;
use std::sync::Mutex;

use ctt_astcenc::bindings::{astcenc_image, astcenc_type_ASTCENC_TYPE_U8};
use ctt_astcenc::{Context, Flags, Preset, Profile, Swizzle, SwizzleChannel, config_init};

use super::Bc7Quality;
use crate::astc_block::AstcBlock;

/// `astcenc`'s search preset for an effort on BC7's scale.
pub fn preset_of(effort: Bc7Quality) -> (&'static str, Preset) {
    match effort {
        Bc7Quality::UltraFast => ("fastest", Preset::Fastest),
        Bc7Quality::VeryFast => ("fast", Preset::Fast),
        Bc7Quality::Fast => ("medium", Preset::Medium),
        Bc7Quality::Basic => ("thorough", Preset::Thorough),
        Bc7Quality::Slow => ("very thorough", Preset::VeryThorough),
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
    let profile = if key.srgb {
        Profile::LdrSrgb
    } else {
        Profile::Ldr
    };
    // Consumers decode LDR blocks to 8 bits: the encoder rounds as they do.
    let mut flags = Flags::USE_DECODE_UNORM8;
    let preset = if let Some(effort) = key.effort {
        preset_of(effort).1
    } else {
        flags |= Flags::DECOMPRESS_ONLY;
        Preset::Fastest
    };
    let (bx, by) = key.block.dims();
    let config = config_init(profile, bx, by, 1, preset, flags)
        .map_err(|e| format!("astcenc configuration for {}: {e}", key.block))?;
    Context::new(&config).map_err(|e| format!("astcenc context: {e}"))
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
        1 => Swizzle::RRR1,
        2 => Swizzle::RRRG,
        3 => Swizzle::RGB1,
        _ => Swizzle::IDENTITY,
    }
}

/// `astcenc`'s description of a tightly packed RGBA8 image of `width` x `rows` texels whose
/// one plane starts at `plane` (which must outlive the description's use).
fn image(plane: &mut *mut c_void, (width, rows): (u32, u32)) -> astcenc_image {
    astcenc_image {
        dim_x: width,
        dim_y: rows,
        dim_z: 1,
        data_type: astcenc_type_ASTCENC_TYPE_U8,
        data: std::ptr::from_mut(plane),
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
    let blocks = if rgba.len() == width as usize * rows as usize * 4 {
        // astcenc only reads the plane, and only while compressing; its size is checked.
        let mut plane = rgba.as_ptr().cast_mut().cast::<c_void>();
        let mut image = image(&mut plane, (width, rows));
        with_context(key, |ctx| ctx.compress(&mut image, swizzle(channels), out))
            .and_then(|r| r.map_err(|e| format!("astcenc: {e}")))
    } else {
        Err(format!("{} bytes of texels", rgba.len()))
    };
    if let Err(e) = blocks {
        panic!("ASTC {block} encode of {width}x{rows}: {e}");
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
    if out.len() != width as usize * rows as usize * 4 {
        return Err(format!(
            "astcenc decode of {width}x{rows}: {} bytes of texels",
            out.len()
        ));
    }
    let mut plane = out.as_mut_ptr().cast::<c_void>();
    let mut image = image(&mut plane, (width, rows));
    // Luminance and alpha: alpha into the second byte.
    let swz = if channels == 2 {
        Swizzle {
            r: SwizzleChannel::R,
            g: SwizzleChannel::A,
            b: SwizzleChannel::B,
            a: SwizzleChannel::G,
        }
    } else {
        Swizzle::IDENTITY
    };
    with_context(key, |ctx| ctx.decompress(blocks, &mut image, swz))?
        .map_err(|e| format!("astcenc decode: {e}"))
}
