//! Long work on named worker threads (open, save, recover, export, mesh and image import,
//! stamps), each reporting through a [`Progress`], polled every frame; and the documents
//! they make, with their meshes attached.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;

use super::{EditorState, MeshState, notice};
use crate::desk::{Ask, Desk, Finish, JobStart};
use crate::results::{OpenedProject, Saved};
use kapaint_base::task::Progress;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::texel::Channel;
use kapaint_model::{Document, DocumentSettings, ModelError, project};
use kapaint_model::{ImportCommand, SettingsCommand};

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
    /// Starts a job on a named worker (refused, with a notice, while another runs).
    pub(super) fn start(&mut self, job: JobStart) {
        if self.busy() {
            self.notices
                .push(notice("wait for the current job to finish", true));
            return;
        }
        let JobStart {
            label,
            opens,
            modal,
            run,
        } = job;
        let progress = Arc::new(Progress::default());
        let shared = Arc::clone(&progress);
        let waker = self.jobs.waker.clone();
        match std::thread::Builder::new()
            .name(format!("kapaint-{}", label.to_lowercase()))
            .spawn(move || {
                let finish = run(&shared);
                if let Some(ctx) = waker {
                    ctx.request_repaint();
                }
                finish
            }) {
            Ok(handle) => {
                self.jobs.current = Some(Job {
                    label,
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

    /// Once the job under way is done: what it asks is carried out.
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
            Box::new(move |desk: &mut Desk| {
                desk.ask(Ask::JobFailed(format!("{label} failed unexpectedly")));
            })
        });
        let mut desk = Desk::new(&self.doc, &self.tools, self.pointer.seen());
        finish(&mut desk);
        let asks = desk.into_asks();
        self.carry_out(asks);
    }

    /// What the window over the editor says while a job it waits for runs (a project
    /// opening, the maps being resized), if one does.
    pub(super) fn modal_job(&self) -> Option<&str> {
        self.jobs.current.as_ref().and_then(|j| j.modal.as_deref())
    }
}

/// While a project opens or the maps are resized: a window over the editor saying `text`,
/// that takes the pointer (a stroke on the document about to be replaced would be lost).
pub(super) fn modal_job_ui(text: Option<&str>, ctx: &egui::Context) {
    let Some(text) = text else {
        return;
    };
    egui::Modal::new(egui::Id::new("kapaint-opening")).show(ctx, |ui| {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(text);
        });
    });
}

/// A project opened (or recovered): the document now.
pub(super) fn open_done(opened: Box<OpenedProject>, desk: &mut Desk) {
    desk.ask(Ask::Opened(opened));
}

/// A save done, or conflicted.
pub(super) fn save_done(saved: Saved, desk: &mut Desk) {
    desk.ask(Ask::Saved(saved));
}

/// An export written.
pub(super) fn export_done((dir, m): (PathBuf, Box<kapaint_export::Exported>), desk: &mut Desk) {
    desk.notice(exported_notice(&dir, *m));
}

/// An image decoded and resampled into a channel's planes: into the document.
fn image_done(
    (path, planes): (PathBuf, Box<kapaint_model::import::ChannelPlanes>),
    desk: &mut Desk,
) {
    let channel = planes.channel();
    let imported = kapaint_model::document::ImportedChannel(Arc::new(*planes));
    let said = notice(
        format!("{} imported into {}", path.display(), channel.label()),
        false,
    );
    desk.command_saying(ImportCommand::ImportChannel(imported), vec![said]);
}

/// A new project (File > New), its mesh baked.
pub(super) fn create_done(doc: Box<Document>, desk: &mut Desk) {
    desk.ask(Ask::Created(doc));
}

/// A brush stamp read from an image.
fn stamp_done((path, stamp): (PathBuf, kapaint_model::brush::Stamp), desk: &mut Desk) {
    let mut brush = desk.doc.settings().brush.clone();
    brush.stamp = Some(stamp);
    let said = notice(format!("stamp {}", path.display()), false);
    desk.command_saying(SettingsCommand::SetBrush(brush), vec![said]);
}

