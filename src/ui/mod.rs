//! The editor (issue 7): an eframe app around the model. The UI reads the document and
//! changes it only through [`Command`]s; the GPU side ([`viewport`]) mirrors the maps.
//!
//! Layout: menu bar, tool and material panel on the left, view panel on the right, a dock
//! with the 3D viewport and the UV canvas in the middle, status bar at the bottom. Long work
//! (open, save, export) runs on named worker threads with a progress bar and cancel.

pub mod canvas;
mod dialogs;
pub mod viewport;

use dialogs::{ExportDialog, load_recent};
pub use dialogs::{NEW_SIZES, NewDialog, RECENT_MAX, push_recent};

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use egui::{Color32, Key, KeyboardShortcut, Modifiers};
use egui_dock::{DockArea, DockState, TabViewer};
use glam::Vec2;

use crate::mesh::Mesh;
use crate::mesh::pick::Bvh;
use crate::model::brush::{StrokePoint, SurfacePos};
use crate::model::document::MeshRef;
use crate::model::surface::Surface;
use crate::model::texel::Channel;
use crate::model::texel::MaterialValue;
use crate::model::{Command, Document, DocumentSettings, FillRegion, StrokeTool, project};
use crate::reflectance::{self, AmbientApprox, ShadingModel};
use crate::render::{FrameSettings, Lighting, ViewMode};
use crate::task::Progress;
use canvas::{Canvas, CanvasChannel};
use viewport::{Compare, Viewport, ViewportGpu};

/// Default map size of a new project.
pub const DEFAULT_SIZE: u32 = 1024;

/// Painting tools.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Paint the primary material (B).
    Brush,
    /// Paint the base material back (E).
    Eraser,
    /// Fill the clicked UV island, or the whole map on the canvas (F in 2D).
    Fill,
    /// Pick the material under the cursor (I).
    Picker,
    /// Drag a linear gradient from the primary to the secondary material on the canvas (G).
    Gradient,
}

impl Tool {
    const ALL: [(Self, &'static str, &'static str); 5] = [
        (Self::Brush, "Brush", "B"),
        (Self::Eraser, "Eraser", "E"),
        (Self::Gradient, "Gradient", "G (on the UV canvas)"),
        (Self::Fill, "Fill", "F (on the UV canvas)"),
        (Self::Picker, "Picker", "I"),
    ];
}

/// Dock tabs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Tab {
    /// The 3D viewport.
    Viewport,
    /// The UV canvas.
    Canvas,
}

/// A message for the user, shown for a while.
#[derive(Clone, Debug)]
pub struct Notice {
    /// Text.
    pub text: String,
    /// An error (red) rather than information.
    pub error: bool,
    at: Instant,
}

/// What a worker hands back.
enum JobResult {
    /// A project (to be saved at the path), and whether it came from a recovery copy.
    Opened(PathBuf, Box<Document>, bool),
    Saved(PathBuf, u64),
    Exported(PathBuf, Box<crate::export::set::Manifest>),
    /// A mesh loaded and baked at the map size.
    Mesh(PathBuf, Arc<Surface>),
    /// An image decoded for a channel.
    Image(Channel, PathBuf, Box<image::DynamicImage>),
    /// A new project (File > New), its mesh baked.
    Created(Box<Document>),
    /// A brush stamp read from an image.
    Stamp(PathBuf, crate::model::brush::Stamp),
    Failed(String),
}

/// Long work on a worker thread.
struct Job {
    label: String,
    progress: Arc<Progress>,
    handle: JoinHandle<JobResult>,
}

/// Screen points of a circle of `radius` (world units) around `centre` in the plane normal
/// to `normal`, seen by `camera` in `picture`.
pub fn brush_outline(
    camera: &crate::render::Camera,
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
            let world = centre + (t * a.cos() + b * a.sin()) * radius;
            let clip = view_proj * world.extend(1.0);
            (clip.w > 1e-6).then(|| {
                let ndc = clip.truncate() / clip.w;
                egui::Pos2::new(
                    picture.min.x + (ndc.x * 0.5 + 0.5) * picture.width(),
                    picture.min.y + (0.5 - ndc.y * 0.5) * picture.height(),
                )
            })
        })
        .collect()
}

/// A cheap identity of a stamp for its preview cache: size and a few samples' bits.
fn stamp_key(stamp: &crate::model::brush::Stamp) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (stamp.width, stamp.height).hash(&mut h);
    let step = (stamp.alpha.len() / 61).max(1);
    for v in stamp.alpha.iter().step_by(step) {
        v.to_bits().hash(&mut h);
    }
    h.finish()
}

/// A `size`^2 grey picture of a stamp (white where it paints).
fn stamp_image(stamp: &crate::model::brush::Stamp, size: usize) -> egui::ColorImage {
    let mut pixels = Vec::with_capacity(size * size);
    for y in 0..size {
        for x in 0..size {
            let at = |i: usize| (i as f32 + 0.5) / size as f32 * 2.0 - 1.0;
            let a = stamp.sample(at(x), at(y));
            pixels.push(Color32::from_gray((a * 255.0 + 0.5) as u8));
        }
    }
    egui::ColorImage::new([size, size], pixels)
}

/// The mesh being painted, with what picking and the renderer need.
struct MeshState {
    id: u64,
    mesh: Arc<Mesh>,
    bvh: Bvh,
    /// UV edges in map fractions (u, 1 - v), for the canvas wireframe.
    uv_lines: Vec<[Vec2; 2]>,
}

impl MeshState {
    fn new(mesh: Mesh, id: u64) -> Self {
        let bvh = Bvh::build(&mesh);
        let mut uv_lines = Vec::new();
        if let Some(uvs) = &mesh.uvs {
            for tri in &mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                    if a < b || mesh.triangles.len() < 4 {
                        let at = |i: usize| Vec2::new(uvs[i].x, 1.0 - uvs[i].y);
                        uv_lines.push([at(a), at(b)]);
                    }
                }
            }
        }
        Self {
            id,
            mesh: Arc::new(mesh),
            bvh,
            uv_lines,
        }
    }
}

