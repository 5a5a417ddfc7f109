//! `export --preset gltf-pbr --glb --basisu`: the `.glb`'s textures as Basis Universal KTX2
//! files (`KHR_texture_basisu`, UASTC with zstd, no fallback), what the manifest says of them,
//! and `import-pbr --gltf` reading such a file back (kapaint round-trips its own output);
//! malformed payloads and a supercompression kapaint does not read refused in one line.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;

use kapaint::export::gltf_pbr::PbrManifest;

#[path = "common/gltf_asset.rs"]
#[expect(
    dead_code,
    reason = "these tests make their material from images, not the glTF asset"
)]
mod gltf_asset;
#[path = "common/pbr_project.rs"]
mod pbr_project;
use gltf_asset::{dir, kapaint};
use pbr_project::{flat_project, ok, s, spot_pbr_project};

/// `kapaint export PROJECT --preset gltf-pbr --glb --basisu --out OUT`, which must succeed; what
/// it printed.
fn export_basisu(project: &Path, out: &Path) -> String {
    ok(&[
        "export",
        s(project),
        "--preset",
        "gltf-pbr",
        "--glb",
        "--basisu",
        "--out",
        s(out),
    ])
}

fn manifest(set: &Path) -> PbrManifest {
    serde_json::from_slice(&std::fs::read(set.join("material.json")).expect("manifest"))
        .expect("parses")
}

/// The `.glb`'s JSON and binary chunk.
fn glb_parts(path: &Path) -> (serde_json::Value, Vec<u8>) {
    let bytes = std::fs::read(path).expect("glb");
    let glb = gltf::binary::Glb::from_slice(&bytes).expect("a GLB");
    let json = serde_json::from_slice(&glb.json).expect("JSON");
    (json, glb.bin.expect("a binary chunk").into_owned())
}

