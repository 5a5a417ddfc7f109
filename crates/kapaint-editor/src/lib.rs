//! The editor: an eframe app around the model. The UI reads the document and
//! changes it only through [`Command`]s; the GPU side ([`viewport`]) mirrors the maps.
//!
//! Layout: menu bar, tool and material panel on the left, view panel on the right, a dock
//! with the 3D viewport and the UV canvas in the middle, status bar at the bottom. Long work
//! (open, save, export) runs on named worker threads with a progress bar and cancel.

mod app;
pub mod bake;
pub mod bake_high;
pub mod canvas;
mod carry;
mod claim;
mod desk;
mod dialogs;
mod export_dialog;
mod export_plan;
pub mod files;
mod input;
mod mesh_state;
use mesh_state::MeshState;
mod jobs;
pub mod keys;
mod layer_view;
mod layout;
pub mod material_size;
mod mesh_jobs;
pub mod notices;
pub use notices::{Notice, NoticeLevel, Notices};
mod panels;
mod parts;
pub mod preferences;
mod project_dialog;
mod project_jobs;
mod prompts;
pub use panels::layers::LayerView;
mod readout;
pub mod resize;
mod results;
pub mod screen_brush;
mod stencil_view;
mod tool_overlays;
mod uv_wire;
pub mod viewport;

pub use app::{Editor, run};
pub use dialogs::{NEW_SIZES, NewDialog};
pub use export_dialog::export_folder_in;
pub use layout::{default_layout, layout_json, parse_layout};
pub use project_jobs::{RECENT_MAX, parse_recent, push_recent};

use std::path::Path;
use std::sync::Arc;

use canvas::{Canvas, CanvasChannel};
use kapaint_core::render::{Lighting, ViewMode};
use kapaint_model::texel::Channel;
use kapaint_model::{Command, Document};
use kapaint_tools::Tools;
use viewport::Viewport;

/// Default map size of a new project.
pub const DEFAULT_SIZE: u32 = 1024;

/// Dock tabs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Tab {
    /// The 3D viewport.
    Viewport,
    /// The UV canvas.
    Canvas,
    /// The layer stack.
    Layers,
}

/// Where `world` falls in `picture` through `view_proj`, if in front of the camera.
pub(crate) fn project(
    view_proj: glam::Mat4,
    picture: egui::Rect,
    world: glam::Vec3,
) -> Option<egui::Pos2> {
    let clip = view_proj * world.extend(1.0);
    (clip.w > 1e-6).then(|| {
        let ndc = clip.truncate() / clip.w;
        egui::Pos2::new(
            picture.min.x + (ndc.x * 0.5 + 0.5) * picture.width(),
            picture.min.y + (0.5 - ndc.y * 0.5) * picture.height(),
        )
    })
}

/// Screen points of a circle of `radius` (world units) around `centre` in the plane normal
/// to `normal`, seen by `camera` in `picture`.
pub fn brush_outline(
    camera: &kapaint_core::render::Camera,
    picture: egui::Rect,
    centre: glam::Vec3,
    normal: glam::Vec3,
    radius: f32,
) -> Vec<egui::Pos2> {
    let n = normal.normalize_or(glam::Vec3::Z);
    let (t, b) = n.any_orthonormal_pair();
    let view_proj = camera.view_proj(picture.width() / picture.height().max(1.0));
    (0..48)
        .filter_map(|i| {
            let a = i as f32 / 48.0 * std::f32::consts::TAU;
            project(
                view_proj,
                picture,
                centre + (t * a.cos() + b * a.sin()) * radius,
            )
        })
        .collect()
}

/// Everything the panels and tabs read and change (the dock lives beside it): the document,
/// and each part of the editor owning its own state.
pub struct EditorState {
    /// The document.
    doc: Document,
    /// Where it is saved, its claim on the file, its recovery copy.
    project: project_jobs::Project,
    /// The tools and which one is active.
    tools: Tools,
    /// How the viewport shades and lights.
    look: Look,
    /// The 3D viewport.
    viewport: Viewport,
    /// The UV canvas.
    canvas: Canvas,
    mesh: MeshState,
    /// Messages.
    notices: Notices,
    /// Work on workers: the job under way, the exact chi, bakes made on demand.
    jobs: parts::Jobs,
    /// The dialogs and windows, while open.
    dialogs: parts::Dialogs,
    /// The questions asked before the editor goes on.
    prompts: prompts::Prompts,
    /// Where the pointer is and what it holds.
    pointer: input::Pointer,
    /// The tool panel's own state (brush size, colour field, recent materials).
    tool_panel: panels::tool_panel::ToolPanel,
    /// Material, brush and mask presets.
    presets: panels::presets::Presets,
    /// The Layers tab's thumbnails and rename, and the layer view chosen.
    layers_panel: panels::layers::LayersPanel,
    /// The editor's settings that outlive a run (Edit > Preferences).
    preferences: preferences::Preferences,
}

