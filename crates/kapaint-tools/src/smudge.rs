//! The smudge tool. Picks up what is under the brush and drags it along the stroke, its
//! strength the brush's opacity.

use kapaint_model::{Command, Document, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta};

/// The smudge tool: a stroke from press to release, one undo step, abandoned by Escape.
#[derive(Clone, Debug)]
pub struct Smudge(Stroke);

impl Default for Smudge {
    fn default() -> Self {
        Self(Stroke::new(StrokeTool::Smudge))
    }
}

impl Smudge {
    /// Where its stroke is.
    pub fn state(&self) -> StrokeState {
        self.0.state()
    }
}

impl ToolKind {
    /// Smudge.
    pub const SMUDGE: Self = Self("smudge");
}

impl Tool for Smudge {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::SMUDGE,
            label: "Smudge",
            key: Some('U'),
            key_help: "U",
            summary: "smudge (on the canvas)",
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
