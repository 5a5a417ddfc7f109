//! The `.kapaint` project file.
//!
//! A zip archive holding `manifest.json` (format name, version, size, document settings, and
//! how each channel is stored) and one 16-bit lossless PNG per channel that is not uniform:
//! `kd.png` and `ks.png` as linear unorm16 RGB, `n.png` as 16-bit gray holding half-float
//! bits. A channel that is the same everywhere is a constant in the manifest instead.
//!
//! Saving writes a temporary file beside the target, flushes it to disk and renames it over
//! the target, so a crash or a full disk never leaves a half-written project. Loading checks
//! everything (zip and PNG checksums, sizes, colour types, every stored value) and reports
//! the first problem as one error; it never panics on any input.

mod bakes;
mod images;
pub use bakes::to_png as bake_png;
pub mod layers;
pub mod lock;
mod read;
mod write;

pub use lock::{OnDisk, ProjectLock, save_checked};
pub use read::from_reader;
pub use write::{to_bytes, write_to};

use std::fs::File;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::ModelError;
use super::document::{Document, DocumentSettings, MeshRef};
use super::maps::MAX_SIDE;
use super::texel::N_MAX;
use write::write_project;

/// The format name in the manifest.
pub const FORMAT: &str = "kapaint-project";

/// The newest manifest version this build writes: 6 for a project that keeps a map baked
/// from a high mesh, 5 for one with a projection fill, 4 for one with a generator mask, 3 for
/// one that keeps its mesh inside itself, else 2, which every build since layers reads. It
/// reads 1 to 6.
pub const VERSION: u32 = 6;

/// The version that first held projection fills.
const PROJECTION_VERSION: u32 = 5;

/// The version that first held generator masks.
const GENERATOR_VERSION: u32 = 4;

/// The version that first kept a mesh and bakes.
const MESH_VERSION: u32 = 3;

/// The version of a project that keeps nothing version 3 added.
const LAYERS_VERSION: u32 = 2;

/// Largest manifest accepted (bytes).
const MAX_MANIFEST_BYTES: u64 = 4 << 20;

/// How one channel is stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[serde(deny_unknown_fields)]
pub enum ChannelEntry {
    /// The same stored value at every texel (unorm16 RGB, or half-float bits for `n`).
    Uniform {
        /// The stored value: three components for `kd`/`ks`, one for `n`.
        value: Vec<u16>,
    },
    /// A PNG in the archive.
    Image {
        /// Entry name in the archive.
        file: String,
        /// How the PNG's samples are to be read.
        encoding: String,
    },
}

/// `manifest.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Manifest version.
    pub version: u32,
    /// Map width in texels.
    pub width: u32,
    /// Map height in texels.
    pub height: u32,
    /// Model, approximation, materials, brush, mesh reference.
    pub settings: DocumentSettings,
    /// `k_d` storage.
    pub kd: ChannelEntry,
    /// `k_s` storage.
    pub ks: ChannelEntry,
    /// `n` storage.
    pub n: ChannelEntry,
    /// The base material under the layers (version 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<super::texel::MaterialValue>,
    /// The layer stack, bottom first (version 2); `kd`, `ks` and `n` then hold its composite
    /// for readers that do not composite.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Vec<layers::LayerEntry>>,
    /// The tangent-space normal map, when the material has one (an 8-bit RGB PNG at its own
    /// size).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<NormalEntry>,
    /// The document's identity (32 hex digits), which its recovery journals carry too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// The layer selected when it was saved (version 2): the editor opens on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<SelectionEntry>,
    /// The mesh the project keeps inside itself (version 3), as an OBJ file in the archive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshEntry>,
    /// Maps baked from the mesh (version 3), each a 16-bit PNG in the archive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bakes: Option<Vec<BakeEntry>>,
}