/// How the viewport shades and where its light comes from.
pub(crate) struct Look {
    /// View mode of the viewport.
    mode: ViewMode,
    /// Lights (relative to the camera while `light_follows_camera`).
    lighting: Lighting,
    /// The light turns with the camera.
    light_follows_camera: bool,
}

/// Where quitting stands.
#[derive(Default)]
struct Quit {
    /// Quit was asked (menu, key or the window's close button).
    asked: bool,
    /// Quit once the save under way is done (the quit prompt's Save).
    after_save: bool,
    /// The window may close with unsaved changes: saved meanwhile, or the user discarded them.
    allowed: Option<QuitAllowed>,
}

/// Why the window may close although the document changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum QuitAllowed {
    /// The quit prompt's Save finished.
    Saved,
    /// The user discarded the changes: their recovery copy goes too.
    Discarded,
}

/// A preset's thumbnail: the id of the mesh it shows, and its texture.
type Thumbnail = (u64, egui::TextureHandle);

/// Information, or an error.
fn notice(text: impl Into<String>, error: bool) -> Notice {
    Notice::new(
        text,
        if error {
            NoticeLevel::Error
        } else {
            NoticeLevel::Info
        },
    )
}

/// A warning: done, but short of what was asked (with the number that missed).
fn warning(text: impl Into<String>) -> Notice {
    Notice::new(text, NoticeLevel::Warning)
}

impl EditorState {
    /// The document.
    pub fn doc(&self) -> &Document {
        &self.doc
    }

    /// Where the document is saved, if anywhere yet.
    pub fn path(&self) -> Option<&Path> {
        self.project.path.as_deref()
    }

    /// The tools and which one is active.
    pub fn tools(&self) -> &Tools {
        &self.tools
    }

    /// What the 3D viewport compares, and how.
    pub fn comparison(&self) -> viewport::Comparison {
        self.viewport.comparison
    }

    /// The traced view's samples per pixel and standard error, while one is shown.
    pub fn traced_status(&self) -> Option<(u32, Option<f32>)> {
        self.viewport.traced.status()
    }

    /// The New dialog's choices, while it is open.
    pub fn new_dialog(&self) -> Option<&NewDialog> {
        self.dialogs.new.as_ref()
    }

    /// Sets the New dialog's choices (opening it).
    pub fn set_new_dialog(&mut self, dialog: NewDialog) {
        self.dialogs.new = Some(dialog);
    }

    /// The brush circle on the UV canvas (centre and radius in points), while the cursor is
    /// over it with a painting tool.
    pub fn canvas_outline(&self) -> Option<(egui::Pos2, f32)> {
        self.pointer.canvas_outline
    }

    /// Where the mesh clone source's marker was drawn in the viewport this frame.
    pub fn viewport_clone_marker(&self) -> Option<egui::Pos2> {
        self.pointer.viewport_clone_marker
    }

    /// What the open file dialog is for, if one is open.
    pub fn file_dialog_open_for(&self) -> Option<files::FilePurpose> {
        self.dialogs.files.open_for()
    }

    /// Whether the window is closing (quit asked, and nothing unsaved, or discarded).
    pub fn closing(&self) -> bool {
        self.prompts.quit.asked && (self.prompts.quit.allowed.is_some() || !self.dirty())
    }

    /// The export dialog's folder, while it is open.
    pub fn export_folder(&self) -> Option<&str> {
        self.dialogs
            .export
            .as_ref()
            .map(export_dialog::ExportDialog::folder)
    }

    /// A project waiting to be opened until the user decides about unsaved changes.
    pub fn pending_open(&self) -> Option<&Path> {
        self.prompts.pending_open.as_deref()
    }

