//! A binary glTF (`.glb`) of a mesh with one metallic-roughness material whose textures are
//! embedded, built with the `gltf` crate's JSON types: PNGs, or KTX2 files of Basis Universal
//! blocks (`KHR_texture_basisu`, [`super::gltf_basisu`]) with no fallback, the extension then
//! required and each texture's image named by the extension alone, as it states.
//!
//! kapaint's meshes keep OBJ's UV convention (`v` up); glTF's `v` runs down, so the file
//! stores `1 - v`, as [`kapaint_mesh::gltf_import`] undoes on the way in. With a normal map the
//! file carries MikkTSpace tangents ([`kapaint_mesh::tangents`]). Node transforms are
//! baked into the positions on import, so the one node here has none.

use std::collections::BTreeMap;

use gltf::json;
use gltf::json::validation::{Checked::Valid, USize64};

use kapaint_mesh::Mesh;
use kapaint_mesh::gltf_import::KHR_TEXTURE_BASISU as BASISU;

/// The material's textures, PNG-encoded or (with `ktx2`) Basis Universal KTX2 files.
pub struct Textures<'a> {
    /// The images are KTX2 files of Basis Universal blocks (`KHR_texture_basisu`).
    pub ktx2: bool,
    /// Base colour, sRGB.
    pub base_color: &'a [u8],
    /// Metallic-roughness (G roughness, B metallic).
    pub metallic_roughness: &'a [u8],
    /// The tangent-space normal map, if any.
    pub normal: Option<&'a [u8]>,
    /// The material is seen from both sides (glTF's `doubleSided`).
    pub double_sided: bool,
}

/// The binary chunk being built, and the views into it.
struct Bin {
    bytes: Vec<u8>,
}

impl Bin {
    /// Appends `data` (at a 4-byte boundary) as a new buffer view.
    fn view(
        &mut self,
        root: &mut json::Root,
        data: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(data.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: json::Extras::default(),
        })
    }

    /// Appends `values` as a tightly packed accessor of `kind` (with bounds where given).
    fn accessor<const N: usize>(
        &mut self,
        root: &mut json::Root,
        values: &[[f32; N]],
        kind: json::accessor::Type,
        bounds: Option<([f32; N], [f32; N])>,
    ) -> json::Index<json::Accessor> {
        let data: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(root, &data, Some(json::buffer::Target::ArrayBuffer));
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(values.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: json::Extras::default(),
            type_: Valid(kind),
            min: bounds.map(|(lo, _)| json::Value::from(lo.to_vec())),
            max: bounds.map(|(_, hi)| json::Value::from(hi.to_vec())),
            name: None,
            normalized: false,
            sparse: None,
        })
    }
}

/// The image type of a KTX2 file, as `KHR_texture_basisu` names it.
pub const KTX2_MIME: &str = "image/ktx2";

/// A texture of the image `bytes` (a view of the binary chunk; a PNG, or a KTX2 file where
/// `ktx2`), sampled with linear filtering, trilinear mips and repeat wrapping (sampler 0).
fn texture(
    root: &mut json::Root,
    bin: &mut Bin,
    (bytes, ktx2): (&[u8], bool),
    name: &str,
) -> json::texture::Info {
    let view = bin.view(root, bytes, None);
    let mime = if ktx2 { KTX2_MIME } else { "image/png" };
    let image = root.push(json::Image {
        buffer_view: Some(view),
        mime_type: Some(json::image::MimeType(mime.into())),
        name: Some(name.into()),
        uri: None,
        extensions: None,
        extras: json::Extras::default(),
    });
    let texture = root.push(json::Texture {
        name: Some(name.into()),
        sampler: Some(json::Index::new(0)),
        source: image,
        extensions: None,
        extras: json::Extras::default(),
    });
    json::texture::Info {
        index: texture,
        tex_coord: 0,
        extensions: None,
        extras: json::Extras::default(),
    }
}

