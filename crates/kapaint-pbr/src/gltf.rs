//! A glTF material's metallic-roughness set: its textures (from the GLB's buffers, data:
//! URIs or files beside the `.gltf`), factors, samplers' wrap modes and texture transforms.
//!
//! Images are decoded with the import limits. A KTX2 texture (`KHR_texture_basisu`'s Basis
//! Universal images, or any KTX2 kapaint writes) is decoded by the [`Ktx2Reader`] the caller
//! hands in (the export crate's, which sits above this one), or refused with the reason where
//! none is; so is a texture on another UV set than the one kapaint paints (`TEXCOORD_0`).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::DynamicImage;

use super::import::{Input, PbrSet, Source, UvTransform, Wrap};
use kapaint_mesh::gltf_import::{KHR_TEXTURE_BASISU, Opened, file_beside, names_basisu, open_gltf};
use kapaint_model::ModelError;
use kapaint_model::import::{decode_bytes, read_image};
use kapaint_model::normal::NormalMap;

/// A material's set, and what to say about it.
pub struct MaterialSet {
    /// The set.
    pub set: PbrSet,
    /// The material's name (or `#index`).
    pub name: String,
    /// The material's normal map (`normalTexture`), its scale baked in.
    pub normal: Option<NormalMap>,
    /// What was left out, one line each.
    pub notes: Vec<String>,
    /// The material is seen from both sides (`doubleSided`).
    pub double_sided: bool,
}

/// Decodes a KTX2 file to its level 0's texels, or says why not in one line: the export
/// crate's `ktx::decode_image`, handed in by whoever opens the file (the CLI, the editor).
pub type Ktx2Reader = fn(&[u8]) -> Result<DynamicImage, String>;

