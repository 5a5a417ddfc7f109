//! The picker: a press reads every channel under the pointer into the primary material, on
//! the UV canvas or on the mesh.

use crate::model::{Command, Document};

use super::{Tool, ToolEvent};

/// The picker tool.
#[derive(Clone, Copy, Debug, Default)]
pub struct Picker;

impl Tool for Picker {
    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        let size = (doc.maps().width(), doc.maps().height());
        match event {
            ToolEvent::Press { at, .. } | ToolEvent::Drag { at, .. } => at
                .texel_index(size)
                .map(|(x, y)| Command::Pick { x, y })
                .into_iter()
                .collect(),
            ToolEvent::Release | ToolEvent::Escape => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        false
    }
}