/// Image `i`'s bytes in the binary chunk.
fn image_bytes(json: &serde_json::Value, bin: &[u8], i: usize) -> Vec<u8> {
    let view = json["images"][i]["bufferView"].as_u64().expect("a view") as usize;
    let v = &json["bufferViews"][view];
    let at = v["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = v["byteLength"].as_u64().expect("length") as usize;
    bin[at..at + len].to_vec()
}

#[test]
fn a_basisu_glb_holds_uastc_ktx2_textures_and_reads_back() {
    let d = dir("gltf-basisu");
    let p = spot_pbr_project(&d, 128);
    let (png_set, basis_set) = (d.join("png"), d.join("basis"));
    ok(&[
        "export",
        s(&p),
        "--preset",
        "gltf-pbr",
        "--glb",
        "--out",
        s(&png_set),
    ]);
    let out = export_basisu(&p, &basis_set);
    assert!(out.contains("basisu: base_color "), "{out}");
    let m = manifest(&basis_set);
    let b = m.basisu.as_ref().expect("the manifest says how");
    assert_eq!(b.zstd_level, 18);
    for t in &b.textures[1..] {
        assert_eq!(t.codec, "UASTC", "the data textures: {t:?}");
    }
    // The spot texture's detail is more than UASTC holds within 2 levels at the 99.9th
    // percentile (BC7's transcode, the worse target): the best settings are kept and said.
    let budget = kapaint::export::preset::find("gltf-pbr")
        .expect("preset")
        .budget;
    let over = b.ka_error_srgb.p999 > budget.ka_error_srgb_p999
        || b.ka_error_srgb.mean > budget.ka_error_srgb_mean;
    assert_eq!(b.within_budget, !over, "{b:?}");
    if !b.within_budget {
        // The nearest kept: the base colour in UASTC like the data, at the same settings.
        assert_eq!(b.textures[0].codec, "UASTC", "{b:?}");
        assert_eq!(b.textures[0].settings, b.textures[1].settings, "{b:?}");
        assert!(out.contains("over the budget"), "{out}");
    }
    assert_eq!(
        (
            b.textures[2].codec.as_str(),
            b.textures[2].settings.as_str()
        ),
        ("UASTC", "level 3, no RDO"),
        "the normal map"
    );
    assert!(b.ka_error_srgb.mean < 0.5, "{b:?}");
    assert_eq!(
        b.textures.len(),
        3,
        "base colour, metallic-roughness, normal"
    );
    assert!(manifest(&png_set).basisu.is_none());

    textures_are_basis_ktx2(&basis_set.join("model.glb"), b, 3);
    // Smaller on the GPU and in the file than the PNGs' glTF? At least no larger than a
    // whole UASTC chain (16 bytes a block) before zstd.
    let ktx_bytes: u64 = b.textures.iter().map(|t| t.bytes).sum();
    assert!(ktx_bytes < 3 * 128 * 128 * 4 / 3, "{ktx_bytes}");

    // Round trip: import-pbr reads the Basis glTF; its maps are near the PNG glTF's.
    let (from_png, from_basis) = (d.join("from_png.kapaint"), d.join("from_basis.kapaint"));
    ok(&[
        "import-pbr",
        "--gltf",
        s(&png_set.join("model.glb")),
        "--out",
        s(&from_png),
    ]);
    let said = ok(&[
        "import-pbr",
        "--gltf",
        s(&basis_set.join("model.glb")),
        "--out",
        s(&from_basis),
    ]);
    assert!(!said.contains("does not read"), "{said}");
    let (a, c) = (kd_of(&from_png), kd_of(&from_basis));
    let mean: f64 = a
        .iter()
        .zip(&c)
        .map(|(x, y)| f64::from((x - y).abs()))
        .sum::<f64>()
        / a.len() as f64;
    assert!(mean < 0.02, "mean k_d difference {mean}");
    assert!(mean > 0.0, "the KTX2 textures were read, not the PNGs");
}

/// The file's `n` textures: the extension used and required, each texture's image only in
/// it, each a KTX2 file as the manifest lists it (UASTC with zstd, or ETC1S with BasisLZ), the
/// colour space and mips it lists.
fn textures_are_basis_ktx2(glb: &Path, b: &kapaint::export::gltf_basisu::BasisuReport, n: usize) {
    let (json, bin) = glb_parts(glb);
    for key in ["extensionsUsed", "extensionsRequired"] {
        assert_eq!(
            json[key],
            serde_json::json!(["KHR_texture_basisu"]),
            "{key}"
        );
    }
    let textures = json["textures"].as_array().expect("textures");
    assert_eq!(textures.len(), n);
    for (t, listed) in textures.iter().zip(&b.textures) {
        assert!(t.get("source").is_none(), "no fallback: {t}");
        let i = t["extensions"]["KHR_texture_basisu"]["source"]
            .as_u64()
            .expect("the extension names the image") as usize;
        assert_eq!(json["images"][i]["mimeType"], "image/ktx2");
        assert_eq!(json["images"][i]["name"], listed.name.as_str());
        let ktx = image_bytes(&json, &bin, i);
        assert_eq!(ktx.len() as u64, listed.bytes);
        let reader = ktx2::Reader::new(&ktx[..]).expect("a KTX2 file");
        let header = reader.header();
        assert_eq!(header.format, None, "Basis Universal has no Vulkan format");
        let (scheme, model) = if listed.codec == "ETC1S" {
            (
                ktx2::SupercompressionScheme::BasisLZ,
                ktx2::ColorModel::ETC1S,
            )
        } else {
            (
                ktx2::SupercompressionScheme::Zstandard,
                ktx2::ColorModel::UASTC,
            )
        };
        assert_eq!(header.supercompression_scheme, Some(scheme), "{listed:?}");
        assert_eq!(reader.color_model(), Some(model), "{listed:?}");
        assert_eq!(
            (header.pixel_width, header.pixel_height, header.level_count),
            (listed.width, listed.height, listed.levels)
        );
        assert_eq!(
            listed.levels,
            listed.width.max(listed.height).ilog2() + 1,
            "a full chain"
        );
        let srgb = reader.transfer_function() == Some(ktx2::TransferFunction::SRGB);
        assert_eq!(srgb, listed.name == "base_color", "{}", listed.name);
    }
}

/// Every texel's `k_d` components of a project.
fn kd_of(project: &Path) -> Vec<f32> {
    let doc = kapaint::model::project::load(project).expect("loads");
    let maps = doc.maps();
    let mut out = Vec::new();
    for y in 0..maps.height() {
        for x in 0..maps.width() {
            out.extend(maps.texel(x, y).kd.map(|c| f32::from(c) / 65535.0));
        }
    }
    out
}

/// `model.glb` with image `i`'s bytes replaced by `bytes` (views and lengths rewritten).
fn with_image(glb: &Path, i: usize, bytes: &[u8], to: &Path) {
    let (mut json, bin) = glb_parts(glb);
    let view = json["images"][i]["bufferView"].as_u64().expect("a view") as usize;
    let mut out = bin.clone();
    while out.len() % 4 != 0 {
        out.push(0);
    }
    let at = out.len();
    out.extend_from_slice(bytes);
    while out.len() % 4 != 0 {
        out.push(0);
    }
    json["bufferViews"][view]["byteOffset"] = at.into();
    json["bufferViews"][view]["byteLength"] = bytes.len().into();
    json["buffers"][0]["byteLength"] = out.len().into();
    let text = serde_json::to_vec(&json).expect("JSON");
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: text.into(),
        bin: Some(out.into()),
    };
    std::fs::write(to, glb.to_vec().expect("GLB")).expect("write");
}

