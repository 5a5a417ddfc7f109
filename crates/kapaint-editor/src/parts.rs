//! The parts of the editor's state that gather what several modules own: the dialogs open
//! and the work on workers. They live apart from those modules, which use each other.

/// The dialogs and windows, while open.
#[derive(Default)]
pub(super) struct Dialogs {
    pub(super) export: Option<super::export_dialog::ExportDialog>,
    /// The last export's preset and folder, offered again by the next.
    pub(super) export_choice: Option<(String, String)>,
    /// The Resize dialog, while open.
    pub(super) resize: Option<super::resize::ResizeDialog>,
    /// Mesh > Bake, while open.
    pub(super) bake: Option<super::bake::BakeDialog>,
    /// Mesh > Bake from high poly, while open.
    pub(super) bake_high: Option<super::bake_high::HighDialog>,
    /// Image > Project image, while open.
    pub(super) project: Option<super::project_dialog::ProjectDialog>,
    /// Whether the Preferences window is open.
    pub(super) preferences_open: bool,
    /// The New dialog, while open.
    pub(super) new: Option<super::NewDialog>,
    /// The New dialog's project, created once the save its "Save, then create" started is
    /// done.
    pub(super) pending_new: Option<super::NewDialog>,
    /// Whether Help > Keyboard shortcuts is open.
    pub(super) shortcuts_open: bool,
    /// The file chooser: the system's, or kapaint's own without a desktop portal.
    pub(super) files: super::files::FileChooser,
}

/// Work on workers: the one job with a progress bar, and the workers panels keep.
pub(super) struct Jobs {
    pub(super) current: Option<super::jobs::Job>,
    /// The window's context, for a worker to wake the window when its job is done (a frame
    /// is drawn then, not at the next progress tick).
    pub(super) waker: Option<egui::Context>,
    /// Exact `chi` values for the status bar, integrated on a worker.
    pub(super) exact_chi: super::readout::ExactChi,
    /// The bakes the editor makes on its own: a generator mask set while a bake it reads was
    /// missing (laid once they arrive), and the document version last looked at for bakes its
    /// masks read and lack.
    pub(super) bake_on_demand: super::bake::OnDemand,
}
