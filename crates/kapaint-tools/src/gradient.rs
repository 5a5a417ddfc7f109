//! The gradient tool: press at the start, drag to the end, release to lay a gradient from
//! the primary material (at the start) to the secondary (at the end); Escape drops it. On
//! the mesh the points are where the surface falls on the map, so a gradient can be dragged
//! in the 3D viewport too.

use glam::Vec2;

use kapaint_model::PaintCommand;
use kapaint_model::paint::GradientShape;
use kapaint_model::{Command, Document};

use super::{
    OptionChange, OptionWidget, Overlay, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta,
    ToolOption,
};

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
    /// The drag under way, `(start, end)` in texel units.
    pub fn drag(&self) -> Option<(Vec2, Vec2)> {
        self.drag
    }
}

impl ToolKind {
    /// The gradient.
    pub const GRADIENT: Self = Self("gradient");
}

/// A change to the gradient tool's options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GradientOption {
    /// Its shape.
    Shape(GradientShape),
}

impl Tool for Gradient {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::GRADIENT,
            label: "Gradient",
            key: Some('G'),
            key_help: "G",
            summary: "gradient (drag, on the canvas or the mesh)",
            cursor: ToolCursor::Crosshair,
        }
    }

    /// A gradient half dragged is dropped, not laid.
    fn leave(&mut self, _doc: &Document) -> Vec<Command> {
        self.drag = None;
        Vec::new()
    }

    fn lays_material(&self, command: &Command) -> bool {
        matches!(command, Command::Paint(PaintCommand::Gradient { .. }))
    }

    /// The drag under way, as an arrow from start to end.
    fn overlay(&self) -> Option<Overlay> {
        self.drag.map(|(from, to)| Overlay::Arrow { from, to })
    }

    fn options(&self, _doc: &Document) -> Vec<ToolOption> {
        let shape = |name, s| (name, OptionChange::Gradient(GradientOption::Shape(s)));
        vec![ToolOption {
            label: "",
            hover: "",
            widget: OptionWidget::Choice {
                choices: vec![
                    shape("Linear", GradientShape::Linear),
                    shape("Radial", GradientShape::Radial),
                ],
                chosen: usize::from(self.shape == GradientShape::Radial),
                dropdown: false,
            },
        }]
    }

    fn set_option(&mut self, change: OptionChange, _doc: &Document) -> Vec<Command> {
        if let OptionChange::Gradient(GradientOption::Shape(shape)) = change {
            self.shape = shape;
        }
        Vec::new()
    }

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
            ToolEvent::PickSource { .. } | ToolEvent::Commit => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        self.drag.is_some()
    }
}