    /// The messages shown in the corner.
    pub fn notices(&self) -> &[Notice] {
        &self.notices
    }

    /// Writes the recovery copy now if the document differs from it, and waits until it is
    /// on disk: what the timer does every interval, at once.
    ///
    /// # Errors
    /// The autosave's failure.
    pub fn autosave_now(&mut self) -> Result<(), String> {
        self.project
            .autosaver
            .save_now(&self.doc)
            .map_err(|e| e.to_string())
    }

    /// This editor's recovery copy (its session folder; it may not exist yet).
    pub fn recovery_copy(&self) -> std::path::PathBuf {
        self.project.autosaver.session()
    }

    /// The layer view chosen (see [`Self::shown_layer_view`] for what is shown).
    pub fn layer_view(&self) -> LayerView {
        self.layers_panel.view
    }

    /// What the viewport and canvas show of the layers: the chosen view, except that a mask
    /// tools paint shows alone, in grey, while the chosen view is the whole stack.
    pub fn shown_layer_view(&self) -> LayerView {
        self.layers_panel.shown_view(&self.doc)
    }

    /// Whether anything the project file stores (maps or settings) changed since the last
    /// save.
    pub fn dirty(&self) -> bool {
        self.doc.version() != self.project.saved_version
    }

    /// What the UV canvas shows.
    pub fn canvas_channel(&self) -> CanvasChannel {
        self.canvas.channel
    }

    /// The UV canvas's zoom, in screen points per texel (0 until it is fitted to its
    /// panel).
    pub fn canvas_zoom(&self) -> f32 {
        self.canvas.zoom
    }

    /// The mesh each preset thumbnail shows (`None` until it is drawn) and the mesh the
    /// document is on now: thumbnails follow the mesh after New, Open or an import.
    pub fn thumbnail_meshes(&self) -> (Vec<Option<u64>>, u64) {
        let shown = self
            .presets
            .materials
            .iter()
            .map(|p| p.thumbnail.as_ref().map(|(id, _)| *id))
            .collect();
        (shown, self.mesh.id)
    }

    /// The window's title: the project's file name (or "untitled"), a `*` while it has
    /// unsaved changes, then the program's name.
    pub fn window_title(&self) -> String {
        let name = self
            .project
            .path
            .as_deref()
            .and_then(Path::file_name)
            .map_or_else(|| "untitled".into(), |n| n.to_string_lossy().into_owned());
        let marker = if self.dirty() { "*" } else { "" };
        let read_only = if self.project.claim.read_only {
            " [read-only]"
        } else {
            ""
        };
        format!("{name}{marker}{read_only} - kapaint")
    }

    /// The left panel: tools, brush, material, channels (the tool panel asks, the editor
    /// carries it out).
    fn tools_ui(&mut self, ui: &mut egui::Ui) {
        let mut desk = desk::Desk::new(&self.doc, &self.tools, self.pointer.seen());
        self.tool_panel.ui(ui, &mut desk, &mut self.presets);
        let asks = desk.into_asks();
        self.carry_out(asks);
    }

    /// The Layers tab (the panel asks, the editor carries it out).
    fn layers_ui(&mut self, ui: &mut egui::Ui) {
        let mut desk = desk::Desk::new(&self.doc, &self.tools, self.pointer.seen());
        self.layers_panel.ui(ui, &mut desk, &mut self.presets);
        let asks = desk.into_asks();
        self.carry_out(asks);
    }

    /// What tools paint (a layer or its mask) and which layer view is shown, as the viewport
    /// and canvas say it.
    pub fn painting_text(&self) -> Option<String> {
        self.layers_panel.painting_text(&self.doc)
    }

    /// The right panel: shading, compare, view, light, material presets, history (the panel
    /// asks, the editor carries it out).
    fn view_ui(&mut self, ui: &mut egui::Ui) {
        let frame = self.frame_settings();
        let mut desk = desk::Desk::new(&self.doc, &self.tools, self.pointer.seen());
        let mut shown = panels::view_panel::Shown {
            look: &mut self.look,
            comparison: &mut self.viewport.comparison,
            layers: &mut self.layers_panel.view,
            canvas: &mut self.canvas,
        };
        let (gpu, mesh) = (&mut self.viewport.gpu, &self.mesh);
        let mut thumbnail = |value| panels::view_panel::thumbnail(gpu.as_mut(), mesh, frame, value);
        shown.ui(ui, &mut desk, &mut self.presets, (mesh.id, &mut thumbnail));
        let asks = desk.into_asks();
        self.carry_out(asks);
    }

