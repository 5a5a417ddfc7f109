//! The layer commands, and the editing of the selected layer's planes by fills and gradients
//! (imports: `import.rs`). Each command that changes the stack is one undo step.

use super::paths::{CommandContext, command_error, no_layer, resolve, selected_mut};
use super::{Document, LayerCommand, moves, structure};
use crate::ModelError;
use crate::layers::edit::{EditValue, LayerEdit, Planes, PrePlanes};
use crate::layers::{Layer, LayerContent, LayerId, LayerStroke, Mask, State, channel_index};
use crate::texel::MaterialValue;

impl Document {
    /// Whether tools can paint the selection: a layer is selected, unlocked, and has planes
    /// (its mask, or a paint layer's content).
    pub(super) fn check_paintable(&self) -> Result<(), ModelError> {
        let sel = self.state.selection();
        let layer = self
            .state
            .stack
            .layer(&sel.path)
            .ok_or_else(|| command_error("no layer is selected: add one to paint on"))?;
        let name = &layer.props.name;
        if layer.props.locked {
            return Err(command_error(format!("the layer \"{name}\" is locked")));
        }
        if layer.planes(sel.mask).is_none() {
            return Err(command_error(if sel.mask {
                format!("the layer \"{name}\" has no mask: add one first")
            } else {
                format!(
                    "the {} layer \"{name}\" has no pixels to paint: paint its mask, or a paint layer",
                    layer.kind_name()
                )
            }));
        }
        Ok(())
    }

    /// What tools write: the material from `from` to `to` in the tool channels, or on a mask
    /// their gray.
    pub(super) fn layer_edit(
        &self,
        from: MaterialValue,
        to: MaterialValue,
        stroke: LayerStroke,
    ) -> LayerEdit {
        let c = self.settings.channels;
        // On a mask, tools paint the value of their colour (as Krita and Substance do: white
        // reveals, black hides, grey between) and the eraser hides (black), as seen through
        // the mask's inversion.
        let shown = |v: MaterialValue| {
            if stroke == LayerStroke::Erase {
                0.0
            } else {
                mask_gray(v)
            }
        };
        LayerEdit {
            from: EditValue::of(from),
            to: EditValue::of(to),
            channels: [c.kd, c.ks, c.n],
            stroke,
            gray: [self.stored_gray(shown(from)), self.stored_gray(shown(to))],
            energy_guard: self.settings.brush.energy_guard,
        }
    }

    /// A projection fill's parameters, checked: a loaded image, a projection whose numbers
    /// make a frame, and the mesh it needs.
    fn projection_fill(
        &self,
        image: crate::paint_image::PaintImage,
        projection: crate::paint::projection::Projection,
        channels: crate::texel::Channels,
    ) -> Result<crate::layers::projected::ProjectionFill, ModelError> {
        image.pixels()?;
        projection.check().map_err(ModelError::Command)?;
        if projection.needs_surface() {
            self.require_surface("a projection fill")?;
        }
        if !(channels.kd || channels.ks || channels.n) {
            return Err(command_error(
                "a projection fill must fill at least one channel",
            ));
        }
        Ok(crate::layers::projected::ProjectionFill {
            image,
            projection,
            channels,
        })
    }

    /// The selected layer's value at texel `(x, y)` over `under`: the channels a paint layer
    /// (or a group's merge) covers there, or a fill layer's material.
    pub(super) fn layer_value(&self, x: u32, y: u32, under: MaterialValue) -> MaterialValue {
        let Some(layer) = self.state.stack.layer(&self.state.selected_path()) else {
            return under;
        };
        let (id, i) = self.maps.locate(x, y);
        let merged;
        let tile = match &layer.content {
            LayerContent::Fill(value) => return *value,
            LayerContent::Paint(tiles) => tiles.get(id).and_then(Option::as_ref).map(|t| t.get()),
            LayerContent::Projected(p) => p.tile(id).map(|t| t.get()),
            LayerContent::Group(children) => {
                merged = crate::layers::merge_tile(children, id);
                merged.as_ref()
            }
        };
        let Some(tile) = tile else {
            return under;
        };
        let v = tile.value.texel(i).decode();
        let [kd, ks, n] = tile.alpha.each_ref().map(|a| a.get(i) > 0);
        MaterialValue {
            kd: if kd { v.kd } else { under.kd },
            ks: if ks { v.ks } else { under.ks },
            n: if n { v.n } else { under.n },
        }
    }

