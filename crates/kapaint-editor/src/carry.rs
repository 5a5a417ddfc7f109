//! The one place the editor changes: what its views and finished jobs asked ([`Ask`]),
//! carried out in order; and what the editor does when a project opens, saves or is made
//! anew, which touches several of its parts at once.

use std::path::PathBuf;

use super::files::{ChooserEvent, FilePurpose, Picked, with_project_extension};
use super::{
    EditorState, MeshState, NewDialog, bake, jobs, material_size, mesh_jobs, notice, preferences,
    resize,
};
use crate::desk::{Ask, Desk, Prompt, Window};
use crate::results::{OpenedProject, Saved};
use kapaint_model::texel::Channel;
use kapaint_model::{Document, project, recovery};

impl EditorState {
    /// Carries out what a view or a job asked, in order.
    pub(super) fn carry_out(&mut self, asks: Vec<Ask>) {
        for ask in asks {
            match ask {
                Ask::Command(command) => self.apply(command),
                Ask::CommandSaying(command, said) => {
                    if self.applied(command) {
                        for n in said {
                            self.notices.push(n);
                        }
                    }
                }
                Ask::SelectTool(kind) => self.select_tool(kind),
                Ask::ProjectImage(image) => {
                    if let Some(dialog) = &mut self.dialogs.project {
                        dialog.choose(image);
                    }
                }
                Ask::ToolOption(change) => {
                    for command in self.tools.set_option(change, &self.doc) {
                        self.apply(command);
                    }
                }
                Ask::ChooseFile(purpose) => self.choose_file(purpose),
                Ask::Notice(notice) => self.notices.push(notice),
                Ask::LayGenerator(generator) => {
                    let mut desk = Desk::new(&self.doc, &self.tools, self.pointer.seen());
                    self.jobs.bake_on_demand.lay(generator, &mut desk);
                    let asks = desk.into_asks();
                    self.carry_out(asks);
                }
                Ask::LightFollowsCamera(follow) => self.set_light_follows_camera(follow),
                Ask::Job(job) => self.start(job),
                Ask::JobFailed(e) => {
                    self.job_dropped();
                    self.notices.push(notice(e, true));
                }
                Ask::JobCancelled(label) => {
                    self.job_dropped();
                    self.notices
                        .push(notice(format!("{label} cancelled"), false));
                }
                Ask::Prompt(Prompt::Material(path)) => self.prompts.material = Some(path),
                Ask::Prompt(Prompt::Size(prompt)) => self.prompts.size = Some(*prompt),
                Ask::Prompt(Prompt::Unwrap(prompt)) => self.prompts.unwrap = Some(prompt),
                Ask::OpenNow(path) => self.open_now(path),
                Ask::Save => self.save(),
                Ask::Opened(opened) => {
                    let note = opened.note.clone();
                    self.opened(*opened);
                    if let Some(note) = note {
                        self.notices.push(notice(note, true));
                    }
                }
                Ask::Saved(Saved::Saved(path, version, on_disk)) => {
                    self.saved(path, version, on_disk);
                }
                Ask::Saved(Saved::Conflicted {
                    message,
                    written,
                    version,
                }) => self.conflicted(message, written, version),
                Ask::Created(doc) => self.created(*doc),
                Ask::BakedOnDemand => {
                    if let Some(command) = self.jobs.bake_on_demand.baked(&self.doc) {
                        self.apply(command);
                    }
                }
                Ask::Preferences(preferences) => self.set_preferences(preferences),
                Ask::Act(action) => self.act(&[action]),
                Ask::Show(window) => self.show(window),
                Ask::Open(path) => self.open(path),
                Ask::CageRead(path, cage) => {
                    if let Some(dialog) = &mut self.dialogs.bake_high
                        && dialog.cage.as_ref() == Some(&path)
                    {
                        dialog.cage_mesh = Some(cage);
                    }
                }
            }
        }
    }

    /// Opens Image > Resize at the current size.
    pub fn open_resize(&mut self) {
        self.dialogs.resize = Some(resize::ResizeDialog {
            width: self.doc.maps().width(),
            height: self.doc.maps().height(),
        });
    }

    /// The Resize dialog's choices, while it is open.
    pub fn resize_dialog(&self) -> Option<resize::ResizeDialog> {
        self.dialogs.resize
    }

    /// Sets the Resize dialog's choices (opening it).
    pub fn set_resize_dialog(&mut self, dialog: resize::ResizeDialog) {
        self.dialogs.resize = Some(dialog);
    }

