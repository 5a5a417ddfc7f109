//! The clone tool. Ctrl+click sets the source; a stroke then paints what the maps held there,
//! aligned (the offset from the first stroke's first point is kept until a new source). On
//! the mesh the source is a surface point and the clone runs in object space, across UV
//! seams.

use kapaint_model::{Command, Document, SettingsCommand, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Overlay, Place, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta};

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
            summary: "clone (Ctrl+click sets the source, on the canvas or the mesh)",
            cursor: ToolCursor::BrushOutline,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        match event {
            // On the mesh the source is the surface point (a mesh stroke clones in object
            // space) and, where the mesh has UVs there, its texel too (for the canvas).
            ToolEvent::PickSource { at } if self.0.state() == StrokeState::Ready => {
                let surface = match at {
                    Place::Surface { pos, .. } => {
                        Some(SettingsCommand::SetSurfaceCloneSource(pos.point).into())
                    }
                    Place::Canvas(_) => None,
                };
                surface
                    .into_iter()
                    .chain(
                        at.texel()
                            .map(|p| SettingsCommand::SetCloneSource(p).into()),
                    )
                    .collect()
            }
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
