//! A real glTF PBR material for tests: spot's mesh and texture, metallic and roughness made
//! here, written with the `gltf` crate's JSON types; and the PBR tests' scratch folders and
//! command runner (shared by `tests/pbr.rs`, `tests/pbr_export.rs` and `tests/editor_pbr.rs`).

use std::path::{Path, PathBuf};

use glam::Vec3;
use gltf::json;
use json::validation::Checked::Valid;

/// A fresh scratch folder `name` for this test process.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kapaint-pbr-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

/// Runs the kapaint binary with `args`.
pub fn kapaint(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("run kapaint")
}

/// The spot test data's folder.
pub fn spot() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot")
}

/// How the test asset's material is written.
pub struct Asset {
    /// The base colour texture's URI.
    pub base_uri: String,
    /// The base colour texture's MIME type, if given.
    pub base_mime: Option<&'static str>,
    /// A texture transform on the base colour.
    pub transform: Option<([f32; 2], f32, [f32; 2])>,
    /// The base colour's texCoord.
    pub tex_coord: u32,
    /// A normal map (`normal.png`, made by [`bumps`]) with this scale.
    pub normal_scale: Option<f32>,
    /// The material is seen from both sides (`doubleSided`).
    pub double_sided: bool,
}

/// A bumpy tangent-space normal map of `w x h` (8-bit RGB, +Y up).
pub fn bumps(w: u32, h: u32) -> image::RgbImage {
    image::RgbImage::from_fn(w, h, |x, y| {
        let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
        let n = Vec3::new(0.4 * (u * 40.0).sin(), 0.4 * (v * 25.0).cos(), 1.0).normalize();
        image::Rgb(n.to_array().map(|c| ((c + 1.0) * 127.5).round() as u8))
    })
}

impl Default for Asset {
    fn default() -> Self {
        Self {
            base_uri: "spot_texture.png".into(),
            base_mime: None,
            transform: None,
            tex_coord: 0,
            normal_scale: None,
            double_sided: false,
        }
    }
}

