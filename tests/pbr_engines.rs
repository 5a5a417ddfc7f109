//! The engine presets (`unreal`, `unity-hdrp`, `unity-urp`, `godot`) against the `gltf-pbr`
//! export of the same project: the same conversion, laid out as each engine reads it, with
//! occlusion from the project's AO bake; and user layouts that cannot be written refused.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

use kapaint::export::gltf_pbr::PbrManifest;

#[path = "common/gltf_asset.rs"]
#[expect(
    dead_code,
    reason = "these tests make their material from images, not the glTF asset"
)]
mod gltf_asset;
#[path = "common/pbr_project.rs"]
#[expect(dead_code, reason = "the engine presets need no flat material")]
mod pbr_project;
use gltf_asset::dir;
use pbr_project::{ok, s, spot_pbr_project};

/// The 256^2 spot project ([`spot_pbr_project`]), with an AO bake where `ao`.
fn project(d: &Path, ao: bool) -> PathBuf {
    let p = spot_pbr_project(d, 256);
    if ao {
        ok(&["bake", s(&p), "--map", "ao", "--rays", "8"]);
    }
    p
}

fn export(project: &Path, preset: &str, out: &Path) -> String {
    ok(&["export", s(project), "--preset", preset, "--out", s(out)])
}

fn manifest(set: &Path) -> PbrManifest {
    serde_json::from_slice(&std::fs::read(set.join("material.json")).expect("manifest"))
        .expect("a PBR manifest")
}

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path).expect("image").to_rgba8()
}

#[test]
fn engine_layouts_hold_the_gltf_values_occlusion_and_their_normal_convention() {
    let d = dir("engines");
    let p = project(&d, true);
    let sets: Vec<(&str, PathBuf)> = ["gltf-pbr", "unreal", "unity-hdrp", "unity-urp", "godot"]
        .into_iter()
        .map(|name| {
            let out = d.join(name);
            let text = export(&p, name, &out);
            if name != "gltf-pbr" {
                assert!(text.contains(&format!("{name} PBR textures")), "{text}");
                assert!(
                    text.contains("occlusion: the project's AO bake (256x256, 8 rays a texel)"),
                    "{text}"
                );
            }
            (name, out)
        })
        .collect();
    let file = |set: usize, name: &str| rgba(&sets[set].1.join(name));
    let base = file(0, "base_color.png");
    let mr = file(0, "metallic_roughness.png");
    let normal = file(0, "normal.png");
    let unreal = |n: &str| file(1, &format!("unreal_{n}.png"));
    let (u_base, orm, u_normal) = (
        unreal("BaseColor"),
        unreal("OcclusionRoughnessMetallic"),
        unreal("Normal"),
    );
    let hdrp = |n: &str| file(2, &format!("unity-hdrp_{n}.png"));
    let (h_base, mask, h_normal) = (hdrp("BaseMap"), hdrp("MaskMap"), hdrp("Normal"));
    let urp = |n: &str| file(3, &format!("unity-urp_{n}.png"));
    let (ms, occ) = (urp("MetallicSmoothness"), urp("Occlusion"));
    let g_orm = file(4, "godot_orm.png");
    let (mut occluded, mut varied) = (0, false);
    for (i, ((b, m), n)) in base
        .pixels()
        .zip(mr.pixels())
        .zip(normal.pixels())
        .enumerate()
    {
        let (x, y) = ((i % 256) as u32, (i / 256) as u32);
        let px = |img: &image::RgbaImage| img.get_pixel(x, y).0;
        // Unreal: the same base colour; ORM's G and B are glTF's; green flipped.
        assert_eq!(px(&u_base)[..3], b.0[..3]);
        let o = px(&orm);
        assert_eq!([o[1], o[2]], [m.0[1], m.0[2]], "({x}, {y})");
        assert_eq!(px(&u_normal)[..3], [n.0[0], 255 - n.0[1], n.0[2]]);
        // Unity HDRP: R metallic, G occlusion, B detail (white), A smoothness.
        assert_eq!(px(&h_base)[..3], b.0[..3]);
        assert_eq!(px(&mask), [m.0[2], o[0], 255, 255 - m.0[1]], "({x}, {y})");
        assert_eq!(px(&h_normal)[..3], n.0[..3]);
        // Unity URP: metallic in RGB, smoothness in A, occlusion alone.
        assert_eq!(px(&ms), [m.0[2], m.0[2], m.0[2], 255 - m.0[1]]);
        assert_eq!(px(&occ)[0], o[0]);
        // Godot: the same ORM.
        assert_eq!(px(&g_orm)[..3], o[..3]);
        occluded += usize::from(o[0] < 200);
        varied |= m.0[1] != mr.get_pixel(0, 0).0[1];
    }
    assert!(
        occluded > 500,
        "the AO bake reached the occlusion channel ({occluded} texels)"
    );
    assert!(varied, "roughness varies");
    // The manifests say what each file holds and where occlusion came from.
    let m = manifest(&sets[1].1);
    assert_eq!(m.preset, "unreal");
    assert!(
        m.occlusion.as_ref().is_some_and(|o| o.baked),
        "{:?}",
        m.occlusion
    );
    assert_eq!(
        m.normal_green,
        Some(kapaint::export::preset::NormalGreen::DirectX)
    );
    let orm_entry = m
        .files
        .iter()
        .find(|f| f.path == "unreal_OcclusionRoughnessMetallic.png")
        .expect("ORM listed");
    assert_eq!(orm_entry.layout, ["occlusion", "roughness", "metallic"]);
    assert_eq!(manifest(&sets[0].1).round_trip, m.round_trip);
    // An engine set is replaced by its own export, like any set.
    export_replacing(&p, "unreal", &sets[1].1);
}