    /// The stored gray of the selected mask that shows as `shown`.
    pub(super) fn stored_gray(&self, shown: f32) -> f32 {
        let inverted = self
            .state
            .stack
            .layer(&self.state.selected_path())
            .and_then(|l| l.mask.as_ref())
            .is_some_and(|m| m.inverted);
        if inverted { 1.0 - shown } else { shown }
    }

    /// One undo step that writes the selected planes: `f` gets them, the same planes as they
    /// were before, and the tile count.
    pub(super) fn edit_planes(
        &mut self,
        label: &str,
        f: impl FnOnce(Planes<'_>, PrePlanes<'_>, usize),
    ) -> Result<(), ModelError> {
        self.edit_planes_and(label, f, |_| {})
    }

    /// As [`Document::edit_planes`], with `and` changing the rest of the state in the same
    /// undo step.
    pub(super) fn edit_planes_and(
        &mut self,
        label: &str,
        f: impl FnOnce(Planes<'_>, PrePlanes<'_>, usize),
        and: impl FnOnce(&mut State),
    ) -> Result<(), ModelError> {
        self.try_edit_planes(
            label,
            |planes, pre, count| {
                f(planes, pre, count);
                Ok(())
            },
            and,
        )
    }

    /// As [`Document::edit_planes_and`], where `f` may find the edit void: its error leaves
    /// the state as it was, with no undo step.
    pub(super) fn try_edit_planes(
        &mut self,
        label: &str,
        f: impl FnOnce(Planes<'_>, PrePlanes<'_>, usize) -> Result<(), ModelError>,
        and: impl FnOnce(&mut State),
    ) -> Result<(), ModelError> {
        self.check_paintable()?;
        let before = self.state.clone();
        let count = self.state.stack.tile_count();
        let sel = self.state.selection();
        let pre = before
            .stack
            .layer(&sel.path)
            .and_then(|l| l.planes(sel.mask));
        let planes = self
            .state
            .stack
            .layer_mut(&sel.path)
            .and_then(|l| l.planes_mut(sel.mask));
        if let (Some(planes), Some(pre)) = (planes, pre)
            && let Err(e) = f(planes, pre, count)
        {
            self.state = before;
            return Err(e);
        }
        and(&mut self.state);
        self.commit(label, before);
        Ok(())
    }

    /// Records `before` as one undo step and brings the composite up to date.
    pub(super) fn commit(&mut self, label: &str, before: State) {
        self.record(label, before);
        self.compositor.update(&self.state.stack, &mut self.maps);
    }

    /// Runs `f` on the state as one undo step; on an error nothing changes.
    pub(super) fn change(
        &mut self,
        label: &str,
        f: impl FnOnce(&mut State, &CommandContext) -> Result<(), ModelError>,
    ) -> Result<(), ModelError> {
        self.end_stroke();
        let before = self.state.clone();
        let cx = CommandContext {
            tile_count: self.state.stack.tile_count(),
            primary: self.settings.primary,
            maps: &self.maps,
        };
        if let Err(e) = f(&mut self.state, &cx) {
            self.state = before;
            return Err(e);
        }
        self.commit(label, before);
        Ok(())
    }

