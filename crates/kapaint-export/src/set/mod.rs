//! Writing and reading texture sets: images plus `material.json`.
//!
//! A set is written into a temporary folder beside the target and renamed into place at the
//! end, so a half-written set is never left where the target should be.

mod choose;
mod encode;
mod import;
mod manifest;
mod measure;
mod normal;
mod plan;
mod target;

use std::path::{Path, PathBuf};

use glam::Vec3;
use rayon::prelude::*;

pub use self::choose::{BlockChoice, BlockLayout, Trial};
pub(crate) use self::encode::png_bytes;
use self::encode::{Encoded, StoredImage, encode_image, rows};
pub use self::import::import;
pub use self::manifest::{
    Approximation, ColourSpace, Compression, Constants, FileEntry, MANIFEST_FORMAT,
    MANIFEST_VERSION, Manifest, MemoryReport,
};
use self::manifest::{Comp, approximation};
use self::measure::ka_error_of_set;
pub use self::normal::{NORMAL_FILE, NormalFile};
use self::plan::plan_set;
pub use self::plan::{PlannedFile, SetPlan, plan};
pub use self::target::{SetKind, Target, holds, target};
pub(crate) use self::target::{claim, commit};
use super::encoding::KaError;
use super::preset::{ExportPreset, Format};
use kapaint_core::mesh::bake::Coverage;
use kapaint_core::model::Document;
use kapaint_core::reflectance;
use kapaint_core::task::Progress;
/// Why an export or import failed.
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// A file could not be written or read.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The set is malformed.
    #[error("{path}: {reason}")]
    Invalid {
        /// The manifest or image.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The target cannot take a set (a file, or a folder that is not empty).
    #[error("{path}: {reason}")]
    Target {
        /// The target.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Cancelled through its [`Progress`]; nothing was left at the target.
    #[error("export cancelled")]
    Cancelled,
}

fn io(path: &Path, e: impl std::fmt::Display) -> SetError {
    SetError::Io {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Exports `doc` with `preset` into the folder `out` (which must not exist or be empty).
///
/// # Errors
/// An unwritable or non-empty target, or a failed encode or write: nothing is left at `out`.
pub fn export(doc: &Document, preset: &ExportPreset, out: &Path) -> Result<Manifest, SetError> {
    export_with(doc, preset, out, &Progress::default())
}

/// [`export`], reporting to `progress` (stages `analyse`, `encode`, `measure`) and stopping
/// with [`SetError::Cancelled`] when it is cancelled.
///
/// # Errors
/// As [`export`], or cancelled.
pub fn export_with(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
) -> Result<Manifest, SetError> {
    export_into(doc, preset, out, progress, false, None)
}

/// [`export_with`] that may also replace a set already at `out` ([`Target::Set`]): the new
/// set is written beside it, swapped in, and the old one removed, so `out` always holds a
/// whole set. A target that is not a set is never replaced.
///
/// # Errors
/// As [`export_with`]; a target that is neither free nor a set.
pub fn export_replacing(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
) -> Result<Manifest, SetError> {
    export_into(doc, preset, out, progress, true, None)
}

#[expect(
    clippy::too_many_lines,
    reason = "one pass: analyse, encode in parallel, measure"
)]
pub(super) fn export_into(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
    replace: bool,
    brought: Option<&dyn crate::blocks::BlockEncoder>,
) -> Result<Manifest, SetError> {
    let cancelled = |_| SetError::Cancelled;
    progress.start("analyse", 1);
    let found = claim(out, replace, SetKind::Material)?;
    if preset.format == Format::GltfPbr {
        return Err(SetError::Invalid {
            path: out.to_path_buf(),
            reason: "a glTF PBR set is written by crate::run (crate::gltf_pbr)".into(),
        });
    }
    let maps = doc.maps();
    let (model, approx) = (doc.settings().model, doc.settings().approx);
    let (w, h) = (maps.width(), maps.height());
    let (planned, mono_ks, images) = plan_set(doc, preset);
    let (constants, n_enc) = (planned.constants, planned.n_encoding);
    let (texels, dilated) = padded_texels(doc);
    let ka: Vec<Vec3> = if preset.include_ka {
        texels
            .par_iter()
            .map(|t| {
                let v = t.decode();
                reflectance::ka(model, approx, v.kd, v.ks, v.n)
            })
            .collect()
    } else {
        Vec::new()
    };

    let ext = preset.format.extension();
    progress.check().map_err(cancelled)?;
    progress.start("encode", images.len() as u64 * u64::from(h));

    commit(out, &found, |tmp| {
        let fail = |e: String, file: &str| {
            if progress.is_cancelled() {
                SetError::Cancelled
            } else {
                io(&tmp.join(file), e)
            }
        };
        let shape = measure::Shape {
            width: w,
            constants: &constants,
            n_encoding: n_enc,
        };
        let (encoded, blocks): (Vec<Result<Encoded, SetError>>, _) = if preset.format
            == Format::Ktx2Bc
        {
            let job = choose::Job {
                texels: &texels,
                ka: &ka,
                size: (w, h),
                preset,
                n_enc,
                shape,
                model,
                approx,
                brought,
            };
            let apart = choose::n_apart(&images, mono_ks);
            let (encoded, choice) = choose::encode_blocks(&job, &images, apart.as_ref(), progress)
                .map_err(|e| fail(e, "material.json"))?;
            (
                encoded.into_iter().map(Ok).collect(),
                Some(Box::new(choice)),
            )
        } else {
            let encoded = images
                .par_iter()
                .map(|(stem, comps)| {
                    let file = format!("{stem}.{ext}");
                    if progress.is_cancelled() {
                        return Err(SetError::Cancelled);
                    }
                    let image = encode_image(&texels, &ka, (w, h), comps, preset, n_enc, progress)
                        .map_err(|e| fail(e, &file))?;
                    if progress.is_cancelled() {
                        return Err(SetError::Cancelled);
                    }
                    Ok((file, comps.clone(), image))
                })
                .collect();
            (encoded, None)
        };
        progress.start("measure", 1);
        let mut files = Vec::new();
        let mut stored = Vec::new();
        let mut mips: Vec<Mips> = Vec::new();
        for item in encoded {
            let (file, comps, mut image) = item?;
            if let Some(k) = image.ktx.as_mut() {
                mips.push(Mips {
                    comps: comps.clone(),
                    levels: std::mem::take(&mut k.mips),
                    srgb: image.srgb,
                    half: image.half,
                });
            }
            let path = tmp.join(&file);
            kapaint_core::atomic::write_atomic(&path, &image.bytes).map_err(|e| io(&path, e))?;
            let (mip_levels, psnr, compression) = match image.ktx {
                Some(k) => (Some(k.levels), k.psnr, k.compression),
                None if preset.format == Format::Exr => (None, None, Compression::Exr),
                None => (None, None, Compression::Png),
            };
            files.push(FileEntry {
                path: file,
                layout: comps.iter().map(|c| c.name(mono_ks)).collect(),
                colour_space: if image.srgb {
                    ColourSpace::Srgb
                } else {
                    ColourSpace::Linear
                },
                bit_depth: match preset.format {
                    _ if image.half => 16,
                    Format::Png8 | Format::Ktx2 | Format::Ktx2Bc | Format::GltfPbr => 8,
                    Format::Png16 => 16,
                    Format::Exr => 32,
                },
                compression,
                width: w,
                height: h,
                bytes: image.bytes.len() as u64,
                mip_levels,
                psnr,
            });
            if let Some(data) = image.stored {
                stored.push(StoredImage {
                    comps,
                    data: data.into(),
                    srgb: image.srgb,
                    half: image.half,
                });
            }
        }
        let depth = match preset.format {
            Format::Png8 | Format::Ktx2 | Format::Ktx2Bc | Format::GltfPbr => 1,
            Format::Png16 => 2,
            Format::Exr => 4,
        };
        let texel_count = u64::from(w) * u64::from(h);
        let mut manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            version: MANIFEST_VERSION,
            width: w,
            height: h,
            model,
            approximation: approximation(approx, model),
            constants,
            n_encoding: n_enc,
            files,
            ka_error: KaError::default(),
            dilated,
            bytes: MemoryReport {
                exported: 0,
                naive: texel_count * 10 * depth,
                project: texel_count * 14,
            },
            preset: preset.name.clone(),
            layers: u32::try_from(doc.stack().walk().len()).unwrap_or(u32::MAX),
            level_ka_error: Vec::new(),
            blocks,
            normal: None,
        };
        // The k_a error, measured on the set as a consumer decodes it.
        manifest.ka_error = ka_error_of_set(&texels, shape, &stored, preset.format, model, approx);
        if preset.format.is_ktx2() {
            manifest.level_ka_error = level_errors(&texels, (w, h), shape, &mips, model, approx);
            manifest.level_ka_error.insert(0, manifest.ka_error);
        }
        // The decode + k_a snippets for engines (WGSL and GLSL), beside the images.
        let mut exported = manifest.files.iter().map(|f| f.bytes).sum::<u64>();
        if let Some(normal) = doc.normal() {
            let file = NormalFile::write(normal, tmp)?;
            exported += file.bytes;
            manifest.normal = Some(Box::new(file));
        }
        for (name, snippet) in [
            ("material.wgsl", crate::snippet::wgsl(&manifest)),
            ("material.glsl", crate::snippet::glsl(&manifest)),
        ] {
            let snippet_path = tmp.join(name);
            kapaint_core::atomic::write_atomic(&snippet_path, snippet.as_bytes())
                .map_err(|e| io(&snippet_path, e))?;
            exported += snippet.len() as u64;
        }
        // The manifest counts itself, and its length depends on the count's digits: repeat
        // until they agree (the count only grows, so this ends, in two or three rounds).
        let json = loop {
            let json = serde_json::to_vec_pretty(&manifest).map_err(|e| io(tmp, e))?;
            let total = exported + json.len() as u64;
            if manifest.bytes.exported == total {
                break json;
            }
            manifest.bytes.exported = total;
        };
        let path = tmp.join("material.json");
        kapaint_core::atomic::write_atomic(&path, &json).map_err(|e| io(&path, e))?;
        Ok(manifest)
    })
}

