//! The mask room: add, delete, apply, invert, enable, make from a channel, and which of the
//! selected layer's planes tools paint.

use super::paths::{CommandContext, command_error, selected_mut};
use super::{Document, MaskCommand};
use crate::ModelError;
use crate::layers::{ChannelBlend, LayerBlend, LayerContent, Mask, State, ops};

impl Document {
    /// The mask commands, each one undo step (the selection switches are not steps).
    pub(super) fn mask_command(&mut self, command: MaskCommand) -> Result<(), ModelError> {
        match command {
            MaskCommand::SelectMask => {
                let layer = self.selected()?;
                if layer.mask.is_none() {
                    return Err(command_error(format!(
                        "the layer \"{}\" has no mask: add one first",
                        layer.props.name
                    )));
                }
                self.select(&self.state.selected_path(), true);
                Ok(())
            }
            MaskCommand::SelectContent => {
                self.selected()?;
                self.select(&self.state.selected_path(), false);
                Ok(())
            }
            MaskCommand::AddMask => self.change("Add mask", |st, cx| {
                let layer = selected_mut(st)?;
                if layer.mask.is_none() {
                    layer.mask = Some(Mask::white(cx.tile_count));
                }
                Ok(())
            }),
            MaskCommand::DeleteMask => self.change("Delete mask", |st, _| {
                selected_mut(st)?.mask = None;
                st.selection.mask = false;
                Ok(())
            }),
            MaskCommand::InvertMask => self.mask_props("Invert mask", |m| {
                m.inverted = !m.inverted;
            }),
            MaskCommand::SetMaskEnabled(on) => {
                self.mask_props(if on { "Enable mask" } else { "Disable mask" }, |m| {
                    m.enabled = on;
                })
            }
            MaskCommand::MaskFromChannel { channel, threshold } => {
                self.change("Mask from channel", |st, cx| {
                    let tiles = ops::mask_from_channel(cx.maps, channel, threshold);
                    let layer = selected_mut(st)?;
                    let mask = layer.mask.get_or_insert_with(|| Mask::white(cx.tile_count));
                    mask.tiles = tiles;
                    mask.inverted = false;
                    Ok(())
                })
            }
            MaskCommand::ApplyMask => self.change("Apply mask", apply_mask),
        }
    }
}

/// Bakes the selected layer's mask into its content (a paint layer) and deletes the mask.
fn apply_mask(st: &mut State, cx: &CommandContext) -> Result<(), ModelError> {
    let layer = selected_mut(st)?;
    if layer.mask.is_none() {
        return Err(command_error(format!(
            "the layer \"{}\" has no mask to apply",
            layer.props.name
        )));
    }
    let mut bake = layer.clone();
    bake.props.opacity = 1.0;
    bake.props.visible = true;
    for c in &mut bake.props.channels {
        *c = ChannelBlend {
            enabled: true,
            mode: LayerBlend::Normal,
        };
    }
    layer.content = LayerContent::Paint(ops::merged(&[bake], cx.tile_count));
    layer.mask = None;
    st.selection.mask = false;
    Ok(())
}