    /// Resamples the maps to `width x height` on a worker (the mesh baked again at that
    /// size); the editor waits behind a window, then installs them as one undo step.
    pub fn resize_maps(&mut self, width: u32, height: u32) {
        self.start(resize::resize_maps(&self.doc, width, height));
    }

    /// Opens Edit > Preferences.
    pub fn open_preferences(&mut self) {
        self.dialogs.preferences_open = true;
    }

    /// The preferences in force.
    pub fn preferences(&self) -> preferences::Preferences {
        self.preferences
    }

    /// Opens Mesh > Bake.
    pub fn open_bake(&mut self) {
        self.dialogs.bake = Some(bake::BakeDialog::default());
    }

    /// Opens Mesh > Bake from high poly.
    pub fn open_bake_high(&mut self) {
        if self.dialogs.bake_high.is_none() {
            self.dialogs.bake_high = Some(crate::bake_high::HighDialog::default());
        }
    }

    /// The Bake from high poly dialog's choices, while it is open.
    pub fn bake_high_dialog(&self) -> Option<&crate::bake_high::HighDialog> {
        self.dialogs.bake_high.as_ref()
    }

    /// The Bake dialog's choices, while it is open.
    pub fn bake_dialog(&self) -> Option<bake::BakeDialog> {
        self.dialogs.bake
    }

    /// Bakes `dialog.map` of the project's mesh on a worker; it is kept when it arrives.
    pub fn bake(&mut self, dialog: bake::BakeDialog) {
        let ask = bake::bake(&self.doc, dialog);
        self.carry_out(vec![ask]);
    }

    /// Bakes the maps `dialog.all` checks in one job; they are kept together as one undo step.
    pub fn bake_all(&mut self, dialog: bake::BakeDialog) {
        let ask = bake::bake_all(&self.doc, dialog);
        self.carry_out(vec![ask]);
    }

    /// Loads and bakes a mesh on a worker; it becomes the project's mesh (or, without
    /// paintable UVs, the editor asks whether to unwrap it).
    pub fn import_mesh(&mut self, path: std::path::PathBuf) {
        self.start(mesh_jobs::import_mesh(&self.doc, path));
    }

    /// Mesh > Unwrap automatically: asks whether to replace the mesh's UVs with a new atlas.
    pub fn ask_unwrap(&mut self) {
        let ask = mesh_jobs::ask_unwrap(&self.doc);
        self.carry_out(vec![ask]);
    }

    /// Converts a glTF's material, or a texture set, into the selected layer on a worker
    /// (asking first when its size is not the maps').
    pub fn import_pbr(&mut self, path: std::path::PathBuf) {
        self.start(material_size::import_pbr(&self.doc, path));
    }

    /// The material size question, while it is open.
    pub fn size_prompt(&self) -> Option<&material_size::SizePrompt> {
        self.prompts.size.as_ref()
    }

    /// Answers the material size question: adopt the material's size, resample it to the
    /// maps, or import nothing.
    pub fn answer_size_prompt(&mut self, answer: material_size::SizeAnswer) {
        if let Some(prompt) = self.prompts.size.take()
            && let Some(job) = material_size::answer(&self.doc, prompt, answer)
        {
            self.start(job);
        }
    }

    /// Loads a brush stamp from an image on a worker.
    pub fn load_stamp(&mut self, path: std::path::PathBuf) {
        self.start(jobs::load_stamp(path));
    }

    /// Decodes and resamples an image on a worker; it is written into `channel` (one undo
    /// step) when it arrives.
    pub fn import_image(&mut self, path: std::path::PathBuf, channel: Channel) {
        self.start(jobs::import_image(&self.doc, path, channel));
    }

    /// Reads the presets again: the shipped ones, then the user's from the preset folder (a
    /// malformed file is a notice).
    pub fn reload_presets(&mut self) {
        self.presets.reload(&mut self.notices);
    }

    /// Replaces the document with a new one as `dialog` says (the old one's unsaved changes
    /// are in its recovery copy and were asked about before).
    pub fn create_project(&mut self, dialog: &NewDialog) {
        self.start(dialog.create(&self.presets.materials));
    }

    /// Asks for a file for `purpose`, starting in the project's folder.
    pub(super) fn choose_file(&mut self, purpose: FilePurpose) {
        let dir = self
            .project
            .path
            .as_deref()
            .and_then(std::path::Path::parent)
            .filter(|d| !d.as_os_str().is_empty())
            .map(std::path::Path::to_path_buf);
        if !self.dialogs.files.request(purpose, dir) {
            self.notices
                .push(notice("a file dialog is open already", true));
        }
    }

