//! File choosers. The system's dialog (rfd, through the desktop portal) comes first; where no
//! portal runs, or the system dialog fails, kapaint's own (egui-file-dialog) opens in the
//! window instead, with a notice. Either way the choice arrives as a [`Picked`] that the
//! editor turns into a command (open, save, import, ...).
//!
//! The system dialog runs on its own thread, so the window keeps drawing while it is open.
//! rfd answers `None` both when the user cancels and when it could not show anything; a
//! `None` sooner than [`FAILED_WITHIN`] is taken as a failure (no one cancels a dialog that
//! fast), and the in-app dialog opens for the same request.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use egui_file_dialog::{DialogState, FileDialog};

use kapaint_model::texel::Channel;

/// What a file is chosen for: its title, filter and what the editor does with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilePurpose {
    /// File > Open.
    OpenProject,
    /// Save As, and Save of an untitled project.
    SaveProject,
    /// File > Import mesh.
    ImportMesh,
    /// File > Import image into a channel.
    ImportImage(Channel),
    /// File > Import PBR material (a glTF file's material).
    ImportPbr,
    /// The brush stamp's Load.
    StampImage,
    /// An image for the active tool (the decal's).
    ToolImage,
    /// The stencil's Load.
    StencilImage,
    /// Image > Project image's image.
    ProjectImage,
    /// New > File: the mesh of the new project.
    NewMesh,
    /// Mesh > Bake from high poly: a high-poly mesh.
    HighMesh,
    /// Mesh > Bake from high poly: the cage.
    Cage,
    /// The export dialog's folder.
    ExportFolder,
}

/// Whether a file is opened, saved, or a folder picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Open,
    Save,
    Folder,
}

const PROJECT: (&str, &[&str]) = ("kapaint project", &["kapaint"]);
const MESH: (&str, &[&str]) = ("mesh", &["obj", "gltf", "glb"]);
const IMAGE: (&str, &[&str]) = ("image", &["png", "jpg", "jpeg", "tga", "exr"]);
const PBR: (&str, &[&str]) = (
    "PBR material (glTF, or one image of a texture set)",
    &["glb", "gltf", "png", "jpg", "jpeg", "tga", "exr"],
);

impl FilePurpose {
    fn mode(self) -> Mode {
        match self {
            Self::SaveProject => Mode::Save,
            Self::ExportFolder => Mode::Folder,
            _ => Mode::Open,
        }
    }

    /// The dialog's title.
    pub fn title(self) -> String {
        match self {
            Self::OpenProject => "Open project".into(),
            Self::SaveProject => "Save project".into(),
            Self::ImportMesh => "Import mesh".into(),
            Self::ImportImage(c) => {
                format!("Import image into {}", c.label())
            }
            Self::StampImage => "Load brush stamp".into(),
            Self::ToolImage => "Image for the tool".into(),
            Self::StencilImage => "Load stencil".into(),
            Self::ProjectImage => "Image to project".into(),
            Self::ImportPbr => "Import PBR material".into(),
            Self::NewMesh => "Mesh of the new project".into(),
            Self::HighMesh => "High-poly mesh to bake from".into(),
            Self::Cage => "Cage (the mesh pushed out)".into(),
            Self::ExportFolder => "Export into folder".into(),
        }
    }

    fn filter(self) -> Option<(&'static str, &'static [&'static str])> {
        match self {
            Self::OpenProject | Self::SaveProject => Some(PROJECT),
            Self::ImportMesh | Self::NewMesh | Self::HighMesh | Self::Cage => Some(MESH),
            Self::ImportImage(_)
            | Self::StampImage
            | Self::ToolImage
            | Self::StencilImage
            | Self::ProjectImage => Some(IMAGE),
            Self::ImportPbr => Some(PBR),
            Self::ExportFolder => None,
        }
    }

    fn file_name(self) -> Option<&'static str> {
        (self == Self::SaveProject).then_some("material.kapaint")
    }
}

/// Which dialog the editor uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileDialogBackend {
    /// The system's, through rfd and the desktop portal.
    System,
    /// kapaint's own, drawn in the window (egui-file-dialog).
    Builtin,
}

impl FileDialogBackend {
    /// `KAPAINT_FILE_DIALOG=system` or `builtin` chooses one; anything else leaves it to the
    /// portal probe.
    fn from_env() -> Option<Self> {
        match std::env::var("KAPAINT_FILE_DIALOG").ok()?.as_str() {
            "system" => Some(Self::System),
            "builtin" => Some(Self::Builtin),
            _ => None,
        }
    }
}

