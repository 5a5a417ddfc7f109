//! glTF 2.0 import: files built here (GLB, .gltf with a .bin, data: URIs), the spot mesh
//! converted to GLB, and corrupted copies of them.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use kapaint::mesh::{self, Mesh};

fn temp(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write");
    path
}

/// A GLB container: the JSON chunk and the binary chunk, each padded to 4 bytes.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

fn f32_bytes(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// The binary data and JSON of one mesh (positions, optional normals and UVs, u32
/// indices), instanced by `nodes` (a JSON array) in scene 0.
fn mesh_gltf(m: &Mesh, with_normals: bool, nodes: &str, mode: u32) -> (String, Vec<u8>) {
    let mut bin = f32_bytes(m.positions.iter().flat_map(Vec3::to_array));
    let (lo, hi) = m.bounds();
    let n = m.positions.len();
    let mut views = vec![format!(
        r#"{{"buffer":0,"byteOffset":0,"byteLength":{}}}"#,
        12 * n
    )];
    let mut accessors = vec![format!(
        r#"{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}}"#,
        lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
    )];
    let mut attributes = vec![r#""POSITION":0"#.to_string()];
    if with_normals {
        let offset = bin.len();
        bin.extend(f32_bytes(m.normals.iter().flat_map(Vec3::to_array)));
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{}}}"#,
            12 * n
        ));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5126,"count":{n},"type":"VEC3"}}"#,
            views.len() - 1
        ));
        attributes.push(format!(r#""NORMAL":{}"#, accessors.len() - 1));
    }
    if let Some(uvs) = &m.uvs {
        let offset = bin.len();
        // glTF's v runs down the texture.
        bin.extend(f32_bytes(uvs.iter().flat_map(|t| [t.x, 1.0 - t.y])));
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{}}}"#,
            8 * n
        ));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5126,"count":{n},"type":"VEC2"}}"#,
            views.len() - 1
        ));
        attributes.push(format!(r#""TEXCOORD_0":{}"#, accessors.len() - 1));
    }
    let offset = bin.len();
    let indices: Vec<u32> = m.triangles.iter().flatten().copied().collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    views.push(format!(
        r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{}}}"#,
        4 * indices.len()
    ));
    accessors.push(format!(
        r#"{{"bufferView":{},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
        views.len() - 1,
        indices.len()
    ));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[{nodes_idx}]}}],"nodes":{nodes},
"meshes":[{{"name":"m","primitives":[{{"attributes":{{{attrs}}},"indices":{idx},"mode":{mode}}}]}}],
"accessors":[{acc}],"bufferViews":[{views}],"buffers":[{{"byteLength":{len}}}]}}"#,
        nodes_idx = (0..nodes.matches("\"mesh\"").count())
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(","),
        attrs = attributes.join(","),
        idx = accessors.len() - 1,
        acc = accessors.join(","),
        views = views.join(","),
        len = bin.len(),
    );
    (json, bin)
}

fn spot() -> Mesh {
    mesh::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot")
}

#[test]
fn spot_as_glb_loads_like_the_obj() {
    let obj = spot();
    let (json, bin) = mesh_gltf(&obj, true, r#"[{"mesh":0}]"#, 4);
    let path = temp("spot.glb", &glb(&json, &bin));
    let m = mesh::load(&path).expect("loads");
    assert_eq!(m.triangles, obj.triangles);
    assert_eq!(m.positions, obj.positions);
    assert!(m.had_normals);
    let (a, b) = (m.uvs.expect("uvs"), obj.uvs.clone().expect("uvs"));
    assert!(a.iter().zip(&b).all(|(x, y)| (*x - *y).length() < 1e-6));
    assert_eq!(m.normals.len(), obj.normals.len());
    // Same UV islands, so the same seams and bake.
    let info = mesh::info_text(&path, &mesh::load(&path).expect("loads"));
    assert!(info.contains("triangles: 5856"), "{info}");
    assert_eq!(
        mesh::load(&path).expect("loads").uv_islands(),
        obj.uv_islands()
    );
}

#[test]
fn node_transforms_apply_and_mirrored_nodes_keep_facing_out() {
    let quad = mesh::plane(); // 2 x 2 in XZ facing +Y
    // Two instances: translated and scaled, and mirrored in X (negative determinant).
    let nodes = r#"[{"mesh":0,"translation":[1,2,3],"scale":[2,2,2]},{"mesh":0,"scale":[-1,1,1]}]"#;
    let (json, bin) = mesh_gltf(&quad, true, nodes, 4);
    let m = mesh::load(&temp("quad.glb", &glb(&json, &bin))).expect("loads");
    assert_eq!(m.triangles.len(), 2 * quad.triangles.len());
    let (lo, hi) = m.bounds();
    assert!((lo - Vec3::new(-1.0, 0.0, -1.0)).length() < 1e-5, "{lo}");
    assert!((hi - Vec3::new(3.0, 2.0, 5.0)).length() < 1e-5, "{hi}");
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let face = (b - a).cross(c - a);
        let normal = m.normals[t[0] as usize];
        assert!(face.dot(normal) > 0.0, "winding agrees with the normal");
        assert!((normal - Vec3::Y).length() < 1e-5);
    }
    assert!(m.paintable().is_ok());
}

