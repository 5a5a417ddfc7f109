//! The fill tool: a press fills with the primary material, as its mode says.

use kapaint_model::PaintCommand;
use kapaint_model::texel::Channel;
use kapaint_model::{Command, Document, FillRegion};

use super::{
    OptionChange, OptionWidget, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta, ToolOption,
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

/// A change to the fill tool's options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FillOption {
    /// What a fill covers (a fill of similar texels starts comparing `k_d` within 0.05).
    Mode(FillKind),
    /// The channel a fill of similar texels compares.
    Channel(Channel),
    /// The largest difference a fill of similar texels still fills, `[0, 1]`.
    Tolerance(f32),
}

/// What a fill covers, without its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillKind {
    /// [`FillMode::Island`].
    Island,
    /// [`FillMode::Similar`].
    Similar,
    /// [`FillMode::All`].
    All,
}

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
        let mode = |name, kind| (name, OptionChange::Fill(FillOption::Mode(kind)));
        let mut options = vec![ToolOption {
            label: "Fill",
            hover: "",
            widget: OptionWidget::Choice {
                choices: vec![
                    mode("UV island (or all)", FillKind::Island),
                    mode("Similar texels", FillKind::Similar),
                    mode("Whole map", FillKind::All),
                ],
                chosen,
                dropdown: true,
            },
        }];
        if let FillMode::Similar { channel, tolerance } = self.mode {
            options.push(ToolOption {
                label: "Compared channel",
                hover: "",
                widget: OptionWidget::Choice {
                    choices: Channel::ALL
                        .iter()
                        .map(|&c| (c.label(), OptionChange::Fill(FillOption::Channel(c))))
                        .collect(),
                    chosen: Channel::ALL.iter().position(|&c| c == channel).unwrap_or(0),
                    dropdown: true,
                },
            });
            options.push(ToolOption {
                label: "Tolerance",
                hover: "The largest difference still filled, in blend space",
                widget: OptionWidget::Slider {
                    value: tolerance,
                    min: 0.0,
                    max: 1.0,
                    integer: false,
                    change: |t| OptionChange::Fill(FillOption::Tolerance(t)),
                },
            });
        }
        options
    }

    fn set_option(&mut self, change: OptionChange, _doc: &Document) -> Vec<Command> {
        let OptionChange::Fill(option) = change else {
            return Vec::new();
        };
        match (option, &mut self.mode) {
            (FillOption::Mode(FillKind::Island), mode) => *mode = FillMode::Island,
            (FillOption::Mode(FillKind::Similar), mode @ (FillMode::Island | FillMode::All)) => {
                *mode = FillMode::Similar {
                    channel: Channel::Kd,
                    tolerance: 0.05,
                };
            }
            (FillOption::Mode(FillKind::All), mode) => *mode = FillMode::All,
            (FillOption::Channel(c), FillMode::Similar { channel, .. }) => *channel = c,
            (FillOption::Tolerance(t), FillMode::Similar { tolerance, .. }) => {
                if t.is_finite() {
                    *tolerance = t.clamp(0.0, 1.0);
                }
            }
            // Similar texels already: its channel and tolerance stay. A channel or tolerance
            // only means something to a fill of similar texels.
            (FillOption::Mode(FillKind::Similar), FillMode::Similar { .. })
            | (
                FillOption::Channel(_) | FillOption::Tolerance(_),
                FillMode::Island | FillMode::All,
            ) => {}
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
            ToolEvent::Drag { .. }
            | ToolEvent::Release
            | ToolEvent::Escape
            | ToolEvent::PickSource { .. }
            | ToolEvent::Commit => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        false
    }
}
