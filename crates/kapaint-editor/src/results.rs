//! What the editor's jobs hand back and its questions hold: plain data, made on workers and
//! carried in [`Ask`](crate::desk::Ask)s (so the desk that carries them needs nothing of the
//! modules that make them).

use std::path::PathBuf;
use std::sync::Arc;

use kapaint_model::project;

/// A PBR conversion whose largest relative error passes this is a warning: a quarter of the
/// shading lost somewhere on the material.
pub(crate) const PBR_ERROR_WARNING: f32 = 0.25;

/// A save's outcome: saved at the path (the document version saved, and the file as
/// written), or conflicted.
pub(crate) enum Saved {
    /// Saved at the path: the document version saved, and the file as written.
    Saved(PathBuf, u64, project::OnDisk),
    /// A save that found its project changed on disk (another kapaint saved it): the work went
    /// to `written` instead, as the document version `version`.
    Conflicted {
        /// What happened, for the notice.
        message: String,
        /// Where the work went.
        written: PathBuf,
        /// The document version written there.
        version: u64,
    },
}

/// A mesh whose UVs cannot be painted as they are, and why.
#[derive(Clone)]
pub(crate) struct UnwrapPrompt {
    pub(crate) path: PathBuf,
    pub(crate) mesh: Arc<kapaint_mesh::Mesh>,
    /// What is wrong with its UVs, for the question.
    pub(crate) why: String,
    /// Whether it has UVs of its own to keep.
    pub(crate) has_uvs: bool,
}

/// A material read from its files, before conversion.
pub struct LoadedMaterial {
    /// What the size question calls it: "The texture set Bricks", "cow.glb's material".
    pub(crate) name: String,
    pub(crate) set: kapaint_pbr::import::PbrSet,
    pub(crate) normal: Option<kapaint_model::normal::NormalMap>,
    pub(crate) notes: Vec<String>,
    /// The material is seen from both sides (glTF's `doubleSided`).
    pub(crate) double_sided: bool,
}

/// File > Import PBR material's question while it is open ([`crate::material_size`]): the
/// material, its size, and which answer is the default.
pub struct SizePrompt {
    /// The glTF file or the set's image the import came from.
    pub path: PathBuf,
    pub(crate) loaded: Arc<LoadedMaterial>,
    /// The material's own size (its largest image).
    pub size: (u32, u32),
    /// The project's size when asked.
    pub project: (u32, u32),
    /// Adopting is the default (the project holds no paint yet).
    pub adopt_by_default: bool,
}

/// A glTF material converted on a worker (File > Import PBR material).
pub(crate) struct PbrMaterial {
    pub(crate) maps: kapaint_model::MaterialMaps,
    pub(crate) normal: Option<kapaint_model::normal::NormalMap>,
    pub(crate) report: kapaint_model::provenance::ImportReport,
}

/// A project a worker opened or recovered.
pub(crate) struct OpenedProject {
    /// Where it is saved (`None` for recovered untitled work).
    pub(crate) path: Option<std::path::PathBuf>,
    pub(crate) doc: kapaint_model::Document,
    /// The recovery copy it came from, if it did.
    pub(crate) recovered: Option<std::path::PathBuf>,
    /// A note for the user (its mesh could not be loaded, its recovery failed).
    pub(crate) note: Option<String>,
    /// The project file as it was when read: what a save expects to replace.
    pub(crate) on_disk: Option<kapaint_model::project::OnDisk>,
    /// Opened read-only (another kapaint has it open).
    pub(crate) read_only: bool,
}