/// A `None` from the system dialog sooner than this is a failure, not a cancel.
pub const FAILED_WITHIN: Duration = Duration::from_millis(400);

/// One request, as plain data (the system dialog is built from it on its thread).
#[derive(Clone, Debug)]
pub struct FileRequest {
    /// What for.
    pub purpose: FilePurpose,
    /// The folder it starts in.
    pub dir: Option<PathBuf>,
}

/// Shows the system dialog for a request and blocks until it closes; `None` for cancelled
/// or failed.
pub type SystemDialog = fn(&FileRequest) -> Option<PathBuf>;

/// A chosen path and what it was chosen for.
#[derive(Debug)]
pub struct Picked {
    /// What for.
    pub purpose: FilePurpose,
    /// The file or folder.
    pub path: PathBuf,
}

/// What one frame of the chooser came to.
#[derive(Debug)]
pub enum ChooserEvent {
    /// A path was chosen.
    Picked(Picked),
    /// The dialog was cancelled.
    Cancelled(FilePurpose),
    /// The system dialog failed; kapaint's own is open instead (the text says so).
    FellBack(String),
}

enum Active {
    System {
        request: FileRequest,
        since: Instant,
        answer: Receiver<Option<PathBuf>>,
    },
    Builtin {
        purpose: FilePurpose,
        dialog: Box<FileDialog>,
    },
}

/// The editor's file chooser: at most one dialog at a time.
pub struct FileChooser {
    /// Chosen by the environment or a test, else by the probe.
    forced: Option<FileDialogBackend>,
    /// Whether the desktop portal offers a file chooser (found on a thread at start).
    portal: Arc<OnceLock<bool>>,
    /// Set once the system dialog has failed: the in-app one from then on.
    system_failed: bool,
    system: SystemDialog,
    active: Option<Active>,
    /// The folder the last choice was made in.
    last_dir: Option<PathBuf>,
    ctx: Option<egui::Context>,
}

impl Default for FileChooser {
    fn default() -> Self {
        Self::new()
    }
}

impl FileChooser {
    /// A chooser that probes for the portal on a thread.
    pub fn new() -> Self {
        let forced = FileDialogBackend::from_env();
        let portal = Arc::new(OnceLock::new());
        if forced.is_none() {
            let found = Arc::clone(&portal);
            let spawned = std::thread::Builder::new()
                .name("kapaint-portal-probe".into())
                .spawn(move || {
                    let _ = found.set(portal_has_file_chooser());
                });
            if spawned.is_err() {
                let _ = portal.set(false);
            }
        }
        Self {
            forced,
            portal,
            system_failed: false,
            system: system_dialog,
            active: None,
            last_dir: None,
            ctx: None,
        }
    }

    /// Uses `backend` from now on (tests, and `KAPAINT_FILE_DIALOG`).
    pub fn force(&mut self, backend: FileDialogBackend) {
        self.forced = Some(backend);
    }

    /// Shows the system dialog with `system` instead of rfd (tests).
    pub fn set_system_dialog(&mut self, system: SystemDialog) {
        self.system = system;
    }

    /// The folder the next dialog starts in, when the project gives none.
    pub fn set_last_dir(&mut self, dir: PathBuf) {
        self.last_dir = Some(dir);
    }

    /// The backend the next request gets.
    pub fn backend(&self) -> FileDialogBackend {
        if let Some(b) = self.forced {
            return b;
        }
        // Until the probe has answered, try the system dialog: a failure falls back.
        if self.system_failed || self.portal.get() == Some(&false) {
            FileDialogBackend::Builtin
        } else {
            FileDialogBackend::System
        }
    }

    /// What the open dialog is for, if one is open.
    pub fn open_for(&self) -> Option<FilePurpose> {
        match &self.active {
            Some(Active::System { request, .. }) => Some(request.purpose),
            Some(Active::Builtin { purpose, .. }) => Some(*purpose),
            None => None,
        }
    }

    /// Opens a dialog for `purpose`, starting in `dir` (else the last folder used). Returns
    /// false when one is open already.
    pub fn request(&mut self, purpose: FilePurpose, dir: Option<PathBuf>) -> bool {
        if self.active.is_some() {
            return false;
        }
        let request = FileRequest {
            purpose,
            dir: dir.or_else(|| self.last_dir.clone()),
        };
        self.active = Some(match self.backend() {
            FileDialogBackend::System => self.start_system(request),
            FileDialogBackend::Builtin => builtin(&request, self.ctx.as_ref()),
        });
        true
    }

