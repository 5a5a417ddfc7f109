//! Tools: one file a tool, each a small state machine that turns pointer and key events into
//! [`Command`]s. The editor translates egui's input into [`ToolEvent`]s and applies what the
//! active tool answers; tests feed events directly, with no window.
//!
//! ```text
//! egui input --> editor::input --> ToolEvent --> Tools::handle --> [Command] --> Document::apply
//! ```
//!
//! Tools read the document (its size, its mesh's UV islands) but never change it themselves.

mod blur;
mod brush;
mod clone;
mod decal;
mod eraser;
mod fill;
mod gradient;
mod picker;
mod smudge;
mod stroke;

pub use blur::{Blur, BlurOption};
pub use brush::Brush;
pub use clone::CloneTool;
pub use decal::{DecalOption, DecalTool};
pub use eraser::Eraser;
pub use fill::{Fill, FillMode, FillOption};
pub use gradient::{Gradient, GradientOption};
pub use picker::{Picker, PickerOption};
pub use smudge::Smudge;

use std::any::Any;

use glam::Vec2;

use kapaint_model::brush::SurfacePos;
use kapaint_model::{Command, Document};

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
    /// The primary button went down with Ctrl held: a source to copy from (clone's).
    PickSource {
        /// Where.
        at: Place,
    },
    /// Enter: commit what is being placed (a decal).
    Commit,
}

/// What every tool is and does. Everything the editor knows of a tool it asks here: its name
/// and key ([`ToolMeta`]), its options ([`Tool::options`], drawn by the editor from this
/// description), its overlay, its cursor, and which of its commands lay a material.
pub trait Tool: Any + std::fmt::Debug {
    /// Its name, key and cursor.
    fn meta(&self) -> ToolMeta;

    /// The commands that answer one event, in the order they are to be applied.
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command>;

    /// Whether something is under way (a stroke, a drag).
    fn busy(&self) -> bool;

    /// The commands that end what is under way when another tool is chosen: by default as if
    /// released (a stroke is kept).
    fn leave(&mut self, doc: &Document) -> Vec<Command> {
        self.handle(ToolEvent::Release, doc)
    }

    /// Whether `command`, which this tool answered, lays the primary material (the editor
    /// then keeps it among the recent materials).
    fn lays_material(&self, _command: &Command) -> bool {
        false
    }

    /// What the editor draws over the views while the tool works.
    fn overlay(&self) -> Option<Overlay> {
        None
    }

    /// The tool's options, as the panel shows them.
    fn options(&self, _doc: &Document) -> Vec<ToolOption> {
        Vec::new()
    }

    /// Makes a change one of its [`Tool::options`] offered; the commands it takes, if the
    /// option lives in the document (a brush setting). Another tool's change does nothing.
    fn set_option(&mut self, _change: OptionChange, _doc: &Document) -> Vec<Command> {
        Vec::new()
    }
}

/// A tool's name: each tool's file declares its own (`ToolKind::BRUSH`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ToolKind(&'static str);

impl ToolKind {
    /// The name, lower case (`"brush"`).
    pub fn name(self) -> &'static str {
        self.0
    }
}

/// What the editor shows of a tool besides its options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ToolMeta {
    /// Which tool.
    pub kind: ToolKind,
    /// Its label in the panel.
    pub label: &'static str,
    /// The key that chooses it (none: chosen some other way, `key_help` says how).
    pub key: Option<char>,
    /// The key in the tool's tooltip ("B", "F on the UV canvas").
    pub key_help: &'static str,
    /// What the shortcut sheet says its key does ("gradient (drag, on the canvas or the mesh)").
    pub summary: &'static str,
    /// What the pointer shows over the views.
    pub cursor: ToolCursor,
}

/// The pointer over the views.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolCursor {
    /// A crosshair inside the brush's outline (the dab's size on the canvas or the mesh).
    BrushOutline,
    /// A crosshair.
    Crosshair,
    /// A cell: a click acts on what is under it.
    Cell,
}

/// What a tool asks the editor to draw over the views, in texel units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Overlay {
    /// An arrow (a gradient's drag).
    Arrow {
        /// Where it starts.
        from: Vec2,
        /// Where it points.
        to: Vec2,
    },
    /// The clone source's marker: at the document's clone source, and once a stroke fixed
    /// the offset, at the pointer plus that offset (it follows the brush).
    CloneSource,
    /// A decal being placed, in object space: its outline (top-left, top-right,
    /// bottom-right, bottom-left) and its handles (scale at the top-right corner, turn above
    /// the top edge), drawn through the viewport's camera.
    Decal {
        /// Its corners.
        corners: [glam::Vec3; 4],
        /// The scale handle and the turn handle.
        handles: [glam::Vec3; 2],
    },
}

/// One of a tool's options, as the panel shows it: its control, and the typed change each
/// of the control's values makes.
#[derive(Clone, Debug)]
pub struct ToolOption {
    /// Its label (empty: none).
    pub label: &'static str,
    /// Its tooltip (empty: none).
    pub hover: &'static str,
    /// The control and its value.
    pub widget: OptionWidget,
}

