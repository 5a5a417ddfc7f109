//! The editor's panels: tools, brush and material on the left; shading, compare, view, light
//! and presets on the right; the menu bar, the status bar, dropped files and notices. Each
//! reads the state and issues [`Command`](kapaint_model::Command)s.

mod bars;
pub mod colour;
pub(super) mod generator;
mod layer_settings;
pub mod layers;
pub(super) mod presets;
pub(super) mod tool_panel;
pub(super) mod view_panel;

use kapaint_core::tools::{OptionChange, ToolKind, Tools};
use kapaint_model::{Command, Document};

use crate::Notice;
use crate::files::FilePurpose;

/// What a panel is given for one frame (egui's View pattern): the document and the tools to
/// read, and an outbox for what it asks. A panel owns its own state, reads the document and
/// asks; it never changes the editor itself. The editor carries the asks out, in order, once
/// the panel is drawn (so a panel reads the document as the frame found it).
pub(crate) struct Desk<'a> {
    /// The document.
    pub(crate) doc: &'a Document,
    /// The tools and which one is active.
    pub(crate) tools: &'a Tools,
    /// Texels per screen point under the cursor (canvas zoom, or the surface's scale).
    pub(crate) texels_per_point: Option<f32>,
    asks: Vec<Ask>,
}

/// What a panel asks of the editor.
pub(crate) enum Ask {
    /// A command for the document (an error becomes a notice).
    Command(Command),
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
}

impl<'a> Desk<'a> {
    /// A desk over the document and the tools, with nothing asked yet.
    pub(crate) fn new(doc: &'a Document, tools: &'a Tools, texels_per_point: Option<f32>) -> Self {
        Self {
            doc,
            tools,
            texels_per_point,
            asks: Vec::new(),
        }
    }

    /// Asks for a command on the document.
    pub(crate) fn command(&mut self, command: impl Into<Command>) {
        self.asks.push(Ask::Command(command.into()));
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