    /// The layer room.
    pub(super) fn layer_command(
        &mut self,
        command: LayerCommand,
        opacity_run: Option<LayerId>,
    ) -> Result<(), ModelError> {
        match command {
            LayerCommand::SelectLayer(r) => {
                let path = resolve(&self.state.stack, &r)?;
                self.select(&path, false);
                Ok(())
            }
            LayerCommand::SelectPath(path) => {
                if self.state.stack.layer(&path).is_none() {
                    return Err(command_error(format!("no layer is at {path:?}")));
                }
                self.select(&path, false);
                Ok(())
            }
            LayerCommand::SetLayerOpacity(opacity) => self.set_opacity(opacity, opacity_run),
            LayerCommand::SetLayerVisible(v) => {
                self.props(if v { "Show layer" } else { "Hide layer" }, |l| {
                    l.props.visible = v;
                    Ok(())
                })
            }
            LayerCommand::SetLayerLocked(v) => {
                self.props(if v { "Lock layer" } else { "Unlock layer" }, |l| {
                    l.props.locked = v;
                    Ok(())
                })
            }
            LayerCommand::RenameLayer(name) => self.props("Rename layer", |l| {
                l.props.name = crate::check::fit_name(&name, "", &l.props.name);
                Ok(())
            }),
            LayerCommand::SetLayerBlend { channel, mode } => {
                self.props("Layer blend mode", |l| set_blend(l, channel, mode))
            }
            LayerCommand::SetLayerChannels(c) => self.props("Layer channels", |l| {
                for (ch, on) in [c.kd, c.ks, c.n].into_iter().enumerate() {
                    l.props.channels[ch].enabled = on;
                }
                Ok(())
            }),
            LayerCommand::SetLayerFill(v) => self.props("Fill material", |l| set_fill(l, v)),
            LayerCommand::SetLayerProjection {
                image,
                projection,
                channels,
            } => {
                let fill = self.projection_fill(image, projection, channels)?;
                self.change("Fill projection", |st, _| {
                    let source = super::masks::source_of(st);
                    let layer = selected_mut(st)?;
                    if !matches!(
                        layer.content,
                        LayerContent::Fill(_) | LayerContent::Projected(_)
                    ) {
                        return Err(command_error(format!(
                            "the layer \"{}\" is not a fill layer",
                            layer.props.name
                        )));
                    }
                    layer.content = laid(fill, source)?;
                    Ok(())
                })
            }
            LayerCommand::AddProjectionFill {
                name,
                image,
                projection,
                channels,
            } => {
                let fill = self.projection_fill(image, projection, channels)?;
                self.change("Add projection fill", |st, cx| {
                    structure::add(st, cx, crate::document::LayerKind::Fill, name)?;
                    let source = super::masks::source_of(st);
                    selected_mut(st)?.content = laid(fill, source)?;
                    Ok(())
                })
            }
            LayerCommand::AddLayer { kind, name } => {
                self.change("Add layer", |st, cx| structure::add(st, cx, kind, name))
            }
            LayerCommand::DeleteLayer => self.change("Delete layer", |st, _| structure::delete(st)),
            LayerCommand::DuplicateLayer => {
                self.change("Duplicate layer", |st, _| structure::duplicate(st))
            }
            LayerCommand::MergeDown => self.change("Merge down", structure::merge_down),
            LayerCommand::Flatten => self.change("Flatten", |st, cx| {
                structure::flatten(st, cx);
                Ok(())
            }),
            LayerCommand::MoveLayer(m) => {
                self.change("Move layer", |st, _| moves::move_layer(st, m))
            }
            LayerCommand::MoveLayerTo { target, place } => self.change("Move layer", |st, _| {
                moves::move_layer_to(st, &target, place)
            }),
            LayerCommand::Group => self.change("Group", |st, _| structure::group(st)),
            LayerCommand::Ungroup => self.change("Ungroup", |st, _| structure::ungroup(st)),
        }
    }

