//! Long work on named worker threads (open, save, recover, export, mesh and image import,
//! stamps), each reporting through a [`Progress`], polled every frame; and the documents
//! they make, with their meshes attached.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;

use super::{EditorState, MeshState, notice};
use kapaint_base::task::Progress;
use kapaint_model::texel::Channel;
use kapaint_model::{Document, DocumentSettings, ModelError, project, recovery};
use kapaint_model::{ImportCommand, SettingsCommand};

/// What a finished job does to the editor: made on the worker from the job's own typed
/// result (each job names its result type and the function that takes it), run on the UI
/// thread. A job's failure is its error line.
pub(super) type Finish = Box<dyn FnOnce(&mut EditorState) + Send>;

/// A save's outcome: saved at the path (the document version saved, and the file as
/// written), or conflicted.
pub(super) enum Saved {
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
pub(super) struct UnwrapPrompt {
    pub(super) path: PathBuf,
    pub(super) mesh: Arc<kapaint_mesh::Mesh>,
    /// What is wrong with its UVs, for the question.
    pub(super) why: String,
    /// Whether it has UVs of its own to keep.
    pub(super) has_uvs: bool,
}

/// A material read from its files, before conversion.
pub struct LoadedMaterial {
    /// What the size question calls it: "The texture set Bricks", "cow.glb's material".
    pub(super) name: String,
    pub(super) set: kapaint_pbr::import::PbrSet,
    pub(super) normal: Option<kapaint_model::normal::NormalMap>,
    pub(super) notes: Vec<String>,
    /// The material is seen from both sides (glTF's `doubleSided`).
    pub(super) double_sided: bool,
}

/// File > Import PBR material's question while it is open ([`crate::material_size`]): the
/// material, its size, and which answer is the default.
pub struct SizePrompt {
    /// The glTF file or the set's image the import came from.
    pub path: PathBuf,
    pub(super) loaded: Arc<LoadedMaterial>,
    /// The material's own size (its largest image).
    pub size: (u32, u32),
    /// The project's size when asked.
    pub project: (u32, u32),
    /// Adopting is the default (the project holds no paint yet).
    pub adopt_by_default: bool,
}

/// A glTF material converted on a worker (File > Import PBR material).
pub(super) struct PbrMaterial {
    pub(super) maps: kapaint_model::MaterialMaps,
    pub(super) normal: Option<kapaint_model::normal::NormalMap>,
    pub(super) report: kapaint_model::provenance::ImportReport,
}

/// Long work on a worker thread.
pub(super) struct Job {
    pub(super) label: String,
    /// The project it opens (or the recovery copy it recovers), replacing the document.
    pub(super) opens: Option<PathBuf>,
    /// What a window over the editor says while the job runs: the editor takes no input
    /// until it is done (the document is about to be replaced or resized).
    pub(super) modal: Option<String>,
    pub(super) progress: Arc<Progress>,
    pub(super) handle: JoinHandle<Finish>,
}

/// A new `size`^2 document on the default settings, with its mesh.
pub(super) fn new_document(size: u32) -> Result<(Document, MeshState), String> {
    let doc = new_document_with((size, size), DocumentSettings::default())?;
    let mesh = doc.surface().map(|s| s.mesh.clone()).ok_or("no mesh")?;
    Ok((doc, MeshState::new(mesh, 1)))
}

/// A new `width x height` document with `settings`, its mesh (built in or a file, as the settings
/// name it) attached and baked.
pub(super) fn new_document_with(
    (width, height): (u32, u32),
    settings: DocumentSettings,
) -> Result<Document, String> {
    let mut doc = Document::new(width, height, settings).map_err(|e| e.to_string())?;
    project::attach_own_mesh(&mut doc).map_err(|e| e.to_string())?;
    Ok(doc)
}

/// Loads a project with its mesh (the sphere, and a note saying why, where the mesh cannot
/// be attached).
pub(super) fn load_project(path: &Path) -> Result<(Document, Option<String>), String> {
    let (doc, failed) = project::open_with_mesh(path, None).map_err(|e| e.to_string())?;
    with_fallback(doc, failed)
}

/// `doc` as it is, or, when its mesh `failed`, with the built-in sphere and a note.
pub(super) fn with_fallback(
    mut doc: Document,
    failed: Option<ModelError>,
) -> Result<(Document, Option<String>), String> {
    let Some(e) = failed else {
        return Ok((doc, None));
    };
    project::attach_mesh(&mut doc, Path::new("sphere")).map_err(|e| e.to_string())?;
    Ok((doc, Some(format!("{e}; showing the sphere instead"))))
}

impl EditorState {
    /// Starts a job: `work` runs on a worker, and `done` takes its result on the UI thread
    /// (an error becomes a notice).
    pub(super) fn start_job<T: Send + 'static>(
        &mut self,
        label: &str,
        work: impl FnOnce(&Progress) -> Result<T, String> + Send + 'static,
        done: fn(&mut EditorState, T),
    ) {
        self.start_job_with(label, None, None, work, done);
    }

