//! The PBR tests' projects made through the command line (`import-pbr`): spot with a
//! roughness checker, metallic stripes and a bumpy normal map, or one flat material; with the
//! path and command helpers they use (shared by `tests/gltf_basisu.rs`, `tests/peers.rs` and
//! `tests/pbr_engines.rs`, each of which includes `common/gltf_asset.rs` as `gltf_asset`).

use std::path::{Path, PathBuf};

use super::gltf_asset::{bumps, kapaint, spot};

/// A path as the command line's argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs the kapaint binary with `args`, which must succeed; what it printed.
pub fn ok(args: &[&str]) -> String {
    let o = kapaint(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A `size`^2 project `p.kapaint` in `d`, imported: spot's mesh and texture, a roughness
/// checker of eight squares a side (40 and 220), metallic stripes four to the width and a
/// bumpy normal map.
pub fn spot_pbr_project(d: &Path, size: u32) -> PathBuf {
    let rough = image::GrayImage::from_fn(size, size, |x, y| {
        image::Luma([if (x / (size / 8) + y / (size / 8)).is_multiple_of(2) {
            40
        } else {
            220
        }])
    });
    let metal = image::GrayImage::from_fn(size, size, |x, _| {
        image::Luma([if (x / (size / 4)).is_multiple_of(2) {
            0
        } else {
            255
        }])
    });
    rough.save(d.join("rough.png")).expect("rough");
    metal.save(d.join("metal.png")).expect("metal");
    bumps(size, size)
        .save(d.join("normal.png"))
        .expect("normal");
    let p = d.join("p.kapaint");
    ok(&[
        "import-pbr",
        "--out",
        s(&p),
        "--size",
        &size.to_string(),
        "--base-color",
        s(&spot().join("spot_texture.png")),
        "--roughness",
        s(&d.join("rough.png")),
        "--metallic",
        s(&d.join("metal.png")),
        "--normal",
        s(&d.join("normal.png")),
        "--mesh",
        s(&spot().join("spot_triangulated.obj")),
    ]);
    p
}

/// A 64^2 project `name` in `d` of one flat material on spot's mesh: base colour (0.5, 0.3,
/// 0.2), roughness 0.5, metallic 0.
pub fn flat_project(d: &Path, name: &str) -> PathBuf {
    let p = d.join(name);
    ok(&[
        "import-pbr",
        "--out",
        s(&p),
        "--size",
        "64",
        "--base-color",
        "0.5,0.3,0.2",
        "--roughness",
        "0.5",
        "--metallic",
        "0",
        "--mesh",
        s(&spot().join("spot_triangulated.obj")),
    ]);
    p
}