/// Loads a brush stamp from an image on a worker.
pub(super) fn load_stamp(path: PathBuf) -> JobStart {
    JobStart::new(
        "Stamp",
        move |progress| {
            progress.start("decode", 1);
            match kapaint_model::import::read_stamp(&path) {
                Ok(stamp) => Ok((path, stamp)),
                Err(e) => Err(e.to_string()),
            }
        },
        stamp_done,
    )
}

/// Loads an image to paint through (a decal's, a stencil's) on a worker.
fn load_paint_image(path: PathBuf) -> Result<PaintImage, String> {
    let mut image = PaintImage::named(path);
    image
        .load(std::path::Path::new(""))
        .map_err(|e| e.to_string())?;
    Ok(image)
}

/// An image decoded on a worker (job `label`), handed to `done`.
fn image_job(label: &str, path: PathBuf, done: fn(PaintImage, &mut Desk)) -> JobStart {
    JobStart::new(
        label,
        move |progress| {
            progress.start("decode", 1);
            load_paint_image(path)
        },
        done,
    )
}

/// The active tool's image (the decal's), loaded on a worker.
pub(super) fn load_tool_image(path: PathBuf) -> JobStart {
    image_job("Image", path, |image, desk| {
        let said = notice(format!("image {}", image.path().display()), false);
        desk.ask(Ask::ToolOption(kapaint_tools::OptionChange::Image(image)));
        desk.ask(Ask::Notice(said));
    })
}

/// Image > Project image's image, loaded on a worker.
pub(super) fn load_project_image(path: PathBuf) -> JobStart {
    image_job("Image", path, |image, desk| {
        desk.ask(Ask::ProjectImage(image));
    })
}

/// A stencil from an image, loaded on a worker: laid over the middle of the map, half its
/// width wide (of the viewport's picture, where the stencil before lay on the screen).
pub(super) fn load_stencil(path: PathBuf) -> JobStart {
    image_job("Stencil", path, |image, desk| {
        let said = notice(format!("stencil {}", image.path().display()), false);
        let on_screen = desk.doc.stencil().is_some_and(|s| s.view.is_some());
        let placement = match desk.screen_view {
            Some(view) if on_screen => crate::stencil_view::Placement::on_screen(view),
            _ => crate::stencil_view::Placement::on_canvas(desk.doc),
        };
        let stencil = crate::stencil_view::placed(image, placement);
        desk.command_saying(stencil, vec![said]);
    })
}

/// Decodes and resamples an image on a worker to `doc`'s size; it is written into `channel`
/// (one undo step) when it arrives.
pub(super) fn import_image(doc: &Document, path: PathBuf, channel: Channel) -> JobStart {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    JobStart::new(
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
        image_done,
    )
}

/// The notice of a finished export: a warning, with the number that missed, when the set is
/// over its `k_a` budget or the PBR round trip loses more than [`crate::results::PBR_ERROR_WARNING`].
fn exported_notice(dir: &std::path::Path, m: kapaint_export::Exported) -> super::Notice {
    let missed = match &m {
        kapaint_export::Exported::Set(m) => m.blocks.as_ref().is_some_and(|b| !b.within_budget),
        kapaint_export::Exported::Pbr(m) => m.round_trip.max > crate::results::PBR_ERROR_WARNING,
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
            if let Some(saved) = m.supercompression_summary() {
                text.push_str("; supercompression ");
                text.push_str(&saved);
            }
            text
        }
        kapaint_export::Exported::Pbr(m) => format!(
            "exported {} as {} ({} files, round-trip error max {:.1}% mean {:.1}% p99 {:.1}%{}{})",
            dir.display(),
            m.kind(),
            m.files.len() + 1,
            m.round_trip.max * 100.0,
            m.round_trip.mean * 100.0,
            m.round_trip.p99 * 100.0,
            m.occlusion
                .as_ref()
                .map_or_else(String::new, |o| format!("; occlusion {}", o.note)),
            m.basisu.as_ref().map_or_else(String::new, |b| format!(
                "; model.glb textures {}",
                b.summary()
            ))
        ),
    }
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