fn fail(path: &Path, reason: impl Into<String>) -> ModelError {
    ModelError::Image {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// The reason a file names Basis Universal or KTX2 textures, if it does.
fn basis_reason() -> String {
    "it uses KTX2 / Basis Universal textures (KHR_texture_basisu), which kapaint does not read; \
     export the material with PNG or JPEG textures"
        .into()
}

/// The metallic-roughness set of the material `selector` (a name, or an index) of the glTF
/// at `path`; with no selector, the material of the first primitive that has one.
///
/// # Errors
/// A file that does not open, a missing material, a texture that does not read (missing,
/// corrupt, too large, KTX2 without a `ktx2` reader, one the reader refuses), or one on
/// another UV set.
pub fn material_set(
    path: &Path,
    selector: Option<&str>,
    ktx2: Option<Ktx2Reader>,
) -> Result<MaterialSet, ModelError> {
    let opened = open_gltf(path).map_err(|e| {
        // Without a KTX2 reader, a file naming Basis Universal textures is refused for that,
        // whatever else the JSON says.
        let raw = std::fs::read(path).unwrap_or_default();
        if ktx2.is_none() && names_basisu(&raw) {
            fail(path, basis_reason())
        } else {
            match e {
                kapaint_mesh::MeshError::Io { source, .. } => ModelError::io(path, source),
                kapaint_mesh::MeshError::Invalid { reason, .. } => fail(path, reason),
            }
        }
    })?;
    let document = &opened.document;
    if ktx2.is_none() && document.extensions_used().any(|e| e == KHR_TEXTURE_BASISU) {
        return Err(fail(path, basis_reason()));
    }
    // Before anything reads an image or a factor: what the gltf crate would panic on, misread
    // or pass on out of range.
    super::gltf_check::check_materials(&opened.json).map_err(|e| fail(path, e))?;
    let material = pick_material(document, path, selector)?;
    let name = material.name().map_or_else(
        || format!("#{}", material.index().unwrap_or(0)),
        str::to_string,
    );
    let mut images = Images {
        opened: &opened,
        path,
        cache: HashMap::new(),
        ktx2,
    };
    let pbr = material.pbr_metallic_roughness();
    let base_factor = Vec3::from_slice(&pbr.base_color_factor()[..3]);
    let mut base = Source::constant(base_factor);
    if let Some(info) = pbr.base_color_texture() {
        base = images.source(&info, "baseColorTexture", None, true)?;
        base.factor = base_factor;
    }
    let (metallic_factor, roughness_factor) = (pbr.metallic_factor(), pbr.roughness_factor());
    let (mut metallic, mut roughness) = (
        Source::constant(Vec3::splat(metallic_factor)),
        Source::constant(Vec3::splat(roughness_factor)),
    );
    if let Some(info) = pbr.metallic_roughness_texture() {
        metallic = images.source(&info, "metallicRoughnessTexture", Some(2), false)?;
        metallic.factor = Vec3::splat(metallic_factor);
        roughness = images.source(&info, "metallicRoughnessTexture", Some(1), false)?;
        roughness.factor = Vec3::splat(roughness_factor);
    }
    let mut notes = Vec::new();
    let normal = material
        .normal_texture()
        .map(|t| images.normal(&t, &mut notes))
        .transpose()?;
    if material.emissive_texture().is_some() || material.occlusion_texture().is_some() {
        notes.push(
            "emissive and occlusion textures have no place in kapaint's material; left out"
                .to_string(),
        );
    }
    Ok(MaterialSet {
        set: PbrSet::MetallicRoughness {
            base,
            metallic,
            roughness,
        },
        name,
        normal,
        notes,
        double_sided: material.double_sided(),
    })
}

/// Whether the glTF at `path` has a material with a base colour, metallic-roughness or
/// normal texture (what the editor offers to bring in with the mesh). Reads the JSON only; a
/// file that does not parse has none.
pub fn has_textured_material(path: &Path) -> bool {
    let Ok(bytes) = kapaint_base::file_check::read_limited(path, kapaint_mesh::MAX_FILE_BYTES)
    else {
        return false;
    };
    let Ok(gltf) = gltf::Gltf::from_slice_without_validation(&bytes) else {
        return false;
    };
    gltf.materials().any(|m| {
        let pbr = m.pbr_metallic_roughness();
        pbr.base_color_texture().is_some()
            || pbr.metallic_roughness_texture().is_some()
            || m.normal_texture().is_some()
    })
}

/// The material `selector` names (a name, or an index), or the first primitive's.
fn pick_material<'a>(
    document: &'a gltf::Document,
    path: &Path,
    selector: Option<&str>,
) -> Result<gltf::Material<'a>, ModelError> {
    let names: Vec<String> = document
        .materials()
        .map(|m| {
            m.name()
                .map_or_else(|| format!("#{}", m.index().unwrap_or(0)), str::to_string)
        })
        .collect();
    let material = match selector {
        Some(s) => document
            .materials()
            .find(|m| m.name() == Some(s))
            .or_else(|| {
                s.parse::<usize>()
                    .ok()
                    .and_then(|i| document.materials().nth(i))
            })
            .ok_or_else(|| {
                fail(
                    path,
                    format!(
                        "it has no material {s:?} (its materials: {})",
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(", ")
                        }
                    ),
                )
            })?,
        None => document
            .meshes()
            .flat_map(|m| m.primitives().collect::<Vec<_>>())
            .find_map(|p| {
                p.material()
                    .index()
                    .and_then(|i| document.materials().nth(i))
            })
            .or_else(|| document.materials().next())
            .ok_or_else(|| fail(path, "it has no material"))?,
    };
    Ok(material)
}

/// The file's images, each decoded once.
struct Images<'a> {
    opened: &'a Opened,
    path: &'a Path,
    cache: HashMap<usize, Arc<DynamicImage>>,
    ktx2: Option<Ktx2Reader>,
}

