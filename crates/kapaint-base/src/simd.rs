//! Hot loops (painting, compositing, the bakes' rays) compiled for the CPU at hand.
//!
//! The release build targets baseline x86-64 (SSE2: four floats a step). Most x86-64 CPUs
//! since 2013 have AVX2 and FMA (eight a step, and conversions between 16- and 32-bit lanes
//! in one instruction). [`vectorized`] calls a function inside one compiled for them when the
//! CPU has them (detected once), so the loops inlined into it are vectorised for them;
//! elsewhere it calls the function as it is. The results are the same bit for bit: every
//! operation is IEEE arithmetic with no contraction into fused multiply-adds, so only the
//! width of the steps differs (the layer tests composite both ways and compare).

/// Work to run through [`vectorized`]: its [`pulp::WithSimd::with_simd`] marked
/// `#[inline(always)]`, with the loops it should speed up inlined into it the same way (a
/// closure's body, or a function called through `FnOnce`, is a function of its own that is
/// compiled for the baseline).
pub use pulp::WithSimd as Kernel;

/// The instruction set a [`Kernel`] is handed (its `with_simd`'s type parameter).
pub use pulp::Simd;

/// `kernel` run compiled for the widest vector instructions the CPU has (see the module).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
pub fn vectorized<K: Kernel>(kernel: K) -> K::Output {
    pulp::Arch::new().dispatch(kernel)
}