/// Everything the panels and tabs read and change (the dock lives beside it).
pub struct EditorState {
    /// The document.
    pub doc: Document,
    /// Where it is saved.
    pub path: Option<PathBuf>,
    saved_version: u64,
    /// Current tool.
    pub tool: Tool,
    /// View mode of the viewport.
    pub view: ViewMode,
    /// Lights.
    pub lighting: Lighting,
    /// The 3D viewport.
    pub viewport: Viewport,
    /// The UV canvas.
    pub canvas: Canvas,
    mesh: MeshState,
    /// Messages.
    pub notices: Vec<Notice>,
    job: Option<Job>,
    export: Option<ExportDialog>,
    /// The New dialog, while open.
    pub new_dialog: Option<NewDialog>,
    /// A project to open once the user has decided about the unsaved changes.
    pub pending_open: Option<PathBuf>,
    /// Recently opened or saved projects, newest first.
    pub recent: Vec<PathBuf>,
    /// The pen's last pressure in the current stroke (1 with a mouse).
    pressure: f32,
    /// The brush stamp's preview texture, and which stamp it shows.
    stamp_preview: Option<(u64, egui::TextureHandle)>,
    /// The texel under the cursor, in either view.
    pub hover: Option<(u32, u32)>,
    /// The tab under the cursor.
    pub hover_tab: Option<Tab>,
    /// The tab whose drag is painting a stroke.
    stroking: Option<Tab>,
    /// Where a gradient drag started, in texels.
    gradient_start: Option<Vec2>,
    /// `hover` as of the last frame (the status bar is drawn before the tabs).
    shown_hover: Option<(u32, u32)>,
    quit_asked: bool,
    /// Set when the user confirmed closing with unsaved changes.
    pub allow_close: bool,
    /// A recovery copy found at start, newer than the project.
    pub recovery_offer: Option<PathBuf>,
    /// Material presets with their thumbnails (rendered a few per frame).
    presets: Vec<(String, MaterialValue, Option<egui::TextureHandle>)>,
    autosaver: project::Autosaver,
}

/// The editor app.
pub struct Editor {
    /// Panels' state.
    pub state: EditorState,
    dock: DockState<Tab>,
    /// When the process started, until the first frame is drawn (then logged to stderr when
    /// `KAPAINT_LOG_STARTUP` is set).
    started: Option<Instant>,
}

fn new_document(size: u32) -> Result<(Document, MeshState), String> {
    let doc = new_document_with(size, DocumentSettings::default())?;
    let mesh = doc.surface().map(|s| s.mesh.clone()).ok_or("no mesh")?;
    Ok((doc, MeshState::new(mesh, 1)))
}

/// A new `size`^2 document with `settings`, its mesh (built in or a file, as the settings
/// name it) attached and baked.
fn new_document_with(size: u32, settings: DocumentSettings) -> Result<Document, String> {
    let spec = settings.mesh.spec().to_string();
    let mesh = match crate::mesh::builtin(&spec) {
        Some(m) => m,
        None => crate::mesh::open(Path::new(&spec)).map_err(|e| e.to_string())?,
    };
    let mut doc = Document::new(size, size, settings).map_err(|e| e.to_string())?;
    attach(&mut doc, &mesh)?;
    Ok(doc)
}
/// Bakes `mesh` at the document's size and attaches it.
fn attach(doc: &mut Document, mesh: &Mesh) -> Result<(), String> {
    let surface = Surface::new(mesh.clone(), doc.maps.width(), doc.maps.height())?;
    doc.set_surface(Some(Arc::new(surface)))
        .map_err(|e| e.to_string())
}

/// Loads a project and its mesh (falling back to the sphere, with a note, if the mesh file is
/// gone).
fn load_project(path: &Path) -> Result<(Document, Mesh, Option<String>), String> {
    let mut doc = project::load(path).map_err(|e| e.to_string())?;
    let spec = PathBuf::from(doc.settings.mesh.spec());
    let spec = match path.parent() {
        Some(dir) if spec.is_relative() && !spec.exists() && dir.join(&spec).exists() => {
            dir.join(spec)
        }
        _ => spec,
    };
    let (mesh, note) = match crate::mesh::open(&spec) {
        Ok(m) => (m, None),
        Err(e) => (
            crate::mesh::builtin("sphere").ok_or("no built-in sphere")?,
            Some(format!("{e}; showing the sphere instead")),
        ),
    };
    attach(&mut doc, &mesh)?;
    Ok((doc, mesh, note))
}

impl Editor {
    /// The editor on a new default document (sphere, default material), or on `path` when
    /// given (a missing file becomes a new project saved there).
    pub fn new(
        render_state: Option<&eframe::egui_wgpu::RenderState>,
        path: Option<PathBuf>,
    ) -> Self {
        let gpu = render_state.map(ViewportGpu::new);
        let mut notices = Vec::new();
        let (doc, mesh) = match path.as_deref().filter(|p| p.exists()).map(load_project) {
            Some(Ok((doc, mesh, note))) => {
                if let Some(note) = note {
                    notices.push(notice(note, true));
                }
                (doc, MeshState::new(mesh, 1))
            }
            other => {
                if let Some(Err(e)) = other {
                    notices.push(notice(e, true));
                }
                match new_document(DEFAULT_SIZE) {
                    Ok(x) => x,
                    Err(e) => {
                        notices.push(notice(e, true));
                        let doc = Document::new(16, 16, DocumentSettings::default())
                            .unwrap_or_else(|_| unreachable_doc());
                        (doc, MeshState::new(crate::mesh::plane(), 1))
                    }
                }
            }
        };
        let mut viewport = Viewport::new(gpu);
        viewport.frame(&mesh.mesh);
        let recovery = project::recovery_path(path.as_deref());
        let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
        let recovery_offer = match (modified(&recovery), path.as_deref().and_then(modified)) {
            (Some(copy), Some(saved)) if copy > saved => Some(recovery.clone()),
            (Some(_), None) => Some(recovery.clone()),
            _ => None,
        };
        let autosaver = project::Autosaver::new(Duration::from_mins(2), recovery, &doc);
        let dock = load_layout().unwrap_or_else(default_layout);
        let saved_version = doc.maps.version();
        Self {
            state: EditorState {
                doc,
                path,
                saved_version,
                tool: Tool::Brush,
                view: ViewMode::Shaded,
                lighting: Lighting::default(),
                viewport,
                canvas: Canvas::default(),
                mesh,
                notices,
                job: None,
                export: None,
                new_dialog: None,
                pending_open: None,
                recent: load_recent(),
                stamp_preview: None,
                pressure: 1.0,
                hover: None,
                hover_tab: None,
                stroking: None,
                gradient_start: None,
                shown_hover: None,
                quit_asked: false,
                allow_close: false,
                recovery_offer,
                presets: crate::model::preset::builtin()
                    .into_iter()
                    .map(|(name, p)| (name, p.value(), None))
                    .collect(),
                autosaver,
            },
            dock,
            started: None,
        }
    }
}

/// The dock's first layout: the viewport left, the UV canvas right.
pub fn default_layout() -> DockState<Tab> {
    let mut dock = DockState::new(vec![Tab::Viewport]);
    dock.main_surface_mut()
        .split_right(egui_dock::NodeIndex::root(), 0.55, vec![Tab::Canvas]);
    dock
}

/// Where the dock layout is kept between runs.
fn layout_path() -> Option<PathBuf> {
    std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))
        .map(|d| d.join("kapaint").join("layout.json"))
}

/// The saved layout, if there is a readable one holding both tabs.
fn load_layout() -> Option<DockState<Tab>> {
    let text = std::fs::read(layout_path()?).ok()?;
    let dock: DockState<Tab> = serde_json::from_slice(&text).ok()?;
    (dock.find_tab(&Tab::Viewport).is_some() && dock.find_tab(&Tab::Canvas).is_some())
        .then_some(dock)
}

