//! The app around the editor's state: start-up (on a new document, or opening a project on a
//! worker), one frame of the whole window (panels, dock, dialogs), exit, and `run`.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_dock::{DockArea, DockState, TabViewer};

use super::canvas::Canvas;
use super::canvas::CanvasChannel;
use super::jobs::new_document;
use super::layout::{load_layout, save_layout};
use super::panels::layers::LayerView;
use super::project_jobs::load_recent;
use super::viewport::{Viewport, ViewportGpu};
use super::{DEFAULT_SIZE, EditorState, MeshState, Tab, default_layout, notice, readout};
use crate::desk::Desk;
use kapaint_core::render::{Lighting, ViewMode};
use kapaint_model::texel::MaterialValue;
use kapaint_model::{Document, DocumentSettings, recovery};
use kapaint_tools::Tools;

/// The map size of the document shown while a project named at start opens.
const PLACEHOLDER_SIZE: u32 = 16;

/// The editor app.
pub struct Editor {
    /// Panels' state.
    pub state: EditorState,
    dock: DockState<Tab>,
    /// When the process started, until the first frame is drawn (then logged to stderr when
    /// `KAPAINT_LOG_STARTUP` is set).
    started: Option<Instant>,
    /// The window title last sent.
    title: String,
}

/// The document the editor starts on: a new `size`^2 one on the sphere, or, where that cannot
/// be made, a tiny one on the plane (with a notice saying why).
fn first_document(size: u32, notices: &mut super::Notices) -> (Document, MeshState) {
    match new_document(size) {
        Ok(x) => x,
        Err(e) => {
            notices.push(notice(e, true));
            let doc = Document::new(16, 16, DocumentSettings::default())
                .unwrap_or_else(|_| unreachable_doc());
            (doc, MeshState::new(kapaint_mesh::plane(), 1))
        }
    }
}

/// How often the window redraws while a job runs, for its progress and estimate.
const JOB_REPAINT: Duration = Duration::from_secs(1);

impl Editor {
    /// The editor on a new default document (sphere, default material), or on `path` when
    /// given: a project there opens on a worker once the window is up (the window shows at
    /// once, with the opening in progress over it); a missing file becomes a new project
    /// saved there.
    pub fn new(
        render_state: Option<&eframe::egui_wgpu::RenderState>,
        path: Option<PathBuf>,
    ) -> Self {
        let gpu = render_state.map(ViewportGpu::new);
        let mut notices = super::Notices::default();
        // A project that is there opens on a worker; until then the document is untitled,
        // so nothing can be saved over the file.
        let (existing, untitled_until_open) = match path {
            Some(p) if p.exists() => (Some(p), None),
            other => (None, other),
        };
        // Under a project being opened, a placeholder costs next to nothing to make.
        let size = if existing.is_some() {
            PLACEHOLDER_SIZE
        } else {
            DEFAULT_SIZE
        };
        let (doc, mesh) = first_document(size, &mut notices);
        let path = existing.as_deref().or(untitled_until_open.as_deref());
        let mut viewport = Viewport::new(gpu);
        viewport.frame(&mesh.mesh);
        let recovery_offer = recovery::offer(path);
        let preferences = crate::preferences::Preferences::load();
        let autosaver = recovery::Autosaver::new(
            preferences.autosave_interval(),
            untitled_until_open.as_deref(),
            &doc,
        );
        let preset_dir = kapaint_model::preset::user_dir();
        let (presets, brush_presets, mask_presets) =
            super::panels::presets::load_all(preset_dir.as_deref(), &mut notices);
        let dock = load_layout().unwrap_or_else(default_layout);
        let saved_version = doc.version();
        let mut editor = Self {
            state: EditorState {
                doc,
                project: super::project_jobs::Project {
                    path: untitled_until_open,
                    starting: None,
                    saved_version,
                    recent: load_recent(),
                    autosaver,
                    claim: super::claim::Claim::default(),
                },
                tools: Tools::default(),
                look: super::Look {
                    mode: ViewMode::Shaded,
                    lighting: Lighting::default(),
                    light_follows_camera: false,
                },
                viewport,
                canvas: Canvas::default(),
                mesh,
                notices,
                jobs: super::parts::Jobs {
                    current: None,
                    waker: None,
                    exact_chi: readout::ExactChi::new(),
                    bake_on_demand: crate::bake::OnDemand::default(),
                },
                dialogs: super::parts::Dialogs::default(),
                prompts: super::prompts::Prompts {
                    recovery_offer,
                    ..Default::default()
                },
                pointer: super::input::Pointer::default(),
                tool_panel: super::panels::tool_panel::ToolPanel::default(),
                presets: super::panels::presets::Presets {
                    materials: presets,
                    brushes: brush_presets,
                    masks: mask_presets,
                    dir: preset_dir,
                    naming: None,
                },
                layers_panel: super::panels::layers::LayersPanel::default(),
                preferences,
            },
            dock,
            started: None,
            title: String::new(),
        };
        if let Some(p) = existing {
            let s = &mut editor.state;
            if s.prompts.recovery_offer.is_some() {
                // Recover or Discard decides what opens.
                s.project.starting = Some(p);
            } else {
                s.open_now(p);
            }
        }
        editor
    }
}

