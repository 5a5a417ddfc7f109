//! Writing and reading texture sets: images plus `material.json`.
//!
//! A set is written into a temporary folder beside the target and renamed into place at the
//! end, so a half-written set is never left where the target should be.

mod budget;
mod choice;
mod choose;
mod encode;
mod failure;
mod import;
pub(crate) mod manifest;
mod measure;
mod normal;
pub mod perceptual;
mod plan;
mod role;
mod target;
mod trial;

use std::path::{Path, PathBuf};

use glam::Vec3;
use rayon::prelude::*;

pub use self::choice::{BlockChoice, BlockLayout, Trial};
use self::encode::{Encoded, StoredImage, encode_image, rows};
use self::failure::Failure;
pub use self::import::import;
pub use self::manifest::{
    Approximation, ColourSpace, Compression, Constants, FileEntry, MANIFEST_FORMAT,
    MANIFEST_VERSION, Manifest, MemoryReport, Supercompression,
};
use self::manifest::{Comp, approximation};
use self::measure::ka_error_of_set;
pub use self::normal::{
    AngularError, NORMAL_FILE, NORMAL_KTX2_FILE, NORMAL_XY_ENCODING, NORMAL_Z, NormalFile,
    NormalStorage,
};
use self::plan::plan_set;

pub use self::plan::{
    BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE, PlannedFile, PlannedNormal, SetPlan, plan,
};
pub use self::target::{PBR_MANIFEST_FORMAT, SetKind, Target, holds, target};
pub(crate) use self::target::{claim, commit};
use super::encoding::KaError;
use super::preset::{ExportPreset, Format};
use kapaint_base::task::Progress;
use kapaint_mesh::bake::Coverage;
use kapaint_model::Document;
use kapaint_reflectance as reflectance;
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

/// The export, stage after stage: plan (what each file holds, the texels and their `k_a`),
/// choose and encode (`choose.rs` for block-compressed sets, `encode.rs`), write the images,
/// measure the set as a consumer decodes it (`measure.rs`), write the manifest and snippets.
/// No stage calls back into one before it.
pub(super) fn export_into(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
    replace: bool,
    brought: Option<&dyn crate::blocks::BlockEncoder>,
) -> Result<Manifest, SetError> {
    progress.start("analyse", 1);
    let found = claim(out, replace, SetKind::Material)?;
    if preset.format.is_pbr() {
        return Err(SetError::Invalid {
            path: out.to_path_buf(),
            reason: "a PBR set is written by the PBR writer".into(),
        });
    }
    let source = Source::plan(doc, preset);
    progress.check().map_err(|_| SetError::Cancelled)?;
    progress.start(
        "encode",
        source.images.len() as u64 * u64::from(source.size.1),
    );
    commit(out, &found, |tmp| {
        let (encoded, blocks) = source.encode(preset, progress, brought, tmp)?;
        progress.start("measure", 1);
        let written = write_images(&source, preset, tmp, encoded)?;
        let mut manifest = source.manifest(preset, written.files, blocks);
        source.measure(&mut manifest, &written.stored, &written.mips, preset);
        write_manifest(
            &mut manifest,
            doc,
            (NormalStorage::of(preset), preset.zstd),
            tmp,
        )?;
        Ok(manifest)
    })
}

/// What the plan stage hands on: the document's maps as the set will hold them.
struct Source<'d> {
    doc: &'d Document,
    model: reflectance::ShadingModel,
    approx: reflectance::AmbientApprox,
    size: (u32, u32),
    planned: SetPlan,
    mono_ks: bool,
    images: role::Images,
    /// Row-major, padded past the UV islands ([`padded_texels`]).
    texels: Vec<kapaint_model::texel::Texel>,
    dilated: bool,
    /// Per texel, where the preset writes `k_a`.
    ka: Vec<Vec3>,
}