/// Saves the layout (atomically; failures only cost the layout).
fn save_layout(dock: &DockState<Tab>) {
    if let (Some(path), Ok(json)) = (layout_path(), serde_json::to_vec(dock)) {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let _ = crate::atomic::write_atomic(&path, &json);
    }
}

/// A 16 x 16 document cannot fail to allocate; this is only for the type checker.
fn unreachable_doc() -> Document {
    Document::from_parts(
        crate::model::MaterialMaps::new(1, 1, MaterialValue::default())
            .unwrap_or_else(|_| std::process::abort()),
        DocumentSettings::default(),
    )
}

fn notice(text: impl Into<String>, error: bool) -> Notice {
    Notice {
        text: text.into(),
        error,
        at: Instant::now(),
    }
}

/// Hotkeys (shown in tooltips and the README).
pub mod keys {
    use super::{Key, KeyboardShortcut, Modifiers};
    /// Undo.
    pub const UNDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
    /// Redo.
    pub const REDO: KeyboardShortcut =
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::Z);
    /// Redo (alternative).
    pub const REDO_Y: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
    /// Save.
    pub const SAVE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
    /// Save as.
    pub const SAVE_AS: KeyboardShortcut =
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::S);
    /// Open.
    pub const OPEN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
    /// New.
    pub const NEW: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::N);
    /// Export.
    pub const EXPORT: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::E);
    /// Quit (asks first when there are unsaved changes).
    pub const QUIT: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Q);
}

impl EditorState {
    /// Whether the maps changed since the last save.
    pub fn dirty(&self) -> bool {
        self.doc.maps.version() != self.saved_version
    }

    fn apply(&mut self, command: Command) {
        if let Err(e) = self.doc.apply(command) {
            self.notices.push(notice(e.to_string(), true));
        }
    }

    fn busy(&self) -> bool {
        self.job.is_some()
    }

    fn start_job(
        &mut self,
        label: &str,
        work: impl FnOnce(&Progress) -> JobResult + Send + 'static,
    ) {
        if self.busy() {
            self.notices
                .push(notice("wait for the current job to finish", true));
            return;
        }
        let progress = Arc::new(Progress::default());
        let shared = Arc::clone(&progress);
        match std::thread::Builder::new()
            .name(format!("kapaint-{}", label.to_lowercase()))
            .spawn(move || work(&shared))
        {
            Ok(handle) => {
                self.job = Some(Job {
                    label: label.into(),
                    progress,
                    handle,
                });
            }
            Err(e) => self
                .notices
                .push(notice(format!("cannot start {label}: {e}"), true)),
        }
    }

    fn poll_job(&mut self) {
        if !self.job.as_ref().is_some_and(|j| j.handle.is_finished()) {
            return;
        }
        let Some(job) = self.job.take() else { return };
        let result = job
            .handle
            .join()
            .unwrap_or_else(|_| JobResult::Failed(format!("{} failed unexpectedly", job.label)));
        match result {
            JobResult::Opened(path, doc, recovered) => {
                let mesh = doc.surface().map(|s| s.mesh.clone());
                self.doc = *doc;
                // Recovered work is unsaved work.
                self.saved_version = if recovered {
                    u64::MAX
                } else {
                    self.doc.maps.version()
                };
                if let Some(mesh) = mesh {
                    self.mesh = MeshState::new(mesh, self.mesh.id + 1);
                    self.viewport.frame(&self.mesh.mesh);
                }
                self.autosaver = project::Autosaver::new(
                    Duration::from_mins(2),
                    project::recovery_path(Some(&path)),
                    &self.doc,
                );
                self.notices
                    .push(notice(format!("opened {}", path.display()), false));
                self.remember(&path);
                self.path = Some(path);
            }
            JobResult::Saved(path, version) => {
                self.saved_version = version;
                self.notices
                    .push(notice(format!("saved {}", path.display()), false));
                self.remember(&path);
                self.path = Some(path);
                if !self.dirty()
                    && let Some(next) = self.pending_open.take()
                {
                    self.open_now(next);
                }
            }
            JobResult::Exported(dir, m) => self.notices.push(notice(
                format!(
                    "exported {} ({} files, {} bytes, k_a error max {:.2}% mean {:.3}%)",
                    dir.display(),
                    m.files.len(),
                    m.bytes.exported,
                    m.ka_error.max * 100.0,
                    m.ka_error.mean * 100.0
                ),
                false,
            )),
            JobResult::Mesh(path, surface) => {
                let mesh = surface.mesh.clone();
                let spec = MeshRef::from_spec(&path.display().to_string());
                match self.doc.set_mesh(spec, surface) {
                    Ok(()) => {
                        self.mesh = MeshState::new(mesh, self.mesh.id + 1);
                        self.viewport.frame(&self.mesh.mesh);
                        self.notices
                            .push(notice(format!("mesh {}", path.display()), false));
                    }
                    Err(e) => self.notices.push(notice(e.to_string(), true)),
                }
            }
            JobResult::Image(channel, path, image) => {
                crate::model::import::import_into(&mut self.doc, channel, &image);
                self.notices.push(notice(
                    format!("{} imported into {}", path.display(), channel.name()),
                    false,
                ));
            }
            JobResult::Created(doc) => {
                let mesh = doc.surface().map(|s| s.mesh.clone());
                self.doc = *doc;
                if let Some(mesh) = mesh {
                    self.mesh = MeshState::new(mesh, self.mesh.id + 1);
                    self.viewport.frame(&self.mesh.mesh);
                }
                self.saved_version = self.doc.maps.version();
                self.path = None;
                self.autosaver = project::Autosaver::new(
                    Duration::from_mins(2),
                    project::recovery_path(None),
                    &self.doc,
                );
            }
            JobResult::Stamp(path, stamp) => {
                let mut brush = self.doc.settings.brush.clone();
                brush.stamp = Some(stamp);
                self.apply(Command::SetBrush(brush));
                self.notices
                    .push(notice(format!("stamp {}", path.display()), false));
            }
            JobResult::Failed(e) => self.notices.push(notice(e, true)),
        }
    }

    /// Loads and bakes a mesh on a worker; it becomes the project's mesh.
    pub fn import_mesh(&mut self, path: PathBuf) {
        let (w, h) = (self.doc.maps.width(), self.doc.maps.height());
        self.start_job("Mesh", move |progress| {
            progress.start("load", 1);
            let mesh = match crate::mesh::open(&path) {
                Ok(m) => m,
                Err(e) => return JobResult::Failed(format!("{}: {e}", path.display())),
            };
            progress.start("bake", 1);
            match Surface::new(mesh, w, h) {
                Ok(s) => JobResult::Mesh(path, Arc::new(s)),
                Err(e) => JobResult::Failed(format!("{}: {e}", path.display())),
            }
        });
    }

    /// Loads a brush stamp from an image on a worker thread.
    pub fn load_stamp(&mut self, path: PathBuf) {
        self.start_job("Stamp", move |progress| {
            progress.start("decode", 1);
            match crate::model::import::read_stamp(&path) {
                Ok(stamp) => JobResult::Stamp(path, stamp),
                Err(e) => JobResult::Failed(e.to_string()),
            }
        });
    }