    /// Starts a job that opens a project: it replaces the document when done, and the editor
    /// takes no input until then.
    pub(super) fn start_job_opening<T: Send + 'static>(
        &mut self,
        label: &str,
        opens: PathBuf,
        work: impl FnOnce(&Progress) -> Result<T, String> + Send + 'static,
        done: fn(&mut EditorState, T),
    ) {
        let name = opens.file_name().map_or_else(
            || opens.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let modal = format!("Opening {name}…");
        self.start_job_with(label, Some(opens), Some(modal), work, done);
    }

    /// Starts a job that the editor waits for behind a window saying `modal`.
    pub(super) fn start_job_modal<T: Send + 'static>(
        &mut self,
        label: &str,
        modal: String,
        work: impl FnOnce(&Progress) -> Result<T, String> + Send + 'static,
        done: fn(&mut EditorState, T),
    ) {
        self.start_job_with(label, None, Some(modal), work, done);
    }

    fn start_job_with<T: Send + 'static>(
        &mut self,
        label: &str,
        opens: Option<PathBuf>,
        modal: Option<String>,
        work: impl FnOnce(&Progress) -> Result<T, String> + Send + 'static,
        done: fn(&mut EditorState, T),
    ) {
        if self.busy() {
            self.notices
                .push(notice("wait for the current job to finish", true));
            return;
        }
        let progress = Arc::new(Progress::default());
        let shared = Arc::clone(&progress);
        let waker = self.jobs.waker.clone();
        match std::thread::Builder::new()
            .name(format!("kapaint-{}", label.to_lowercase()))
            .spawn(move || {
                let finish: Finish = match work(&shared) {
                    Ok(value) => Box::new(move |s: &mut EditorState| done(s, value)),
                    Err(e) => Box::new(move |s: &mut EditorState| s.job_failed(e)),
                };
                if let Some(ctx) = waker {
                    ctx.request_repaint();
                }
                finish
            }) {
            Ok(handle) => {
                self.jobs.current = Some(Job {
                    label: label.into(),
                    opens,
                    modal,
                    progress,
                    handle,
                });
            }
            Err(e) => self
                .notices
                .push(notice(format!("cannot start {label}: {e}"), true)),
        }
    }

    /// Once the job under way is done: what it made goes where its starter said.
    pub(super) fn poll_job(&mut self) {
        if !self
            .jobs
            .current
            .as_ref()
            .is_some_and(|j| j.handle.is_finished())
        {
            return;
        }
        let Some(job) = self.jobs.current.take() else {
            return;
        };
        let label = job.label;
        let finish = job.handle.join().unwrap_or_else(|_| {
            Box::new(move |s: &mut EditorState| {
                s.job_failed(format!("{label} failed unexpectedly"));
            })
        });
        finish(self);
    }

    /// A job failed: what waited on it is dropped, and the error shown.
    fn job_failed(&mut self, e: String) {
        self.prompts.quit.after_save = false;
        self.dialogs.pending_new = None;
        self.bake_failed();
        self.notices.push(notice(e, true));
    }

    /// A project opened (or recovered), with its note.
    pub(super) fn open_done(&mut self, opened: Box<OpenedProject>) {
        let note = opened.note.clone();
        self.opened(*opened);
        if let Some(note) = note {
            self.notices.push(notice(note, true));
        }
    }

    /// A save done, or conflicted.
    pub(super) fn save_done(&mut self, saved: Saved) {
        match saved {
            Saved::Saved(path, version, on_disk) => self.saved(path, version, on_disk),
            Saved::Conflicted {
                message,
                written,
                version,
            } => self.conflicted(message, written, version),
        }
    }

    /// An export written.
    pub(super) fn export_done(&mut self, (dir, m): (PathBuf, Box<kapaint_export::Exported>)) {
        self.notices.push(exported_notice(&dir, *m));
    }

    /// An image decoded and resampled into a channel's planes: into the document.
    fn image_done(&mut self, (path, planes): (PathBuf, Box<kapaint_model::import::ChannelPlanes>)) {
        let channel = planes.channel();
        let imported = kapaint_model::document::ImportedChannel(Arc::new(*planes));
        match self.doc.apply(ImportCommand::ImportChannel(imported)) {
            Ok(()) => self.notices.push(notice(
                format!("{} imported into {}", path.display(), channel.label()),
                false,
            )),
            Err(e) => self.notices.push(notice(e.to_string(), true)),
        }
    }

    /// The maps resized, with the mesh baked at their size.
    pub(super) fn resize_done(&mut self, resized: kapaint_model::resize::ResizedMaps) {
        let (w, h) = (resized.0.0.width, resized.0.0.height);
        self.apply(ImportCommand::Resize(resized));
        self.notices
            .push(notice(format!("Resized the maps to {w}x{h}"), false));
    }

    /// A new project (File > New), its mesh baked.
    pub(super) fn create_done(&mut self, doc: Box<Document>) {
        self.replace_document(*doc);
        self.project.saved_version = self.doc.version();
        self.project.path = None;
        self.project.claim.hold(None, None, false);
        // The old document was saved or its changes discarded (asked before).
        self.project.autosaver.discard();
        self.project.autosaver =
            recovery::Autosaver::new(self.preferences.autosave_interval(), None, &self.doc);
    }

    /// A brush stamp read from an image.
    fn stamp_done(&mut self, (path, stamp): (PathBuf, kapaint_model::brush::Stamp)) {
        let mut brush = self.doc.settings().brush.clone();
        brush.stamp = Some(stamp);
        self.apply(SettingsCommand::SetBrush(brush));
        self.notices
            .push(notice(format!("stamp {}", path.display()), false));
    }

    pub(super) fn replace_document(&mut self, doc: Document) {
        let mesh = doc.surface().map(|s| s.mesh.clone());
        let size = |d: &Document| (d.maps().width(), d.maps().height());
        if size(&doc) != size(&self.doc) {
            // A map of another size: fit it anew (the old zoom would show a 4096^2 map 4x).
            self.canvas.fit();
        }
        // The texel under the cursor was found on the old maps.
        self.pointer.hover = None;
        self.pointer.shown_hover = None;
        self.doc = doc;
        if let Some(mesh) = mesh {
            self.mesh = MeshState::new(mesh, self.mesh.id + 1);
            self.viewport.frame(&self.mesh.mesh);
        }
    }

    /// Takes a converted PBR material: its maps into the selected layer (one undo step), its
    /// normal map and its report into the document.
    pub(super) fn take_material(&mut self, path: &Path, m: PbrMaterial) {
        let PbrMaterial {
            maps,
            normal,
            report,
        } = m;
        let imported = kapaint_model::document::ImportedMaterial {
            maps: Arc::new(maps),
            normal: normal.map(Arc::new),
            report: Some(report.clone()),
        };
        if let Err(e) = self.doc.apply(ImportCommand::ImportMaterial(imported)) {
            self.notices.push(notice(e.to_string(), true));
            return;
        }
        let e = report.error;
        let text = format!(
            "{} imported for {}: conversion error max {:.1}%, mean {:.1}%, p99 {:.1}%",
            path.display(),
            report.model,
            e.max * 100.0,
            e.mean * 100.0,
            e.p99 * 100.0
        );
        self.notices.push(if e.max > PBR_ERROR_WARNING {
            super::warning(format!(
                "{text}: over the {:.0}% a faithful conversion keeps",
                PBR_ERROR_WARNING * 100.0
            ))
        } else {
            notice(text, false)
        });
        for note in &report.notes {
            self.notices.push(notice(note.clone(), false));
        }
    }

    /// Loads a brush stamp from an image on a worker thread.
    pub fn load_stamp(&mut self, path: PathBuf) {
        self.start_job(
            "Stamp",
            move |progress| {
                progress.start("decode", 1);
                match kapaint_model::import::read_stamp(&path) {
                    Ok(stamp) => Ok((path, stamp)),
                    Err(e) => Err(e.to_string()),
                }
            },
            Self::stamp_done,
        );
    }

    /// Decodes and resamples an image on a worker; it is written into `channel` (one undo
    /// step) when it arrives.
    pub fn import_image(&mut self, path: PathBuf, channel: Channel) {
        let (w, h) = (self.doc.maps().width(), self.doc.maps().height());
        self.start_job(
            "Image",
            move |progress| {
                progress.start("decode", 1);
                match kapaint_model::import::read_image(&path) {
                    Ok(image) => {
                        progress.start("resample", 1);
                        let planes = kapaint_model::import::resample(&image, channel, w, h);
                        Ok((path, Box::new(planes)))
                    }
                    Err(e) => Err(e.to_string()),
                }
            },
            Self::image_done,
        );
    }

    /// What the window over the editor says while a job it waits for runs (a project
    /// opening, the maps being resized), if one does.
    pub(super) fn modal_job(&self) -> Option<&str> {
        self.jobs.current.as_ref().and_then(|j| j.modal.as_deref())
    }

    /// While a project opens or the maps are resized: a window over the editor saying so,
    /// that takes the pointer (a stroke on the document about to be replaced would be lost).
    pub(super) fn modal_job_ui(&self, ctx: &egui::Context) {
        let Some(text) = self.modal_job() else {
            return;
        };
        egui::Modal::new(egui::Id::new("kapaint-opening")).show(ctx, |ui| {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(text);
            });
        });
    }
}

