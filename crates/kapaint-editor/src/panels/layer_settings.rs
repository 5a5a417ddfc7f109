//! The Layers tab's lower half: the selected layer's name, opacity, channel enables and blend
//! modes, a fill layer's material, its mask's switches and the moves. Each change is a
//! [`Command`].

use super::layers::LayersPanel;
use super::presets::Presets;
use crate::desk::{Ask, Desk, Window};
use kapaint_model::layers::{Layer, LayerBlend, LayerContent};
use kapaint_model::texel::{Channel, Channels};
use kapaint_model::{Command, LayerMove};
use kapaint_model::{LayerCommand, MaskCommand};

impl LayersPanel {
    /// The selected layer's name, opacity, channels and blends, fill material, mask and moves.
    pub(super) fn selected_layer_ui(
        &mut self,
        ui: &mut egui::Ui,
        desk: &mut Desk,
        presets: &mut Presets,
    ) {
        let doc = desk.doc;
        let Some(layer) = doc.selected_layer() else {
            ui.label("No layer is selected.");
            return;
        };
        let mut commands: Vec<Command> = Vec::new();
        ui.label(egui::RichText::new(&layer.props.name).strong())
            .on_hover_text("Double-click the name in the list to rename");
        let mut opacity = layer.props.opacity * 100.0;
        if ui
            .add(
                egui::Slider::new(&mut opacity, 0.0..=100.0)
                    .suffix(" %")
                    .text("Opacity"),
            )
            .changed()
        {
            commands.push(LayerCommand::SetLayerOpacity(opacity / 100.0).into());
        }
        commands.extend(channels_ui(ui, layer).into_iter().map(Command::from));
        // A fill's material, or a projection fill's image and kind: either becomes a fill of
        // the primary.
        let flat = match &layer.content {
            LayerContent::Fill(value) => Some(format!("Now: n {:.0}", value.n)),
            LayerContent::Projected(p) => {
                projection_ui(ui, desk, p.fill());
                Some("Make it a flat fill again".to_string())
            }
            LayerContent::Paint(_) | LayerContent::Group(_) => None,
        };
        if let Some(hover) = flat
            && ui
                .button("Fill with the primary material")
                .on_hover_text(hover)
                .clicked()
        {
            commands.push(LayerCommand::SetLayerFill(doc.settings().primary).into());
        }
        commands.extend(
            mask_ui(ui, layer, doc.painting_mask())
                .into_iter()
                .map(Command::from),
        );
        // The generator's commands follow the ones above, in the order they were asked.
        for c in commands.drain(..) {
            desk.command(c);
        }
        self.generator_ui(ui, desk, layer, presets);
        ui.horizontal_wrapped(|ui| {
            for (text, m) in [
                ("Up", LayerMove::Up),
                ("Down", LayerMove::Down),
                ("Into group", LayerMove::IntoGroup),
                ("Out of group", LayerMove::OutOfGroup),
            ] {
                if ui.button(text).clicked() {
                    commands.push(LayerCommand::MoveLayer(m).into());
                }
            }
            if ui.button("Group").clicked() {
                commands.push(LayerCommand::Group.into());
            }
            if matches!(layer.content, LayerContent::Group(_)) && ui.button("Ungroup").clicked() {
                commands.push(LayerCommand::Ungroup.into());
            }
        });
        for c in commands {
            desk.command(c);
        }
    }
}

/// A projection fill's image and kind, and the button that opens Image > Project image on it.
fn projection_ui(
    ui: &mut egui::Ui,
    desk: &mut Desk,
    fill: &kapaint_model::layers::projected::ProjectionFill,
) {
    let name = fill
        .image
        .path()
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    ui.label(format!(
        "Projection: {name}, {}",
        crate::project_dialog::kind_name(&fill.projection)
    ));
    if ui
        .button("Edit projection…")
        .on_hover_text("Image > Project image, on this fill's choices")
        .clicked()
    {
        desk.ask(Ask::Show(Window::ProjectImage));
    }
}

/// Per channel: whether the layer lays it over those below, and its blend mode.
fn channels_ui(ui: &mut egui::Ui, layer: &Layer) -> Vec<LayerCommand> {
    let mut commands = Vec::new();
    let mut on = layer.props.channels.map(|c| c.enabled);
    egui::Grid::new("layer channels").show(ui, |ui| {
        for (k, channel) in Channel::ALL.into_iter().enumerate() {
            if ui.checkbox(&mut on[k], channel.name()).changed() {
                commands.push(LayerCommand::SetLayerChannels(Channels {
                    kd: on[0],
                    ks: on[1],
                    n: on[2],
                }));
            }
            let mode = layer.props.channels[k].mode;
            egui::ComboBox::from_id_salt(("layer blend", k))
                .selected_text(mode.name(channel))
                .width(110.0)
                .show_ui(ui, |ui| {
                    for m in LayerBlend::ALL
                        .into_iter()
                        .filter(|m| m.allowed_for(channel))
                    {
                        if ui.selectable_label(m == mode, m.name(channel)).clicked() && m != mode {
                            commands.push(LayerCommand::SetLayerBlend { channel, mode: m });
                        }
                    }
                });
            ui.end_row();
        }
    });
    commands
}

/// The mask's switches, or a button adding one.
fn mask_ui(ui: &mut egui::Ui, layer: &Layer, painting_mask: bool) -> Vec<MaskCommand> {
    let mut commands = Vec::new();
    ui.horizontal_wrapped(|ui| {
        let Some(mask) = &layer.mask else {
            if ui
                .button("Add mask")
                .on_hover_text("A white mask: paint black to hide")
                .clicked()
            {
                commands.push(MaskCommand::AddMask);
            }
            return;
        };
        let (text, command) = if painting_mask {
            ("Paint the layer", MaskCommand::SelectContent)
        } else {
            ("Paint the mask", MaskCommand::SelectMask)
        };
        if ui.button(text).clicked() {
            commands.push(command);
        }
        let mut enabled = mask.enabled;
        if ui.checkbox(&mut enabled, "Mask on").changed() {
            commands.push(MaskCommand::SetMaskEnabled(enabled));
        }
        for (text, command) in [
            ("Invert", MaskCommand::InvertMask),
            ("Apply", MaskCommand::ApplyMask),
            ("Delete mask", MaskCommand::DeleteMask),
        ] {
            if ui.button(text).clicked() {
                commands.push(command);
            }
        }
    });
    commands
}
