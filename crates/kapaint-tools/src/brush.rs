//! The brush tool. Paints the primary material with the brush settings, on the UV canvas or on the mesh.

use kapaint_model::{Command, Document, StrokeCommand, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta};

/// The brush tool: a stroke from press to release, one undo step, abandoned by Escape.
#[derive(Clone, Debug)]
pub struct Brush(Stroke);

impl Default for Brush {
    fn default() -> Self {
        Self(Stroke::new(StrokeTool::Brush))
    }
}

impl Brush {
    /// Where its stroke is.
    pub fn state(&self) -> StrokeState {
        self.0.state()
    }
}

impl ToolKind {
    /// The brush.
    pub const BRUSH: Self = Self("brush");
}

impl Tool for Brush {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::BRUSH,
            label: "Brush",
            key: Some('B'),
            key_help: "B",
            summary: "brush",
            cursor: ToolCursor::BrushOutline,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }

    /// A brush stroke lays the primary material from its first dab.
    fn lays_material(&self, command: &Command) -> bool {
        matches!(
            command,
            Command::Stroke(StrokeCommand::BeginStroke(StrokeTool::Brush))
        )
    }
}
