//! The `gltf-pbr` export: a project's `k_d`, `k_s`, `n` back to glTF's metallic-roughness
//! textures ([`kapaint_core::pbr::round_trip`]), with the round-trip error in the manifest, and
//! optionally a `.glb` of the project's mesh with the material embedded ([`super::glb`]).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::preset::ExportPreset;
use super::set::{ColourSpace, SetError, claim, commit, padded_texels, png_bytes};
use kapaint_core::mesh::Mesh;
use kapaint_core::model::Document;
use kapaint_core::model::provenance::ErrorSummary;
use kapaint_core::pbr::round_trip::convert;
use kapaint_core::reflectance::ShadingModel;
use kapaint_core::task::Progress;

/// `format` of a glTF PBR set's `material.json`.
pub const PBR_MANIFEST_FORMAT: &str = "kapaint-gltf-pbr";
/// Its version.
pub const PBR_MANIFEST_VERSION: u32 = 1;
/// The base colour image's name.
pub const BASE_COLOR_FILE: &str = "base_color.png";
/// The metallic-roughness image's name.
pub const METALLIC_ROUGHNESS_FILE: &str = "metallic_roughness.png";
/// The normal map's name (where the project has one).
pub const NORMAL_FILE: &str = "normal.png";
/// The `.glb`'s name.
pub const GLB_FILE: &str = "model.glb";

/// One file of a glTF PBR set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PbrFile {
    /// File name, in the set's folder.
    pub path: String,
    /// What it holds, channel by channel (`base.r base.g base.b`, `- roughness metallic`).
    pub layout: Vec<String>,
    /// How its colour is encoded (images).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour_space: Option<ColourSpace>,
    /// Size in bytes.
    pub bytes: u64,
}

/// A glTF PBR set's `material.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PbrManifest {
    /// Always [`PBR_MANIFEST_FORMAT`].
    pub format: String,
    /// [`PBR_MANIFEST_VERSION`].
    pub version: u32,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// The project's shading model, whose `n` was read back into roughness.
    pub model: ShadingModel,
    /// `fitted` (Phong, Blinn-Phong: the inverse of the fitted table) or `cook-torrance`.
    pub n_mapping: String,
    /// The round-trip error (relative, box average; see the module docs).
    pub round_trip: ErrorSummary,
    /// Texels outside the mesh's UV islands were filled from the nearest island.
    pub dilated: bool,
    /// The images, then the `.glb` when written.
    pub files: Vec<PbrFile>,
    /// The preset used.
    pub preset: String,
}

/// The manifest's list of files, with their sizes.
fn files_of(
    base: usize,
    metallic_roughness: usize,
    normal: Option<usize>,
    glb: Option<usize>,
) -> Vec<PbrFile> {
    let file = |path: &str, layout: &[&str], colour_space, bytes: usize| PbrFile {
        path: path.into(),
        layout: layout.iter().map(ToString::to_string).collect(),
        colour_space,
        bytes: bytes as u64,
    };
    let mut files = vec![
        file(
            BASE_COLOR_FILE,
            &["base.r", "base.g", "base.b"],
            Some(ColourSpace::Srgb),
            base,
        ),
        file(
            METALLIC_ROUGHNESS_FILE,
            &["-", "roughness", "metallic"],
            Some(ColourSpace::Linear),
            metallic_roughness,
        ),
    ];
    if let Some(bytes) = normal {
        files.push(file(
            NORMAL_FILE,
            &["normal.x", "normal.y", "normal.z"],
            Some(ColourSpace::Linear),
            bytes,
        ));
    }
    if let Some(bytes) = glb {
        files.push(file(GLB_FILE, &["mesh", "material"], None, bytes));
    }
    files
}

/// Writes `doc` as a glTF PBR set into the folder `out` (free, or a set to replace when
/// `replace`): the two images, the normal map where the document has one (as stored),
/// `material.json`, and with `glb` that mesh with the material embedded ([`GLB_FILE`]).
///
/// # Errors
/// A taken target, a mesh without UVs, a failed encode or write (nothing is left at `out`);
/// cancelled.
pub fn export(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
    replace: bool,
    glb: Option<&Mesh>,
) -> Result<PbrManifest, SetError> {
    progress.start("analyse", 1);
    let found = claim(out, replace, crate::set::SetKind::Pbr)?;
    let (w, h) = (doc.maps().width(), doc.maps().height());
    let model = doc.settings().model;
    let (texels, dilated) = padded_texels(doc);
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start("encode", 2);
    let converted = convert(&texels, model);
    drop(texels);
    let invalid = |reason: String| SetError::Invalid {
        path: out.to_path_buf(),
        reason,
    };
    let (base_png, mr_png) = rayon::join(
        || {
            png_bytes(
                converted.base.as_flattened(),
                (w, h),
                image::ExtendedColorType::Rgb8,
            )
        },
        || {
            png_bytes(
                converted.metallic_roughness.as_flattened(),
                (w, h),
                image::ExtendedColorType::Rgb8,
            )
        },
    );
    let (base_png, mr_png) = (base_png.map_err(invalid)?, mr_png.map_err(invalid)?);
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start("measure", 1);
    // The normal map passes through as stored.
    let normal_png = doc
        .normal()
        .map(|m| m.to_png())
        .transpose()
        .map_err(invalid)?;
    let glb_bytes = glb
        .map(|mesh| {
            super::glb::write(
                mesh,
                &super::glb::Textures {
                    base_color: &base_png,
                    metallic_roughness: &mr_png,
                    normal: normal_png.as_deref(),
                },
                out.file_name()
                    .map_or_else(|| "kapaint".into(), |n| n.to_string_lossy().into_owned()),
            )
        })
        .transpose()
        .map_err(invalid)?;
    let files = files_of(
        base_png.len(),
        mr_png.len(),
        normal_png.as_ref().map(Vec::len),
        glb_bytes.as_ref().map(Vec::len),
    );
    let manifest = PbrManifest {
        format: PBR_MANIFEST_FORMAT.into(),
        version: PBR_MANIFEST_VERSION,
        width: w,
        height: h,
        model,
        n_mapping: if model == ShadingModel::CookTorrance {
            "cook-torrance".into()
        } else {
            "fitted".into()
        },
        round_trip: converted.error,
        dilated,
        files,
        preset: preset.name.clone(),
    };
    commit(out, &found, |tmp| {
        let io = |path: &Path, e: std::io::Error| SetError::Io {
            path: path.to_path_buf(),
            reason: e.to_string(),
        };
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| invalid(e.to_string()))?;
        let mut writes: Vec<(&str, &[u8])> = vec![
            (BASE_COLOR_FILE, &base_png),
            (METALLIC_ROUGHNESS_FILE, &mr_png),
            ("material.json", &json),
        ];
        if let Some(bytes) = &normal_png {
            writes.push((NORMAL_FILE, bytes));
        }
        if let Some(bytes) = &glb_bytes {
            writes.push((GLB_FILE, bytes));
        }
        for (name, bytes) in writes {
            let path = tmp.join(name);
            kapaint_core::atomic::write_atomic(&path, bytes).map_err(|e| io(&path, e))?;
        }
        Ok(manifest)
    })
}