    /// Sets the selected layer's opacity as one undo step, or, right after another change of
    /// the same layer's opacity (`run`), as part of that step.
    pub(super) fn set_opacity(
        &mut self,
        opacity: f32,
        run: Option<LayerId>,
    ) -> Result<(), ModelError> {
        const LABEL: &str = "Layer opacity";
        let id = self.state.selection.id;
        let opacity = opacity.clamp(0.0, 1.0);
        let joined = id.is_some() && run == id && !self.stroking();
        match joined.then(|| self.history.take_last(LABEL)).flatten() {
            Some(before) => {
                selected_mut(&mut self.state)?.props.opacity = opacity;
                self.commit(LABEL, before);
            }
            None => self.props(LABEL, |l| {
                l.props.opacity = opacity;
                Ok(())
            })?,
        }
        self.opacity_run = id;
        Ok(())
    }

    pub(super) fn select(&mut self, path: &[usize], mask: bool) {
        self.end_stroke();
        self.state.select_path(path);
        self.state.selection.mask = mask;
    }

    pub(super) fn selected(&self) -> Result<&Layer, ModelError> {
        self.selected_layer().ok_or_else(no_layer)
    }

    /// Changes the selected layer's settings as one undo step.
    pub(super) fn props(
        &mut self,
        label: &str,
        f: impl FnOnce(&mut Layer) -> Result<(), ModelError>,
    ) -> Result<(), ModelError> {
        self.change(label, |st, _| f(selected_mut(st)?))
    }

    /// Changes the selected layer's mask's switches as one undo step.
    pub(super) fn mask_props(
        &mut self,
        label: &str,
        f: impl FnOnce(&mut Mask),
    ) -> Result<(), ModelError> {
        self.change(label, |st, _| {
            let layer = selected_mut(st)?;
            let name = layer.props.name.clone();
            let mask = layer
                .mask
                .as_mut()
                .ok_or_else(|| command_error(format!("the layer \"{name}\" has no mask")))?;
            f(mask);
            Ok(())
        })
    }
}

/// The gray a material paints on a mask: the value (HSV's V) of its `k_d` as displayed, in
/// sRGB, so the swatch's brightness is the mask's.
pub fn mask_gray(v: MaterialValue) -> f32 {
    let kd = v.sanitized().kd;
    crate::texel::linear_to_srgb(kd.max_element()).clamp(0.0, 1.0)
}

/// Sets the blend mode of one of a layer's channels, where the channel has that mode.
fn set_blend(
    l: &mut Layer,
    channel: crate::texel::Channel,
    mode: crate::layers::LayerBlend,
) -> Result<(), ModelError> {
    if !mode.allowed_for(channel) {
        return Err(command_error(format!(
            "{} does not blend {}: use one of {}",
            channel.name(),
            mode.name(channel),
            crate::layers::LayerBlend::ALL
                .iter()
                .filter(|m| m.allowed_for(channel))
                .map(|m| m.name(channel))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    l.props.channels[channel_index(channel)].mode = mode;
    Ok(())
}

/// A projection fill laid on `source`, refused where it reaches no texel (its tiles laid now,
/// in parallel: the composite reads them next).
fn laid(
    fill: crate::layers::projected::ProjectionFill,
    source: crate::generator::tiles::Source,
) -> Result<LayerContent, ModelError> {
    use rayon::prelude::*;
    let laid = crate::layers::projected::Projected::new(fill, source);
    let count = laid.tile_count();
    if !(0..count).into_par_iter().any(|id| laid.tile(id).is_some()) {
        return Err(command_error(
            "the projection reaches no texel of the map (nothing faces it, or it lies off the mesh)",
        ));
    }
    Ok(LayerContent::Projected(std::sync::Arc::new(laid)))
}

/// Sets a fill layer's material (a projection fill's included).
fn set_fill(l: &mut Layer, v: MaterialValue) -> Result<(), ModelError> {
    match &mut l.content {
        LayerContent::Fill(_) | LayerContent::Projected(_) => {
            l.content = LayerContent::Fill(v.sanitized());
            Ok(())
        }
        _ => Err(command_error(format!(
            "the layer \"{}\" is not a fill layer",
            l.props.name
        ))),
    }
}
