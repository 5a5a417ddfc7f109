//! Mesh jobs: a mesh imported (and the question when its UVs cannot be painted as they are),
//! unwrapped on request, or baked, each on a worker; and what the editor does when one ends.

use std::path::PathBuf;
use std::sync::Arc;

use super::jobs::UnwrapPrompt;
use super::{EditorState, notice};
use kapaint_base::task::Progress;
use kapaint_mesh::unwrap;
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

/// A map baked from the mesh, what it holds and how many seconds it took.
pub(super) type Baked = (
    Arc<kapaint_mesh::bakes::Baked>,
    kapaint_mesh::bakes::BakeStats,
    f64,
);

/// Fraction of a mesh's texels claimed twice above which the editor offers to unwrap it.
const OVERLAP_OFFER: f64 = 0.01;

impl EditorState {
    /// A mesh import's outcome: the mesh baked, or the question whether to unwrap it.
    fn mesh_done(&mut self, mesh: MeshImport) {
        match mesh {
            MeshImport::Baked(path, surface, textured) => {
                self.mesh_baked((path, surface, textured));
            }
            MeshImport::NeedsUnwrap(prompt) => self.prompts.unwrap = Some(prompt),
        }
    }

    /// A mesh loaded and baked at the map size: the project's mesh now, and the question
    /// about its material when its file has a textured one.
    fn mesh_baked(&mut self, (path, surface, textured): (PathBuf, Arc<Surface>, bool)) {
        if textured {
            self.prompts.material = Some(path.clone());
        }
        let mesh = MeshRef::from_spec(&path.display().to_string());
        let attached = kapaint_model::document::AttachedMesh { mesh, surface };
        match self.doc.apply(ImportCommand::SetMesh(attached)) {
            Ok(()) => {
                self.follow_mesh();
                self.notices
                    .push(notice(format!("mesh {}", path.display()), false));
            }
            Err(e) => self.notices.push(notice(e.to_string(), true)),
        }
    }

    /// Maps baked from the mesh (one, or "Bake all"'s), what each holds and how many seconds
    /// it took: into the document.
    pub(super) fn baked(&mut self, baked: Vec<Baked>) {
        let lines: Vec<String> = baked
            .iter()
            .map(|(b, stats, seconds)| {
                format!(
                    "baked {}: {} texels, mean {:.3}, min {:.3}, {seconds:.1} s",
                    b.map.name(),
                    stats.texels,
                    stats.mean,
                    stats.min
                )
            })
            .collect();
        let bakes = baked
            .into_iter()
            .map(|(b, _, _)| kapaint_model::document::AttachedBake(b))
            .collect();
        match self.doc.apply(ImportCommand::SetBakes(bakes)) {
            Ok(()) => {
                for line in lines {
                    self.notices.push(notice(line, false));
                }
                self.baked_on_demand();
            }
            Err(e) => {
                self.bake_failed();
                self.notices.push(notice(e.to_string(), true));
            }
        }
    }

    /// A mesh unwrapped and baked at the map size: the project keeps it.
    fn unwrapped(&mut self, (path, surface, summary): (PathBuf, Arc<Surface>, String)) {
        let attached = kapaint_model::document::AttachedMesh {
            mesh: MeshRef::Embedded(surface.mesh.name.clone()),
            surface,
        };
        match self.doc.apply(ImportCommand::SetMesh(attached)) {
            Ok(()) => {
                self.follow_mesh();
                self.notices.push(notice(summary, false));
            }
            Err(e) => self
                .notices
                .push(notice(format!("{}: {e}", path.display()), true)),
        }
    }

    /// Loads and bakes a mesh on a worker; it becomes the project's mesh. A mesh without UVs,
    /// or whose UVs overlap, comes back as a question: unwrap it, keep its UVs, or cancel.
    pub fn import_mesh(&mut self, path: PathBuf) {
        let (w, h) = (self.doc.maps().width(), self.doc.maps().height());
        self.start_job("Mesh", move |progress| {
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
                        "has UVs that overlap: {:.0} % of its texels are shared by two places                          of the surface, so painting one paints the other",
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
            let (path, surface, textured) = Self::bake_mesh(path, mesh, (w, h), progress)?;
            Ok(MeshImport::Baked(path, surface, textured))
        }, Self::mesh_done);
    }

    /// Mesh > Unwrap automatically: asks, for the project's mesh, whether to replace its UVs
    /// with a new atlas.
    pub fn ask_unwrap(&mut self) {
        let Some(surface) = self.doc.surface() else {
            self.notices
                .push(notice("there is no mesh to unwrap", true));
            return;
        };
        let mesh = Arc::new(surface.mesh.clone());
        let why = if mesh.uvs.is_some() {
            "is painted on its own UVs: a new atlas replaces them, and what is painted stays \
             where it is on the map, so it no longer sits on the same places of the surface"
        } else {
            "has no UVs"
        };
        self.prompts.unwrap = Some(UnwrapPrompt {
            path: PathBuf::from(self.doc.settings().mesh.spec()),
            mesh,
            why: why.to_string(),
            has_uvs: false,
        });
    }

    /// Bakes a mesh whose UVs are kept as they are (the answer "Keep its UVs").
    pub(super) fn keep_mesh_uvs(&mut self, prompt: UnwrapPrompt) {
        let (w, h) = (self.doc.maps().width(), self.doc.maps().height());
        self.start_job(
            "Mesh",
            move |progress| Self::bake_mesh(prompt.path, (*prompt.mesh).clone(), (w, h), progress),
            Self::mesh_baked,
        );
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

    /// Unwraps a mesh on a worker (progress and Cancel in the status bar) and bakes it; the
    /// project keeps the unwrapped mesh (the answer "Unwrap automatically").
    pub(super) fn unwrap_mesh(&mut self, prompt: UnwrapPrompt) {
        let (w, h) = (self.doc.maps().width(), self.doc.maps().height());
        self.start_job(
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
            Self::unwrapped,
        );
    }
}