    /// The brush's stamp row: a preview of the stamp, the built-in grain, loading one from an
    /// image, and back to the round dab.
    fn stamp_ui(&mut self, ui: &mut egui::Ui, brush: &mut crate::model::brush::BrushSettings) {
        ui.horizontal(|ui| {
            ui.label("Stamp");
            match &brush.stamp {
                None => {
                    ui.label("round");
                }
                Some(stamp) => {
                    let key = stamp_key(stamp);
                    if self.stamp_preview.as_ref().is_none_or(|(k, _)| *k != key) {
                        let image = stamp_image(stamp, 32);
                        let texture = ui.ctx().load_texture(
                            "brush stamp",
                            image,
                            egui::TextureOptions::LINEAR,
                        );
                        self.stamp_preview = Some((key, texture));
                    }
                    if let Some((_, texture)) = &self.stamp_preview {
                        ui.image((texture.id(), egui::vec2(32.0, 32.0)))
                            .on_hover_text(format!("{}x{} stamp", stamp.width, stamp.height));
                    }
                }
            }
            if ui
                .button("Grain")
                .on_hover_text("A built-in grainy stamp")
                .clicked()
            {
                brush.stamp = Some(crate::model::brush::Stamp::grain(64));
            }
            if ui
                .button("Load…")
                .on_hover_text("A stamp from an image (luminance times alpha)")
                .clicked()
                && let Some(p) = rfd::FileDialog::new()
                    .add_filter("image", &["png", "jpg", "jpeg", "tga", "exr"])
                    .pick_file()
            {
                self.load_stamp(p);
            }
            if brush.stamp.is_some() && ui.button("Round").clicked() {
                brush.stamp = None;
            }
        });
    }

    /// Decodes an image on a worker and writes it into `channel` (one undo step).
    pub fn import_image(&mut self, path: PathBuf, channel: Channel) {
        self.start_job("Image", move |progress| {
            progress.start("decode", 1);
            match crate::model::import::read_image(&path) {
                Ok(image) => JobResult::Image(channel, path, Box::new(image)),
                Err(e) => JobResult::Failed(e.to_string()),
            }
        });
    }

    /// The channel the canvas shows (`k_d` for the derived `k_a`): where dropped images go.
    fn canvas_target(&self) -> Channel {
        match self.canvas.channel {
            CanvasChannel::Ks => Channel::Ks,
            CanvasChannel::N => Channel::N,
            CanvasChannel::Kd | CanvasChannel::Ka => Channel::Kd,
        }
    }

    /// Saves to `path` on a worker (a snapshot of the maps, so painting goes on).
    pub fn save_to(&mut self, path: PathBuf) {
        let snapshot = Document::from_parts(self.doc.maps.clone(), self.doc.settings.clone());
        let version = self.doc.maps.version();
        self.start_job("Save", move |progress| {
            progress.start("save", 1);
            match project::save(&snapshot, &path) {
                Ok(()) => JobResult::Saved(path, version),
                Err(e) => JobResult::Failed(format!("could not save: {e}")),
            }
        });
    }

    /// Opens `path` on a worker.
    pub fn open(&mut self, path: PathBuf) {
        if self.dirty() {
            // Unsaved work is never dropped: ask first (see `open_prompt`).
            self.pending_open = Some(path);
            return;
        }
        self.open_now(path);
    }

    fn open_now(&mut self, path: PathBuf) {
        self.start_job("Open", move |progress| {
            progress.start("open", 1);
            match load_project(&path) {
                Ok((doc, _, _)) => JobResult::Opened(path, Box::new(doc), false),
                Err(e) => JobResult::Failed(format!("could not open {}: {e}", path.display())),
            }
        });
    }

    /// Opens the recovery copy `from` as the project at `path` (unsaved).
    fn recover(&mut self, from: PathBuf, path: Option<PathBuf>) {
        self.start_job("Recover", move |progress| {
            progress.start("open", 1);
            match load_project(&from) {
                Ok((doc, _, _)) => {
                    JobResult::Opened(path.unwrap_or_else(|| from.clone()), Box::new(doc), true)
                }
                Err(e) => JobResult::Failed(format!("could not recover {}: {e}", from.display())),
            }
        });
    }

    fn save(&mut self) {
        match self.path.clone() {
            Some(p) => self.save_to(p),
            None => self.save_as(),
        }
    }

    fn save_as(&mut self) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("kapaint project", &["kapaint"])
            .set_file_name("material.kapaint")
            .save_file()
        {
            self.save_to(p);
        }
    }

    fn open_dialog(&mut self) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("kapaint project", &["kapaint"])
            .pick_file()
        {
            self.open(p);
        }
    }

    /// Hotkeys: tools, brush size and hardness, swap, undo/redo, files.
    fn hotkeys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let mut commands = Vec::new();
        ctx.input_mut(|i| {
            for (shortcut, action) in [
                (keys::REDO, 1),
                (keys::REDO_Y, 1),
                (keys::UNDO, 0),
                (keys::SAVE_AS, 3),
                (keys::SAVE, 2),
                (keys::OPEN, 4),
                (keys::NEW, 5),
                (keys::EXPORT, 6),
                (keys::QUIT, 7),
            ] {
                if i.consume_shortcut(&shortcut) {
                    commands.push(action);
                }
            }
        });
        for action in commands {
            match action {
                0 => self.apply(Command::Undo),
                1 => self.apply(Command::Redo),
                2 => self.save(),
                3 => self.save_as(),
                4 => self.open_dialog(),
                5 => self.new_project(),
                6 => self.open_export(),
                _ => self.quit_asked = true,
            }
        }
        let (shift, pressed) = ctx.input(|i| {
            let keys = [
                Key::B,
                Key::E,
                Key::G,
                Key::I,
                Key::X,
                Key::OpenBracket,
                Key::CloseBracket,
                Key::F,
            ];
            let pressed: Vec<Key> = if i.modifiers.command || i.modifiers.alt {
                Vec::new()
            } else {
                keys.into_iter().filter(|k| i.key_pressed(*k)).collect()
            };
            (i.modifiers.shift, pressed)
        });
        let mut brush = self.doc.settings.brush.clone();
        for key in pressed {
            match key {
                Key::B => self.tool = Tool::Brush,
                Key::E => self.tool = Tool::Eraser,
                Key::G => self.tool = Tool::Gradient,
                Key::I => self.tool = Tool::Picker,
                Key::X => self.apply(Command::SwapMaterials),
                Key::OpenBracket if shift => brush.hardness = (brush.hardness - 0.1).max(0.0),
                Key::CloseBracket if shift => brush.hardness = (brush.hardness + 0.1).min(1.0),
                Key::OpenBracket => brush.radius_px = (brush.radius_px / 1.25).max(0.5),
                Key::CloseBracket => brush.radius_px = (brush.radius_px * 1.25).min(2048.0),
                Key::F => {
                    // F fills on the canvas, frames the mesh in the viewport.
                    if self.hover_tab == Some(Tab::Canvas) {
                        self.tool = Tool::Fill;
                    } else {
                        self.viewport.frame(&self.mesh.mesh);
                    }
                }
                _ => {}
            }
        }
        if brush != self.doc.settings.brush {
            self.apply(Command::SetBrush(brush));
        }
    }
}

