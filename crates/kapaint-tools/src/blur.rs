//! The blur tool. Smooths the enabled channels under the brush, on the UV canvas or on the mesh.

use kapaint_model::{Command, Document, SettingsCommand, StrokeTool};

use super::stroke::{Stroke, StrokeState};
use super::{
    OptionChange, OptionWidget, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta, ToolOption,
};

/// A change to the blur tool's options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlurOption {
    /// The kernel's radius in texels, `[1, 16]` (rounded).
    Radius(f32),
}

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

impl ToolKind {
    /// The blur.
    pub const BLUR: Self = Self("blur");
}

impl Tool for Blur {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::BLUR,
            label: "Blur",
            key: Some('R'),
            key_help: "R",
            summary: "blur",
            cursor: ToolCursor::BrushOutline,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        self.0.handle(event, doc)
    }

    fn busy(&self) -> bool {
        self.0.state() != StrokeState::Ready
    }

    /// The kernel's radius, a brush setting of the document.
    fn options(&self, doc: &Document) -> Vec<ToolOption> {
        vec![ToolOption {
            label: "Blur radius",
            hover: "Kernel radius in texels",
            widget: OptionWidget::Slider {
                value: doc.settings().brush.blur_radius_px as f32,
                min: 1.0,
                max: 16.0,
                integer: true,
                change: |r| OptionChange::Blur(BlurOption::Radius(r)),
            },
        }]
    }

    fn set_option(&mut self, change: OptionChange, doc: &Document) -> Vec<Command> {
        let OptionChange::Blur(BlurOption::Radius(r)) = change else {
            return Vec::new();
        };
        if !r.is_finite() {
            return Vec::new();
        }
        let mut brush = doc.settings().brush.clone();
        brush.blur_radius_px = r.round().clamp(1.0, 16.0) as u32;
        if brush == doc.settings().brush {
            return Vec::new();
        }
        vec![SettingsCommand::SetBrush(brush).into()]
    }
}
