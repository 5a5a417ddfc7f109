//! Renaming a layer in its row of the list.

use kapaint_model::layers::{Layer, LayerId};

use super::LayersPanel;
use super::RowAction;

/// A layer's name being typed in place of its label in the list: Enter, Tab or a click
/// elsewhere commits it, Escape cancels, and the keyboard is the editor's again either way.
pub(in crate::panels) struct Rename {
    /// The document (its instance) the layer is in.
    pub(super) document: u64,
    /// The layer renamed.
    pub(super) id: LayerId,
    /// What is typed so far.
    pub(super) text: String,
    /// Whether the field has had the keyboard (it is given it once, on the first frame).
    pub(super) focused: bool,
}

impl LayersPanel {
    /// The layer's name in its row: a label to select (double-click renames), or the field
    /// of a rename under way.
    pub(super) fn name_ui(
        ui: &mut egui::Ui,
        layer: &Layer,
        selected: bool,
        rename: &mut Option<Rename>,
    ) -> Option<RowAction> {
        let p = &layer.props;
        let mut action = None;
        if let Some(r) = rename.as_mut().filter(|r| r.id == p.id) {
            let edit = ui.add(
                egui::TextEdit::singleline(&mut r.text)
                    .desired_width(140.0)
                    .id_salt(("rename layer", p.id)),
            );
            if !r.focused {
                edit.request_focus();
                r.focused = true;
            } else if !edit.has_focus() {
                // Enter, Tab and a click elsewhere take the keyboard from the field:
                // the name is done. Escape cancels it.
                // Read from the frame's raw input: egui takes the keyboard from the field
                // on Escape before any widget runs, and the editor's own Escape (abandon
                // the stroke) may have taken the key press by now.
                let pressed = |key| {
                    ui.input(|i| {
                        i.raw.events.iter().any(|e| {
                            matches!(e, egui::Event::Key { key: k, pressed: true, .. } if *k == key)
                        })
                    })
                };
                let (cancelled, tabbed) = (pressed(egui::Key::Escape), pressed(egui::Key::Tab));
                let text = r.text.trim().to_owned();
                action = Some(RowAction::Renamed {
                    name: (!cancelled && !text.is_empty() && text != p.name).then_some(text),
                    tabbed,
                });
            }
        } else {
            let name = ui.selectable_label(selected, &p.name);
            if name.double_clicked() {
                action = Some(RowAction::Rename);
            } else if name.clicked() {
                action = Some(RowAction::Select {
                    mask: false,
                    alone: false,
                });
            }
        }
        action
    }
}
