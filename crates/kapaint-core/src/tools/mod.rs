//! Tools: one file a tool, each a small state machine that turns pointer and key events into
//! [`Command`]s. The editor translates egui's input into [`ToolEvent`]s and applies what the
//! active tool answers; tests feed events directly, with no window.
//!
//! ```text
//! egui input --> ui::input --> ToolEvent --> Tools::handle --> [Command] --> Document::apply
//! ```
//!
//! Tools read the document (its size, its mesh's UV islands) but never change it themselves.

mod blur;
mod brush;
mod eraser;
mod fill;
mod gradient;
mod picker;
mod stroke;

pub use blur::Blur;
pub use brush::Brush;
pub use eraser::Eraser;
pub use fill::{Fill, FillMode};
pub use gradient::Gradient;
pub use picker::Picker;

use glam::Vec2;

use crate::model::brush::SurfacePos;
use crate::model::{Command, Document};

/// Where a pointer event happened, in the model's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Place {
    /// On the UV canvas, in texel units (texel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`).
    Canvas(Vec2),
    /// On the mesh in the 3D viewport: the surface point, and where it falls on the map in
    /// texel units (`None` where the mesh has no UVs there).
    Surface {
        /// The point and its normal, in object space.
        pos: SurfacePos,
        /// The point's UV in texel units.
        texel: Option<Vec2>,
    },
}

impl Place {
    /// The position on the map in texel units, from either view.
    pub fn texel(self) -> Option<Vec2> {
        match self {
            Self::Canvas(p) => Some(p),
            Self::Surface { texel, .. } => texel,
        }
    }

    /// The texel the position falls in, if it is on a `width x height` map.
    pub fn texel_index(self, (width, height): (u32, u32)) -> Option<(u32, u32)> {
        let p = self.texel()?;
        (p.is_finite() && p.x >= 0.0 && p.y >= 0.0 && p.x < width as f32 && p.y < height as f32)
            .then_some((p.x as u32, p.y as u32))
    }
}

/// An input event, as a tool sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToolEvent {
    /// The primary button went down.
    Press {
        /// Where.
        at: Place,
        /// Pen pressure in `[0, 1]` (1 for a mouse).
        pressure: f32,
    },
    /// The pointer moved with the primary button down.
    Drag {
        /// Where.
        at: Place,
        /// Pen pressure in `[0, 1]`.
        pressure: f32,
    },
    /// The primary button went up.
    Release,
    /// Escape: abandon what is under way (a stroke is undone, a drag dropped).
    Escape,
}

/// What every tool does.
pub trait Tool {
    /// The commands that answer one event, in the order they are to be applied.
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command>;

    /// Whether something is under way (a stroke, a drag).
    fn busy(&self) -> bool;
}

/// The tools, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ToolKind {
    /// Paints the primary material.
    #[default]
    Brush,
    /// Paints the base material back.
    Eraser,
    /// Smooths the enabled channels.
    Blur,
    /// Fills a UV island, a region of similar texels, or the whole map.
    Fill,
    /// A gradient from the primary to the secondary material, dragged on the map.
    Gradient,
    /// Reads the material under the pointer into the primary.
    Picker,
}

impl ToolKind {
    /// Every tool, in the order the editor lists them.
    pub const ALL: [Self; 6] = [
        Self::Brush,
        Self::Eraser,
        Self::Blur,
        Self::Fill,
        Self::Gradient,
        Self::Picker,
    ];

    /// The tool's name.
    pub fn label(self) -> &'static str {
        match self {
            Self::Brush => "Brush",
            Self::Eraser => "Eraser",
            Self::Blur => "Blur",
            Self::Fill => "Fill",
            Self::Gradient => "Gradient",
            Self::Picker => "Picker",
        }
    }

    /// Whether the tool paints strokes (and so shows the brush outline).
    pub fn strokes(self) -> bool {
        matches!(self, Self::Brush | Self::Eraser | Self::Blur)
    }
}

/// The editor's tools and which one is active. Switching tools while one is busy ends its
/// stroke (kept) or drag (dropped).
#[derive(Debug, Default)]
pub struct Tools {
    active: ToolKind,
    brush: Brush,
    eraser: Eraser,
    blur: Blur,
    /// The fill tool and its options.
    pub fill: Fill,
    /// The gradient tool and its options.
    pub gradient: Gradient,
    /// The picker and its option.
    pub picker: Picker,
}

impl Tools {
    /// The active tool.
    pub fn active(&self) -> ToolKind {
        self.active
    }

    /// Makes `kind` the active tool; returns the commands that end what the old one had
    /// under way.
    pub fn select(&mut self, kind: ToolKind, doc: &Document) -> Vec<Command> {
        if kind == self.active {
            return Vec::new();
        }
        let ended = match self.active {
            // A gradient half dragged is dropped, not laid.
            ToolKind::Gradient => {
                self.gradient.cancel();
                Vec::new()
            }
            // A stroke under way is kept: it ends as if released.
            active => self.tool_mut(active).handle(ToolEvent::Release, doc),
        };
        self.active = kind;
        ended
    }

    /// The active tool's answer to `event`.
    pub fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        let kind = self.active;
        self.tool_mut(kind).handle(event, doc)
    }

    /// Whether the active tool has something under way.
    pub fn busy(&self) -> bool {
        self.tool(self.active).busy()
    }

    fn tool(&self, kind: ToolKind) -> &dyn Tool {
        match kind {
            ToolKind::Brush => &self.brush,
            ToolKind::Eraser => &self.eraser,
            ToolKind::Blur => &self.blur,
            ToolKind::Fill => &self.fill,
            ToolKind::Gradient => &self.gradient,
            ToolKind::Picker => &self.picker,
        }
    }

    fn tool_mut(&mut self, kind: ToolKind) -> &mut dyn Tool {
        match kind {
            ToolKind::Brush => &mut self.brush,
            ToolKind::Eraser => &mut self.eraser,
            ToolKind::Blur => &mut self.blur,
            ToolKind::Fill => &mut self.fill,
            ToolKind::Gradient => &mut self.gradient,
            ToolKind::Picker => &mut self.picker,
        }
    }
}
