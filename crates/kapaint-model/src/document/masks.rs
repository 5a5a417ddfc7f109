//! The mask room: add, delete, apply, invert, enable, make from a channel, and which of the
//! selected layer's planes tools paint.

use std::sync::Arc;

use super::paths::{CommandContext, command_error, selected_mut};
use super::{Document, MaskCommand};
use crate::ModelError;
use crate::generator::Generator;
use crate::generator::tiles::{Generated, Source};
use crate::layers::{ChannelBlend, LayerBlend, LayerContent, LayerId, Mask, Stamped, State, ops};

impl Document {
    /// The mask commands, each one undo step (the selection switches are not steps).
    pub(super) fn mask_command(
        &mut self,
        command: MaskCommand,
        generator_run: Option<LayerId>,
    ) -> Result<(), ModelError> {
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
                    mask.generator = None;
                    Ok(())
                })
            }
            MaskCommand::ApplyMask => self.change("Apply mask", apply_mask),
            MaskCommand::SetMaskGenerator(generator) => {
                self.set_generator(generator, false, generator_run)
            }
            MaskCommand::PreviewMaskGenerator(generator) => {
                self.set_generator(Some(generator), true, generator_run)?;
                self.generator_run = self.state.selection.id;
                Ok(())
            }
        }
    }
}

impl Document {
    /// Sets (or clears) the selected layer's mask generator as one undo step, or, right after
    /// a preview of the same layer's (`run`), as part of that step.
    fn set_generator(
        &mut self,
        generator: Option<Generator>,
        coarse: bool,
        run: Option<LayerId>,
    ) -> Result<(), ModelError> {
        const LABEL: &str = "Mask generator";
        if let Some(g) = &generator {
            g.check().map_err(command_error)?;
            // A bake the generator reads must be there: never a flat default in its place.
            if let Some(map) = g
                .bakes_needed()
                .into_iter()
                .find(|&m| self.bake_of(m).is_none())
            {
                return Err(command_error(missing_bake(map)));
            }
        }
        let id = self.state.selection.id;
        let joined = id.is_some() && run == id && !self.stroking();
        let Some(before) = joined.then(|| self.history.take_last(LABEL)).flatten() else {
            return self.change(LABEL, |st, cx| lay(st, cx, generator, coarse));
        };
        let cx = super::paths::CommandContext {
            tile_count: self.state.stack.tile_count(),
            primary: self.settings.primary,
            maps: &self.maps,
        };
        let mut state = self.state.clone();
        match lay(&mut state, &cx, generator, coarse) {
            Ok(()) => {
                self.state = state;
                self.commit(LABEL, before);
                Ok(())
            }
            Err(e) => {
                // The drag's step goes back as it was.
                self.record(LABEL, before);
                Err(e)
            }
        }
    }
}

/// Why a generator that reads the `map` bake cannot be laid on a document without one.
fn missing_bake(map: kapaint_mesh::bakes::BakeMap) -> String {
    format!(
        "the mask generator reads the {name} bake, which the project does not have yet: bake \
         it first (`kapaint bake PROJECT --map {name}`, or Mesh > Bake in the editor)",
        name = map.name()
    )
}

/// What a generator reads in `st`: its surface, bakes and map size.
pub(super) fn source_of(st: &State) -> Source {
    Source::new(
        st.surface.clone(),
        &st.bakes,
        st.stack.width,
        st.stack.height,
    )
}

/// Lays `generator` on the selected layer's mask (added if it has none). Paint over a
/// generator stays; a painted mask's pixels give way to the generator. `None` turns a
/// generated mask into the pixels it shows.
fn lay(
    st: &mut State,
    cx: &CommandContext,
    generator: Option<Generator>,
    coarse: bool,
) -> Result<(), ModelError> {
    let source = source_of(st);
    let layer = selected_mut(st)?;
    match generator {
        Some(g) => {
            let made = Generated::new(g, source, coarse);
            match &mut layer.mask {
                Some(mask) if mask.generator.is_some() => mask.generator = Some(Arc::new(made)),
                Some(mask) => {
                    mask.tiles = vec![crate::layers::neutral_tile(); cx.tile_count];
                    mask.generator = Some(Arc::new(made));
                }
                None => layer.mask = Some(Mask::generated(cx.tile_count, made)),
            }
        }
        None => {
            if let Some(mask) = &mut layer.mask
                && mask.generator.is_some()
            {
                use rayon::prelude::*;
                let tiles = (0..mask.tiles.len())
                    .into_par_iter()
                    .map(|id| {
                        let mut plane = mask.plane(id).into_owned();
                        plane.compact();
                        Arc::new(Stamped::new(plane))
                    })
                    .collect();
                mask.tiles = tiles;
                mask.generator = None;
            }
        }
    }
    Ok(())
}

/// Lays every generator mask in `st` again where what it reads changed (the mesh, the
/// bakes, the map size): whether any was. Paint over them stays.
pub(super) fn lay_generators(st: &mut State) -> bool {
    let source = source_of(st);
    crate::layers::lay_generators(&mut st.stack.layers, &source)
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
