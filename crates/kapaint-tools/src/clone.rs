//! The clone tool. Ctrl+click sets the source; a stroke then paints what the maps held there,
//! aligned (the offset from the first stroke's first point is kept until a new source).

use kapaint_model::{Command, Document, SettingsCommand, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Overlay, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta};

/// The clone tool: a source picked with Ctrl+click, then strokes from press to release, one
/// undo step each, abandoned by Escape.
#[derive(Clone, Debug)]
pub struct CloneTool(Stroke);

impl Default for CloneTool {
    fn default() -> Self {
        Self(Stroke::new(StrokeTool::Clone))
    }
}

impl CloneTool {
    /// Where its stroke is.
    pub fn state(&self) -> StrokeState {
        self.0.state()
    }
}

impl ToolKind {
    /// Clone.
    pub const CLONE: Self = Self("clone");
}

impl Tool for CloneTool {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::CLONE,
            label: "Clone",
            key: Some('S'),
            key_help: "S; Ctrl+click sets the source",
            summary: "clone (Ctrl+click sets the source, on the canvas)",
            cursor: ToolCursor::BrushOutline,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        match event {
            ToolEvent::PickSource { at } if self.0.state() == StrokeState::Ready => at
                .texel()
                .map(|p| SettingsCommand::SetCloneSource(p).into())
                .into_iter()
                .collect(),
            _ => self.0.handle(event, doc),
        }
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }

    /// The source's marker, where the brush would copy from.
    fn overlay(&self) -> Option<Overlay> {
        Some(Overlay::CloneSource)
    }
}
