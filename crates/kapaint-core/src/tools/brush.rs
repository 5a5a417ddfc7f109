//! The brush tool. Paints the primary material with the brush settings, on the UV canvas or on the mesh.

use crate::model::{Command, Document, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolEvent};

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

impl Tool for Brush {
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }
}
