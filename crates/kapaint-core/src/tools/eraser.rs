//! The eraser tool. Paints the base material back, on the UV canvas or on the mesh.

use crate::model::{Command, Document, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolEvent};

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

impl Tool for Eraser {
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }
}