/// A mesh's runs of triangles, by name.
fn runs(r: &[mesh::Run]) -> Vec<(&str, std::ops::Range<u32>)> {
    r.iter()
        .map(|r| (r.name.as_str(), r.triangles.clone()))
        .collect()
}

/// Nodes' names are the mesh's objects (what `bake --match by-name` pairs), primitives'
/// materials its materials, `COLOR_0` its vertex colours; `mesh-info` lists them.
#[test]
fn node_names_materials_and_vertex_colours_are_read() {
    let quad = mesh::plane();
    let nodes =
        r#"[{"mesh":0,"name":"door_low"},{"mesh":0,"name":"frame_low","translation":[3,0,0]}]"#;
    let (json, bin) = mesh_gltf(&quad, true, nodes, 4);
    // The positions read as colours too.
    let json = json.replace(r#""POSITION":0"#, r#""POSITION":0,"COLOR_0":0"#);
    let path = temp("named.glb", &glb(&json, &bin));
    let m = mesh::load(&path).expect("loads");
    assert_eq!(
        runs(&m.labels.objects),
        [("door_low", 0..2), ("frame_low", 2..4)]
    );
    assert_eq!(runs(&m.labels.materials), [("default material", 0..4)]);
    let colors = m.labels.colors.as_ref().expect("colours");
    assert_eq!(colors[..4], quad.positions[..]);
    let info = mesh::info_text(&path, &m);
    assert!(
        info.contains("objects: 2: door_low, frame_low")
            && info.contains("vertex colours: present"),
        "{info}"
    );
}

#[test]
fn missing_normals_are_smooth_over_shared_vertices_and_strips_unroll() {
    let quad = mesh::plane();
    let (json, bin) = mesh_gltf(&quad, false, r#"[{"mesh":0}]"#, 4);
    let m = mesh::load(&temp("flat.glb", &glb(&json, &bin))).expect("loads");
    assert!(!m.had_normals);
    assert!(m.normals.iter().all(|n| (*n - Vec3::Y).length() < 1e-6));
    // A UV sphere without normals: shared vertices get the smooth (radial) normal.
    let sphere = mesh::uv_sphere(32, 16);
    let (json, bin) = mesh_gltf(&sphere, false, r#"[{"mesh":0}]"#, 4);
    let m = mesh::load(&temp("sphere.glb", &glb(&json, &bin))).expect("loads");
    let uvs = m.uvs.as_ref().expect("uvs");
    for (i, (p, n)) in m.positions.iter().zip(&m.normals).enumerate() {
        let inner = uvs[i].x > 0.0 && uvs[i].x < 1.0 && p.y.abs() < 0.99;
        if inner {
            assert!(n.dot(p.normalize()) > 0.99, "vertex {i}: {n} at {p}");
        }
    }
    // The same 4 vertices as a strip: indices 0 1 2 3 give two triangles.
    let strip = Mesh {
        triangles: vec![[2, 0, 3], [3, 0, 1]],
        ..quad.clone()
    };
    let (json, bin) = mesh_gltf(&strip, true, r#"[{"mesh":0}]"#, 5);
    let m = mesh::load(&temp("strip.glb", &glb(&json, &bin))).expect("loads");
    assert_eq!(m.triangles.len(), 4, "6 indices make 4 strip triangles");
}

#[test]
fn gltf_with_a_bin_file_and_with_a_data_uri() {
    let quad = mesh::plane();
    let (json, bin) = mesh_gltf(&quad, true, r#"[{"mesh":0}]"#, 4);
    let with_file = json.replace(r#""buffers":[{"#, r#""buffers":[{"uri":"quad.bin","#);
    temp("quad.bin", &bin);
    let m = mesh::load(&temp("quad.gltf", with_file.as_bytes())).expect("loads");
    assert_eq!(m.triangles.len(), 2);
    let uvs = m.uvs.expect("uvs");
    assert!(uvs.contains(&Vec2::new(0.0, 0.0)) && uvs.contains(&Vec2::new(1.0, 1.0)));

    let encoded = base64_encode(&bin);
    let with_uri = json.replace(
        r#""buffers":[{"#,
        &format!(r#""buffers":[{{"uri":"data:application/octet-stream;base64,{encoded}","#),
    );
    let m = mesh::load(&temp("inline.gltf", with_uri.as_bytes())).expect("loads");
    assert_eq!(m.triangles.len(), 2);
}

/// Standard base64 (the test builds its own data: URI).
fn base64_encode(bytes: &[u8]) -> String {
    const ABC: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn load_err(name: &str, bytes: &[u8]) -> String {
    let path = temp(name, bytes);
    let err = mesh::load(&path).expect_err("must fail").to_string();
    assert!(err.contains(name), "the error names the file: {err}");
    err
}

#[test]
fn corrupt_gltf_files_are_clear_errors_naming_the_file() {
    let quad = mesh::plane();
    let (json, bin) = mesh_gltf(&quad, true, r#"[{"mesh":0}]"#, 4);

    // Indices out of range.
    let mut bad = bin.clone();
    let last = bad.len() - 4;
    bad[last..].copy_from_slice(&99u32.to_le_bytes());
    assert!(load_err("index.glb", &glb(&json, &bad)).contains("out of range"));

    // A NaN position.
    let mut bad = bin.clone();
    bad[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(load_err("nan.glb", &glb(&json, &bad)).contains("non-finite"));

    // An accessor claiming 2^40 elements.
    let absurd = json.replacen(r#""count":4,"#, r#""count":1099511627776,"#, 1);
    assert_ne!(absurd, json);
    let err = load_err("absurd.glb", &glb(&absurd, &bin));
    assert!(err.contains("accessor") || err.contains("glTF"), "{err}");

    // Points only: no triangles.
    let points = json.replace(r#""mode":4"#, r#""mode":0"#);
    assert!(load_err("points.glb", &glb(&points, &bin)).contains("no triangles"));

    // A node that is its own child.
    let cycle = json.replace(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0,"children":[0]}]"#,
    );
    load_err("cycle.glb", &glb(&cycle, &bin));

    // Not JSON at all, and a missing .bin.
    assert!(load_err("junk.gltf", b"{ this is not json").contains("glTF"));
    let missing = json.replace(r#""buffers":[{"#, r#""buffers":[{"uri":"nothere.bin","#);
    load_err("missing.gltf", missing.as_bytes());
}

#[test]
fn every_truncation_and_byte_flip_of_a_glb_is_an_error_or_a_valid_mesh() {
    let quad = mesh::plane();
    let (json, bin) = mesh_gltf(&quad, true, r#"[{"mesh":0}]"#, 4);
    let file = glb(&json, &bin);
    for len in 0..file.len() {
        let path = temp("cut.glb", &file[..len]);
        assert!(mesh::load(&path).is_err(), "prefix of {len} bytes");
    }
    let mut state = 0x1234_5678_u32;
    for _ in 0..2000 {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let mut copy = file.clone();
        let at = (state >> 8) as usize % copy.len();
        copy[at] ^= 1 << (state % 8);
        let path = temp("flip.glb", &copy);
        // Any outcome but a panic: a valid mesh must pass validation.
        if let Ok(m) = mesh::load(&path) {
            m.validate().expect("a loaded mesh is valid");
        }
    }
}

#[test]
fn byte_flips_in_the_json_of_spot_as_glb_never_panic() {
    let (json, bin) = mesh_gltf(&spot(), true, r#"[{"mesh":0}]"#, 4);
    let file = glb(&json, &bin);
    let json_end = 20 + json.len();
    let mut state = 0x9E37_79B9_u32;
    for _ in 0..1500 {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let mut copy = file.clone();
        let at = 20 + (state >> 8) as usize % (json_end - 20);
        copy[at] = b"0123456789-e.,:[]{}\" x"[(state % 21) as usize];
        if let Ok(m) = mesh::load(&temp("spot_flip.glb", &copy)) {
            m.validate().expect("a loaded mesh is valid");
        }
    }
}

#[test]
fn mesh_info_reads_glb() {
    let (json, bin) = mesh_gltf(&spot(), false, r#"[{"mesh":0}]"#, 4);
    let path = temp("spot_flat.glb", &glb(&json, &bin));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["mesh-info", path.to_str().expect("path")])
        .output()
        .expect("runs");
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    assert!(text.contains("triangles: 5856"), "{text}");
    assert!(text.contains("normals: computed"), "{text}");
}

/// A GLB like the ones artists download: the spot mesh, and a PBR material whose base colour
/// and metallic-roughness PNGs sit in the binary chunk (bufferView images), the base colour
/// with a texture transform.
fn textured_glb() -> Vec<u8> {
    let (json, mut bin) = mesh_gltf(&spot(), true, r#"[{"mesh":0}]"#, 4);
    let mut root: serde_json::Value = serde_json::from_str(&json).expect("json");
    let png = |rgb: [u8; 3]| {
        let mut bytes = Vec::new();
        image::RgbImage::from_fn(16, 16, |x, y| {
            image::Rgb([rgb[0] ^ (x as u8 * 9), rgb[1], rgb[2] ^ (y as u8 * 7)])
        })
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .expect("png");
        bytes
    };
    let views = root["bufferViews"].as_array_mut().expect("views");
    let mut image_views = Vec::new();
    for bytes in [png([200, 120, 40]), png([0, 160, 255])] {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        image_views.push(views.len());
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}),
        );
        bin.extend_from_slice(&bytes);
    }
    root["buffers"][0]["byteLength"] = bin.len().into();
    root["images"] = serde_json::json!([
        {"bufferView": image_views[0], "mimeType": "image/png", "name": "base"},
        {"bufferView": image_views[1], "mimeType": "image/png", "name": "mr"}
    ]);
    root["samplers"] = serde_json::json!([{"wrapS": 10497, "wrapT": 33648}]);
    root["textures"] = serde_json::json!([{"source": 0, "sampler": 0}, {"source": 1}]);
    root["materials"] = serde_json::json!([{
        "name": "barrel",
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 0.9, 0.8, 1.0],
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.1, 0.0], "rotation": 0.2, "scale": [2.0, 2.0]}}},
            "metallicFactor": 1.0, "roughnessFactor": 0.8,
            "metallicRoughnessTexture": {"index": 1}
        }
    }]);
    root["extensionsUsed"] = serde_json::json!(["KHR_texture_transform"]);
    root["meshes"][0]["primitives"][0]["material"] = 0.into();
    glb(&serde_json::to_string(&root).expect("json"), &bin)
}

#[test]
fn byte_flips_and_truncations_of_a_textured_glb_never_panic_in_import_pbr_or_mesh_info() {
    let file = textured_glb();
    let path = temp("barrel.glb", &file);
    let set =
        kapaint::pbr::gltf::material_set(&path, None, Some(kapaint::export::ktx::decode_image))
            .expect("the unflipped file imports");
    assert_eq!(set.name, "barrel");
    let json_len = u32::from_le_bytes(file[12..16].try_into().expect("len")) as usize;
    let mut state = 0x2545_F491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    let (mut panics, mut imported) = (Vec::new(), 0);
    for k in 0..1500 {
        let r = next();
        let copy = match k % 3 {
            // A character of the JSON replaced by one that changes its meaning.
            0 | 1 => {
                let mut c = file.clone();
                let at = 20 + r as usize % json_len;
                c[at] = b"0123456789-e.,:[]{}\" xE+"[(r >> 24) as usize % 24];
                c
            }
            // A bit anywhere, or the file cut short.
            _ if r % 2 == 0 => {
                let mut c = file.clone();
                let at = (r >> 1) as usize % c.len();
                c[at] ^= 1 << (r >> 28);
                c
            }
            _ => file[..(r >> 1) as usize % file.len()].to_vec(),
        };
        let path = temp("barrel_mutant.glb", &copy);
        let outcome = std::panic::catch_unwind(|| {
            let imported = kapaint::pbr::gltf::material_set(
                &path,
                None,
                Some(kapaint::export::ktx::decode_image),
            )
            .is_ok();
            let _ = mesh::load(&path);
            imported
        });
        match outcome {
            Ok(ok) => imported += usize::from(ok),
            Err(_) => panics.push(k),
        }
    }
    assert!(
        panics.is_empty(),
        "{} of 1500 mutations panicked: {panics:?}",
        panics.len()
    );
    assert!(
        imported > 100,
        "few mutations kept a readable material: {imported}"
    );
}

#[test]
fn an_image_without_a_source_is_one_line_and_exit_2() {
    let file = textured_glb();
    let json_len = u32::from_le_bytes(file[12..16].try_into().expect("len")) as usize;
    let json = std::str::from_utf8(&file[20..20 + json_len]).expect("utf-8");
    let bin = &file[20 + json_len + 8..];
    let dir = std::env::temp_dir().join(format!("kapaint-gltf-src-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let cases: [(&str, &str, &str); 2] = [
        ("nosource", "bufferView", "neither"),
        ("nomime", "mimeType", "no mimeType"),
    ];
    for (tag, field, says) in cases {
        let mut root: serde_json::Value = serde_json::from_str(json).expect("json");
        root["images"][1]
            .as_object_mut()
            .expect("image")
            .remove(field);
        let text = serde_json::to_string(&root).expect("json");
        let path = temp(&format!("{tag}.glb"), &glb(&text, bin));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args([
                "import-pbr",
                "--gltf",
                path.to_str().expect("path"),
                "--out",
            ])
            .arg(dir.join(format!("{tag}.kapaint")))
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{tag}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(says), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