/// Where a project keeps a map baked from its mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BakeEntry {
    /// Which map: `ao`, `curvature`, `thickness`, `position`, `normal`.
    pub map: String,
    /// Entry name in the archive (`bake_MAP.png`): 16-bit grey, or RGB for position and
    /// normal.
    pub file: String,
    /// The hash of the mesh it was baked from (16 hex digits).
    pub mesh_hash: String,
    /// Rays per texel.
    pub rays: u32,
    /// How far its rays looked, if bounded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_distance: Option<f32>,
    /// Where it came from when it was baked from a high mesh (version 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub high: Option<HighEntry>,
}

/// A bake's high mesh, as [`BakeEntry::high`] names it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HighEntry {
    /// The high mesh's name.
    pub mesh: String,
    /// Its hash (16 hex digits).
    pub mesh_hash: String,
    /// The ray distances (object units).
    pub front: f32,
    /// The ray distances (object units).
    pub rear: f32,
    /// Samples per texel (1, 4 or 16).
    pub samples: u32,
    /// The cage's name, if the rays started on one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cage: Option<String>,
}

/// Where a project keeps its mesh.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshEntry {
    /// Entry name in the archive ([`MESH_FILE`]).
    pub file: String,
    /// Its triangles (checked on reading).
    pub triangles: u64,
}

/// The kept mesh's entry in the archive.
pub const MESH_FILE: &str = "mesh.obj";

/// The selected layer as a project stores it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectionEntry {
    /// Indices from the top-level list down into groups.
    #[serde(deserialize_with = "super::check::layer_path")]
    pub path: Vec<usize>,
    /// Tools paint its mask.
    pub mask: bool,
}

impl SelectionEntry {
    /// The entry of a selection.
    pub fn of(selection: &super::layers::Selection) -> Self {
        Self {
            path: selection.path.clone(),
            mask: selection.mask,
        }
    }

    /// The selection it stores.
    pub fn selection(&self) -> super::layers::Selection {
        super::layers::Selection {
            path: self.path.clone(),
            mask: self.mask,
        }
    }
}

/// Where a project keeps its normal map.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalEntry {
    /// Entry name in the archive ([`NORMAL_FILE`]).
    pub file: String,
    /// [`NORMAL_ENCODING`].
    pub encoding: String,
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
}

/// The normal map's entry in the archive.
pub const NORMAL_FILE: &str = "normal.png";
/// How the normal map's PNG is read: 8-bit RGB, `2 c - 1` in the tangent frame.
pub const NORMAL_ENCODING: &str = "png-rgb8-tangent-normal";

const RGB_ENCODING: &str = "png-rgb16-unorm-linear";
const N_ENCODING: &str = "png-gray16-half-float-bits";

/// One channel of the whole map, row-major.
enum Raster {
    Uniform(Vec<u16>),
    Rgb(Vec<u16>),
    Gray(Vec<u16>),
}

/// The settings as a project at `project` stores them: a mesh file's path relative to the
/// project's folder (so a project and its mesh can move together, and commands run from any
/// folder find it), or absolute where no relative path exists.
fn settings_for_file(settings: &DocumentSettings, project: &Path) -> DocumentSettings {
    let mut stored = settings.clone();
    if let MeshRef::File(mesh) = &settings.mesh
        && let (Ok(mesh_abs), Ok(dir_abs)) = (
            std::path::absolute(mesh),
            std::path::absolute(project_dir(project)),
        )
    {
        let relative = relative_path(&dir_abs, &mesh_abs).unwrap_or(mesh_abs);
        stored.mesh = MeshRef::File(relative.to_string_lossy().into_owned());
    }
    stored
}

/// The settings as loaded from a project at `project`: a relative mesh path is taken from the
/// project's folder (projects written before paths were stored that way held paths relative
/// to the folder they were made in: those are tried there too), and held absolute.
pub(super) fn settings_from_file(
    mut settings: DocumentSettings,
    project: &Path,
) -> DocumentSettings {
    if let MeshRef::File(mesh) = &settings.mesh {
        let mesh = Path::new(mesh);
        if mesh.is_relative() {
            let beside = project_dir(project).join(mesh);
            let found = if beside.exists() || !mesh.exists() {
                beside
            } else {
                mesh.to_path_buf()
            };
            let found = std::path::absolute(&found).unwrap_or(found);
            settings.mesh = MeshRef::File(found.to_string_lossy().into_owned());
        }
    }
    settings
}

