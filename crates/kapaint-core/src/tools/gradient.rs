//! The gradient tool: press at the start, drag to the end, release to lay a gradient from
//! the primary material (at the start) to the secondary (at the end); Escape drops it. On
//! the mesh the points are where the surface falls on the map, so a gradient can be dragged
//! in the 3D viewport too.

use glam::Vec2;

use crate::model::PaintCommand;
use crate::model::paint::GradientShape;
use crate::model::{Command, Document};

use super::{Tool, ToolEvent};

/// The gradient tool, its shape, and the drag under way.
#[derive(Clone, Debug)]
pub struct Gradient {
    /// Linear or radial.
    pub shape: GradientShape,
    drag: Option<(Vec2, Vec2)>,
}

impl Default for Gradient {
    fn default() -> Self {
        Self {
            shape: GradientShape::Linear,
            drag: None,
        }
    }
}

impl Gradient {
    /// The drag under way, `(start, end)` in texel units, for the editor to draw.
    pub fn drag(&self) -> Option<(Vec2, Vec2)> {
        self.drag
    }

    /// Drops the drag under way.
    pub fn cancel(&mut self) {
        self.drag = None;
    }
}

impl Tool for Gradient {
    fn handle(&mut self, event: ToolEvent, _doc: &Document) -> Vec<Command> {
        match event {
            ToolEvent::Press { at, .. } => {
                self.drag = at.texel().map(|p| (p, p));
                Vec::new()
            }
            ToolEvent::Drag { at, .. } => {
                match (self.drag.as_mut(), at.texel()) {
                    (Some((_, end)), Some(p)) => *end = p,
                    // A drag that reaches the map only now starts there.
                    (None, Some(p)) => self.drag = Some((p, p)),
                    _ => {}
                }
                Vec::new()
            }
            ToolEvent::Release => match self.drag.take() {
                Some((start, end)) if start != end => vec![
                    PaintCommand::Gradient {
                        shape: self.shape,
                        start,
                        end,
                    }
                    .into(),
                ],
                _ => Vec::new(),
            },
            ToolEvent::Escape => {
                self.drag = None;
                Vec::new()
            }
        }
    }

    fn busy(&self) -> bool {
        self.drag.is_some()
    }
}