/// A PBR conversion whose largest relative error passes this is a warning: a quarter of the
/// shading lost somewhere on the material.
const PBR_ERROR_WARNING: f32 = 0.25;

/// The notice of a finished export: a warning, with the number that missed, when the set is
/// over its `k_a` budget or the PBR round trip loses more than [`PBR_ERROR_WARNING`].
fn exported_notice(dir: &std::path::Path, m: kapaint_export::Exported) -> super::Notice {
    let missed = match &m {
        kapaint_export::Exported::Set(m) => m.blocks.as_ref().is_some_and(|b| !b.within_budget),
        kapaint_export::Exported::Pbr(m) => m.round_trip.max > PBR_ERROR_WARNING,
    };
    let mut text = exported_text(dir, m);
    if missed {
        text = format!("{text} (over budget)");
        return super::warning(text);
    }
    notice(text, false)
}

/// What a finished export says.
fn exported_text(dir: &std::path::Path, m: kapaint_export::Exported) -> String {
    match m {
        kapaint_export::Exported::Set(m) => {
            let head = format!(
                "exported {} ({} files, {} bytes",
                dir.display(),
                m.file_count(),
                m.bytes.exported
            );
            // A block-compressed set's numbers come with the budget's verdict on them, in
            // the summary; no number stands beside it unjudged.
            let mut text = if let Some(blocks) = &m.blocks {
                format!("{head}); blocks: {}", blocks.summary())
            } else {
                let mut text = format!(
                    "{head}, k_a error max {:.2}% mean {:.3}%)",
                    m.ka_error.max * 100.0,
                    m.ka_error.mean * 100.0
                );
                if let Some(e) = m.ka_error_srgb {
                    text.push_str("; ");
                    text.push_str(&e.describe());
                }
                text
            };
            if let Some(normal) = m.normal.as_ref().and_then(|n| n.summary()) {
                text.push_str("; normal map: ");
                text.push_str(&normal);
            }
            text
        }
        kapaint_export::Exported::Pbr(m) => format!(
            "exported {} as glTF PBR ({} files, round-trip error max {:.1}% mean {:.1}% p99 {:.1}%)",
            dir.display(),
            m.files.len() + 1,
            m.round_trip.max * 100.0,
            m.round_trip.mean * 100.0,
            m.round_trip.p99 * 100.0
        ),
    }
}

