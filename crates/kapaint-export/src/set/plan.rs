//! Planning a set before anything is encoded: which images, with which components, what
//! stays a constant, `n`'s encoding and what it costs (the export dialog's preview).

use rayon::prelude::*;

use super::manifest::{Comp, Constants, MemoryReport};
use super::role::{Images, Role};
use crate::encoding::{KaError, NEncoding, rank_encodings};
use crate::preset::{ExportPreset, Format, Layout};
use kapaint_model::texel::{decode_n, decode_unorm};
use kapaint_model::tile::Plane;
use kapaint_model::{Document, MaterialMaps};

/// Whether `k_s` is grey everywhere.
fn ks_monochrome(maps: &MaterialMaps) -> bool {
    (0..maps.tile_count())
        .into_par_iter()
        .all(|id| match &maps.tile(id).ks {
            Plane::Uniform(v) => v[0] == v[1] && v[1] == v[2],
            Plane::Data(d) => d.iter().all(|v| v[0] == v[1] && v[1] == v[2]),
        })
}

/// Which images a set holds, with which components: what is constant is left out, `k_s` is
/// one channel when grey, and the packed layout puts `n` in `k_d`'s alpha.
fn plan_images(preset: &ExportPreset, constants: &Constants, mono_ks: bool) -> Images {
    let kd: Vec<Comp> = (0..3).map(Comp::Kd).collect();
    let ks: Vec<Comp> = if mono_ks {
        vec![Comp::Ks(0)]
    } else {
        (0..3).map(Comp::Ks).collect()
    };
    let (with_kd, with_n) = (constants.kd.is_none(), constants.n.is_none());
    let mut images: Images = Vec::new();
    let with_ks = constants.ks.is_none();
    if preset.layout == Layout::Packed && with_kd && with_n {
        images.push((Role::KdN, [kd, vec![Comp::N]].concat()));
    } else if preset.layout == Layout::Packed && with_n && with_ks && mono_ks {
        // k_d constant: grey k_s and n share a two-component image.
        images.push((Role::KsN, vec![Comp::Ks(0), Comp::N]));
        if preset.include_ka {
            images.push((Role::Ka, (0..3).map(Comp::Ka).collect()));
        }
        return images;
    } else {
        if with_kd {
            images.push((Role::Kd, kd));
        }
        if with_n {
            images.push((Role::N, vec![Comp::N]));
        }
    }
    if constants.ks.is_none() {
        images.push((Role::Ks, ks));
    }
    if preset.include_ka {
        images.push((Role::Ka, (0..3).map(Comp::Ka).collect()));
    }
    images
}

/// One file a set will hold, as planned before anything is encoded.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedFile {
    /// File name.
    pub path: String,
    /// Components in channel order (`kd.r`, `n`, `ks`, ...).
    pub layout: Vec<String>,
    /// Bytes of the image uncompressed, at the preset's depth (the file is smaller when the
    /// format compresses).
    pub raw_bytes: u64,
}

/// What exporting a document with a preset will write, and the `k_a` error that `n`'s
/// quantisation alone will cost: the export dialog's preview, computed without encoding.
#[derive(Clone, Debug, PartialEq)]
pub struct SetPlan {
    /// The images, in the order they are written.
    pub files: Vec<PlannedFile>,
    /// Channels that become constants in the manifest instead of images.
    pub constants: Constants,
    /// `n`'s curve, range and bits, when `n` is stored in an integer image.
    pub n_encoding: Option<NEncoding>,
    /// The relative `k_a` error of that quantisation (block compression adds to it).
    pub ka_error: KaError,
    /// Bytes: the images uncompressed, the naive maps, the project's maps.
    pub bytes: MemoryReport,
    /// The project's normal map, written beside the maps, when it has one.
    pub normal: Option<PlannedNormal>,
    /// A PBR layout with an occlusion channel: where it will come from, in words.
    pub occlusion: Option<String>,
}

/// The normal map a set will hold: its file, its size, and how it is stored.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedNormal {
    /// File name (`normal.png`, or `normal.ktx2` in KTX2 sets).
    pub path: &'static str,
    /// Size in texels (the normal map's own).
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// How it is stored, in words ("x and y as BC5, z rebuilt by the consumer").
    pub storage: String,
}