/// The mesh's vertices (positions, normals, texture coordinates with `v` flipped) and
/// triangles as accessors: the primitive's attributes and indices.
fn push_geometry(
    root: &mut json::Root,
    bin: &mut Bin,
    mesh: &Mesh,
    uvs: &[glam::Vec2],
    tangents: Option<&[[f32; 4]]>,
) -> (
    BTreeMap<json::validation::Checked<json::mesh::Semantic>, json::Index<json::Accessor>>,
    json::Index<json::Accessor>,
) {
    let (lo, hi) = mesh.bounds();
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(glam::Vec3::to_array).collect();
    let normals: Vec<[f32; 3]> = mesh.normals.iter().map(glam::Vec3::to_array).collect();
    let texcoords: Vec<[f32; 2]> = uvs.iter().map(|t| [t.x, 1.0 - t.y]).collect();
    let a_pos = bin.accessor(
        root,
        &positions,
        json::accessor::Type::Vec3,
        Some((lo.to_array(), hi.to_array())),
    );
    let a_normal = bin.accessor(root, &normals, json::accessor::Type::Vec3, None);
    let a_uv = bin.accessor(root, &texcoords, json::accessor::Type::Vec2, None);
    let indices: Vec<u8> = mesh
        .triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let v_idx = bin.view(
        root,
        &indices,
        Some(json::buffer::Target::ElementArrayBuffer),
    );
    let a_idx = root.push(json::Accessor {
        buffer_view: Some(v_idx),
        byte_offset: None,
        count: USize64::from(mesh.triangles.len() * 3),
        component_type: Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::U32,
        )),
        extensions: None,
        extras: json::Extras::default(),
        type_: Valid(json::accessor::Type::Scalar),
        min: None,
        max: None,
        name: None,
        normalized: false,
        sparse: None,
    });
    let mut attributes = BTreeMap::from([
        (Valid(json::mesh::Semantic::Positions), a_pos),
        (Valid(json::mesh::Semantic::Normals), a_normal),
        (Valid(json::mesh::Semantic::TexCoords(0)), a_uv),
    ]);
    if let Some(tangents) = tangents {
        let a_tangent = bin.accessor(root, tangents, json::accessor::Type::Vec4, None);
        attributes.insert(Valid(json::mesh::Semantic::Tangents), a_tangent);
    }
    (attributes, a_idx)
}

/// The material: base colour, metallic-roughness and the normal map where given, each an
/// embedded PNG, all through one sampler (linear, trilinear mips, repeat).
fn push_material(
    root: &mut json::Root,
    bin: &mut Bin,
    textures: &Textures<'_>,
    name: String,
) -> json::Index<json::Material> {
    root.push(json::texture::Sampler {
        mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
        min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
        name: None,
        wrap_s: Valid(json::texture::WrappingMode::Repeat),
        wrap_t: Valid(json::texture::WrappingMode::Repeat),
        extensions: None,
        extras: json::Extras::default(),
    });
    let k = textures.ktx2;
    let base = texture(root, bin, (textures.base_color, k), "base_color");
    let mr = texture(
        root,
        bin,
        (textures.metallic_roughness, k),
        "metallic_roughness",
    );
    let normal = textures.normal.map(|bytes| {
        let info = texture(root, bin, (bytes, k), "normal");
        json::material::NormalTexture {
            index: info.index,
            scale: 1.0,
            tex_coord: 0,
            extensions: None,
            extras: json::Extras::default(),
        }
    });
    root.push(json::Material {
        name: Some(name),
        normal_texture: normal,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(base),
            metallic_roughness_texture: Some(mr),
            ..Default::default()
        },
        double_sided: textures.double_sided,
        ..Default::default()
    })
}