impl Images<'_> {
    /// The source for a texture slot: its image, channel, colour space, transform and wrap.
    fn source(
        &mut self,
        info: &gltf::texture::Info<'_>,
        slot: &str,
        channel: Option<usize>,
        srgb: bool,
    ) -> Result<Source, ModelError> {
        let texture = info.texture();
        let transform = info.texture_transform();
        let tex_coord = transform
            .as_ref()
            .and_then(gltf::texture::TextureTransform::tex_coord)
            .unwrap_or_else(|| info.tex_coord());
        if tex_coord != 0 {
            return Err(fail(
                self.path,
                format!("{slot} uses TEXCOORD_{tex_coord}; kapaint paints on TEXCOORD_0 only"),
            ));
        }
        let image = texture.source();
        let index = image.index();
        let decoded = if let Some(d) = self.cache.get(&index) {
            Arc::clone(d)
        } else {
            let d = Arc::new(self.decode(&image, slot)?);
            self.cache.insert(index, Arc::clone(&d));
            d
        };
        let wrap_of = |m: gltf::texture::WrappingMode| match m {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = texture.sampler();
        let transform = transform.map(|t| UvTransform {
            offset: Vec2::from(t.offset()),
            rotation: t.rotation(),
            scale: Vec2::from(t.scale()),
            wrap: [wrap_of(sampler.wrap_s()), wrap_of(sampler.wrap_t())],
        });
        let label = format!(
            "{} {slot} (image {index}{})",
            super::import::file_name(self.path),
            image.name().map_or_else(String::new, |n| format!(" {n:?}"))
        );
        Ok(Source {
            input: Input::Decoded(decoded, label),
            channel,
            srgb,
            factor: Vec3::ONE,
            transform,
        })
    }

    /// The normal map of `normalTexture` (on `TEXCOORD_0`), its scale baked in. It is kept as
    /// stored, at its own size: a texture transform on it (which the gltf crate does not
    /// read for normal textures) is not applied.
    fn normal(
        &self,
        t: &gltf::material::NormalTexture<'_>,
        notes: &mut Vec<String>,
    ) -> Result<NormalMap, ModelError> {
        if t.tex_coord() != 0 {
            return Err(fail(
                self.path,
                format!(
                    "normalTexture uses TEXCOORD_{}; kapaint paints on TEXCOORD_0 only",
                    t.tex_coord()
                ),
            ));
        }
        let image = t.texture().source();
        let decoded = self.decode(&image, "normalTexture")?;
        let label = format!(
            "{} normalTexture (image {})",
            super::import::file_name(self.path),
            image.index()
        );
        super::import::normal_map(&decoded, t.scale(), &label, notes)
    }

    fn decode(&self, image: &gltf::Image<'_>, slot: &str) -> Result<DynamicImage, ModelError> {
        let what = |reason: String| fail(self.path, format!("{slot}: {reason}"));
        let is_ktx = |mime: Option<&str>, uri: Option<&str>| {
            mime.is_some_and(|m| m.contains("ktx2") || m.contains("basis"))
                || uri.is_some_and(|u| {
                    Path::new(u).extension().is_some_and(|e| {
                        e.eq_ignore_ascii_case("ktx2") || e.eq_ignore_ascii_case("basis")
                    })
                })
        };
        // A KTX2 image through the reader handed in; refused where there is none.
        let read = |bytes: &[u8], ktx: bool, label: &Path| -> Result<DynamicImage, ModelError> {
            // The KTX2 reader bounds its own sizes (kapaint's largest map).
            if !ktx {
                return decode_bytes(bytes, label).map_err(|e| what(e.to_string()));
            }
            let reader = self.ktx2.ok_or_else(|| what(basis_reason()))?;
            let decoded = reader(bytes).map_err(|e| {
                what(format!(
                    "image {} (KTX2) does not decode: {e}",
                    image.index()
                ))
            })?;
            Ok(decoded)
        };
        let label = self.path.join(format!("image{}", image.index()));
        match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let buffer = &self.opened.buffers[view.buffer().index()];
                let (start, len) = (view.offset(), view.length());
                let bytes = start
                    .checked_add(len)
                    .and_then(|end| buffer.get(start..end))
                    .ok_or_else(|| {
                        what(format!(
                            "image {} lies outside its buffer ({} bytes)",
                            image.index(),
                            buffer.len()
                        ))
                    })?;
                read(bytes, is_ktx(Some(mime_type), None), &label)
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                let ktx = is_ktx(mime_type, Some(uri));
                if uri.starts_with("data:") {
                    let bytes = gltf::buffer::Data::from_source_and_blob(
                        gltf::buffer::Source::Uri(uri),
                        None,
                        &mut None,
                    )
                    .map_err(|e| what(format!("its data: URI does not decode: {e}")))?;
                    read(&bytes.0, ktx, &label)
                } else {
                    let file = file_beside(&self.opened.dir, uri).map_err(|e| {
                        what(if ktx {
                            format!("its KTX2 image: {e}")
                        } else {
                            e
                        })
                    })?;
                    if ktx {
                        let bytes = kapaint_base::file_check::read_limited(
                            &file,
                            kapaint_mesh::MAX_FILE_BYTES,
                        )
                        .map_err(|e| what(format!("its KTX2 image: {e}")))?;
                        read(&bytes, true, &file)
                    } else {
                        read_image(&file).map_err(|e| what(e.to_string()))
                    }
                }
            }
        }
    }
}