/// The folder a project is in (`.` for a bare file name).
fn project_dir(project: &Path) -> &Path {
    project
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `target` relative to the folder `base` (both absolute), by their components: `None` when
/// they share no root (another drive).
fn relative_path(base: &Path, target: &Path) -> Option<PathBuf> {
    use std::path::Component;
    fn normal(p: &Path) -> Vec<Component<'_>> {
        let mut out: Vec<Component<'_>> = Vec::new();
        for c in p.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                    out.pop();
                }
                other => out.push(other),
            }
        }
        out
    }
    let (base, target) = (normal(base), normal(target));
    if base.first() != target.first() {
        return None;
    }
    let common = base.iter().zip(&target).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..base.len() {
        out.push("..");
    }
    for c in &target[common..] {
        out.push(c.as_os_str());
    }
    Some(out)
}

/// Saves a document to `path` atomically.
///
/// # Errors
/// [`ModelError::Unsaveable`] (nothing written) when the document holds what a project cannot
/// (the loader's checks, run before a byte is written, say which field); else an I/O error.
pub fn save(doc: &Document, path: &Path) -> Result<(), ModelError> {
    let mut unloadable = None;
    // A serialisation failure (e.g. the disk filling up inside the zip writer) is reported as
    // an I/O error on the file, like any other write failure.
    let written = kapaint_base::atomic::write_atomic_with(path, |file| {
        // The first write error (a full disk) is the one reported; the zip writer then
        // finishes quietly instead of printing its own failure.
        let mut out = kapaint_base::atomic::FirstError::new(file);
        let written = write_project(doc, settings_for_file(doc.settings(), path), &mut out);
        if let Some(e) = out.take_error() {
            return Err(e);
        }
        written.map_err(|e| match e {
            write::WriteFailure::Unloadable(reason) => {
                let e = std::io::Error::other(reason.clone());
                unloadable = Some(reason);
                e
            }
            write::WriteFailure::Other(e) => std::io::Error::other(e),
        })
    });
    match (written, unloadable) {
        (Ok(()), _) => Ok(()),
        (Err(_), Some(reason)) => Err(ModelError::Unsaveable {
            path: path.to_path_buf(),
            reason,
        }),
        (Err(e), None) => Err(ModelError::io(path, e)),
    }
}

/// Loads `mesh` (a built-in name or a mesh file), bakes it at the document's size and
/// attaches it: what strokes on the mesh and island fills paint on.
///
/// # Errors
/// A mesh that does not load (an I/O error as [`ModelError::Io`]), has no UVs, or does not
/// bake; the document is unchanged.
pub fn attach_mesh(doc: &mut Document, mesh: &Path) -> Result<(), ModelError> {
    let loaded = load_mesh(mesh)?;
    attach_loaded(doc, loaded, &mesh.display().to_string())
}

/// Attaches the document's own mesh: the one its project keeps, a built-in one or a file.
///
/// # Errors
/// As [`attach_mesh`]; a kept mesh the document does not hold.
pub fn attach_own_mesh(doc: &mut Document) -> Result<(), ModelError> {
    let mesh = own_mesh(doc)?;
    let name = doc.settings().mesh.spec().to_string();
    attach_loaded(doc, mesh, &name)
}

/// The document's own mesh: the one its project keeps, a built-in one or a file.
///
/// # Errors
/// A mesh file that does not load; a kept mesh the document does not hold.
pub fn own_mesh(doc: &Document) -> Result<kapaint_mesh::Mesh, ModelError> {
    match &doc.settings().mesh {
        MeshRef::Embedded(name) => doc
            .embedded_mesh()
            .map(|m| (**m).clone())
            .ok_or_else(|| ModelError::Command(format!("the kept mesh {name} is missing"))),
        other => load_mesh(Path::new(other.spec())),
    }
}