impl EditorState {
    /// The texel under a map-space position, if inside.
    fn texel_at(&self, p: Vec2) -> Option<(u32, u32)> {
        let (w, h) = (self.doc.maps.width(), self.doc.maps.height());
        (p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32)
            .then_some((p.x as u32, p.y as u32))
    }

    /// The fill region for a click at a texel: its UV island when the mesh covers it, else
    /// the whole map.
    fn fill_region(&self, (x, y): (u32, u32)) -> FillRegion {
        let on_island = self.doc.surface().is_some_and(|s| {
            let k = (y * s.bake.width + x) as usize;
            s.bake.island.get(k).is_some_and(|i| *i != u32::MAX)
        });
        if on_island {
            FillRegion::Island { x, y }
        } else {
            FillRegion::All
        }
    }

    fn stroke_tool(&self) -> Option<StrokeTool> {
        match self.tool {
            Tool::Brush => Some(StrokeTool::Brush),
            Tool::Eraser => Some(StrokeTool::Eraser),
            Tool::Fill | Tool::Picker | Tool::Gradient => None,
        }
    }

    /// Follows the pen's pressure where the platform delivers it (egui reports a tablet pen's
    /// force with its touch events); kept until the stroke ends, 1 for a mouse.
    fn track_pressure(&mut self, ctx: &egui::Context) {
        let force = ctx.input(|i| {
            i.events.iter().rev().find_map(|e| match e {
                egui::Event::Touch { force: Some(f), .. } if f.is_finite() => {
                    Some(f.clamp(0.0, 1.0))
                }
                _ => None,
            })
        });
        if let Some(f) = force {
            self.pressure = f;
        }
    }

    /// A click of the fill or picker tool on texel `t`.
    fn click_texel(&mut self, t: (u32, u32)) {
        match self.tool {
            Tool::Fill => {
                let region = self.fill_region(t);
                self.apply(Command::Fill(region));
            }
            _ => self.apply(Command::Pick { x: t.0, y: t.1 }),
        }
    }

    /// Ends the stroke that `tab` is painting once its button is released.
    fn end_stroke_on_release(&mut self, tab: Tab, response: &egui::Response) {
        if self.stroking == Some(tab)
            && (response.drag_stopped() || !response.is_pointer_button_down_on())
        {
            self.end_stroke();
        }
    }

    fn end_stroke(&mut self) {
        self.pressure = 1.0;
        if self.stroking.take().is_some() {
            self.apply(Command::EndStroke);
        }
    }

    fn begin_stroke(&mut self, tab: Tab, tool: StrokeTool) {
        if self.stroking.is_none() {
            self.stroking = Some(tab);
            self.apply(Command::BeginStroke(tool));
        }
    }