impl<'d> Source<'d> {
    /// The plan stage.
    fn plan(doc: &'d Document, preset: &ExportPreset) -> Self {
        let maps = doc.maps();
        let (model, approx) = (doc.settings().model, doc.settings().approx);
        let (planned, mono_ks, images) = plan_set(doc, preset);
        let (texels, _, dilated) = padded_texels(doc, None);
        let ka = if preset.include_ka {
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
        Self {
            doc,
            model,
            approx,
            size: (maps.width(), maps.height()),
            planned,
            mono_ks,
            images,
            texels,
            dilated,
            ka,
        }
    }

    fn shape(&self) -> measure::Shape<'_> {
        measure::Shape {
            width: self.size.0,
            constants: &self.planned.constants,
            n_encoding: self.planned.n_encoding,
        }
    }

    /// The choose and encode stages: the images' bytes, and for block-compressed sets the
    /// layout chosen by measurement.
    fn encode(
        &self,
        preset: &ExportPreset,
        progress: &Progress,
        brought: Option<&dyn crate::blocks::BlockEncoder>,
        tmp: &Path,
    ) -> Result<(Vec<Encoded>, Option<Box<BlockChoice>>), SetError> {
        let fail = |e: Failure, file: &str| match e {
            Failure::Cancelled => SetError::Cancelled,
            Failure::Failed(e) => io(&tmp.join(file), e),
        };
        let n_enc = self.planned.n_encoding;
        if preset.format.is_blocks() {
            let job = choose::Job {
                texels: &self.texels,
                ka: &self.ka,
                size: self.size,
                preset,
                n_enc,
                shape: self.shape(),
                model: self.model,
                approx: self.approx,
                brought,
            };
            let apart = choose::n_apart(&self.images, self.mono_ks);
            let (encoded, choice) =
                choose::encode_blocks(&job, &self.images, apart.as_ref(), progress)
                    .map_err(|e| fail(e, "material.json"))?;
            return Ok((encoded, Some(Box::new(choice))));
        }
        let ext = preset.format.extension();
        let encoded = self
            .images
            .par_iter()
            .map(|(role, comps)| {
                let file = role.file(ext);
                progress.check().map_err(|_| SetError::Cancelled)?;
                let image = encode_image(
                    &self.texels,
                    &self.ka,
                    self.size,
                    comps,
                    preset,
                    n_enc,
                    progress,
                )
                .map_err(|e| fail(e, &file))?;
                progress.check().map_err(|_| SetError::Cancelled)?;
                Ok((file, comps.clone(), image))
            })
            .collect::<Result<Vec<_>, SetError>>()?;
        Ok((encoded, None))
    }

    /// The manifest of the written `files`, its measures still to come.
    fn manifest(
        &self,
        preset: &ExportPreset,
        files: Vec<FileEntry>,
        blocks: Option<Box<BlockChoice>>,
    ) -> Manifest {
        let depth = u64::from(preset.format.component_bytes());
        let (w, h) = self.size;
        let texel_count = u64::from(w) * u64::from(h);
        Manifest {
            format: MANIFEST_FORMAT.into(),
            version: MANIFEST_VERSION,
            width: w,
            height: h,
            model: self.model,
            approximation: approximation(self.approx, self.model),
            constants: self.planned.constants,
            n_encoding: self.planned.n_encoding,
            files,
            ka_error: KaError::default(),
            ka_error_srgb: None,
            dilated: self.dilated,
            bytes: MemoryReport {
                exported: 0,
                naive: texel_count * 10 * depth,
                project: texel_count * 14,
            },
            preset: preset.name.clone(),
            layers: u32::try_from(self.doc.stack().walk().len()).unwrap_or(u32::MAX),
            level_ka_error: Vec::new(),
            level_ka_error_srgb: Vec::new(),
            blocks,
            normal: None,
        }
    }

