//! The PBR exports: a project's `k_d`, `k_s`, `n` back to glTF's metallic-roughness values
//! ([`kapaint_pbr::round_trip`]), with the round-trip error in the manifest, written in glTF's
//! layout (the `gltf-pbr` preset, optionally a `.glb` of the project's mesh with the material
//! embedded, [`super::glb`]) or a preset's own (the engine presets: Unreal's ORM, Unity's
//! mask map, Godot's ORM, with occlusion from the AO bake; [`super::pbr_files`]).

use std::path::Path;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::gltf_basisu::{self, BasisuReport};
use super::pbr_files::{Encoded, Sources};
use super::preset::{ExportPreset, NormalGreen};
use super::set::{SetError, claim, commit, padded_texels};
use kapaint_base::task::Progress;
use kapaint_mesh::Mesh;
use kapaint_model::Document;
use kapaint_model::provenance::ErrorSummary;
use kapaint_pbr::round_trip::convert;
use kapaint_reflectance::ShadingModel;

pub use crate::pbr_files::{Occlusion, PbrFile};
pub use crate::preset::textures::GLTF_NORMAL_FILE as NORMAL_FILE;
pub use crate::set::{BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE, PBR_MANIFEST_FORMAT};
/// Its version.
pub const PBR_MANIFEST_VERSION: u32 = 1;
/// The `.glb`'s name.
pub const GLB_FILE: &str = "model.glb";

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
    /// Where the occlusion came from, where the layout has an occlusion channel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub occlusion: Option<Occlusion>,
    /// Which way the written normal map's green points, where one was written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_green: Option<NormalGreen>,
    /// The layout's files not written, each with why (`x_Normal.png: the project has no
    /// normal map`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<String>,
    /// How the `.glb`'s textures were encoded, where they are Basis Universal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basisu: Option<BasisuReport>,
}

/// A `.glb` to write beside a glTF set: the mesh, and whether its textures are Basis
/// Universal KTX2 files (`KHR_texture_basisu`, [`crate::gltf_basisu`]) rather than the PNGs.
#[derive(Clone, Copy)]
pub struct Glb<'a> {
    /// The mesh the material is on.
    pub mesh: &'a Mesh,
    /// Basis Universal textures.
    pub basisu: bool,
}

impl PbrManifest {
    /// What the set is, in words: "glTF metallic-roughness" for glTF's layout, else
    /// "PRESET PBR textures" (the CLI's line and the editor's notice).
    pub fn kind(&self) -> String {
        let gltf = [BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE]
            .iter()
            .all(|name| self.files.iter().any(|f| f.path == *name));
        if gltf {
            "glTF metallic-roughness".into()
        } else {
            format!("{} PBR textures", self.preset)
        }
    }
}

/// Writes `doc` as a PBR set into the folder `out` (free, or a set to replace when
/// `replace`): the preset's layout ([`ExportPreset::pbr_files`]; a normal map's file only
/// where the document has one), `material.json`, and for glTF's layout with `glb` that mesh
/// with the material embedded ([`GLB_FILE`]), its textures the PNGs or Basis Universal.
///
/// # Errors
/// A taken target, a layout whose names meet once the set's name is in them, a failed
/// encode or write (nothing is left at `out`); cancelled.
pub fn export(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
    replace: bool,
    glb: Option<Glb<'_>>,
) -> Result<PbrManifest, SetError> {
    progress.start("analyse", 1);
    let found = claim(out, replace, crate::set::SetKind::Pbr)?;
    let invalid = |reason: String| SetError::Invalid {
        path: out.to_path_buf(),
        reason,
    };
    let name = out
        .file_name()
        .map_or_else(|| "kapaint".into(), |n| n.to_string_lossy().into_owned());
    let layout = preset.pbr_files();
    let paths = paths_in(&layout, &name).map_err(invalid)?;
    let wants_occlusion = layout
        .iter()
        .any(|f| f.channels.contains(&crate::preset::Channel::Occlusion));
    let (occlusion, occlusion_note) = if wants_occlusion {
        let (plane, note) = crate::pbr_files::occlusion(doc);
        (plane, Some(note))
    } else {
        (None, None)
    };
    let (model, mapping) = (doc.settings().model, doc.settings().n_mapping());
    let (texels, occlusion, dilated) = padded_texels(doc, occlusion);
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start("encode", 2);
    let converted = convert(&texels, model, mapping);
    drop(texels);
    let sources = Sources {
        size: (doc.maps().width(), doc.maps().height()),
        converted: &converted,
        occlusion: occlusion.as_deref(),
        normal: doc.normal().map(AsRef::as_ref),
        green: preset.normal_green,
    };
    let encoded: Vec<Option<Result<Encoded, String>>> = layout
        .par_iter()
        .zip(paths.clone())
        .map(|(file, path)| sources.encode(file, path))
        .collect();
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start("measure", 1);
    let (mut written, mut skipped) = (Vec::new(), Vec::new());
    for (file, (path, e)) in layout.iter().zip(paths.iter().zip(encoded)) {
        match e {
            Some(e) => written.push(e.map_err(invalid)?),
            None if file.is_normal() => {
                skipped.push(format!("{path}: the project has no normal map"));
            }
            None => skipped.push(format!("{path}: nothing to write")),
        }
    }
    let normal_green = layout
        .iter()
        .any(|f| f.is_normal() && doc.normal().is_some())
        .then_some(preset.normal_green);
    let basisu = match glb {
        Some(g) if g.basisu => Some(basisu_textures(doc, preset, &sources, &layout, progress)?),
        _ => None,
    };
    let glb = glb
        .map(|g| gltf_glb(doc, g.mesh, &written, basisu.as_ref(), name))
        .transpose()
        .map_err(invalid)?;
    let mut files: Vec<PbrFile> = written.iter().map(|e| e.entry.clone()).collect();
    if let Some(bytes) = &glb {
        files.push(PbrFile {
            path: GLB_FILE.into(),
            layout: vec!["mesh".into(), "material".into()],
            colour_space: None,
            bytes: bytes.len() as u64,
        });
    }
    let manifest = PbrManifest {
        format: PBR_MANIFEST_FORMAT.into(),
        version: PBR_MANIFEST_VERSION,
        width: doc.maps().width(),
        height: doc.maps().height(),
        model,
        n_mapping: mapping.report_name(model).into(),
        round_trip: converted.error,
        dilated,
        files,
        preset: preset.name.clone(),
        occlusion: occlusion_note,
        normal_green,
        skipped,
        basisu: basisu.map(|b| b.report),
    };
    commit(out, &found, |tmp| {
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| invalid(e.to_string()))?;
        let mut writes: Vec<(&str, &[u8])> = written
            .iter()
            .map(|e| (e.entry.path.as_str(), e.bytes.as_slice()))
            .collect();
        writes.push(("material.json", &json));
        if let Some(bytes) = &glb {
            writes.push((GLB_FILE, bytes));
        }
        write_all(tmp, &writes)?;
        Ok(manifest)
    })
}