    /// Paints from a canvas response.
    fn canvas_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let size = (self.doc.maps.width(), self.doc.maps.height());
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let pos = pointer.map(|p| self.canvas.to_texel(rect, p, size));
        if response.hovered() {
            self.hover = pos.and_then(|p| self.texel_at(p));
            self.hover_tab = Some(Tab::Canvas);
        }
        let space = response.ctx.input(|i| i.key_down(Key::Space));
        let primary = response.dragged_by(egui::PointerButton::Primary) && !space;
        if self.tool == Tool::Gradient {
            self.gradient_input(response, pos, rect, primary);
            return;
        }
        match (self.stroke_tool(), pos) {
            (Some(tool), Some(p)) if primary || (response.clicked() && !space) => {
                self.begin_stroke(Tab::Canvas, tool);
                let pressure = self.pressure;
                self.apply(Command::StrokeTo(StrokePoint {
                    pos: glam::Vec2::new(p.x, p.y),
                    pressure,
                }));
                if response.clicked() {
                    self.end_stroke();
                }
            }
            (None, Some(p)) if response.clicked() => {
                if let Some(t) = self.texel_at(p) {
                    self.click_texel(t);
                }
            }
            _ => {}
        }
        self.end_stroke_on_release(Tab::Canvas, response);
    }

    /// The gradient tool on the canvas: drag from start to end, applied on release.
    fn gradient_input(
        &mut self,
        response: &egui::Response,
        pos: Option<Vec2>,
        rect: egui::Rect,
        primary: bool,
    ) {
        if response.drag_started_by(egui::PointerButton::Primary) {
            self.gradient_start = pos;
        }
        if let (Some(start), Some(end)) = (self.gradient_start, pos) {
            if primary {
                let size = (self.doc.maps.width(), self.doc.maps.height());
                let at = |p: Vec2| {
                    rect.min + egui::vec2(p.x / size.0 as f32, p.y / size.1 as f32) * rect.size()
                };
                response.ctx.layer_painter(response.layer_id).arrow(
                    at(start),
                    at(end) - at(start),
                    egui::Stroke::new(2.0, egui::Color32::WHITE),
                );
            }
            if response.drag_stopped() {
                self.gradient_start = None;
                self.apply(Command::Gradient {
                    shape: crate::model::paint::GradientShape::Linear,
                    start,
                    end,
                });
            }
        }
    }

    /// Paints from a viewport response (left button, not with Alt).
    fn viewport_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let alt = response.ctx.input(|i| i.modifiers.alt);
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let hit =
            pointer.and_then(|p| self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh));
        if response.hovered() {
            self.hover_tab = Some(Tab::Viewport);
            self.hover = hit.as_ref().and_then(|h| h.uv).and_then(|uv| {
                self.texel_at(Vec2::new(
                    uv.x * self.doc.maps.width() as f32,
                    (1.0 - uv.y) * self.doc.maps.height() as f32,
                ))
            });
        }
        let primary = response.dragged_by(egui::PointerButton::Primary) && !alt;
        match (self.stroke_tool(), hit) {
            (Some(tool), Some(hit)) if primary || (response.clicked() && !alt) => {
                self.begin_stroke(Tab::Viewport, tool);
                let pressure = self.pressure;
                self.apply(Command::SurfaceStrokeTo(StrokePoint {
                    pos: SurfacePos {
                        point: hit.position,
                        normal: hit.normal,
                    },
                    pressure,
                }));
                if response.clicked() {
                    self.end_stroke();
                }
            }
            (None, Some(_)) if response.clicked() && !alt => {
                if let Some(t) = self.hover {
                    self.click_texel(t);
                }
            }
            _ => {}
        }
        self.end_stroke_on_release(Tab::Viewport, response);
        // The brush circle, projected on the surface: a circle of the dab's world radius in
        // the tangent plane under the cursor, drawn through the camera.
        if let (Some(p), Some(surface)) = (response.hover_pos(), self.doc.surface())
            && self.stroke_tool().is_some()
            && let Some(hit) = self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh)
        {
            let world = self.doc.settings.brush.radius_px * surface.units_per_texel;
            let picture = self.viewport.picture_at(rect, p);
            let points = brush_outline(
                &self.viewport.camera,
                picture,
                hit.position,
                hit.normal,
                world,
            );
            response
                .ctx
                .layer_painter(response.layer_id)
                .add(egui::Shape::closed_line(
                    points,
                    egui::Stroke::new(1.0, egui::Color32::WHITE),
                ));
        }
    }

    fn frame_settings(&self) -> FrameSettings {
        FrameSettings {
            model: self.doc.settings.model,
            approx: self.doc.settings.approx,
            view: self.view,
            lighting: self.lighting,
            camera: self.viewport.camera,
        }
    }

    /// Left panel: tools, brush, material, channels.
    fn tools_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Tools");
        ui.horizontal_wrapped(|ui| {
            for (tool, label, key) in Tool::ALL {
                ui.selectable_value(&mut self.tool, tool, label)
                    .on_hover_text(format!("{label} ({key})"));
            }
        });
        ui.separator();
        ui.heading("Brush settings");
        let mut brush = self.doc.settings.brush.clone();
        ui.add(
            egui::Slider::new(&mut brush.radius_px, 0.5..=512.0)
                .logarithmic(true)
                .text("Radius"),
        )
        .on_hover_text("[ and ] change the size");
        ui.add(egui::Slider::new(&mut brush.hardness, 0.0..=1.0).text("Hardness"))
            .on_hover_text("Shift+[ and Shift+] change the hardness");
        ui.add(egui::Slider::new(&mut brush.opacity, 0.0..=1.0).text("Opacity"));
        ui.add(egui::Slider::new(&mut brush.flow, 0.0..=1.0).text("Flow"));
        ui.add(egui::Slider::new(&mut brush.spacing_percent, 1.0..=200.0).text("Spacing %"));
        ui.add(egui::Slider::new(&mut brush.jitter, 0.0..=1.0).text("Jitter"));
        ui.checkbox(&mut brush.pressure_size, "Pressure: size");
        ui.checkbox(&mut brush.pressure_opacity, "Pressure: opacity");
        self.stamp_ui(ui, &mut brush);
        if brush != self.doc.settings.brush {
            self.apply(Command::SetBrush(brush));
        }
        ui.separator();
        ui.heading("Material");
        let mut primary = self.doc.settings.primary;
        ui.horizontal(|ui| {
            let mut kd = primary.kd.to_array();
            egui::color_picker::color_edit_button_rgb(ui, &mut kd)
                .on_hover_text("Diffuse colour k_d (linear)");
            ui.label("k_d");
            primary.kd = glam::Vec3::from(kd);
            let mut ks = primary.ks.to_array();
            egui::color_picker::color_edit_button_rgb(ui, &mut ks)
                .on_hover_text("Specular colour k_s (linear)");
            ui.label("k_s");
            primary.ks = glam::Vec3::from(ks);
        });
        let mut grey = primary.ks.max_element();
        if ui
            .add(egui::Slider::new(&mut grey, 0.0..=1.0).text("k_s (grey)"))
            .changed()
        {
            primary.ks = glam::Vec3::splat(grey);
        }
        ui.add(
            egui::Slider::new(&mut primary.n, 0.0..=crate::model::texel::N_MAX)
                .logarithmic(true)
                .text("n"),
        );
        let other = match self.doc.settings.model {
            ShadingModel::Phong => ShadingModel::BlinnPhong,
            ShadingModel::BlinnPhong => ShadingModel::Phong,
        };
        let eq = reflectance::equivalent::equivalent_exponent(
            self.doc.settings.model,
            f64::from(primary.n),
        );
        ui.label(format!("≈ n {eq:.1} in {}", other.name()))
            .on_hover_text("The exponent of the other model with the closest highlight");
        if primary != self.doc.settings.primary {
            self.apply(Command::SetPrimary(primary));
        }
        if ui
            .button("Swap primary / secondary")
            .on_hover_text("X")
            .clicked()
        {
            self.apply(Command::SwapMaterials);
        }
        ui.separator();
        ui.heading("Channels");
        let mut ch = self.doc.settings.channels;
        ui.horizontal(|ui| {
            ui.checkbox(&mut ch.kd, "k_d");
            ui.checkbox(&mut ch.ks, "k_s");
            ui.checkbox(&mut ch.n, "n");
        });
        if ch != self.doc.settings.channels {
            self.apply(Command::SetChannels(ch));
        }
    }

    /// Compare controls: the mode, then each side's model and approximation, the divider or
    /// the heatmap's scale.
    fn compare_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Compare");
        let c = &mut self.viewport.comparison;
        ui.horizontal_wrapped(|ui| {
            for (mode, label) in Compare::ALL {
                ui.selectable_value(&mut c.mode, mode, label);
            }
        });
        if c.mode == Compare::Single {
            return;
        }
        for (name, side) in [("Left", &mut c.left), ("Right", &mut c.right)] {
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt(("compare model", name))
                    .selected_text(side.model.name())
                    .show_ui(ui, |ui| {
                        for m in ShadingModel::ALL {
                            ui.selectable_value(&mut side.model, m, m.name());
                        }
                    });
                egui::ComboBox::from_id_salt(("compare approx", name))
                    .selected_text(side.approx.name())
                    .show_ui(ui, |ui| {
                        for a in AmbientApprox::ALL {
                            ui.selectable_value(&mut side.approx, a, a.name());
                        }
                    });
                ui.label(name);
            });
        }
        match c.mode {
            Compare::Split => {
                ui.add(egui::Slider::new(&mut c.split_at, 0.0..=1.0).text("Divider"))
                    .on_hover_text("Or drag the line in the viewport");
            }
            Compare::Difference => {
                ui.add(
                    egui::Slider::new(&mut c.diff_max, 1e-4..=1.0)
                        .logarithmic(true)
                        .text("Heat scale"),
                )
                .on_hover_text("The difference |left - right| shown white");
            }
            Compare::Single | Compare::SideBySide => {}
        }
    }

    /// Right panel: model, view, compare, light, canvas channel, history.
    fn view_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Shading");
        let mut model = self.doc.settings.model;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut model, ShadingModel::Phong, "Phong (8)");
            ui.selectable_value(&mut model, ShadingModel::BlinnPhong, "Blinn-Phong (11)");
        });
        if model != self.doc.settings.model {
            self.apply(Command::SetModel(model));
        }
        let mut approx = self.doc.settings.approx;
        egui::ComboBox::from_label("Approximation")
            .selected_text(approx.name())
            .show_ui(ui, |ui| {
                for a in AmbientApprox::ALL {
                    ui.selectable_value(&mut approx, a, a.name());
                }
            });
        if approx != self.doc.settings.approx {
            self.apply(Command::SetApprox(approx));
        }
        self.compare_ui(ui);
        ui.heading("View");
        egui::ComboBox::from_label("View mode")
            .selected_text(self.view.name())
            .show_ui(ui, |ui| {
                for v in ViewMode::ALL {
                    ui.selectable_value(&mut self.view, v, v.name());
                }
            });
        egui::ComboBox::from_label("Canvas shows")
            .selected_text(self.canvas.channel.label())
            .show_ui(ui, |ui| {
                for c in CanvasChannel::ALL {
                    ui.selectable_value(&mut self.canvas.channel, c, c.label());
                }
            });
        ui.checkbox(&mut self.canvas.wireframe, "UV wireframe");
        ui.heading("Light");
        let l = self.lighting.light.normalize_or(glam::Vec3::Z);
        let (mut yaw, mut pitch) = (l.x.atan2(l.z), l.y.clamp(-1.0, 1.0).asin());
        let a = ui.add(
            egui::Slider::new(&mut yaw, -std::f32::consts::PI..=std::f32::consts::PI)
                .text("Light yaw"),
        );
        let b = ui.add(egui::Slider::new(&mut pitch, -1.55..=1.55).text("Light pitch"));
        if a.changed() || b.changed() {
            self.lighting.light = glam::Vec3::new(
                pitch.cos() * yaw.sin(),
                pitch.sin(),
                pitch.cos() * yaw.cos(),
            );
        }
        ui.add(egui::Slider::new(&mut self.lighting.ia, 0.0..=2.0).text("Ambient I_a"));
        ui.add(egui::Slider::new(&mut self.lighting.il, 0.0..=4.0).text("Light I_l"));
        egui::CollapsingHeader::new("Material presets")
            .default_open(true)
            .show(ui, |ui| self.presets_panel(ui));
        ui.heading("History");
        ui.label(format!(
            "{} steps, {:.1} MB",
            self.doc.history.undo_steps().count(),
            self.doc.history.bytes() as f64 / 1e6
        ));
        egui::ScrollArea::vertical()
            .max_height(160.0)
            .show(ui, |ui| {
                for step in self
                    .doc
                    .history
                    .undo_steps()
                    .collect::<Vec<_>>()
                    .iter()
                    .rev()
                {
                    ui.label(format!("{} ({} KB)", step.label, step.bytes() / 1024));
                }
            });
    }

    /// Renders a thumbnail: on the GPU with the preview renderer, else with the CPU reference
    /// renderer (the same shading, ray traced).
    fn thumbnail(&mut self, value: MaterialValue) -> egui::ColorImage {
        const SIZE: u32 = 56;
        let camera = crate::render::Camera::default()
            .orbit(0.5, 0.35)
            .framing(&self.mesh.mesh.positions);
        let settings = FrameSettings {
            camera,
            view: ViewMode::Shaded,
            ..self.frame_settings()
        };
        let mesh = (self.mesh.id, Arc::clone(&self.mesh.mesh));
        if let Some(image) = self
            .viewport
            .gpu
            .as_mut()
            .and_then(|g| g.thumbnail(&mesh, value, &settings, SIZE))
        {
            return image;
        }
        let material = crate::render::reference::Material::Uniform(crate::render::Sample {
            kd: value.kd,
            ks: value.ks,
            n: value.n,
        });
        let pixels = crate::render::reference::render(
            &self.mesh.mesh,
            &self.mesh.bvh,
            &material,
            &settings,
            SIZE,
            SIZE,
        );
        let c = |x: f32| (crate::model::texel::linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0) as u8;
        let rgba: Vec<u8> = pixels
            .iter()
            .flat_map(|p| [c(p.x), c(p.y), c(p.z), (p.w.clamp(0.0, 1.0) * 255.0) as u8])
            .collect();
        egui::ColorImage::from_rgba_unmultiplied([SIZE as usize; 2], &rgba)
    }

    /// The preset browser: thumbnails, a click makes the preset the primary material.
    fn presets_panel(&mut self, ui: &mut egui::Ui) {
        // A few thumbnails per frame keep the first frames fast.
        let mut budget = 3;
        for i in 0..self.presets.len() {
            if self.presets[i].2.is_none() && budget > 0 {
                budget -= 1;
                let image = self.thumbnail(self.presets[i].1);
                let name = self.presets[i].0.clone();
                self.presets[i].2 = Some(ui.ctx().load_texture(
                    name,
                    image,
                    egui::TextureOptions::LINEAR,
                ));
            }
        }
        if budget == 0 {
            ui.ctx().request_repaint();
        }
        let mut chosen = None;
        ui.horizontal_wrapped(|ui| {
            for (name, value, texture) in &self.presets {
                let response = match texture {
                    Some(t) => ui.add(egui::Button::image(
                        egui::Image::from_texture(egui::load::SizedTexture::from_handle(t))
                            .fit_to_exact_size(egui::vec2(40.0, 40.0)),
                    )),
                    None => ui.add_sized([48.0, 48.0], egui::Button::new("…")),
                };
                if response
                    .on_hover_text(format!(
                        "{name}: k_d {:.2} {:.2} {:.2}, k_s {:.2}, n {:.0}",
                        value.kd.x, value.kd.y, value.kd.z, value.ks.x, value.n
                    ))
                    .clicked()
                {
                    chosen = Some(*value);
                }
            }
        });
        if let Some(v) = chosen {
            self.apply(Command::SetPrimary(v));
        }
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let maps = &self.doc.maps;
            ui.label(format!("{}x{}", maps.width(), maps.height()));
            ui.separator();
            ui.label(format!(
                "maps {:.0} MB, history {:.0} MB",
                maps.heap_bytes() as f64 / 1e6,
                self.doc.history.bytes() as f64 / 1e6
            ));
            ui.separator();
            match &self.viewport.gpu {
                Some(g) => ui.label(format!(
                    "frame {:.1} ms, viewport {:.1} ms ({})",
                    ui.input(|i| i.stable_dt) * 1000.0,
                    self.viewport.frame_ms,
                    g.adapter()
                )),
                None => ui.label("no GPU"),
            };
            if let Some((x, y)) = self.shown_hover {
                let v = maps.value(x, y);
                let ka = |m, a| reflectance::ka(m, a, v.kd, v.ks, v.n);
                let approx = self.doc.settings.approx;
                let phong = ka(ShadingModel::Phong, approx);
                let blinn = ka(ShadingModel::BlinnPhong, approx);
                let exact = |m| {
                    v.kd * reflectance::diffuse_factor(AmbientApprox::Fast) as f32
                        + v.ks
                            * reflectance::exact::chi_exact(m, f64::from(v.n)) as f32
                };
                let model = self.doc.settings.model;
                ui.separator();
                ui.label(format!(
                    "({x}, {y}) k_d {:.3} {:.3} {:.3}  k_s {:.3}  n {:.1}  k_a eq.8 {:.4}  eq.11 {:.4}  exact {:.4}",
                    v.kd.x, v.kd.y, v.kd.z, v.ks.x, v.n, phong.x, blinn.x, exact(model).x
                ))
                .on_hover_text("k_a of the red channel: Phong by eq. (8), Blinn-Phong by eq. (11), and the exact integral for the current model");
            }
            if let Some(job) = &self.job {
                ui.separator();
                ui.add(
                    egui::ProgressBar::new(job.progress.fraction())
                        .desired_width(160.0)
                        .text(format!("{} {}", job.label, job.progress.stage())),
                );
                if ui.button("Cancel").clicked() {
                    job.progress.cancel();
                }
            }
        });
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                let item = |ui: &mut egui::Ui, label: &str, key: &KeyboardShortcut| {
                    ui.add(egui::Button::new(label).shortcut_text(ui.ctx().format_shortcut(key)))
                        .clicked()
                };
                if item(ui, "New", &keys::NEW) {
                    self.new_project();
                }
                if item(ui, "Open…", &keys::OPEN) {
                    self.open_dialog();
                }
                ui.menu_button("Open Recent", |ui| {
                    if self.recent.is_empty() {
                        ui.label("No recent files");
                    }
                    let mut chosen = None;
                    for p in &self.recent {
                        let name = p.file_name().map_or_else(
                            || p.display().to_string(),
                            |n| n.to_string_lossy().into_owned(),
                        );
                        if ui
                            .button(name)
                            .on_hover_text(p.display().to_string())
                            .clicked()
                        {
                            chosen = Some(p.clone());
                        }
                    }
                    if let Some(p) = chosen {
                        self.open(p);
                    }
                });
                if item(ui, "Save", &keys::SAVE) {
                    self.save();
                }
                if item(ui, "Save As…", &keys::SAVE_AS) {
                    self.save_as();
                }
                if item(ui, "Export…", &keys::EXPORT) {
                    self.open_export();
                }
                ui.separator();
                if ui.button("Import mesh…").clicked()
                    && let Some(p) = rfd::FileDialog::new()
                        .add_filter("mesh", &["obj", "gltf", "glb"])
                        .pick_file()
                {
                    self.import_mesh(p);
                }
                for channel in [Channel::Kd, Channel::Ks, Channel::N] {
                    if ui
                        .button(format!("Import image into {}…", channel.name()))
                        .clicked()
                        && let Some(p) = rfd::FileDialog::new()
                            .add_filter("image", &["png", "jpg", "jpeg", "tga", "exr"])
                            .pick_file()
                    {
                        self.import_image(p, channel);
                    }
                }
                ui.separator();
                if item(ui, "Quit", &keys::QUIT) {
                    self.quit_asked = true;
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add(
                        egui::Button::new("Undo")
                            .shortcut_text(ui.ctx().format_shortcut(&keys::UNDO)),
                    )
                    .clicked()
                {
                    self.apply(Command::Undo);
                }
                if ui
                    .add(
                        egui::Button::new("Redo")
                            .shortcut_text(ui.ctx().format_shortcut(&keys::REDO)),
                    )
                    .clicked()
                {
                    self.apply(Command::Redo);
                }
            });
        });
    }

    fn dropped_files(&mut self, ctx: &egui::Context) {
        let files: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        for path in files {
            let ext = path
                .extension()
                .map(|e| e.to_string_lossy().to_lowercase())
                .unwrap_or_default();
            match ext.as_str() {
                "kapaint" => self.open(path),
                "obj" | "gltf" | "glb" => self.import_mesh(path),
                "png" | "jpg" | "jpeg" | "tga" | "exr" => {
                    let channel = self.canvas_target();
                    self.import_image(path, channel);
                }
                _ => self.notices.push(notice(
                    format!(
                        "{}: drop a project (.kapaint), a mesh (.obj, .gltf, .glb) or an image",
                        path.display()
                    ),
                    true,
                )),
            }
        }
    }

    fn notices(&mut self, ctx: &egui::Context) {
        self.notices
            .retain(|n| n.at.elapsed() < Duration::from_secs(if n.error { 12 } else { 5 }));
        if self.notices.is_empty() {
            return;
        }
        egui::Area::new(egui::Id::new("notices"))
            .anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-12.0, -36.0))
            .show(ctx, |ui| {
                for n in &self.notices {
                    let colour = if n.error {
                        egui::Color32::from_rgb(220, 80, 80)
                    } else {
                        egui::Color32::from_rgb(120, 200, 120)
                    };
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.colored_label(colour, &n.text);
                    });
                }
            });
        ctx.request_repaint_after(Duration::from_millis(500));
    }
}