/// A project a worker opened or recovered.
pub(super) struct OpenedProject {
    /// Where it is saved (`None` for recovered untitled work).
    pub(super) path: Option<std::path::PathBuf>,
    pub(super) doc: kapaint_model::Document,
    /// The recovery copy it came from, if it did.
    pub(super) recovered: Option<std::path::PathBuf>,
    /// A note for the user (its mesh could not be loaded, its recovery failed).
    pub(super) note: Option<String>,
    /// The project file as it was when read: what a save expects to replace.
    pub(super) on_disk: Option<kapaint_model::project::OnDisk>,
    /// Opened read-only (another kapaint has it open).
    pub(super) read_only: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_compressed_exports_notice_names_its_layout_encoder_and_verdict() {
        let doc = kapaint_core::report::typical::stroke_edge_document(32, None).expect("project");
        let out = std::env::temp_dir().join(format!("kapaint-notice-{}", std::process::id()));
        let preset = kapaint_export::preset::find("ktx2").expect("preset");
        let m = kapaint_export::set::export(&doc, &preset, &out).expect("export");
        let blocks = m.blocks.clone().expect("a block-compressed set");
        let n = exported_notice(&out, kapaint_export::Exported::Set(m));
        let _ = std::fs::remove_dir_all(&out);
        let text = n.text.clone();
        // The stroke's dark-beside-light blocks miss the k_a budget: a warning with the
        // numbers it missed, never a green notice.
        assert!(!blocks.within_budget, "{text}");
        assert_eq!(n.level, crate::NoticeLevel::Warning, "{text}");
        assert!(
            text.contains("over the k_a budget (k_a within 2 levels of the displayed colour for 99.9 % of texels"),
            "{text}"
        );
        // One verdict: the numbers it judges, and the max beside it said not to be judged.
        assert!(text.contains("which judges level 0: p99.9 "), "{text}");
        assert!(text.contains("not judged: max "), "{text}");
        assert!(!text.contains("k_a error max"), "{text}");
        assert!(text.contains("; blocks: "), "{text}");
        assert!(
            text.contains(&format!("at {:?}", blocks.bc7_effort)),
            "{text}"
        );
        assert!(text.contains("encoder"), "{text}");
        assert!(text.contains("k_a budget"), "{text}");
    }
}
