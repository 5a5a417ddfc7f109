//! The fill tool: a press fills with the primary material, as its mode says.

use crate::model::PaintCommand;
use crate::model::texel::Channel;
use crate::model::{Command, Document, FillRegion};

use super::{
    OptionValue, OptionWidget, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta, ToolOption,
};

/// What a fill covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FillMode {
    /// The UV island under the pointer; the whole map where no island is (off the mesh's UVs,
    /// or a document without a mesh).
    Island,
    /// The connected texels whose `channel` is within `tolerance` (in blend space, `[0, 1]`)
    /// of the one under the pointer.
    Similar {
        /// The channel compared.
        channel: Channel,
        /// The largest difference still filled.
        tolerance: f32,
    },
    /// The whole map.
    All,
}

/// The fill tool and its mode.
#[derive(Clone, Debug)]
pub struct Fill {
    /// What a fill covers.
    pub mode: FillMode,
}

impl Default for Fill {
    fn default() -> Self {
        Self {
            mode: FillMode::Island,
        }
    }
}

impl Fill {
    /// The region a fill at texel `(x, y)` covers.
    fn region(&self, doc: &Document, (x, y): (u32, u32)) -> FillRegion {
        match self.mode {
            FillMode::All => FillRegion::All,
            FillMode::Similar { channel, tolerance } => FillRegion::Similar {
                x,
                y,
                channel,
                tolerance: tolerance.clamp(0.0, 1.0),
            },
            FillMode::Island => {
                let on_island = doc.surface().is_some_and(|s| {
                    let k = (y * s.bake.width + x) as usize;
                    k < s.bake.len() && s.bake.island(k).is_some()
                });
                if on_island {
                    FillRegion::Island { x, y }
                } else {
                    FillRegion::All
                }
            }
        }
    }
}

impl ToolKind {
    /// The fill.
    pub const FILL: Self = Self("fill");
}

/// The fill modes as the panel names them, in [`FillMode`]'s order.
const MODES: &[&str] = &["UV island (or all)", "Similar texels", "Whole map"];
/// The channels as the panel names them, in [`Channel::ALL`]'s order.
const CHANNELS: &[&str] = &["k_d", "k_s", "n"];

impl Tool for Fill {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::FILL,
            label: "Fill",
            // F is shared: the fill over the UV canvas, framing the mesh over the viewport.
            key: None,
            key_help: "F on the UV canvas",
            summary: "fill (UV canvas) / frame mesh (viewport)",
            cursor: ToolCursor::Cell,
        }
    }

    fn lays_material(&self, command: &Command) -> bool {
        matches!(command, Command::Paint(PaintCommand::Fill(_)))
    }

    /// The mode; for similar texels, the channel compared and the tolerance.
    fn options(&self, _doc: &Document) -> Vec<ToolOption> {
        let chosen = match self.mode {
            FillMode::Island => 0,
            FillMode::Similar { .. } => 1,
            FillMode::All => 2,
        };
        let mut options = vec![ToolOption {
            id: "mode",
            label: "Fill",
            hover: "",
            widget: OptionWidget::Choice {
                choices: MODES,
                chosen,
                dropdown: true,
            },
        }];
        if let FillMode::Similar { channel, tolerance } = self.mode {
            options.push(ToolOption {
                id: "channel",
                label: "Compared channel",
                hover: "",
                widget: OptionWidget::Choice {
                    choices: CHANNELS,
                    chosen: Channel::ALL.iter().position(|&c| c == channel).unwrap_or(0),
                    dropdown: true,
                },
            });
            options.push(ToolOption {
                id: "tolerance",
                label: "Tolerance",
                hover: "The largest difference still filled, in blend space",
                widget: OptionWidget::Slider {
                    value: tolerance,
                    min: 0.0,
                    max: 1.0,
                    integer: false,
                },
            });
        }
        options
    }

    fn set_option(&mut self, id: &str, value: OptionValue, _doc: &Document) -> Vec<Command> {
        match (id, value, &mut self.mode) {
            ("mode", OptionValue::Choice(0), mode) => *mode = FillMode::Island,
            ("mode", OptionValue::Choice(1), mode @ (FillMode::Island | FillMode::All)) => {
                *mode = FillMode::Similar {
                    channel: Channel::Kd,
                    tolerance: 0.05,
                };
            }
            ("mode", OptionValue::Choice(2), mode) => *mode = FillMode::All,
            ("channel", OptionValue::Choice(i), FillMode::Similar { channel, .. }) => {
                if let Some(&c) = Channel::ALL.get(i) {
                    *channel = c;
                }
            }
            ("tolerance", OptionValue::Number(t), FillMode::Similar { tolerance, .. })
                if t.is_finite() =>
            {
                *tolerance = t.clamp(0.0, 1.0);
            }
            _ => {}
        }
        Vec::new()
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        let size = (doc.maps().width(), doc.maps().height());
        match event {
            ToolEvent::Press { at, .. } => at
                .texel_index(size)
                .map(|t| PaintCommand::Fill(self.region(doc, t)).into())
                .into_iter()
                .collect(),
            ToolEvent::Drag { .. } | ToolEvent::Release | ToolEvent::Escape => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        false
    }
}