/// The plan of exporting `doc` with `preset` (see [`SetPlan`]).
pub fn plan(doc: &Document, preset: &ExportPreset) -> SetPlan {
    let (mut plan, _, _) = plan_set(doc, preset);
    if preset.format.is_pbr() {
        // A PBR layout lists the normal map among its files.
        return plan;
    }
    let storage = super::NormalStorage::of(preset);
    plan.normal = doc.normal().map(|n| PlannedNormal {
        path: storage.file(),
        width: n.width(),
        height: n.height(),
        storage: storage.describe(),
    });
    plan
}

/// [`plan`], with the two facts the writer needs besides: whether `k_s` is grey, and the
/// planned images' components.
pub(super) fn plan_set(doc: &Document, preset: &ExportPreset) -> (SetPlan, bool, Images) {
    let maps = doc.maps();
    if preset.format.is_pbr() {
        return (pbr_plan(doc, preset), false, Vec::new());
    }
    let (model, approx) = (doc.settings().model, doc.settings().approx);
    let (kd, ks, n) = maps.uniform_channels();
    let constants = Constants {
        kd: kd.map(|v| v.map(decode_unorm)),
        ks: ks.map(|v| v.map(decode_unorm)),
        n: n.map(decode_n),
    };
    let mono_ks = ks_monochrome(maps);
    let (n_encoding, ka_error) = match (constants.n, preset.format) {
        (Some(_), _) | (None, Format::Exr) => (None, KaError::default()),
        (None, _) => rank_encodings(maps, model, approx, preset.n_bits)
            .first()
            .map_or((None, KaError::default()), |(e, err)| (Some(*e), *err)),
    };
    let images = plan_images(preset, &constants, mono_ks);
    let depth = u64::from(preset.format.component_bytes());
    let texels = u64::from(maps.width()) * u64::from(maps.height());
    let ext = preset.format.extension();
    let files: Vec<PlannedFile> = images
        .iter()
        .map(|(role, comps)| PlannedFile {
            path: role.file(ext),
            layout: comps.iter().map(|c| c.name(mono_ks)).collect(),
            raw_bytes: texels * depth * comps.len() as u64,
        })
        .collect();
    let bytes = MemoryReport {
        exported: files.iter().map(|f| f.raw_bytes).sum(),
        naive: texels * 10 * depth,
        project: texels * 14,
    };
    (
        SetPlan {
            normal: None,
            occlusion: None,
            files,
            constants,
            n_encoding,
            ka_error,
            bytes,
        },
        mono_ks,
        images,
    )
}

/// A PBR set's plan: the preset's files (the normal map's where the project has one), 8-bit
/// channels each.
fn pbr_plan(doc: &Document, preset: &ExportPreset) -> SetPlan {
    let maps = doc.maps();
    let texels = u64::from(maps.width()) * u64::from(maps.height());
    let files: Vec<PlannedFile> = preset
        .pbr_files()
        .into_iter()
        .filter_map(|f| {
            let size = if f.is_normal() {
                doc.normal()
                    .map(|n| u64::from(n.width()) * u64::from(n.height()))?
            } else {
                texels
            };
            Some(PlannedFile {
                path: f.file.clone(),
                layout: f.layout(),
                raw_bytes: size * f.channels.len() as u64,
            })
        })
        .collect();
    let occlusion = preset
        .pbr_files()
        .iter()
        .any(|f| f.channels.contains(&crate::preset::Channel::Occlusion))
        .then(|| crate::pbr_files::occlusion_source(doc).1.note);
    SetPlan {
        normal: None,
        occlusion,
        bytes: MemoryReport {
            exported: files.iter().map(|f| f.raw_bytes).sum(),
            naive: texels * 10,
            project: texels * 14,
        },
        files,
        constants: Constants {
            kd: None,
            ks: None,
            n: None,
        },
        n_encoding: None,
        ka_error: KaError::default(),
    }
}

pub use crate::preset::textures::{BASE_COLOR_FILE, METALLIC_ROUGHNESS_FILE};
