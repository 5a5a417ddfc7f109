//! The picker: a press reads every channel under the pointer into the primary material, on
//! the UV canvas or on the mesh: of the composite, or (an option) of the selected layer.

use crate::model::PaintCommand;
use crate::model::{Command, Document};

use super::{
    OptionValue, OptionWidget, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta, ToolOption,
};

/// The picker tool.
#[derive(Clone, Copy, Debug, Default)]
pub struct Picker {
    /// Read the selected layer (its covered channels) rather than the composite.
    pub from_layer: bool,
}

impl ToolKind {
    /// The picker.
    pub const PICKER: Self = Self("picker");
}

/// Where the picker reads, as the panel names it.
const SOURCES: &[&str] = &["All layers", "Selected layer"];

impl Tool for Picker {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::PICKER,
            label: "Picker",
            key: Some('I'),
            key_help: "I",
            summary: "picker",
            cursor: ToolCursor::Crosshair,
        }
    }

    fn options(&self, _doc: &Document) -> Vec<ToolOption> {
        vec![ToolOption {
            id: "from",
            label: "",
            hover: "Read the composite, or what the selected layer holds",
            widget: OptionWidget::Choice {
                choices: SOURCES,
                chosen: usize::from(self.from_layer),
                dropdown: false,
            },
        }]
    }

    fn set_option(&mut self, id: &str, value: OptionValue, _doc: &Document) -> Vec<Command> {
        if let ("from", OptionValue::Choice(i @ (0 | 1))) = (id, value) {
            self.from_layer = i == 1;
        }
        Vec::new()
    }

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