    /// The measure stage: the `k_a` error of the set as a consumer decodes it, of level 0 and
    /// (KTX2) of every mip level.
    fn measure(
        &self,
        manifest: &mut Manifest,
        stored: &[StoredImage<'_>],
        mips: &[Mips],
        preset: &ExportPreset,
    ) {
        let (model, approx) = (self.model, self.approx);
        let (relative, srgb) = ka_error_of_set(
            &self.texels,
            self.shape(),
            stored,
            preset.format,
            model,
            approx,
        );
        manifest.ka_error = relative;
        manifest.ka_error_srgb = Some(srgb);
        if preset.format.is_ktx2() {
            let levels = level_errors(&self.texels, self.size, self.shape(), mips, model, approx);
            manifest.level_ka_error = std::iter::once(relative)
                .chain(levels.iter().map(|l| l.0))
                .collect();
            manifest.level_ka_error_srgb = std::iter::once(srgb)
                .chain(levels.iter().map(|l| l.1))
                .collect();
        }
    }
}

/// What writing the images leaves for the manifest and the measures.
struct Written {
    files: Vec<FileEntry>,
    stored: Vec<StoredImage<'static>>,
    mips: Vec<Mips>,
}

/// Writes the encoded images into `tmp`: their manifest entries, what a consumer decodes of
/// level 0, and the KTX2 files' decoded mip levels.
fn write_images(
    source: &Source<'_>,
    preset: &ExportPreset,
    tmp: &Path,
    encoded: Vec<Encoded>,
) -> Result<Written, SetError> {
    let mut written = Written {
        files: Vec::new(),
        stored: Vec::new(),
        mips: Vec::new(),
    };
    for (file, comps, mut image) in encoded {
        if let Some(k) = image.ktx.as_mut() {
            written.mips.push(Mips {
                comps: comps.clone(),
                levels: std::mem::take(&mut k.mips),
                srgb: image.srgb,
                half: image.half,
            });
        }
        let path = tmp.join(&file);
        let supercompression = match (preset.zstd, &image.ktx) {
            (Some(level), Some(k)) if !k.compression.has_own_supercompression() => {
                let (bytes, said) = supercompressed(&image.bytes, level, &path)?;
                image.bytes = bytes;
                Some(said)
            }
            _ => None,
        };
        kapaint_base::atomic::write_atomic(&path, &image.bytes).map_err(|e| io(&path, e))?;
        let mut entry = file_entry(source, preset, file, &comps, &image);
        entry.supercompression = supercompression;
        written.files.push(entry);
        if let Some(data) = image.stored {
            written.stored.push(StoredImage {
                comps,
                data: data.into(),
                srgb: image.srgb,
                half: image.half,
            });
        }
    }
    Ok(written)
}

/// A KTX2 file's bytes (to be written at `path`) with every level supercompressed at zstd
/// `level`, and what the manifest says of it.
fn supercompressed(
    bytes: &[u8],
    level: u8,
    path: &Path,
) -> Result<(Vec<u8>, manifest::Supercompression), SetError> {
    let packed = crate::ktx::supercompress(bytes, level).map_err(|e| io(path, e))?;
    Ok((
        packed,
        manifest::Supercompression {
            scheme: manifest::Supercompression::ZSTD.into(),
            level,
            uncompressed_bytes: bytes.len() as u64,
        },
    ))
}

/// An image's manifest entry.
fn file_entry(
    source: &Source<'_>,
    preset: &ExportPreset,
    file: String,
    comps: &[Comp],
    image: &encode::EncodedImage,
) -> FileEntry {
    let (mip_levels, psnr, compression) = match &image.ktx {
        Some(k) => (Some(k.levels), k.psnr.clone(), k.compression),
        None if matches!(preset.format, Format::Exr) => (None, None, Compression::Exr),
        None => (None, None, Compression::Png),
    };
    FileEntry {
        path: file,
        layout: comps.iter().map(|c| c.name(source.mono_ks)).collect(),
        colour_space: if image.srgb {
            ColourSpace::Srgb
        } else {
            ColourSpace::Linear
        },
        bit_depth: if image.half {
            16
        } else {
            u32::from(preset.format.component_bytes()) * 8
        },
        compression,
        width: source.size.0,
        height: source.size.1,
        bytes: image.bytes.len() as u64,
        mip_levels,
        psnr,
        astc_block: preset
            .format
            .astc_block()
            .filter(|_| compression == Compression::Ktx2Astc),
        supercompression: None,
    }
}

/// The write stage's last files: the normal map (as `normal` says), the decode + `k_a`
/// snippets for engines (WGSL and GLSL), and `material.json`, which counts every byte
/// written, itself included.
fn write_manifest(
    manifest: &mut Manifest,
    doc: &Document,
    (normal, zstd): (NormalStorage, Option<u8>),
    tmp: &Path,
) -> Result<(), SetError> {
    let mut exported = manifest.files.iter().map(|f| f.bytes).sum::<u64>();
    if let Some(map) = doc.normal() {
        let file = NormalFile::write(map, tmp, normal, zstd)?;
        exported += file.bytes;
        manifest.normal = Some(Box::new(file));
    }
    for (name, snippet) in [
        ("material.wgsl", crate::snippet::wgsl(manifest)),
        ("material.glsl", crate::snippet::glsl(manifest)),
    ] {
        let snippet_path = tmp.join(name);
        kapaint_base::atomic::write_atomic(&snippet_path, snippet.as_bytes())
            .map_err(|e| io(&snippet_path, e))?;
        exported += snippet.len() as u64;
    }
    // The manifest counts itself, and its length depends on the count's digits: repeat
    // until they agree (the count only grows, so this ends, in two or three rounds).
    let json = loop {
        let json = serde_json::to_vec_pretty(&*manifest).map_err(|e| io(tmp, e))?;
        let total = exported + json.len() as u64;
        if manifest.bytes.exported == total {
            break json;
        }
        manifest.bytes.exported = total;
    };
    let path = tmp.join("material.json");
    kapaint_base::atomic::write_atomic(&path, &json).map_err(|e| io(&path, e))
}

/// A KTX2 file's components, its levels past 0 as decoded, and how its colour is stored.
struct Mips {
    comps: Vec<Comp>,
    levels: Vec<Vec<u8>>,
    srgb: bool,
    half: bool,
}

/// The `k_a` error (relative, and in sRGB levels) of every mip level past 0 of a KTX2 set
/// (`mips`: per file, its components and levels 1 and on as decoded), against the exact level
/// 0 averaged over each texel's footprint.
fn level_errors(
    texels: &[kapaint_model::texel::Texel],
    size: (u32, u32),
    shape: measure::Shape<'_>,
    mips: &[Mips],
    model: reflectance::ShadingModel,
    approx: reflectance::AmbientApprox,
) -> Vec<(KaError, perceptual::SrgbError)> {
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

/// The document's texels, row-major, and `plane` (a grey image of the same size, where
/// given); outside the mesh's UV islands both copy the nearest island's, so mips and
/// filtering do not pull the background into the edges (`true` when that was done: the
/// document has a surface with UVs).
pub(crate) fn padded_texels(
    doc: &Document,
    mut plane: Option<Vec<u8>>,
) -> (Vec<kapaint_model::texel::Texel>, Option<Vec<u8>>, bool) {
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let mut texels = rows(maps);
    let dilated = doc.surface().is_some_and(|surface| {
        let mut filled: Vec<bool> = (0..surface.bake.len())
            .map(|i| surface.bake.coverage(i) == Coverage::Surface)
            .collect();
        let any = filled.iter().any(|f| *f);
        if any {
            kapaint_mesh::bake::dilate_grid(&mut filled, w, h, u32::MAX, |k, src| {
                texels[k] = texels[src];
                if let Some(p) = plane.as_mut() {
                    p[k] = p[src];
                }
            });
        }
        any
    });
    (texels, plane, dilated)
}