/// A KTX2 file's components, its levels past 0 as decoded, and how its colour is stored.
struct Mips {
    comps: Vec<Comp>,
    levels: Vec<Vec<u8>>,
    srgb: bool,
    half: bool,
}

/// The `k_a` error of every mip level past 0 of a KTX2 set (`mips`: per file, its
/// components and levels 1 and on as decoded), against the exact level 0 averaged over each
/// texel's footprint.
fn level_errors(
    texels: &[kapaint_core::model::texel::Texel],
    size: (u32, u32),
    shape: measure::Shape<'_>,
    mips: &[Mips],
    model: reflectance::ShadingModel,
    approx: reflectance::AmbientApprox,
) -> Vec<KaError> {
    let reference = measure::reference_levels(texels, size, model, approx);
    reference
        .iter()
        .enumerate()
        .map(|(l, want)| {
            let stored: Vec<StoredImage> = mips
                .iter()
                .filter_map(|m| {
                    Some(StoredImage {
                        comps: m.comps.clone(),
                        data: m.levels.get(l)?[..].into(),
                        srgb: m.srgb,
                        half: m.half,
                    })
                })
                .collect();
            measure::ka_error_of_level(shape, &stored, want, model, approx)
        })
        .collect()
}

/// The document's texels, row-major; outside the mesh's UV islands they copy the nearest
/// island's, so mips and filtering do not pull the background into the edges (`true` when
/// that was done: the document has a surface with UVs).
pub(crate) fn padded_texels(doc: &Document) -> (Vec<kapaint_core::model::texel::Texel>, bool) {
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let mut texels = rows(maps);
    let dilated = doc.surface().is_some_and(|surface| {
        let mut filled: Vec<bool> = (0..surface.bake.len())
            .map(|i| surface.bake.coverage(i) == Coverage::Surface)
            .collect();
        let any = filled.iter().any(|f| *f);
        if any {
            kapaint_core::mesh::bake::dilate_grid(&mut filled, w, h, u32::MAX, |k, src| {
                texels[k] = texels[src];
            });
        }
        any
    });
    (texels, dilated)
}