/// The `.glb` of `mesh` with the textures as its material (named `name`).
///
/// # Errors
/// A mesh without UVs, or one too large for a GLB (4 GiB).
pub fn write(mesh: &Mesh, textures: &Textures<'_>, name: String) -> Result<Vec<u8>, String> {
    write_glb(mesh, Some(textures), name)
}

/// The `.glb` of `mesh` alone: positions, normals and UVs, no material (what `kapaint unwrap`
/// writes).
///
/// # Errors
/// A mesh without UVs, or one too large for a GLB (4 GiB).
pub fn write_mesh(mesh: &Mesh) -> Result<Vec<u8>, String> {
    write_glb(mesh, None, mesh.name.clone())
}

fn write_glb(
    mesh: &Mesh,
    textures: Option<&Textures<'_>>,
    name: String,
) -> Result<Vec<u8>, String> {
    // A normal map is read in MikkTSpace tangents: they go in the file (vertices split where
    // a seam needs two), so every reader uses the frame it was made for.
    let with_tangents = textures
        .and_then(|t| t.normal)
        .and_then(|_| kapaint_mesh::tangents::generate(mesh));
    let (mesh, tangents) = match &with_tangents {
        Some(t) => (&t.mesh, Some(t.tangents.as_slice())),
        None => (mesh, None),
    };
    let uvs = mesh
        .uvs
        .as_ref()
        .ok_or("the mesh has no UVs to map the textures with")?;
    let mut root = json::Root::default();
    root.asset.generator = Some(format!("kapaint {}", env!("CARGO_PKG_VERSION")));
    let mut bin = Bin { bytes: Vec::new() };
    let (attributes, indices) = push_geometry(&mut root, &mut bin, mesh, uvs, tangents);
    let material = textures.map(|t| push_material(&mut root, &mut bin, t, name));
    let m = root.push(json::Mesh {
        extensions: None,
        extras: json::Extras::default(),
        name: Some(mesh.name.clone()),
        primitives: vec![json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: json::Extras::default(),
            indices: Some(indices),
            material,
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(m),
        name: Some(mesh.name.clone()),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: None,
        extras: json::Extras::default(),
        name: None,
        nodes: vec![node],
    });
    root.scene = Some(scene);
    let length = u32::try_from(bin.bytes.len())
        .ok()
        .filter(|n| *n < u32::MAX - (1 << 20))
        .ok_or("the mesh and textures are too large for a .glb (4 GiB)")?;
    root.buffers.push(json::Buffer {
        byte_length: USize64::from(u64::from(length)),
        name: None,
        uri: None,
        extensions: None,
        extras: json::Extras::default(),
    });
    let ktx2 = textures.is_some_and(|t| t.ktx2);
    if ktx2 {
        root.extensions_used.push(BASISU.into());
        root.extensions_required.push(BASISU.into());
    }
    let mut json = json::serialize::to_vec(&root).map_err(|e| e.to_string())?;
    if ktx2 {
        json = sources_into_extension(&json)?;
    }
    gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: json.into(),
        bin: Some(bin.bytes.into()),
    }
    .to_vec()
    .map_err(|e| e.to_string())
}

/// The JSON `json` with each texture's `source` moved into its `KHR_texture_basisu`
/// extension: the image is a KTX2 file with no fallback, which the texture names only there
/// (the `gltf` crate's types cannot leave `source` out).
fn sources_into_extension(json: &[u8]) -> Result<Vec<u8>, String> {
    let mut root: serde_json::Value = serde_json::from_slice(json).map_err(|e| e.to_string())?;
    if let Some(textures) = root
        .get_mut("textures")
        .and_then(serde_json::Value::as_array_mut)
    {
        for texture in textures
            .iter_mut()
            .filter_map(serde_json::Value::as_object_mut)
        {
            if let Some(source) = texture.remove("source") {
                texture.insert(
                    "extensions".into(),
                    serde_json::json!({ BASISU: { "source": source } }),
                );
            }
        }
    }
    serde_json::to_vec(&root).map_err(|e| e.to_string())
}
