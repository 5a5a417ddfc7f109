//! The picker: a press reads every channel under the pointer into the primary material, on
//! the UV canvas or on the mesh: of the composite, or (an option) of the selected layer.

use kapaint_model::PaintCommand;
use kapaint_model::{Command, Document};

use super::{
    OptionChange, OptionWidget, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta, ToolOption,
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

/// A change to the picker's options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PickerOption {
    /// Read the selected layer (`true`) or the composite.
    FromLayer(bool),
}

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
        let from = |name, layer| (name, OptionChange::Picker(PickerOption::FromLayer(layer)));
        vec![ToolOption {
            label: "",
            hover: "Read the composite, or what the selected layer holds",
            widget: OptionWidget::Choice {
                choices: vec![from("All layers", false), from("Selected layer", true)],
                chosen: usize::from(self.from_layer),
                dropdown: false,
            },
        }]
    }

    fn set_option(&mut self, change: OptionChange, _doc: &Document) -> Vec<Command> {
        if let OptionChange::Picker(PickerOption::FromLayer(layer)) = change {
            self.from_layer = layer;
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
            ToolEvent::Release
            | ToolEvent::Escape
            | ToolEvent::PickSource { .. }
            | ToolEvent::Commit => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        false
    }
}