#[test]
fn a_glb_with_a_bad_basis_payload_is_refused_in_one_line() {
    let d = dir("gltf-basisu-bad");
    let p = spot_pbr_project(&d, 128);
    let set = d.join("basis");
    export_basisu(&p, &set);
    let glb = set.join("model.glb");
    let (json, bin) = glb_parts(&glb);
    let good = image_bytes(&json, &bin, 0);
    // The header's supercompression scheme (bytes 44..48): ZLIB (3), which kapaint does not
    // read; BasisLZ (1) over UASTC blocks.
    let scheme = |n: u32| {
        let mut bytes = good.clone();
        bytes[44..48].copy_from_slice(&n.to_le_bytes());
        bytes
    };
    // An ETC1S file whose global data claims more codebook than it holds.
    let rgba: Vec<u8> = (0..64 * 64 * 4).map(|i| (i % 251) as u8).collect();
    let etc1s = kapaint::export::codec::etc1s::Etc1sCodec::new(4, true)
        .encode(
            &[((64, 64), &rgba[..])],
            kapaint::export::codec::Effort::Fast,
        )
        .expect("ETC1S")
        .image;
    let etc1s = kapaint::export::ktx::etc1s_file(&etc1s, true).expect("KTX2");
    let sgd_at = u64::from_le_bytes(etc1s[64..72].try_into().expect("8 bytes")) as usize;
    let mut short_codebook = etc1s.clone();
    short_codebook[sgd_at + 4..sgd_at + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let cases: [(&str, Vec<u8>); 5] = [
        ("truncated", good[..good.len() / 2].to_vec()),
        ("not-ktx", b"this is not a KTX2 file at all".to_vec()),
        ("zlib", scheme(3)),
        ("basislz-over-uastc", scheme(1)),
        ("short-codebook", short_codebook),
    ];
    for (name, bytes) in cases {
        let bad = d.join(format!("{name}.glb"));
        with_image(&glb, 0, &bytes, &bad);
        let out = d.join(format!("{name}.kapaint"));
        let o = kapaint(&["import-pbr", "--gltf", s(&bad), "--out", s(&out)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.starts_with("kapaint:"), "{name}: {err}");
        assert!(err.contains("KTX2"), "{name}: {err}");
        assert!(!out.exists(), "{name}: nothing written");
    }
}

/// A user preset `gltf-light`: glTF's layout with a looser budget.
const LIGHT: &str = r#"(
    version: 2,
    name: "gltf-light",
    description: "glTF metallic-roughness, a looser budget for Basis textures",
    format: GltfPbr,
    layout: Packed,
    n_bits: 8,
    include_ka: false,
    ka_error_srgb_p999: 8.0,
    ka_error_srgb_mean: 3.0,
)"#;

#[test]
fn a_smooth_material_takes_the_cheapest_settings_its_budget_allows() {
    let d = dir("gltf-basisu-smooth");
    let p = flat_project(&d, "p.kapaint");
    let how = |b: &kapaint::export::gltf_basisu::BasisuReport| -> Vec<(String, String)> {
        b.textures
            .iter()
            .map(|t| (t.codec.clone(), t.settings.clone()))
            .collect()
    };
    let pair = |c: &str, s: &str| (c.to_string(), s.to_string());
    // The default budget: ETC1S's 5-bit colours miss a flat colour by about two levels on
    // every texel (a mean over 0.3); UASTC holds it exactly at its cheapest.
    let set = d.join("basis");
    export_basisu(&p, &set);
    let b = manifest(&set).basisu.expect("basisu");
    assert!(b.within_budget, "{b:?}");
    assert_eq!(
        how(&b),
        [
            pair("UASTC", "level 1, RDO 3.0"),
            pair("UASTC", "level 1, RDO 3.0")
        ],
        "no normal map, no normal texture"
    );
    textures_are_basis_ktx2(&set.join("model.glb"), &b, 2);
    // A looser budget takes ETC1S at its lowest quality for the colour.
    let presets = d.join("presets");
    std::fs::create_dir_all(&presets).expect("dir");
    std::fs::write(presets.join("gltf-light.ron"), LIGHT).expect("preset");
    let light = d.join("light");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args([
            "export",
            s(&p),
            "--preset",
            "gltf-light",
            "--glb",
            "--basisu",
            "--out",
            s(&light),
        ])
        .env("KAPAINT_EXPORT_PRESET_DIR", &presets)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let b = manifest(&light).basisu.expect("basisu");
    assert!(b.within_budget, "{b:?}");
    assert_eq!(
        how(&b),
        [
            pair("ETC1S", "quality 32"),
            pair("UASTC", "level 1, RDO 3.0")
        ]
    );
    textures_are_basis_ktx2(&light.join("model.glb"), &b, 2);
    // ETC1S reads back (BasisLZ through the BC7 transcode), as close as it was measured.
    let back = d.join("back.kapaint");
    ok(&[
        "import-pbr",
        "--gltf",
        s(&light.join("model.glb")),
        "--out",
        s(&back),
    ]);
    let want = [0.5_f32, 0.3, 0.2];
    let worst = kd_of(&back)
        .chunks_exact(3)
        .map(|t| {
            (0..3)
                .map(|c| (t[c] - want[c]).abs())
                .fold(0.0_f32, f32::max)
        })
        .fold(0.0_f32, f32::max);
    assert!(worst < 0.02, "k_d read back within {worst}");
}

#[test]
fn basisu_is_refused_without_a_glb() {
    let d = dir("gltf-basisu-usage");
    let p = spot_pbr_project(&d, 128);
    let o = kapaint(&[
        "export",
        s(&p),
        "--preset",
        "gltf-pbr",
        "--basisu",
        "--out",
        s(&d.join("x")),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--basisu") && err.contains("--glb"), "{err}");
    assert!(!d.join("x").exists());
}
