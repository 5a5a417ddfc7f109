//! What a panel, a dialog or a finished job is given (egui's View pattern): the document and
//! the tools to read, and an outbox of [`Ask`]s. Nothing but the editor's one `carry_out`
//! changes the editor: a view owns its own state, reads the document and asks; the editor
//! carries the asks out, in order, once the view is drawn (so a view reads the document as
//! the frame found it).

use std::path::PathBuf;

use kapaint_model::paint::ScreenView;
use kapaint_model::{Command, Document};
use kapaint_tools::{OptionChange, ToolKind, Tools};

use crate::Notice;
use crate::files::FilePurpose;
use kapaint_base::task::Progress;

use crate::results::{OpenedProject, Saved, SizePrompt, UnwrapPrompt};

/// What a view is given for one frame: the document and the tools to read, and an outbox for
/// what it asks.
pub(crate) struct Desk<'a> {
    /// The document.
    pub(crate) doc: &'a Document,
    /// The tools and which one is active.
    pub(crate) tools: &'a Tools,
    /// Texels per screen point under the cursor (canvas zoom, or the surface's scale).
    pub(crate) texels_per_point: Option<f32>,
    /// The view the viewport's picture shows (none without a viewport drawn).
    pub(crate) screen_view: Option<ScreenView>,
    asks: Vec<Ask>,
}

/// What the pointer's views tell the panels and the jobs: the scale under the cursor, the
/// viewport's view.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Seen {
    /// Texels per screen point under the cursor.
    pub(crate) texels_per_point: Option<f32>,
    /// The viewport's view.
    pub(crate) screen_view: Option<ScreenView>,
}

/// What a view or a finished job asks of the editor.
pub(crate) enum Ask {
    /// A command for the document (an error becomes a notice).
    Command(Command),
    /// A command for the document, and what to say once it is done (an error is said
    /// instead).
    CommandSaying(Command, Vec<Notice>),
    /// Make this the active tool.
    SelectTool(ToolKind),
    /// Set one of the active tool's options.
    ToolOption(OptionChange),
    /// Open the file chooser for this.
    ChooseFile(FilePurpose),
    /// Show a message.
    Notice(Notice),
    /// Lay this generator as the selected layer's mask, baking first what it reads and the
    /// project lacks.
    LayGenerator(kapaint_model::generator::Generator),
    /// Make the light follow the camera, or stay put in the world.
    LightFollowsCamera(bool),
    /// Start this work on a worker (refused, with a notice, while another job runs).
    Job(JobStart),
    /// A job failed: what waited on it is dropped, and the error shown.
    JobFailed(String),
    /// The user cancelled the job with this label: what waited on it is dropped, and that is
    /// all (no error).
    JobCancelled(String),
    /// Ask the user this before going on.
    Prompt(Prompt),
    /// Open this project now: the user answered about unsaved changes or another editor's
    /// claim on it.
    OpenNow(PathBuf),
    /// Save the project (asking where when it is untitled or read-only).
    Save,
    /// A project opened or recovered: the document now.
    Opened(Box<OpenedProject>),
    /// A save done, or conflicted.
    Saved(Saved),
    /// A new project made (File > New): the document now, untitled.
    Created(Box<Document>),
    /// Bakes kept just now: lay the generator mask that waited for them.
    BakedOnDemand,
    /// Take these preferences (kept for the next run).
    Preferences(crate::preferences::Preferences),
    /// Do what this key binding or menu entry does.
    Act(crate::keys::Action),
    /// Open this window.
    Show(Window),
    /// The image Image > Project image projects.
    ProjectImage(kapaint_model::paint_image::PaintImage),
    /// Open this project (asking first about unsaved changes).
    Open(PathBuf),
    /// The cage Mesh > Bake from high poly chose, read: drawn while the dialog still names it.
    CageRead(PathBuf, std::sync::Arc<kapaint_mesh::Mesh>),
}

/// The editor's windows a menu opens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Window {
    /// Image > Resize.
    Resize,
    /// Image > Project image.
    ProjectImage,
    /// Mesh > Bake.
    Bake,
    /// Mesh > Bake from high poly.
    BakeHigh,
    /// Edit > Preferences.
    Preferences,
    /// Help > Keyboard shortcuts.
    Shortcuts,
}