    /// What the file chooser said this frame: a file picked goes where its purpose says.
    pub(super) fn file_chosen(&mut self, event: Option<ChooserEvent>) {
        match event {
            Some(ChooserEvent::FellBack(text)) => self.notices.push(notice(text, false)),
            Some(ChooserEvent::Cancelled(FilePurpose::SaveProject)) => {
                self.prompts.quit.after_save = false;
                self.dialogs.pending_new = None;
            }
            None | Some(ChooserEvent::Cancelled(_)) => {}
            Some(ChooserEvent::Picked(Picked { purpose, path })) => match purpose {
                FilePurpose::OpenProject => self.open(path),
                FilePurpose::SaveProject => self.save_to(with_project_extension(path)),
                FilePurpose::ImportMesh => self.import_mesh(path),
                FilePurpose::ImportImage(channel) => self.import_image(path, channel),
                FilePurpose::ImportPbr => self.import_pbr(path),
                FilePurpose::StampImage => self.load_stamp(path),
                FilePurpose::ToolImage => self.start(jobs::load_tool_image(path)),
                FilePurpose::StencilImage => self.start(jobs::load_stencil(path)),
                FilePurpose::ProjectImage => self.start(jobs::load_project_image(path)),
                FilePurpose::HighMesh | FilePurpose::Cage => {
                    if let Some(dialog) = &mut self.dialogs.bake_high {
                        if purpose == FilePurpose::Cage {
                            dialog.cage = Some(path.clone());
                            dialog.cage_mesh = None;
                            let read = crate::bake_high::read_cage(&self.doc, path);
                            self.carry_out(vec![read]);
                        } else if !dialog.highs.contains(&path) {
                            dialog.highs.push(path);
                        }
                    }
                }
                FilePurpose::NewMesh => {
                    if let Some(dialog) = &mut self.dialogs.new {
                        dialog.mesh = path.display().to_string();
                    }
                }
                FilePurpose::ExportFolder => {
                    if let Some(dialog) = &mut self.dialogs.export {
                        dialog.choose_folder(&path);
                    }
                }
            },
        }
    }

    /// Opens `window`.
    fn show(&mut self, window: Window) {
        match window {
            Window::Resize => self.open_resize(),
            Window::ProjectImage => {
                let dialog =
                    crate::project_dialog::ProjectDialog::new(&self.doc, &self.viewport.camera);
                self.dialogs.project = Some(dialog);
            }
            Window::Bake => self.open_bake(),
            Window::BakeHigh => self.open_bake_high(),
            Window::Preferences => self.open_preferences(),
            Window::Shortcuts => self.dialogs.shortcuts_open = true,
        }
    }

    /// A job failed or was cancelled: what waited on it is dropped.
    fn job_dropped(&mut self) {
        self.prompts.quit.after_save = false;
        self.dialogs.pending_new = None;
        self.jobs.bake_on_demand.failed();
    }

    /// Opens `path` on a worker; with unsaved changes, asks first.
    pub fn open(&mut self, path: PathBuf) {
        if self.dirty() {
            // Unsaved work is never dropped: ask first (see `Prompts::open_window`).
            self.prompts.pending_open = Some(path);
            return;
        }
        self.open_now(path);
    }

    /// Opens `path` on a worker, once the user has answered if another kapaint has it open.
    pub(super) fn open_now(&mut self, path: PathBuf) {
        if let Some(read_only) = self.project.claim.may_open(&path) {
            self.start(super::project_jobs::open(path, read_only));
        }
    }

    /// Saves to `path` on a worker (a snapshot of the maps, so painting goes on).
    pub fn save_to(&mut self, path: PathBuf) {
        // Over its own file, a save expects the file as this editor last read or wrote it;
        // elsewhere (Save As) the user chose to replace what is there.
        let expected = (self.project.path.as_deref() == Some(path.as_path()))
            .then(|| self.project.claim.on_disk.clone())
            .flatten();
        self.start(super::project_jobs::save_to(&self.doc, path, expected));
    }

    /// File > Save: over the project's file, or asking where (untitled or read-only).
    pub(super) fn save(&mut self) {
        match self.project.path.clone() {
            Some(p) if !self.project.claim.read_only => self.save_to(p),
            _ => self.choose_file(FilePurpose::SaveProject),
        }
    }

