//! The picker: a press reads every channel under the pointer into the primary material, on
//! the UV canvas or on the mesh: of the composite, or (an option) of the selected layer.

use crate::model::PaintCommand;
use crate::model::{Command, Document};

use super::{Tool, ToolEvent};

/// The picker tool.
#[derive(Clone, Copy, Debug, Default)]
pub struct Picker {
    /// Read the selected layer (its covered channels) rather than the composite.
    pub from_layer: bool,
}

impl Tool for Picker {
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        let size = (doc.maps().width(), doc.maps().height());
        match event {
            ToolEvent::Press { at, .. } | ToolEvent::Drag { at, .. } => at
                .texel_index(size)
                .map(|(x, y)| {
                    if self.from_layer {
                        PaintCommand::PickLayer { x, y }
                    } else {
                        PaintCommand::Pick { x, y }
                    }
                    .into()
                })
                .into_iter()
                .collect(),
            ToolEvent::Release | ToolEvent::Escape => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        false
    }
}