/// A 16 x 16 document cannot fail to allocate; this is only for the type checker.
fn unreachable_doc() -> Document {
    Document::from_parts(
        kapaint_model::MaterialMaps::new(1, 1, MaterialValue::default())
            .unwrap_or_else(|_| std::process::abort()),
        DocumentSettings::default(),
    )
}

struct Tabs<'a>(&'a mut EditorState);

impl TabViewer for Tabs<'_> {
    type Tab = Tab;

    fn title(&mut self, tab: &mut Tab) -> egui::WidgetText {
        match tab {
            Tab::Viewport => "3D viewport".into(),
            Tab::Canvas => "UV canvas".into(),
            Tab::Layers => "Layers".into(),
        }
    }

    fn id(&mut self, tab: &mut Tab) -> egui::Id {
        egui::Id::new(*tab)
    }

    fn closeable(&mut self, _tab: &mut Tab) -> bool {
        false
    }

    fn ui(&mut self, ui: &mut egui::Ui, tab: &mut Tab) {
        let s = &mut *self.0;
        match tab {
            Tab::Viewport => {
                let mut settings = s.frame_settings();
                if s.shown_layer_view() == LayerView::Mask {
                    settings.view = ViewMode::Kd;
                }
                let mesh = (s.mesh.id, Arc::clone(&s.mesh.mesh));
                let maps = s.layers_panel.view_maps.get(&s.doc, s.shown_layer_view());
                let normal = s.doc.normal().cloned();
                s.viewport.ao_bake = s.doc.bake_of(kapaint_mesh::bakes::BakeMap::Ao).cloned();
                let (response, rect) =
                    s.viewport
                        .show(ui, (maps.0, maps.1, normal.as_ref()), &mesh, &settings);
                if std::mem::take(&mut s.viewport.untraced_requested) {
                    s.look.mode = s.look.mode.untraced();
                }
                s.layers_panel.painting_label(&s.doc, ui, rect);
                s.viewport_input(&response, rect);
            }
            Tab::Canvas => {
                let lines = Arc::clone(&s.mesh.uv_lines);
                // A bake the project no longer keeps (undone, or its mesh replaced): k_d again.
                if let CanvasChannel::Bake(map) = s.canvas.channel
                    && s.doc.bake_of(map).is_none()
                {
                    s.canvas.channel = CanvasChannel::Kd;
                }
                let channel = s.canvas.channel;
                if s.shown_layer_view() == LayerView::Mask {
                    s.canvas.channel = CanvasChannel::Kd;
                }
                let maps = s.layers_panel.view_maps.get(&s.doc, s.shown_layer_view());
                let (response, rect) = s.canvas.show(ui, &s.doc, maps, &lines);
                s.canvas.channel = channel;
                s.layers_panel.painting_label(&s.doc, ui, rect);
                s.canvas_input(&response, rect);
            }
            Tab::Layers => {
                egui::ScrollArea::vertical()
                    .id_salt("layers tab")
                    .show(ui, |ui| s.layers_ui(ui));
            }
        }
    }
}

impl Editor {
    /// Replaces the dock layout (as a saved one is restored at start).
    pub fn set_layout(&mut self, dock: DockState<Tab>) {
        self.dock = dock;
    }