    fn start_system(&self, request: FileRequest) -> Active {
        let (tx, answer) = std::sync::mpsc::channel();
        let system = self.system;
        let ctx = self.ctx.clone();
        let shown = request.clone();
        let spawned = std::thread::Builder::new()
            .name("kapaint-file-dialog".into())
            .spawn(move || {
                let _ = tx.send(system(&shown));
                if let Some(ctx) = ctx {
                    ctx.request_repaint();
                }
            });
        if spawned.is_err() {
            return builtin(&request, self.ctx.as_ref());
        }
        Active::System {
            request,
            since: Instant::now(),
            answer,
        }
    }

    /// Draws the in-app dialog and collects answers; call once a frame.
    pub fn update(&mut self, ctx: &egui::Context) -> Option<ChooserEvent> {
        if self.ctx.is_none() {
            self.ctx = Some(ctx.clone());
        }
        let event = match self.active.as_mut()? {
            Active::System {
                request,
                since,
                answer,
            } => match answer.try_recv() {
                Err(TryRecvError::Empty) => {
                    ctx.request_repaint_after(Duration::from_millis(100));
                    return None;
                }
                Ok(Some(path)) => ChooserEvent::Picked(Picked {
                    purpose: request.purpose,
                    path,
                }),
                Ok(None) if since.elapsed() >= FAILED_WITHIN => {
                    ChooserEvent::Cancelled(request.purpose)
                }
                Ok(None) | Err(TryRecvError::Disconnected) => {
                    // Nothing was shown: kapaint's own dialog for the same request.
                    self.system_failed = true;
                    let request = request.clone();
                    self.active = Some(builtin(&request, Some(ctx)));
                    return Some(ChooserEvent::FellBack(
                        "the system file dialog is not available (no desktop portal); \
                         using kapaint's own"
                            .into(),
                    ));
                }
            },
            Active::Builtin { purpose, dialog } => {
                dialog.update(ctx);
                match dialog.state() {
                    DialogState::Open => return None,
                    DialogState::Picked(path) => ChooserEvent::Picked(Picked {
                        purpose: *purpose,
                        path: path.clone(),
                    }),
                    DialogState::PickedMultiple(paths) => match paths.first() {
                        Some(path) => ChooserEvent::Picked(Picked {
                            purpose: *purpose,
                            path: path.clone(),
                        }),
                        None => ChooserEvent::Cancelled(*purpose),
                    },
                    DialogState::Closed | DialogState::Cancelled => {
                        ChooserEvent::Cancelled(*purpose)
                    }
                }
            }
        };
        self.active = None;
        if let ChooserEvent::Picked(p) = &event {
            let folder = match p.purpose.mode() {
                Mode::Folder => Some(p.path.as_path()),
                Mode::Open | Mode::Save => p.path.parent(),
            };
            self.last_dir = folder.map(Path::to_path_buf);
        }
        Some(event)
    }
}

/// kapaint's own dialog for a request, open.
fn builtin(request: &FileRequest, ctx: Option<&egui::Context>) -> Active {
    const SIZE: egui::Vec2 = egui::vec2(760.0, 480.0);
    let purpose = request.purpose;
    let mut dialog = FileDialog::new()
        .id(egui::Id::new("kapaint-file-dialog"))
        .title(&purpose.title())
        .default_size(SIZE);
    if let Some(ctx) = ctx {
        // In the middle of the window, like the editor's other dialogs.
        dialog = dialog.default_pos(ctx.content_rect().center() - SIZE / 2.0);
    }
    if let Some(dir) = &request.dir {
        dialog = dialog.initial_directory(dir.clone());
    }
    if let Some((name, extensions)) = purpose.filter() {
        dialog = dialog
            .add_file_filter_extensions(name, extensions.to_vec())
            .default_file_filter(name);
        if purpose.mode() == Mode::Save {
            dialog = dialog
                .add_save_extension(name, extensions[0])
                .default_save_extension(name);
        }
    }
    if let Some(name) = purpose.file_name() {
        dialog = dialog.default_file_name(name);
    }
    let labels = dialog.labels_mut();
    labels.open_button = "Open".into();
    labels.save_button = "Save".into();
    labels.cancel_button = "Cancel".into();
    match purpose.mode() {
        Mode::Open => dialog.pick_file(),
        Mode::Save => dialog.save_file(),
        Mode::Folder => dialog.pick_directory(),
    }
    Active::Builtin {
        purpose,
        dialog: Box::new(dialog),
    }
}

