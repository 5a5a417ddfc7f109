//! Mesh jobs: a mesh imported (and the question when its UVs cannot be painted as they are),
//! unwrapped on request, or baked, each on a worker; and what the editor does when one ends.

use std::path::PathBuf;
use std::sync::Arc;

use super::notice;
use crate::desk::{Ask, Desk, JobStart, Prompt};
use crate::results::UnwrapPrompt;
use kapaint_base::task::Progress;
use kapaint_mesh::unwrap;
use kapaint_model::Document;
use kapaint_model::ImportCommand;
use kapaint_model::document::MeshRef;
use kapaint_model::surface::Surface;

/// A mesh import's outcome.
enum MeshImport {
    /// Loaded and baked at the map size, and whether its file has a textured material (the
    /// editor then offers to bring it in).
    Baked(PathBuf, Arc<Surface>, bool),
    /// A mesh that cannot be painted as it is (no UVs) or would paint two places at once
    /// (overlapping UVs): the editor asks whether to unwrap it.
    NeedsUnwrap(UnwrapPrompt),
}

/// Fraction of a mesh's texels claimed twice above which the editor offers to unwrap it.
const OVERLAP_OFFER: f64 = 0.01;

/// A mesh import's outcome: the mesh baked, or the question whether to unwrap it.
fn mesh_done(mesh: MeshImport, desk: &mut Desk) {
    match mesh {
        MeshImport::Baked(path, surface, textured) => mesh_baked((path, surface, textured), desk),
        MeshImport::NeedsUnwrap(prompt) => desk.ask(Ask::Prompt(Prompt::Unwrap(prompt))),
    }
}

/// A mesh loaded and baked at the map size: the project's mesh now, and the question about
/// its material when its file has a textured one.
fn mesh_baked((path, surface, textured): (PathBuf, Arc<Surface>, bool), desk: &mut Desk) {
    if textured {
        desk.ask(Ask::Prompt(Prompt::Material(path.clone())));
    }
    let mesh = MeshRef::from_spec(&path.display().to_string());
    let attached = kapaint_model::document::AttachedMesh { mesh, surface };
    let said = notice(format!("mesh {}", path.display()), false);
    desk.command_saying(ImportCommand::SetMesh(attached), vec![said]);
}

/// A mesh unwrapped and baked at the map size: the project keeps it.
fn unwrapped((_, surface, summary): (PathBuf, Arc<Surface>, String), desk: &mut Desk) {
    let attached = kapaint_model::document::AttachedMesh {
        mesh: MeshRef::Embedded(surface.mesh.name.clone()),
        surface,
    };
    desk.command_saying(
        ImportCommand::SetMesh(attached),
        vec![notice(summary, false)],
    );
}

/// Loads and bakes a mesh on a worker at `doc`'s size; it becomes the project's mesh. A mesh
/// without UVs, or whose UVs overlap, comes back as a question: unwrap it, keep its UVs, or
/// cancel.
pub(super) fn import_mesh(doc: &Document, path: PathBuf) -> JobStart {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    JobStart::new(
        "Mesh",
        move |progress| {
            progress.start("load", 1);
            let mesh = match kapaint_mesh::open(&path) {
                Ok(m) => m,
                Err(e) => return Err(format!("{}: {e}", path.display())),
            };
            progress.start("check UVs", 1);
            let why = if mesh.uvs.is_none() {
                Some("has no UVs, so no texel knows where on the surface it is".to_string())
            } else {
                let overlap = unwrap::uv_overlap(&mesh, w.min(h).min(2048));
                (overlap > OVERLAP_OFFER).then(|| {
                    format!(
                        "has UVs that overlap: {:.0} % of its texels are shared by two places \
                         of the surface, so painting one paints the other",
                        100.0 * overlap
                    )
                })
            };
            if let Some(why) = why {
                return Ok(MeshImport::NeedsUnwrap(UnwrapPrompt {
                    has_uvs: mesh.uvs.is_some(),
                    path,
                    mesh: Arc::new(mesh),
                    why,
                }));
            }
            let (path, surface, textured) = bake_mesh(path, mesh, (w, h), progress)?;
            Ok(MeshImport::Baked(path, surface, textured))
        },
        mesh_done,
    )
}

/// Mesh > Unwrap automatically: asks, for `doc`'s mesh, whether to replace its UVs with a new
/// atlas.
pub(super) fn ask_unwrap(doc: &Document) -> Ask {
    let Some(surface) = doc.surface() else {
        return Ask::Notice(notice("there is no mesh to unwrap", true));
    };
    let mesh = Arc::new(surface.mesh.clone());
    let why = if mesh.uvs.is_some() {
        "is painted on its own UVs: a new atlas replaces them, and what is painted stays where \
         it is on the map, so it no longer sits on the same places of the surface"
    } else {
        "has no UVs"
    };
    Ask::Prompt(Prompt::Unwrap(UnwrapPrompt {
        path: PathBuf::from(doc.settings().mesh.spec()),
        mesh,
        why: why.to_string(),
        has_uvs: false,
    }))
}

/// Bakes a mesh whose UVs are kept as they are (the answer "Keep its UVs").
pub(super) fn keep_mesh_uvs(doc: &Document, prompt: UnwrapPrompt) -> JobStart {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    JobStart::new(
        "Mesh",
        move |progress| bake_mesh(prompt.path, (*prompt.mesh).clone(), (w, h), progress),
        mesh_baked,
    )
}

fn bake_mesh(
    path: PathBuf,
    mesh: kapaint_mesh::Mesh,
    (w, h): (u32, u32),
    progress: &Progress,
) -> Result<(PathBuf, Arc<Surface>, bool), String> {
    progress.start("bake", 1);
    match Surface::new(mesh, w, h) {
        Ok(s) => {
            let textured = kapaint_pbr::gltf::has_textured_material(&path);
            Ok((path, Arc::new(s), textured))
        }
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// Unwraps a mesh on a worker (progress and Cancel in the status bar) and bakes it at
/// `doc`'s size; the project keeps the unwrapped mesh (the answer "Unwrap automatically").
pub(super) fn unwrap_mesh(doc: &Document, prompt: UnwrapPrompt) -> JobStart {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    JobStart::new(
        "Unwrap",
        move |progress| {
            let options = unwrap::UnwrapOptions::for_size(w.min(h).max(64));
            let mut done = match unwrap::unwrap(&prompt.mesh, options, Some(progress)) {
                Ok(done) => done,
                Err(e) => return Err(format!("{}: {e}", prompt.path.display())),
            };
            let summary = format!(
                "{} unwrapped: {} charts, {:.0} % of the map covered",
                prompt.path.display(),
                done.charts,
                100.0 * done.coverage
            );
            let base = done.mesh.name.trim_end_matches(", unwrapped").to_string();
            done.mesh.name = format!("{base}, unwrapped");
            progress.start("bake", 1);
            match Surface::new(done.mesh, w, h) {
                Ok(s) => Ok((prompt.path, Arc::new(s), summary)),
                Err(e) => Err(format!("{}: {e}", prompt.path.display())),
            }
        },
        unwrapped,
    )
}
