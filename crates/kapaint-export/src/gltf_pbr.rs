//! The `gltf-pbr` export: a project's `k_d`, `k_s`, `n` back to glTF's metallic-roughness
//! textures ([`kapaint_pbr::round_trip`]), with the round-trip error in the manifest, and
//! optionally a `.glb` of the project's mesh with the material embedded ([`super::glb`]).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::preset::ExportPreset;
use super::set::{ColourSpace, SetError, claim, commit, padded_texels, png_bytes};
use kapaint_base::task::Progress;
use kapaint_mesh::Mesh;
use kapaint_model::Document;
use kapaint_model::provenance::ErrorSummary;
use kapaint_pbr::round_trip::convert;
use kapaint_reflectance::ShadingModel;

pub use crate::set::{BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE, PBR_MANIFEST_FORMAT};
/// Its version.
pub const PBR_MANIFEST_VERSION: u32 = 1;
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
    /// `height-fitted` or `height-fixed` (Phong, Blinn-Phong: the inverse of that mapping;
    /// manifests written before the height fit say `fitted`, the height-fixed one) or
    /// `cook-torrance`.
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
    let mapping = doc.settings().n_mapping();
    let converted = convert(&texels, model, mapping);
    drop(texels);
    let invalid = |reason: String| SetError::Invalid {
        path: out.to_path_buf(),
        reason,
    };
    let png =
        |rgb: &[[u8; 3]]| png_bytes(rgb.as_flattened(), (w, h), image::ExtendedColorType::Rgb8);
    let (base, metallic_roughness) = rayon::join(
        || png(&converted.base),
        || png(&converted.metallic_roughness),
    );
    let (base, metallic_roughness) = (base.map_err(invalid)?, metallic_roughness.map_err(invalid)?);
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start("measure", 1);
    // The normal map passes through as stored.
    let normal = doc
        .normal()
        .map(|m| m.to_png())
        .transpose()
        .map_err(invalid)?;
    let name = out
        .file_name()
        .map_or_else(|| "kapaint".into(), |n| n.to_string_lossy().into_owned());
    let glb = glb
        .map(|mesh| {
            let textures = super::glb::Textures {
                base_color: &base,
                metallic_roughness: &metallic_roughness,
                normal: normal.as_deref(),
                double_sided: doc
                    .settings()
                    .import
                    .as_ref()
                    .is_some_and(|r| r.double_sided),
            };
            super::glb::write(mesh, &textures, name)
        })
        .transpose()
        .map_err(invalid)?;
    let written = PbrFiles {
        base,
        metallic_roughness,
        normal,
        glb,
    };
    let manifest = PbrManifest {
        format: PBR_MANIFEST_FORMAT.into(),
        version: PBR_MANIFEST_VERSION,
        width: w,
        height: h,
        model,
        n_mapping: mapping.report_name(model).into(),
        round_trip: converted.error,
        dilated,
        files: written.entries(),
        preset: preset.name.clone(),
    };
    commit(out, &found, |tmp| {
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| invalid(e.to_string()))?;
        written.write(tmp, &json)?;
        Ok(manifest)
    })
}

/// The files of a glTF PBR set, encoded.
struct PbrFiles {
    base: Vec<u8>,
    metallic_roughness: Vec<u8>,
    normal: Option<Vec<u8>>,
    glb: Option<Vec<u8>>,
}

impl PbrFiles {
    /// Their manifest entries.
    fn entries(&self) -> Vec<PbrFile> {
        files_of(
            self.base.len(),
            self.metallic_roughness.len(),
            self.normal.as_ref().map(Vec::len),
            self.glb.as_ref().map(Vec::len),
        )
    }

    /// Writes them and the manifest's `json` into `tmp`.
    fn write(&self, tmp: &Path, json: &[u8]) -> Result<(), SetError> {
        let mut writes: Vec<(&str, &[u8])> = vec![
            (BASE_COLOR_FILE, &self.base),
            (METALLIC_ROUGHNESS_FILE, &self.metallic_roughness),
            ("material.json", json),
        ];
        if let Some(bytes) = &self.normal {
            writes.push((NORMAL_FILE, bytes));
        }
        if let Some(bytes) = &self.glb {
            writes.push((GLB_FILE, bytes));
        }
        for (name, bytes) in writes {
            let path = tmp.join(name);
            kapaint_base::atomic::write_atomic(&path, bytes).map_err(|e| SetError::Io {
                path: path.clone(),
                reason: e.to_string(),
            })?;
        }
        Ok(())
    }
}
