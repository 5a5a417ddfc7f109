//! Links the C++ runtime where `intel_tex_2`'s precompiled ISPC kernels are used: its archive
//! holds a C++ object (the ASTC encoder) whose unwind tables name the C++ personality
//! routine, even though kapaint calls only the BC kernels.

fn main() {
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if arch == "x86_64" {
        match os.as_str() {
            "linux" | "freebsd" => println!("cargo:rustc-link-lib=dylib=stdc++"),
            "macos" => println!("cargo:rustc-link-lib=dylib=c++"),
            _ => {}
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
