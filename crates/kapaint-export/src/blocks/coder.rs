//! Who encodes the blocks: the CPU's encoders, or one the caller brings ([`BlockEncoder`], the
//! GPU crate's compute shaders), chosen per export ([`Coder::best`]) and named in manifests
//! ([`Encoder`]).

pub use crate::codec::Encoder;
use crate::codec::{Codec, Cpu, Effort};

/// An encode that a [`BlockEncoder`] stopped part-way: why, and the texel rows from the top
/// whose blocks are in place.
#[derive(Debug)]
pub struct Interrupted {
    /// What failed.
    pub error: String,
    /// Texel rows encoded before it, a multiple of 4.
    pub rows_done: u32,
}

/// A block encoder a caller brings beside the CPU's (the GPU crate's compute shaders), handed
/// to an export rather than found by it; the CPU's encode the codecs it does not.
pub trait BlockEncoder: Send + Sync {
    /// Whether it encodes `codec`'s blocks.
    fn encodes(&self, codec: &dyn Codec) -> bool;

    /// Encodes a `(width, height)` image (sides multiples of 4) of [`Codec::texel_bytes`]
    /// bytes per texel as `codec` at `effort` into `blocks` ([`Codec::blocks_len`] bytes),
    /// strip by strip: `fill(row, rows, texels)` writes texel rows `row..row + rows` into
    /// `texels`; `strip_done(rows)` follows each strip and answers `false` to stop.
    ///
    /// # Errors
    /// A failure part-way, with the rows whose blocks are in place.
    fn encode(
        &self,
        codec: &dyn Codec,
        effort: Effort,
        size: (u32, u32),
        fill: &mut dyn FnMut(u32, u32, &mut [u8]),
        strip_done: &mut dyn FnMut(u32) -> bool,
        blocks: &mut [u8],
    ) -> Result<(), Interrupted>;

    /// Why it was given up, if it was: it is then never asked again.
    fn failure(&self) -> Option<String>;

    /// Gives it up after a failure (the first reason is kept).
    fn give_up(&self, why: &str);
}

/// An encoder as it runs: one of the CPU's, or the one the caller brought.
#[derive(Clone, Copy)]
pub enum Coder<'a> {
    /// Intel's ISPC kernels (`x86_64`).
    Ispc,
    /// `block_compression`'s CPU port.
    Portable,
    /// The caller's encoder; the CPU's best goes on where it fails.
    Brought(&'a dyn BlockEncoder),
}

impl std::fmt::Debug for Coder<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.name())
    }
}

impl<'a> Coder<'a> {
    /// The fastest encoder: `brought` where given and not given up, else the CPU's.
    pub fn best(brought: Option<&'a dyn BlockEncoder>) -> Self {
        match brought {
            Some(b) if b.failure().is_none() => Self::Brought(b),
            _ => Self::best_cpu(),
        }
    }

    /// The fastest encoder this CPU has.
    pub fn best_cpu() -> Self {
        match Encoder::best_cpu() {
            Encoder::Ispc => Self::Ispc,
            _ => Self::Portable,
        }
    }

    /// How a manifest names it.
    pub fn name(self) -> Encoder {
        match self {
            Self::Ispc => Encoder::Ispc,
            Self::Portable => Encoder::Portable,
            Self::Brought(_) => Encoder::Gpu,
        }
    }

    /// The CPU encoder it runs strips on: its own, or for a brought one the CPU's best.
    pub fn cpu(self) -> Cpu {
        match self {
            Self::Ispc => Cpu::Ispc,
            Self::Portable => Cpu::Portable,
            Self::Brought(_) => match Self::best_cpu() {
                Self::Ispc => Cpu::Ispc,
                _ => Cpu::Portable,
            },
        }
    }

    /// Why the brought encoder was given up, if this is it and it was.
    pub fn failure(self) -> Option<String> {
        match self {
            Self::Brought(b) => b.failure(),
            _ => None,
        }
    }
}
