//! The eraser tool. Paints the base material back, on the UV canvas or on the mesh.

use kapaint_model::{Command, Document, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta};

/// The eraser tool: a stroke from press to release, one undo step, abandoned by Escape.
#[derive(Clone, Debug)]
pub struct Eraser(Stroke);

impl Default for Eraser {
    fn default() -> Self {
        Self(Stroke::new(StrokeTool::Eraser))
    }
}

impl Eraser {
    /// Where its stroke is.
    pub fn state(&self) -> StrokeState {
        self.0.state()
    }
}

impl ToolKind {
    /// The eraser.
    pub const ERASER: Self = Self("eraser");
}

impl Tool for Eraser {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::ERASER,
            label: "Eraser",
            key: Some('E'),
            key_help: "E",
            summary: "eraser",
            cursor: ToolCursor::BrushOutline,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }
}