    /// How the brush's size is given.
    pub fn brush_size(&self) -> screen_brush::BrushSize {
        self.tool_panel.brush_size
    }

    /// Sets how the brush's size is given (the radius on screen kept in range).
    pub fn set_brush_size(&mut self, size: screen_brush::BrushSize) {
        self.tool_panel.brush_size = size.clamped();
    }

    /// Texels per screen point under the cursor this frame, if it is over the map or the mesh.
    pub fn texels_per_point(&self) -> Option<f32> {
        self.pointer.texels_per_point
    }

    /// The materials used last, newest first.
    pub fn recent_materials(&self) -> &[kapaint_model::texel::MaterialValue] {
        &self.tool_panel.recent_materials
    }

    /// Saves presets into `dir` from now on (the user preset folder by default).
    pub fn set_preset_dir(&mut self, dir: std::path::PathBuf) {
        self.presets.dir = Some(dir);
    }

    /// The names of the material presets, as the browser shows them.
    pub fn preset_names(&self) -> Vec<&str> {
        self.presets
            .materials
            .iter()
            .map(|p| p.name.as_str())
            .collect()
    }

    /// The smart masks: shipped, then the user's.
    pub fn mask_preset_names(&self) -> Vec<&str> {
        self.presets.masks.iter().map(|p| p.name.as_str()).collect()
    }

    /// The brush presets' names.
    pub fn brush_preset_names(&self) -> Vec<&str> {
        self.presets
            .brushes
            .iter()
            .map(|p| p.name.as_str())
            .collect()
    }

    /// The file chooser (tests choose its backend and starting folder).
    pub fn files_mut(&mut self) -> &mut files::FileChooser {
        &mut self.dialogs.files
    }

    /// Applies a command as the panels do (an error becomes a notice).
    pub fn apply_command(&mut self, command: impl Into<Command>) {
        self.apply(command);
    }

    fn apply(&mut self, command: impl Into<Command>) {
        self.applied(command);
    }

    /// Applies `command`; whether it was done (an error becomes a notice).
    fn applied(&mut self, command: impl Into<Command>) -> bool {
        let done = self.doc.apply(command);
        if let Err(e) = &done {
            self.notices.push(notice(e.to_string(), true));
        }
        self.follow_mesh();
        done.is_ok()
    }

    /// The mesh shown, picked and drawn on follows the document's (a mesh import, its undo):
    /// rebuilt, and the view framed, only when the mesh itself changed.
    fn follow_mesh(&mut self) {
        let Some(surface) = self.doc.surface() else {
            return;
        };
        // Upgraded, not compared by address: a freed bake's address may be reused.
        if self
            .mesh
            .from
            .upgrade()
            .is_some_and(|from| Arc::ptr_eq(&from, surface))
        {
            return;
        }
        if *self.mesh.mesh != surface.mesh {
            self.mesh = MeshState::new(surface.mesh.clone(), self.mesh.id + 1);
            self.viewport.frame(&self.mesh.mesh);
        }
        self.mesh.from = Arc::downgrade(surface);
    }

    /// The channel the canvas shows (`k_d` for the derived `k_a`): where dropped images go.
    fn canvas_target(&self) -> Channel {
        match self.canvas.channel {
            CanvasChannel::Ks => Channel::Ks,
            CanvasChannel::N => Channel::N,
            CanvasChannel::Kd
            | CanvasChannel::Ka
            | CanvasChannel::PbrError
            | CanvasChannel::Bake(_) => Channel::Kd,
        }
    }

    /// Whether a job runs (a bake, an export, an open, ...).
    pub fn busy(&self) -> bool {
        self.jobs.current.is_some()
    }

    /// The project being opened (or recovered) on a worker, if one is: the document is about
    /// to be replaced, so it takes no input meanwhile.
    pub fn opening(&self) -> Option<&Path> {
        self.jobs.current.as_ref().and_then(|j| j.opens.as_deref())
    }
}
