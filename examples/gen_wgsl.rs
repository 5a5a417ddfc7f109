//! Rewrites `shaders/ambient.wgsl` from the Rust constants (run from the repository root).

fn main() -> std::io::Result<()> {
    std::fs::write(
        "shaders/ambient.wgsl",
        kapaint::reflectance::wgsl::ambient_wgsl(),
    )
}
