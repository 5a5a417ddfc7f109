//! The fill tool: a press fills with the primary material, as its mode says.

use crate::model::PaintCommand;
use crate::model::texel::Channel;
use crate::model::{Command, Document, FillRegion};

use super::{Tool, ToolEvent};

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

impl Tool for Fill {
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