fn export_replacing(project: &Path, preset: &str, out: &Path) {
    ok(&[
        "export",
        s(project),
        "--preset",
        preset,
        "--replace",
        "--out",
        s(out),
    ]);
}

#[test]
fn without_an_ao_bake_occlusion_is_white_and_without_a_normal_map_none_is_written() {
    let d = dir("engines-white");
    let p = project(&d, false);
    let out = d.join("white");
    let text = export(&p, "unity-hdrp", &out);
    assert!(
        text.contains("occlusion: white: the project has no AO bake"),
        "{text}"
    );
    let mask = rgba(&out.join("white_MaskMap.png"));
    assert!(mask.pixels().all(|p| p.0[1] == 255));
    let m = manifest(&out);
    assert_eq!(m.occlusion.as_ref().map(|o| o.baked), Some(false));
    // A project without a normal map: the layout's normal file is not written, and said so.
    let bare = d.join("bare.kapaint");
    ok(&["new", "--size", "64", "--out", s(&bare)]);
    let out = d.join("bare");
    let text = export(&bare, "unreal", &out);
    assert!(
        text.contains("not written: bare_Normal.png: the project has no normal map"),
        "{text}"
    );
    assert!(!out.join("bare_Normal.png").exists());
    assert_eq!(manifest(&out).normal_green, None);
}

#[test]
fn a_user_layout_that_cannot_be_written_is_refused_with_nothing_written() {
    let d = dir("engines-bad");
    let presets = d.join("presets");
    std::fs::create_dir_all(&presets).expect("preset dir");
    let bare = d.join("bare.kapaint");
    ok(&["new", "--size", "16", "--out", s(&bare)]);
    let layout = |textures: &str| {
        format!("(version: 2, name: \"mine\", format: PbrTextures, textures: [{textures}])")
    };
    for (text, why) in [
        (
            layout("(file: \"a.png\", channels: [\"gloss\"])"),
            "unknown channel \"gloss\"",
        ),
        (
            layout(
                "(file: \"{name}.png\", channels: [\"one\"]), (file: \"{name}.PNG\", channels: [\"zero\"])",
            ),
            "overlaps itself",
        ),
        (
            layout("(file: \"a.png\", channels: [\"base.r\", \"roughness\", \"base.b\"])"),
            "sRGB",
        ),
        (layout(""), "names 0 files"),
    ] {
        std::fs::write(presets.join("mine.ron"), &text).expect("preset");
        let out = d.join("out");
        let (o, err) = export_mine(&bare, &presets, &out);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("kapaint: ") && err.contains(why), "{err}");
        assert!(!out.exists(), "nothing written");
    }
    // Names that meet only once the set's name is in them: refused at export.
    let text = layout(
        "(file: \"{name}_a.png\", channels: [\"one\"]), (file: \"x_a.png\", channels: [\"zero\"])",
    );
    std::fs::write(presets.join("mine.ron"), text).expect("preset");
    let out = d.join("x");
    let (o, err) = export_mine(&bare, &presets, &out);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("are both x_a.png"), "{err}");
    assert!(!out.exists(), "nothing written");
}

/// `kapaint export PROJECT --preset mine --out OUT` with the user presets in `presets`: its
/// output and its error text.
fn export_mine(project: &Path, presets: &Path, out: &Path) -> (std::process::Output, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["export", s(project), "--preset", "mine", "--out", s(out)])
        .env("KAPAINT_EXPORT_PRESET_DIR", presets)
        .output()
        .expect("run");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o, err)
}
