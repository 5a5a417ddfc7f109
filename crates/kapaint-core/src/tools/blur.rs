//! The blur tool. Smooths the enabled channels under the brush, on the UV canvas or on the mesh.

use crate::model::{Command, Document, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{Tool, ToolEvent};

/// The blur tool: a stroke from press to release, one undo step, abandoned by Escape.
#[derive(Clone, Debug)]
pub struct Blur(Stroke);

impl Default for Blur {
    fn default() -> Self {
        Self(Stroke::new(StrokeTool::Blur))
    }
}

impl Blur {
    /// Where its stroke is.
    pub fn state(&self) -> StrokeState {
        self.0.state()
    }
}

impl Tool for Blur {
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }
}