    /// One frame of the whole editor.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let s = &mut self.state;
        s.jobs.waker = Some(ctx.clone());
        s.poll_job();
        let busy = s.busy();
        let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
        s.jobs.bake_on_demand.look(busy, &mut desk);
        let asks = desk.into_asks();
        s.carry_out(asks);
        s.track_pressure(&ctx);
        s.hotkeys(&ctx);
        s.follow_mesh();
        let channel = s.canvas_target();
        let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
        crate::panels::bars::dropped_files(&ctx, channel, &mut desk);
        let asks = desk.into_asks();
        s.carry_out(asks);
        let now = Instant::now();
        if let Some(Err(e)) = s.project.autosaver.poll(&s.doc, now) {
            s.notices
                .push(notice(format!("autosave failed: {e}"), true));
        }
        // An idle window draws no frames: wake up when the recovery copy falls due.
        if let Some(wait) = s.project.autosaver.next_poll(&s.doc, now) {
            ctx.request_repaint_after(wait);
        }
        s.pointer.shown_hover = s.pointer.hover.take();
        s.pointer.hover_tab = None;
        let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
        egui::Panel::top("menu").show(ui, |ui| {
            crate::panels::bars::menu_ui(ui, &s.project.recent, &mut desk);
        });
        let asks = desk.into_asks();
        s.carry_out(asks);
        let status = crate::panels::bars::Status {
            doc: &s.doc,
            job: s.jobs.current.as_ref(),
            viewport: &s.viewport,
            hover: s.pointer.shown_hover,
            exact_chi: &mut s.jobs.exact_chi,
        };
        egui::Panel::bottom("status").show(ui, |ui| status.ui(ui));
        egui::Panel::left("tools")
            .resizable(true)
            .default_size(250.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| s.tools_ui(ui));
            });
        egui::Panel::right("view")
            .resizable(true)
            .default_size(240.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| s.view_ui(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| {
            DockArea::new(&mut self.dock)
                .show_close_buttons(false)
                .show_leaf_close_all_buttons(false)
                .show_leaf_collapse_buttons(false)
                .show_inside(ui, &mut Tabs(s));
        });
        windows(s, &ctx);
        let chosen = s.dialogs.files.update(&ctx);
        s.file_chosen(chosen);
        if s.jobs.current.is_some() {
            // One progress update a second: on a software renderer each frame of the window
            // takes about 0.1 s of the CPU the job runs on (four a second slowed an AO bake
            // by a third). The worker wakes the window when it is done.
            ctx.request_repaint_after(JOB_REPAINT);
        }
        let title = s.window_title();
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        if let Some(start) = self.started.take()
            && std::env::var_os("KAPAINT_LOG_STARTUP").is_some()
        {
            eprintln!(
                "kapaint: first frame after {:.0} ms",
                start.elapsed().as_secs_f64() * 1000.0
            );
        }
    }
}

/// The editor's windows over the dock, each a view asking through a desk: the dialogs, the
/// recovery offer, the shortcut sheet, preferences, notices, then the prompts and the window
/// of a job the editor waits for.
fn windows(s: &mut EditorState, ctx: &egui::Context) {
    let dirty = s.dirty();
    let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
    let export = (&mut s.dialogs.export, &mut s.dialogs.export_choice);
    crate::export_dialog::export_window(export, s.project.path.as_deref(), ctx, &mut desk);
    let new = (&mut s.dialogs.new, &mut s.dialogs.pending_new);
    crate::dialogs::new_window(new, &s.presets.materials, dirty, ctx, &mut desk);
    crate::resize::resize_window(&mut s.dialogs.resize, ctx, &mut desk);
    crate::bake::bake_window(&mut s.dialogs.bake, ctx, &mut desk);
    crate::bake_high::high_window(&mut s.dialogs.bake_high, ctx, &mut desk);
    let camera = s.viewport.camera;
    crate::project_dialog::project_window(&mut s.dialogs.project, &camera, ctx, &mut desk);
    let asks = desk.into_asks();
    s.carry_out(asks);
    let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
    let offer = &mut s.prompts.recovery_offer;
    crate::dialogs::recovery_window(offer, &mut s.project, ctx, &mut desk);
    crate::dialogs::shortcuts_window(&mut s.dialogs.shortcuts_open, ctx);
    let open = &mut s.dialogs.preferences_open;
    crate::dialogs::preferences_window(open, s.preferences, ctx, &mut desk);
    let asks = desk.into_asks();
    s.carry_out(asks);
    crate::panels::bars::notices_ui(&mut s.notices, ctx);
    let dirty = s.dirty();
    let mut desk = Desk::new(&s.doc, &s.tools, s.pointer.seen());
    s.prompts.close_window(ctx, dirty, &mut desk);
    s.prompts.open_window(ctx, &mut desk);
    s.project.claim.prompt(ctx, &mut desk);
    s.prompts.material_window(ctx, &mut desk);
    crate::material_size::size_prompt_window(&mut s.prompts.size, ctx, &mut desk);
    s.prompts.unwrap_window(ctx, &mut desk);
    let asks = desk.into_asks();
    s.carry_out(asks);
    crate::jobs::modal_job_ui(s.modal_job(), ctx);
}

impl eframe::App for Editor {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }

    fn on_exit(&mut self) {
        save_layout(&self.dock);
        // A clean exit, or one whose changes the user discarded, leaves no recovery copy.
        if !self.state.dirty()
            || self.state.prompts.quit.allowed == Some(super::QuitAllowed::Discarded)
        {
            self.state.project.autosaver.discard();
        }
        self.state.project.claim.release();
    }
}

/// Opens the editor window (on `path` when given); returns the process exit code.
pub fn run(path: Option<PathBuf>) -> i32 {
    let start = Instant::now();
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("kapaint")
            .with_inner_size([1400.0, 900.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    match eframe::run_native(
        "kapaint",
        options,
        Box::new(move |cc| {
            let mut editor = Editor::new(cc.wgpu_render_state.as_ref(), path);
            editor.started = Some(start);
            Ok(Box::new(editor))
        }),
    ) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("kapaint: cannot open the editor window: {e}");
            1
        }
    }
}