/// A built-in mesh or a mesh file.
fn load_mesh(mesh: &Path) -> Result<kapaint_mesh::Mesh, ModelError> {
    use kapaint_mesh::MeshError;
    kapaint_mesh::open(mesh).map_err(|e| match e {
        MeshError::Io { path, source } => ModelError::Io { path, source },
        invalid @ MeshError::Invalid { .. } => ModelError::Command(invalid.to_string()),
    })
}

/// Bakes `mesh` at the document's size and attaches it.
fn attach_loaded(
    doc: &mut Document,
    mesh: kapaint_mesh::Mesh,
    name: &str,
) -> Result<(), ModelError> {
    let surface = super::surface::Surface::new(mesh, doc.maps().width(), doc.maps().height())
        .map_err(|e| ModelError::Command(format!("{name}: {e}")))?;
    doc.attach_surface(Some(std::sync::Arc::new(surface)))
}

/// Opens a project with its mesh attached (`mesh` instead of the project's own, when given):
/// the document, and why the mesh could not be attached when it could not (the document
/// then has no surface, and the caller decides: the editor shows the sphere, `export` skips
/// padding, `paint` refuses strokes on the mesh; a document whose generator masks
/// [need the mesh](Document::needs_mesh) has them made on nothing until a mesh is attached).
///
/// # Errors
/// A project that does not load.
pub fn open_with_mesh(
    path: &Path,
    mesh: Option<&Path>,
) -> Result<(Document, Option<ModelError>), ModelError> {
    let mut doc = read_file(path)?.doc;
    let failed = match mesh {
        Some(mesh) => attach_mesh(&mut doc, mesh),
        None => attach_own_mesh(&mut doc),
    }
    .err();
    Ok((doc, failed))
}

/// Largest project file read (bytes): an 8192^2 project of noise is about 1 GB.
pub const MAX_PROJECT_BYTES: u64 = 4 << 30;

/// Loads and validates a project file (a regular file: a FIFO or a device is refused before
/// it is opened). Its composite is made from its layers; where a generator mask needs the
/// mesh, the project's own mesh is attached first.
///
/// # Errors
/// A project that does not load, or whose generator masks need a mesh that does not.
pub fn load(path: &Path) -> Result<Document, ModelError> {
    let read = read_file(path)?;
    let mut doc = read.doc;
    if read.needs_mesh {
        attach_own_mesh(&mut doc).map_err(|e| ModelError::Project {
            path: path.to_path_buf(),
            reason: format!(
                "its generator masks are laid on its mesh {}, which does not load ({e})",
                doc.settings().mesh.spec()
            ),
        })?;
    }
    Ok(doc)
}

/// Reads a project file, its settings' paths taken from its folder; the mesh not attached.
fn read_file(path: &Path) -> Result<read::ReadProject, ModelError> {
    kapaint_base::file_check::regular_file(path, MAX_PROJECT_BYTES).map_err(|e| match e {
        kapaint_base::file_check::FileCheck::Io(source) => ModelError::io(path, source),
        other => ModelError::Project {
            path: path.to_path_buf(),
            reason: format!("the file {other}"),
        },
    })?;
    let file = File::open(path).map_err(|e| ModelError::io(path, e))?;
    let mut read = read::read(file).map_err(|reason| ModelError::Project {
        path: path.to_path_buf(),
        reason,
    })?;
    let settings = settings_from_file(read.doc.settings().clone(), path);
    read.doc = read.doc.with_settings(settings);
    Ok(read)
}

/// The identity of the project at `path` (from its manifest alone), if it is a project that
/// has one.
pub fn read_id(path: &Path) -> Option<super::document::DocumentId> {
    #[derive(Deserialize)]
    struct Id {
        id: Option<String>,
    }
    kapaint_base::file_check::regular_file(path, MAX_PROJECT_BYTES).ok()?;
    let mut zip = zip::ZipArchive::new(File::open(path).ok()?).ok()?;
    let entry = zip.by_name("manifest.json").ok()?;
    let mut text = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(entry, MAX_MANIFEST_BYTES),
        &mut text,
    )
    .ok()?;
    let id: Id = serde_json::from_slice(&text).ok()?;
    super::document::DocumentId::from_hex(&id.id?)
}