pub fn accessor(
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    kind: json::accessor::Type,
    bounds: Option<(Vec3, Vec3)>,
) -> json::Accessor {
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: json::validation::USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: json::Extras::default(),
        type_: Valid(kind),
        min: bounds.map(|(lo, _)| json::Value::from(lo.to_array().to_vec())),
        max: bounds.map(|(_, hi)| json::Value::from(hi.to_array().to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    }
}

/// The spot mesh's positions, UVs and indices in one buffer (`spot.bin`): its three
/// accessors and the bytes.
pub fn push_mesh_data(root: &mut json::Root) -> ([json::Index<json::Accessor>; 3], Vec<u8>) {
    let mesh = kapaint::mesh::load(&spot().join("spot_triangulated.obj")).expect("spot");
    let uvs = mesh.uvs.clone().expect("spot has UVs");
    let mut bin: Vec<u8> = Vec::new();
    let buffer = json::Index::new(0);
    let view = |bin: &mut Vec<u8>, bytes: Vec<u8>| {
        let offset = bin.len();
        bin.extend_from_slice(&bytes);
        json::buffer::View {
            buffer,
            byte_length: json::validation::USize64::from(bytes.len()),
            byte_offset: Some(json::validation::USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: None,
            extensions: None,
            extras: json::Extras::default(),
        }
    };
    let positions: Vec<u8> = mesh
        .positions
        .iter()
        .flat_map(Vec3::to_array)
        .flat_map(f32::to_le_bytes)
        .collect();
    let texcoords: Vec<u8> = uvs
        .iter()
        .flat_map(glam::Vec2::to_array)
        .flat_map(f32::to_le_bytes)
        .collect();
    let indices: Vec<u8> = mesh
        .triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let v_pos = root.push(view(&mut bin, positions));
    let v_uv = root.push(view(&mut bin, texcoords));
    let v_idx = root.push(view(&mut bin, indices));
    let n = mesh.positions.len();
    let a_pos = root.push(accessor(
        v_pos,
        n,
        json::accessor::ComponentType::F32,
        json::accessor::Type::Vec3,
        Some(mesh.bounds()),
    ));
    let a_uv = root.push(accessor(
        v_uv,
        n,
        json::accessor::ComponentType::F32,
        json::accessor::Type::Vec2,
        None,
    ));
    let a_idx = root.push(accessor(
        v_idx,
        mesh.triangles.len() * 3,
        json::accessor::ComponentType::U32,
        json::accessor::Type::Scalar,
        None,
    ));
    let accessors = [a_pos, a_uv, a_idx];
    root.buffers.push(json::Buffer {
        byte_length: json::validation::USize64::from(bin.len()),
        name: None,
        uri: Some("spot.bin".into()),
        extensions: None,
        extras: json::Extras::default(),
    });
    (accessors, bin)
}

/// Writes `spot.gltf`, `spot.bin`, the base texture and `mr.png` into `d`.
pub fn write_asset(d: &Path, asset: &Asset) -> PathBuf {
    let mut root = json::Root::default();
    let (accessors, bin) = push_mesh_data(&mut root);
    std::fs::copy(spot().join("spot_texture.png"), d.join("spot_texture.png")).expect("copy");
    let (w, h) = image::image_dimensions(spot().join("spot_texture.png")).expect("size");
    image::RgbImage::from_fn(w, h, |x, y| {
        image::Rgb([
            0,
            (40 + (y * 200 / h)) as u8,
            if x < w / 2 { 0 } else { 255 },
        ])
    })
    .save(d.join("mr.png"))
    .expect("mr");
    let image = |uri: &str, mime: Option<&'static str>| json::Image {
        buffer_view: None,
        mime_type: mime.map(|m| json::image::MimeType(m.into())),
        name: Some(uri.into()),
        uri: Some(uri.into()),
        extensions: None,
        extras: json::Extras::default(),
    };
    let i_base = root.push(image(&asset.base_uri, asset.base_mime));
    let i_mr = root.push(image("mr.png", None));
    let texture = |source| json::Texture {
        name: None,
        sampler: None,
        source,
        extensions: None,
        extras: json::Extras::default(),
    };
    let t_base = root.push(texture(i_base));
    let t_mr = root.push(texture(i_mr));
    let info =
        |index, tex_coord, transform: Option<([f32; 2], f32, [f32; 2])>| json::texture::Info {
            index,
            tex_coord,
            extensions: transform.map(|(offset, rotation, scale)| {
                json::extensions::texture::Info {
                    texture_transform: Some(json::extensions::texture::TextureTransform {
                        offset: json::extensions::texture::TextureTransformOffset(offset),
                        rotation: json::extensions::texture::TextureTransformRotation(rotation),
                        scale: json::extensions::texture::TextureTransformScale(scale),
                        tex_coord: None,
                        extras: json::Extras::default(),
                    }),
                }
            }),
            extras: json::Extras::default(),
        };
    let normal_texture = asset.normal_scale.map(|scale| {
        bumps(w, h).save(d.join("normal.png")).expect("normal");
        let image = root.push(image("normal.png", None));
        json::material::NormalTexture {
            index: root.push(texture(image)),
            scale,
            tex_coord: 0,
            extensions: None,
            extras: json::Extras::default(),
        }
    });
    let material = root.push(json::Material {
        name: Some("cow".into()),
        normal_texture,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(info(t_base, asset.tex_coord, asset.transform)),
            metallic_roughness_texture: Some(info(t_mr, 0, None)),
            ..Default::default()
        },
        double_sided: asset.double_sided,
        ..Default::default()
    });
    if asset.transform.is_some() {
        root.extensions_used.push("KHR_texture_transform".into());
    }
    push_scene(&mut root, accessors, material);
    std::fs::write(d.join("spot.bin"), &bin).expect("bin");
    let path = d.join("spot.gltf");
    std::fs::write(
        &path,
        json::serialize::to_string_pretty(&root).expect("json"),
    )
    .expect("gltf");
    path
}

/// The spot mesh's primitive with `material`, one node and the default scene.
pub fn push_scene(
    root: &mut json::Root,
    [a_pos, a_uv, a_idx]: [json::Index<json::Accessor>; 3],
    material: json::Index<json::Material>,
) {
    let mut attributes = std::collections::BTreeMap::new();
    attributes.insert(Valid(json::mesh::Semantic::Positions), a_pos);
    attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), a_uv);
    let m = root.push(json::Mesh {
        extensions: None,
        extras: json::Extras::default(),
        name: Some("spot".into()),
        primitives: vec![json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: json::Extras::default(),
            indices: Some(a_idx),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(m),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: None,
        extras: json::Extras::default(),
        name: None,
        nodes: vec![node],
    });
    root.scene = Some(scene);
    root.asset.generator = Some("kapaint tests".into());
}
