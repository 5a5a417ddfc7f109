//! The state machine the stroke tools share: a press begins a stroke (one undo step), drags
//! add points in the view it began in, release ends it, Escape abandons it.

use kapaint_model::StrokeCommand;
use kapaint_model::brush::StrokePoint;
use kapaint_model::{Command, Document, StrokeTool};

use super::{Place, ToolEvent};

/// Where a stroke is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StrokeState {
    /// No stroke.
    #[default]
    Ready,
    /// Painting on the UV canvas.
    OnCanvas,
    /// Painting on the mesh.
    OnSurface,
}

/// A stroke tool's machine: which model tool it drives and where its stroke is.
#[derive(Clone, Debug)]
pub struct Stroke {
    tool: StrokeTool,
    state: StrokeState,
}

impl Stroke {
    /// A machine for `tool`, ready.
    pub fn new(tool: StrokeTool) -> Self {
        Self {
            tool,
            state: StrokeState::Ready,
        }
    }

    /// Where the stroke is.
    pub fn state(&self) -> StrokeState {
        self.state
    }

    /// The point command for `at`, if it is in the view the stroke is in.
    fn point(&self, at: Place, pressure: f32) -> Option<Command> {
        match (self.state, at) {
            (StrokeState::OnCanvas, Place::Canvas(pos)) => {
                Some(StrokeCommand::StrokeTo(StrokePoint { pos, pressure }).into())
            }
            (StrokeState::OnSurface, Place::Surface { pos, .. }) => {
                Some(StrokeCommand::SurfaceStrokeTo(StrokePoint { pos, pressure }).into())
            }
            _ => None,
        }
    }

    /// The commands for `event`.
    pub fn handle(&mut self, event: ToolEvent, _doc: &Document) -> Vec<Command> {
        match event {
            ToolEvent::Press { at, pressure } | ToolEvent::Drag { at, pressure }
                if self.state == StrokeState::Ready =>
            {
                // A drag that reaches the map or the mesh only now starts there.
                self.state = match at {
                    Place::Canvas(_) => StrokeState::OnCanvas,
                    Place::Surface { .. } => StrokeState::OnSurface,
                };
                let mut out = vec![StrokeCommand::BeginStroke(self.tool).into()];
                out.extend(self.point(at, pressure));
                out
            }
            ToolEvent::Press { at, pressure } | ToolEvent::Drag { at, pressure } => {
                self.point(at, pressure).into_iter().collect()
            }
            ToolEvent::Release if self.state != StrokeState::Ready => {
                self.state = StrokeState::Ready;
                vec![StrokeCommand::EndStroke.into()]
            }
            ToolEvent::Escape if self.state != StrokeState::Ready => {
                self.state = StrokeState::Ready;
                vec![StrokeCommand::AbortStroke.into()]
            }
            ToolEvent::Release
            | ToolEvent::Escape
            | ToolEvent::PickSource { .. }
            | ToolEvent::Commit => Vec::new(),
        }
    }
}