/// Whether half-float bits hold a storable exponent: finite, not negative, at most `N_MAX`.
pub(super) fn valid_n_bits(bits: u16) -> bool {
    let v = half::f16::from_bits(bits).to_f32();
    v.is_finite() && (0.0..=N_MAX).contains(&v) && bits & 0x8000 == 0
}

/// Parses `manifest.json` and checks what it says about the project as a whole (format,
/// version, size); every field was checked as it was read.
fn parse_manifest(json: &[u8]) -> Result<Manifest, String> {
    let manifest: Manifest =
        serde_json::from_slice(json).map_err(|e| format!("manifest.json: {e}"))?;
    if manifest.format != FORMAT {
        return Err(format!(
            "manifest format is {:?}, expected {FORMAT:?}",
            manifest.format
        ));
    }
    if manifest.mesh.is_some() && manifest.version < MESH_VERSION {
        return Err(format!(
            "a version {} project keeps no mesh (a kept mesh is version {MESH_VERSION})",
            manifest.version
        ));
    }
    if manifest.bakes.is_some() && manifest.version < MESH_VERSION {
        return Err(format!(
            "a version {} project keeps no bakes (bakes are version {MESH_VERSION})",
            manifest.version
        ));
    }
    if manifest.version < VERSION && manifest.bakes.iter().flatten().any(|b| b.high.is_some()) {
        return Err(format!(
            "a version {} project keeps no bakes from a high mesh (they are version {VERSION})",
            manifest.version
        ));
    }
    match (manifest.version, &manifest.layers) {
        (1, None) => {}
        (2..=VERSION, Some(entries)) => {
            layers::check_shape(entries, 0, &mut 0)?;
            if manifest.version < GENERATOR_VERSION && layers::any_generator(entries) {
                return Err(format!(
                    "a version {} project has no generator masks (they are version {GENERATOR_VERSION})",
                    manifest.version
                ));
            }
            if manifest.version < PROJECTION_VERSION && layers::any_projection(entries) {
                return Err(format!(
                    "a version {} project has no projection fills (they are version {PROJECTION_VERSION})",
                    manifest.version
                ));
            }
        }
        (1..=VERSION, _) => {
            return Err(format!(
                "a version {} project {} layers",
                manifest.version,
                if manifest.version == 1 {
                    "holds no"
                } else {
                    "must list its"
                }
            ));
        }
        (v, _) => {
            return Err(format!(
                "project version {v} is not supported (this build reads versions 1 to {VERSION})"
            ));
        }
    }
    let (w, h) = (manifest.width, manifest.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!("map size {w}x{h} is out of range"));
    }
    Ok(manifest)
}

/// kapaint's state folder: `$XDG_STATE_HOME/kapaint`, else `~/.local/state/kapaint` (else
/// the temporary folder). It may not exist yet: writers create it.
pub fn state_dir() -> PathBuf {
    std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/state")))
        .unwrap_or_else(std::env::temp_dir)
        .join("kapaint")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_paths_are_stored_relative_to_the_project() {
        let rel = |a: &str, b: &str| relative_path(Path::new(a), Path::new(b));
        assert_eq!(
            rel("/w/sub", "/w/barrel.glb"),
            Some(PathBuf::from("../barrel.glb"))
        );
        assert_eq!(rel("/w", "/w/m/x.obj"), Some(PathBuf::from("m/x.obj")));
        assert_eq!(
            rel("/w/a/b", "/w/a/../m.obj"),
            Some(PathBuf::from("../../m.obj"))
        );
        assert_eq!(rel("/w", "/w/./x.obj"), Some(PathBuf::from("x.obj")));
    }
}