    /// A save finished: the document version it holds, and the file as written.
    pub(super) fn saved(&mut self, path: PathBuf, version: u64, on_disk: project::OnDisk) {
        self.project.saved_version = version;
        self.project.claim.hold(Some(&path), Some(on_disk), false);
        self.notices
            .push(notice(format!("saved {}", path.display()), false));
        self.project.remember(&path);
        if self.project.path.as_deref() != Some(path.as_path()) {
            // Save As (or the first save): the recovery copy follows the work.
            self.project.autosaver.relocate(Some(&path));
        }
        // What was saved needs no recovery copy (unless it changed while saving).
        self.project.autosaver.saved(&self.doc, version);
        self.project.path = Some(path);
        if std::mem::take(&mut self.prompts.quit.after_save) && !self.dirty() {
            // The quit prompt's Save: the work is safe, so the window closes.
            self.prompts.quit.allowed = Some(super::QuitAllowed::Saved);
            self.prompts.quit.asked = true;
        }
        if !self.dirty()
            && let Some(next) = self.prompts.pending_open.take()
        {
            self.open_now(next);
        }
        if !self.dirty()
            && let Some(dialog) = self.dialogs.pending_new.take()
        {
            self.create_project(&dialog);
        }
    }

    /// A save found its project changed on disk: the work went to `written` instead.
    pub(super) fn conflicted(&mut self, message: String, written: PathBuf, version: u64) {
        // The work is safe beside the project: the editor goes on with that file.
        self.project.saved_version = version;
        self.notices.push(notice(message, true));
        self.project.remember(&written);
        self.project.autosaver.relocate(Some(&written));
        self.project.autosaver.saved(&self.doc, version);
        self.project
            .claim
            .hold(Some(&written), project::OnDisk::of(&written), false);
        self.project.path = Some(written);
        self.prompts.quit.after_save = false;
        self.dialogs.pending_new = None;
    }

    /// Takes an opened (or recovered) project as the document.
    pub(super) fn opened(&mut self, opened: OpenedProject) {
        let OpenedProject {
            path,
            doc,
            recovered,
            on_disk,
            read_only,
            ..
        } = opened;
        self.project.claim.hold(path.as_deref(), on_disk, read_only);
        self.replace_document(doc);
        // The old document was saved or its changes discarded (asked before).
        self.project.autosaver.discard();
        let interval = self.preferences.autosave_interval();
        // Recovered work is unsaved work, and its copy stays until this editor has its own.
        (self.project.saved_version, self.project.autosaver) = match recovered.clone() {
            Some(from) => (
                u64::MAX,
                recovery::Autosaver::recovering(interval, path.as_deref(), &self.doc, from),
            ),
            None => (
                self.doc.version(),
                recovery::Autosaver::new(interval, path.as_deref(), &self.doc),
            ),
        };
        let recovered = recovered.is_some();
        let name = path
            .as_deref()
            .map_or_else(|| "an untitled project".into(), |p| p.display().to_string());
        let text = if recovered {
            format!("recovered the unsaved work of {name}: save to keep it")
        } else if read_only {
            format!("opened {name} read-only: Save asks for another file")
        } else {
            format!("opened {name}")
        };
        self.notices.push(notice(text, false));
        if let Some(p) = &path {
            self.project.remember(p);
        }
        self.project.path = path;
    }

    /// A new project (File > New), its mesh baked: the document now, untitled.
    fn created(&mut self, doc: Document) {
        self.replace_document(doc);
        self.project.saved_version = self.doc.version();
        self.project.path = None;
        self.project.claim.hold(None, None, false);
        // The old document was saved or its changes discarded (asked before).
        self.project.autosaver.discard();
        self.project.autosaver =
            recovery::Autosaver::new(self.preferences.autosave_interval(), None, &self.doc);
    }

    /// Makes `doc` the document, with its mesh shown and framed.
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

    /// Sets the preferences: kept for the next run, and in force at once (the autosave's next
    /// copy falls due at the new interval).
    pub fn set_preferences(&mut self, preferences: crate::preferences::Preferences) {
        if preferences == self.preferences {
            return;
        }
        self.preferences = preferences;
        self.project
            .autosaver
            .set_interval(preferences.autosave_interval());
        if let Err(e) = preferences.save() {
            self.notices.push(notice(
                format!("the preferences hold for this run only: {e}"),
                true,
            ));
        }
    }
}