/// An option's control; each value it offers is the change it makes.
#[derive(Clone, Debug)]
pub enum OptionWidget {
    /// One of a few named choices.
    Choice {
        /// The choices: each one's name and the change choosing it makes.
        choices: Vec<(&'static str, OptionChange)>,
        /// The one chosen.
        chosen: usize,
        /// A drop-down list (else a row of buttons).
        dropdown: bool,
    },
    /// A number in a range.
    Slider {
        /// Its value.
        value: f32,
        /// The smallest value.
        min: f32,
        /// The largest value.
        max: f32,
        /// Whole numbers only.
        integer: bool,
        /// The change setting it to a value makes.
        change: fn(f32) -> OptionChange,
    },
    /// An image file: the editor shows its name and a button that chooses another, and
    /// answers with [`OptionChange::Image`] once the image is loaded.
    Image {
        /// The file chosen (none yet).
        path: Option<std::path::PathBuf>,
    },
}

/// A change to one of a tool's options, in the tool's own type (as Graphite's per-tool
/// option updates): a tool answers its own with an exhaustive match, never a string.
#[derive(Clone, Debug, PartialEq)]
pub enum OptionChange {
    /// The fill tool's.
    Fill(FillOption),
    /// The blur tool's.
    Blur(BlurOption),
    /// The gradient tool's.
    Gradient(GradientOption),
    /// The picker's.
    Picker(PickerOption),
    /// The decal tool's.
    Decal(DecalOption),
    /// The image an [`OptionWidget::Image`] asked for, loaded.
    Image(kapaint_model::paint_image::PaintImage),
}

/// Every tool, in the order the editor lists them: adding a tool is its file and one line here.
fn registry() -> Vec<Box<dyn Tool>> {
    vec![
        Box::new(Brush::default()),
        Box::new(Eraser::default()),
        Box::new(Blur::default()),
        Box::new(CloneTool::default()),
        Box::new(Smudge::default()),
        Box::new(DecalTool::default()),
        Box::new(Fill::default()),
        Box::new(Gradient::default()),
        Box::new(Picker::default()),
    ]
}

/// The editor's tools and which one is active. Switching tools while one is busy ends its
/// stroke (kept) or drag (dropped).
#[derive(Debug)]
pub struct Tools {
    active: usize,
    tools: Vec<Box<dyn Tool>>,
}

impl Default for Tools {
    fn default() -> Self {
        Self {
            active: 0,
            tools: registry(),
        }
    }
}

impl Tools {
    /// Every tool's name and key, in the editor's order (before any [`Tools`] is made: the
    /// keymap).
    pub fn all() -> Vec<ToolMeta> {
        registry().iter().map(|t| t.meta()).collect()
    }

    /// These tools' names and keys, in the editor's order.
    pub fn metas(&self) -> impl Iterator<Item = ToolMeta> + '_ {
        self.tools.iter().map(|t| t.meta())
    }

    /// The active tool.
    pub fn active(&self) -> ToolKind {
        self.active_tool().meta().kind
    }

    /// The active tool's name, key and cursor.
    pub fn active_meta(&self) -> ToolMeta {
        self.active_tool().meta()
    }

    /// Makes `kind` the active tool; returns the commands that end what the old one had
    /// under way. An unknown kind changes nothing.
    pub fn select(&mut self, kind: ToolKind, doc: &Document) -> Vec<Command> {
        let Some(i) = self.tools.iter().position(|t| t.meta().kind == kind) else {
            return Vec::new();
        };
        if i == self.active {
            return Vec::new();
        }
        let ended = self.tools[self.active].leave(doc);
        self.active = i;
        ended
    }

    /// The active tool's answer to `event`.
    pub fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        let active = self.active;
        self.tools[active].handle(event, doc)
    }

    /// Whether the active tool has something under way.
    pub fn busy(&self) -> bool {
        self.active_tool().busy()
    }

    /// Whether `command`, answered by the active tool, lays the primary material.
    pub fn lays_material(&self, command: &Command) -> bool {
        self.active_tool().lays_material(command)
    }

    /// What the active tool draws over the views.
    pub fn overlay(&self) -> Option<Overlay> {
        self.active_tool().overlay()
    }

    /// The active tool's options.
    pub fn options(&self, doc: &Document) -> Vec<ToolOption> {
        self.active_tool().options(doc)
    }

    /// Makes a change one of the active tool's options offered; the commands it takes.
    pub fn set_option(&mut self, change: OptionChange, doc: &Document) -> Vec<Command> {
        let active = self.active;
        self.tools[active].set_option(change, doc)
    }

    /// The tool of type `T`, to read or set its state directly (tests, presets).
    pub fn get_mut<T: Tool>(&mut self) -> Option<&mut T> {
        self.tools
            .iter_mut()
            .find_map(|t| (t.as_mut() as &mut dyn Any).downcast_mut::<T>())
    }

    fn active_tool(&self) -> &dyn Tool {
        self.tools[self.active].as_ref()
    }
}
