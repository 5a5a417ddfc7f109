//! ASTC LDR blocks of any 2D footprint ([`AstcBlock`]), 16 bytes each, with ARM's own encoder
//! and decoder (`astcenc`, through `ctt-astcenc`), on the CPU whatever encoder the caller
//! brings.
//!
//! An `astcenc` context holds the footprint's partition and weight tables, which cost more to
//! build than a strip takes to encode, and runs one strip at a time: an [`Astc`] value keeps
//! the contexts its strips used (per effort, and one kind for decoding) and hands them to the
//! next strips, mips and effort trials of its image; they go when it does.
//!
//! Components go in as `astcenc`'s swizzles put them: one as luminance (R = G = B), two as
//! luminance and alpha (the second in A), three as RGB (A one), four as RGBA. Decoded
//! texels come back with the stored components first (luminance and alpha as its first two
//! bytes), so the export measures what a consumer sampling `.r`/`.ra`/`.rgb`/`.rgba` gets.

mod block;

use std::ffi::c_void;
use std::sync::Mutex;

use ctt_astcenc::bindings::{astcenc_image, astcenc_type_ASTCENC_TYPE_U8};
use ctt_astcenc::{Context, Flags, Preset, Profile, Swizzle, SwizzleChannel, config_init};

pub use self::block::AstcBlock;
use super::{Codec, CodecError, Cpu, Effort, Encoder, check_strip};
use crate::file_kind::Compression;

/// `astcenc`'s name and search preset for an effort.
pub fn preset_of(effort: Effort) -> (&'static str, Preset) {
    match effort {
        Effort::UltraFast => ("fastest", Preset::Fastest),
        Effort::VeryFast => ("fast", Preset::Fast),
        Effort::Fast => ("medium", Preset::Medium),
        Effort::Basic => ("thorough", Preset::Thorough),
        Effort::Slow => ("very thorough", Preset::VeryThorough),
    }
}

/// ASTC LDR of one footprint: `channels` components (1 to 4), colour sRGB where `srgb`.
pub struct Astc {
    block: AstcBlock,
    channels: u8,
    srgb: bool,
    /// Contexts not in use, by the effort they search at (`None`: decoding only).
    contexts: Mutex<Vec<(Option<Effort>, Context)>>,
}

impl std::fmt::Debug for Astc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Astc")
            .field("block", &self.block)
            .field("channels", &self.channels)
            .field("srgb", &self.srgb)
            .finish_non_exhaustive()
    }
}

impl Astc {
    /// ASTC of `block` for `channels` meaningful components (clamped to 1..=4), sRGB colour
    /// where `srgb`.
    pub fn new(block: AstcBlock, channels: usize, srgb: bool) -> Self {
        Self {
            block,
            channels: channels.clamp(1, 4) as u8,
            srgb,
            contexts: Mutex::new(Vec::new()),
        }
    }

    /// The footprint.
    pub fn block(&self) -> AstcBlock {
        self.block
    }

    fn context(&self, effort: Option<Effort>) -> Result<Context, CodecError> {
        let failed = |reason: String| CodecError::Library {
            codec: "ASTC",
            reason,
        };
        let profile = if self.srgb {
            Profile::LdrSrgb
        } else {
            Profile::Ldr
        };
        // Consumers decode LDR blocks to 8 bits: the encoder rounds as they do.
        let mut flags = Flags::USE_DECODE_UNORM8;
        let preset = if let Some(effort) = effort {
            preset_of(effort).1
        } else {
            flags |= Flags::DECOMPRESS_ONLY;
            Preset::Fastest
        };
        let (bx, by) = self.block.dims();
        let config = config_init(profile, bx, by, 1, preset, flags)
            .map_err(|e| failed(format!("astcenc configuration for {}: {e}", self.block)))?;
        Context::new(&config).map_err(|e| failed(format!("astcenc context: {e}")))
    }

    /// Runs `f` on a context for `effort`: one this value kept where there is one, else a
    /// new one, kept afterwards.
    fn with_context<R>(
        &self,
        effort: Option<Effort>,
        f: impl FnOnce(&mut Context) -> R,
    ) -> Result<R, CodecError> {
        let kept = {
            let mut contexts = self
                .contexts
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            contexts
                .iter()
                .rposition(|(e, _)| *e == effort)
                .map(|i| contexts.swap_remove(i).1)
        };
        let mut ctx = match kept {
            Some(ctx) => ctx,
            None => self.context(effort)?,
        };
        let out = f(&mut ctx);
        self.contexts
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push((effort, ctx));
        Ok(out)
    }

    fn swizzle(&self) -> Swizzle {
        match self.channels {
            1 => Swizzle::RRR1,
            2 => Swizzle::RRRG,
            3 => Swizzle::RGB1,
            _ => Swizzle::IDENTITY,
        }
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

impl Codec for Astc {
    fn name(&self) -> &'static str {
        "ASTC"
    }

    fn describe(&self) -> String {
        match self.channels {
            1 => format!("ASTC {} (luminance)", self.block),
            2 => format!("ASTC {} (luminance and alpha)", self.block),
            _ => format!("ASTC {}", self.block),
        }
    }

    fn vk_format(&self) -> Option<ktx2::Format> {
        ktx2::Format::new(self.block.vk_format(self.srgb))
    }

    fn compression(&self) -> Compression {
        Compression::Ktx2Astc
    }

    fn block_dims(&self) -> (u32, u32) {
        self.block.dims()
    }

    fn texel_bytes(&self) -> usize {
        4
    }

    fn effort_name(&self, effort: Effort) -> &'static str {
        preset_of(effort).0
    }

    fn own_encoder(&self) -> Option<Encoder> {
        Some(Encoder::Astcenc)
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
        // astcenc only reads the plane, and only while compressing; its size is checked.
        let mut plane = texels.as_ptr().cast_mut().cast::<c_void>();
        let mut image = image(&mut plane, size);
        let swizzle = self.swizzle();
        self.with_context(Some(effort), |ctx| ctx.compress(&mut image, swizzle, out))?
            .map_err(|e| CodecError::Library {
                codec: "ASTC",
                reason: format!("astcenc: {e}"),
            })
    }

    fn decode_strip(
        &self,
        blocks: &[u8],
        size: (u32, u32),
        out: &mut [u8],
    ) -> Result<(), CodecError> {
        check_strip(self, size, out.len(), blocks.len())?;
        let mut plane = out.as_mut_ptr().cast::<c_void>();
        let mut image = image(&mut plane, size);
        // Luminance and alpha: alpha into the second byte.
        let swizzle = if self.channels == 2 {
            Swizzle {
                r: SwizzleChannel::R,
                g: SwizzleChannel::A,
                b: SwizzleChannel::B,
                a: SwizzleChannel::G,
            }
        } else {
            Swizzle::IDENTITY
        };
        self.with_context(None, |ctx| ctx.decompress(blocks, &mut image, swizzle))?
            .map_err(|e| CodecError::Library {
                codec: "ASTC",
                reason: format!("astcenc decode: {e}"),
            })
    }
}