/// The system dialog (rfd), blocking its thread until it closes.
fn system_dialog(request: &FileRequest) -> Option<PathBuf> {
    let purpose = request.purpose;
    let mut dialog = rfd::FileDialog::new().set_title(purpose.title());
    if let Some((name, extensions)) = purpose.filter() {
        dialog = dialog.add_filter(name, extensions);
    }
    if let Some(dir) = &request.dir {
        dialog = dialog.set_directory(dir);
    }
    if let Some(name) = purpose.file_name() {
        dialog = dialog.set_file_name(name);
    }
    match purpose.mode() {
        Mode::Open => dialog.pick_file(),
        Mode::Save => dialog.save_file(),
        Mode::Folder => dialog.pick_folder(),
    }
}

/// Whether the desktop portal (`org.freedesktop.portal.Desktop`) runs, or can be started,
/// on the session bus and offers its FileChooser interface. False at once without a session
/// bus; a portal that does not answer within a few seconds counts as absent.
pub fn portal_has_file_chooser() -> bool {
    let runtime_bus =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).join("bus").exists());
    if std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_none() && !runtime_bus {
        return false;
    }
    pollster::block_on(async {
        let Ok(builder) = zbus::connection::Builder::session() else {
            return false;
        };
        let Ok(connection) = builder.method_timeout(Duration::from_secs(5)).build().await else {
            return false;
        };
        let Ok(proxy) = zbus::fdo::PropertiesProxy::builder(&connection)
            .destination("org.freedesktop.portal.Desktop")
            .and_then(|b| b.path("/org/freedesktop/portal/desktop"))
        else {
            return false;
        };
        let Ok(proxy) = proxy.build().await else {
            return false;
        };
        let Ok(interface) =
            zbus::names::InterfaceName::try_from("org.freedesktop.portal.FileChooser")
        else {
            return false;
        };
        proxy.get(interface, "version").await.is_ok()
    })
}

/// `path`, with `.kapaint` added where the name has another extension or none (a system
/// dialog may return the name as typed).
pub(super) fn with_project_extension(path: PathBuf) -> PathBuf {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("kapaint"))
    {
        path
    } else {
        let mut name = path.clone().into_os_string();
        name.push(".kapaint");
        PathBuf::from(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn answer(chooser: &mut FileChooser, ctx: &egui::Context) -> ChooserEvent {
        for _ in 0..200 {
            if let Some(e) = chooser.update(ctx) {
                return e;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        panic!("no answer from the chooser");
    }

    #[test]
    fn a_system_dialog_that_fails_at_once_falls_back_to_the_builtin_one() {
        let ctx = egui::Context::default();
        let mut chooser = FileChooser::new();
        chooser.force(FileDialogBackend::System);
        chooser.set_system_dialog(|_| None);
        assert!(chooser.request(FilePurpose::SaveProject, None));
        assert!(
            !chooser.request(FilePurpose::OpenProject, None),
            "one at a time"
        );
        let event = answer(&mut chooser, &ctx);
        assert!(matches!(event, ChooserEvent::FellBack(_)), "{event:?}");
        assert_eq!(chooser.open_for(), Some(FilePurpose::SaveProject));
        assert!(matches!(chooser.active, Some(Active::Builtin { .. })));
    }

    #[test]
    fn a_system_dialog_cancelled_after_a_while_is_a_cancel() {
        let ctx = egui::Context::default();
        let mut chooser = FileChooser::new();
        chooser.force(FileDialogBackend::System);
        chooser.set_system_dialog(|_| {
            std::thread::sleep(FAILED_WITHIN + Duration::from_millis(50));
            None
        });
        chooser.request(FilePurpose::OpenProject, None);
        let event = answer(&mut chooser, &ctx);
        assert!(
            matches!(event, ChooserEvent::Cancelled(FilePurpose::OpenProject)),
            "{event:?}"
        );
        assert!(chooser.open_for().is_none());
    }

    #[test]
    fn a_system_choice_arrives_and_sets_the_next_folder() {
        let ctx = egui::Context::default();
        let mut chooser = FileChooser::new();
        chooser.force(FileDialogBackend::System);
        chooser.set_system_dialog(|r| {
            assert!(r.dir.is_none());
            Some(PathBuf::from("/tmp/kapaint-x/a.obj"))
        });
        chooser.request(FilePurpose::ImportMesh, None);
        let ChooserEvent::Picked(p) = answer(&mut chooser, &ctx) else {
            panic!("not picked");
        };
        assert_eq!(p.purpose, FilePurpose::ImportMesh);
        assert_eq!(
            chooser.last_dir.as_deref(),
            Some(Path::new("/tmp/kapaint-x"))
        );
    }
}
