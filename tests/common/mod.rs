//! Helpers shared by the GPU test files.

use kapaint::gpu::Gpu;

/// A headless device, or `None` (reported) where there is no adapter; where the GPU tests
/// must run (`KAPAINT_REQUIRE_GPU`, or CI) a missing adapter fails the test instead.
pub fn gpu() -> Option<Gpu> {
    match Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) => {
            let required = std::env::var_os("KAPAINT_REQUIRE_GPU").is_some()
                || std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false");
            assert!(!required, "GPU tests must run here but: {e}");
            eprintln!("SKIPPED: no GPU adapter ({e})");
            None
        }
    }
}