/// The layout's file names in a set named `name`.
///
/// # Errors
/// Two that meet (case aside) once the name is in them.
fn paths_in(layout: &[crate::preset::TextureFile], name: &str) -> Result<Vec<String>, String> {
    let paths: Vec<String> = layout.iter().map(|f| f.path(name)).collect();
    for (i, p) in paths.iter().enumerate() {
        if let Some(j) = paths[..i].iter().position(|q| q.eq_ignore_ascii_case(p)) {
            return Err(format!(
                "the layout's files {} and {} are both {p} in a set named {name:?}",
                layout[j].file, layout[i].file
            ));
        }
    }
    Ok(paths)
}

/// Writes each `(name, bytes)` into the folder `tmp`.
fn write_all(tmp: &Path, writes: &[(&str, &[u8])]) -> Result<(), SetError> {
    for (name, bytes) in writes {
        let path = tmp.join(name);
        kapaint_base::atomic::write_atomic(&path, bytes).map_err(|e| SetError::Io {
            path: path.clone(),
            reason: e.to_string(),
        })?;
    }
    Ok(())
}

/// glTF's textures as Basis Universal KTX2 files, at the effort the preset's budget asks
/// ([`gltf_basisu::encode`]).
fn basisu_textures(
    doc: &Document,
    preset: &ExportPreset,
    sources: &Sources<'_>,
    layout: &[crate::preset::TextureFile],
    progress: &Progress,
) -> Result<gltf_basisu::Encoded, SetError> {
    let fail = |reason: String| {
        if reason == "cancelled" {
            SetError::Cancelled
        } else {
            SetError::Invalid {
                path: GLB_FILE.into(),
                reason: format!("Basis Universal textures: {reason}"),
            }
        }
    };
    let planes: Vec<Option<crate::pbr_files::Plane>> =
        [BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE, NORMAL_FILE]
            .iter()
            .map(|name| {
                layout
                    .iter()
                    .find(|f| f.file == *name && f.channels.len() == 3)
                    .and_then(|f| sources.plane(f))
            })
            .collect();
    let rgb = |k: usize| {
        planes[k].as_ref().map(|(texels, size)| gltf_basisu::Rgb {
            texels,
            size: *size,
        })
    };
    let settings = doc.settings();
    let reading = gltf_basisu::Reading {
        model: settings.model,
        mapping: settings.n_mapping(),
        approx: settings.approx,
    };
    let rows: u32 = planes.iter().flatten().map(|(_, (_, h))| *h).sum();
    progress.start("basis universal", u64::from(rows));
    gltf_basisu::encode([rgb(0), rgb(1), rgb(2)], reading, &preset.budget, progress).map_err(fail)
}

/// The `.glb` of `mesh` with glTF's images embedded, named `name`: the PNGs `written`, or
/// the Basis Universal files `basisu`.
fn gltf_glb(
    doc: &Document,
    mesh: &Mesh,
    written: &[Encoded],
    basisu: Option<&gltf_basisu::Encoded>,
    name: String,
) -> Result<Vec<u8>, String> {
    let file = |path: &str| {
        written
            .iter()
            .find(|e| e.entry.path == path)
            .map(|e| e.bytes.as_slice())
    };
    let (Some(base_color), Some(metallic_roughness)) =
        (file(BASE_COLOR_FILE), file(METALLIC_ROUGHNESS_FILE))
    else {
        return Err("a .glb is written with glTF's layout (the gltf-pbr preset)".into());
    };
    let textures = super::glb::Textures {
        ktx2: basisu.is_some(),
        base_color: basisu.map_or(base_color, |b| &b.base_color),
        metallic_roughness: basisu.map_or(metallic_roughness, |b| &b.metallic_roughness),
        normal: match basisu {
            Some(b) => b.normal.as_deref(),
            None => file(NORMAL_FILE),
        },
        double_sided: doc
            .settings()
            .import
            .as_ref()
            .is_some_and(|r| r.double_sided),
    };
    super::glb::write(mesh, &textures, name)
}