struct Tabs<'a>(&'a mut EditorState);

impl TabViewer for Tabs<'_> {
    type Tab = Tab;

    fn title(&mut self, tab: &mut Tab) -> egui::WidgetText {
        match tab {
            Tab::Viewport => "3D viewport".into(),
            Tab::Canvas => "UV canvas".into(),
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
                let settings = s.frame_settings();
                let mesh = (s.mesh.id, Arc::clone(&s.mesh.mesh));
                let (response, rect) = s.viewport.show(ui, &s.doc, &mesh, &settings);
                s.viewport_input(&response, rect);
            }
            Tab::Canvas => {
                let lines = std::mem::take(&mut s.mesh.uv_lines);
                let (response, rect) = s.canvas.show(ui, &s.doc, &lines);
                s.mesh.uv_lines = lines;
                s.canvas_input(&response, rect);
            }
        }
    }
}

impl Editor {
    /// One frame of the whole editor.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let s = &mut self.state;
        s.poll_job();
        s.track_pressure(&ctx);
        s.hotkeys(&ctx);
        s.dropped_files(&ctx);
        if let Some(Err(e)) = s.autosaver.poll(&s.doc, Instant::now()) {
            s.notices
                .push(notice(format!("autosave failed: {e}"), true));
        }
        s.shown_hover = s.hover.take();
        s.hover_tab = None;
        egui::Panel::top("menu").show(ui, |ui| s.menu(ui));
        egui::Panel::bottom("status").show(ui, |ui| s.status_bar(ui));
        egui::Panel::left("tools")
            .resizable(true)
            .default_size(250.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| s.tools_panel(ui));
            });
        egui::Panel::right("view")
            .resizable(true)
            .default_size(240.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| s.view_panel(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| {
            DockArea::new(&mut self.dock)
                .show_close_buttons(false)
                .show_leaf_close_all_buttons(false)
                .show_leaf_collapse_buttons(false)
                .show_inside(ui, &mut Tabs(s));
        });
        s.export_window(&ctx);
        s.new_window(&ctx);
        s.recovery_window(&ctx);
        s.notices(&ctx);
        s.close_prompt(&ctx);
        s.open_prompt(&ctx);
        if s.job.is_some() {
            ctx.request_repaint_after(Duration::from_millis(100));
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

impl eframe::App for Editor {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }

    fn on_exit(&mut self) {
        save_layout(&self.dock);
        // A clean exit leaves no recovery file behind.
        if !self.state.dirty() {
            let _ = std::fs::remove_file(self.state.autosaver.path());
        }
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