/// A question for the user, asked in its own window until answered.
pub(crate) enum Prompt {
    /// An imported glTF mesh whose material has textures: bring them in too?
    Material(PathBuf),
    /// A PBR material of another size than the maps: adopt its size?
    Size(Box<SizePrompt>),
    /// A mesh whose UVs cannot be painted as they are: unwrap it?
    Unwrap(UnwrapPrompt),
}

impl<'a> Desk<'a> {
    /// A desk over the document and the tools, with nothing asked yet.
    pub(crate) fn new(doc: &'a Document, tools: &'a Tools, seen: Seen) -> Self {
        Self {
            doc,
            tools,
            texels_per_point: seen.texels_per_point,
            screen_view: seen.screen_view,
            asks: Vec::new(),
        }
    }

    /// Asks for a command on the document.
    pub(crate) fn command(&mut self, command: impl Into<Command>) {
        self.asks.push(Ask::Command(command.into()));
    }

    /// Asks for a command on the document, and for `notices` once it is done.
    pub(crate) fn command_saying(&mut self, command: impl Into<Command>, notices: Vec<Notice>) {
        self.asks.push(Ask::CommandSaying(command.into(), notices));
    }

    /// Asks for work on a worker.
    pub(crate) fn job(&mut self, job: JobStart) {
        self.asks.push(Ask::Job(job));
    }

    /// Says something.
    pub(crate) fn notice(&mut self, notice: Notice) {
        self.asks.push(Ask::Notice(notice));
    }

    /// Asks the editor for something.
    pub(crate) fn ask(&mut self, ask: Ask) {
        self.asks.push(ask);
    }

    /// What was asked, in order.
    pub(crate) fn into_asks(self) -> Vec<Ask> {
        self.asks
    }
}

/// What a finished job asks of the editor: made on the worker from the job's own typed result
/// (each job names its result type and the function that takes it), run on the UI thread
/// over a [`Desk`]. A job's failure is its error line.
pub(crate) type Finish = Box<dyn FnOnce(&mut Desk) + Send>;

/// Work for a worker: what the progress bar calls it, the window it waits behind (if any),
/// and the work itself, which hands back what the job asks of the editor once done.
pub(crate) struct JobStart {
    pub(crate) label: String,
    pub(crate) opens: Option<PathBuf>,
    pub(crate) modal: Option<String>,
    pub(crate) run: Box<dyn FnOnce(&Progress) -> Finish + Send>,
}

impl JobStart {
    /// A job: `work` runs on a worker, and `done` takes its typed result on the UI thread,
    /// asking the editor through a [`Desk`] (an error becomes a notice; work that stops
    /// because the user cancelled it is no error).
    pub(crate) fn new<T: Send + 'static>(
        label: &str,
        work: impl FnOnce(&Progress) -> Result<T, String> + Send + 'static,
        done: fn(T, &mut Desk),
    ) -> Self {
        let named = label.to_string();
        Self {
            label: label.into(),
            opens: None,
            modal: None,
            run: Box::new(move |progress| match work(progress) {
                Ok(value) => Box::new(move |desk: &mut Desk| done(value, desk)),
                // The Cancel button set it: the job stopped because it was asked to.
                Err(_) if progress.is_cancelled() => {
                    Box::new(move |desk: &mut Desk| desk.ask(Ask::JobCancelled(named)))
                }
                Err(e) => Box::new(move |desk: &mut Desk| desk.ask(Ask::JobFailed(e))),
            }),
        }
    }

    /// The same job, which the editor waits for behind a window saying `text`.
    pub(crate) fn modal(mut self, text: String) -> Self {
        self.modal = Some(text);
        self
    }

    /// The same job, opening the project at `path`: it replaces the document when done, and
    /// the editor takes no input until then.
    pub(crate) fn opening(mut self, path: PathBuf) -> Self {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        self.modal = Some(format!("Opening {name}…"));
        self.opens = Some(path);
        self
    }
}

/// A window that opens about the middle of the editor (not at the top left, over the tools);
/// it can still be moved. Its top left is placed once, half a typical dialog's size from the
/// centre, so it stays put when its content grows (a centred pivot would move its buttons
/// from under the pointer).
pub(crate) fn centred<'a>(window: egui::Window<'a>, ctx: &egui::Context) -> egui::Window<'a> {
    window.default_pos(ctx.content_rect().center() - egui::vec2(200.0, 150.0))
}
