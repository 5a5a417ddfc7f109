//! The layer commands, and the editing of the selected layer's planes by fills and gradients
//! (imports: `import.rs`). Each command that changes the stack is one undo step.

use super::{Command, Document, LayerKind, LayerRef, moves};
use crate::model::ModelError;
use crate::model::layers::edit::{EditValue, LayerEdit, Planes, PrePlanes};
use crate::model::layers::{
    Layer, LayerContent, LayerStack, LayerStroke, Mask, State, channel_index,
};
use crate::model::texel::MaterialValue;

/// The most layers (groups and their children included) a document holds.
pub const MAX_LAYERS: usize = 256;

pub(super) fn command_error(text: impl Into<String>) -> ModelError {
    ModelError::Command(text.into())
}

impl Document {
    /// Whether tools can paint the selection: a layer is selected, unlocked, and has planes
    /// (its mask, or a paint layer's content).
    pub(super) fn check_paintable(&self) -> Result<(), ModelError> {
        let sel = &self.state.selection;
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

    /// The selected layer's value at texel `(x, y)` over `under`: the channels a paint layer
    /// (or a group's merge) covers there, or a fill layer's material.
    pub(super) fn layer_value(&self, x: u32, y: u32, under: MaterialValue) -> MaterialValue {
        let Some(layer) = self.state.stack.layer(&self.state.selection.path) else {
            return under;
        };
        let (id, i) = self.maps.locate(x, y);
        let merged;
        let tile = match &layer.content {
            LayerContent::Fill(value) => return *value,
            LayerContent::Paint(tiles) => tiles.get(id).and_then(Option::as_ref).map(|t| t.get()),
            LayerContent::Group(children) => {
                merged = crate::model::layers::merge_tile(children, id);
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
            .layer(&self.state.selection.path)
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
        self.check_paintable()?;
        let before = self.state.clone();
        let count = self.state.stack.tile_count();
        let sel = &self.state.selection;
        let pre = before
            .stack
            .layer(&sel.path)
            .and_then(|l| l.planes(sel.mask));
        let planes = self
            .state
            .stack
            .layer_mut(&sel.path)
            .and_then(|l| l.planes_mut(sel.mask));
        if let (Some(planes), Some(pre)) = (planes, pre) {
            f(planes, pre, count);
        }
        and(&mut self.state);
        self.commit(label, before);
        Ok(())
    }

    /// Records `before` as one undo step and brings the composite up to date.
    fn commit(&mut self, label: &str, before: State) {
        self.record(label, before);
        self.compositor.update(&self.state.stack, &mut self.maps);
    }

    /// Runs `f` on the state as one undo step; on an error nothing changes.
    fn change(
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

    /// The layer commands.
    pub(super) fn layer_command(&mut self, command: Command) -> Result<(), ModelError> {
        match command {
            Command::SelectLayer(r) => {
                let path = resolve(&self.state.stack, &r)?;
                self.select(path, false);
                Ok(())
            }
            Command::SelectPath(path) => {
                if self.state.stack.layer(&path).is_none() {
                    return Err(command_error(format!("no layer is at {path:?}")));
                }
                self.select(path, false);
                Ok(())
            }
            Command::SelectMask => {
                let layer = self.selected()?;
                if layer.mask.is_none() {
                    return Err(command_error(format!(
                        "the layer \"{}\" has no mask: add one first",
                        layer.props.name
                    )));
                }
                self.select(self.state.selection.path.clone(), true);
                Ok(())
            }
            Command::SelectContent => {
                self.selected()?;
                self.select(self.state.selection.path.clone(), false);
                Ok(())
            }
            Command::SetLayerVisible(v) => {
                self.props(if v { "Show layer" } else { "Hide layer" }, |l| {
                    l.props.visible = v;
                    Ok(())
                })
            }
            Command::SetLayerLocked(v) => {
                self.props(if v { "Lock layer" } else { "Unlock layer" }, |l| {
                    l.props.locked = v;
                    Ok(())
                })
            }
            Command::RenameLayer(name) => self.props("Rename layer", |l| {
                l.props.name = crate::model::check::fit_name(&name, "", &l.props.name);
                Ok(())
            }),
            Command::SetLayerBlend { channel, mode } => self.props("Layer blend mode", |l| {
                if !mode.allowed_for(channel) {
                    return Err(command_error(format!(
                        "{} does not blend {}: use one of {}",
                        channel.name(),
                        mode.name(channel),
                        crate::model::layers::LayerBlend::ALL
                            .iter()
                            .filter(|m| m.allowed_for(channel))
                            .map(|m| m.name(channel))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
                l.props.channels[channel_index(channel)].mode = mode;
                Ok(())
            }),
            Command::SetLayerChannels(c) => self.props("Layer channels", |l| {
                for (ch, on) in [c.kd, c.ks, c.n].into_iter().enumerate() {
                    l.props.channels[ch].enabled = on;
                }
                Ok(())
            }),
            Command::SetLayerFill(v) => self.props("Fill material", |l| match &mut l.content {
                LayerContent::Fill(value) => {
                    *value = v.sanitized();
                    Ok(())
                }
                _ => Err(command_error(format!(
                    "the layer \"{}\" is not a fill layer",
                    l.props.name
                ))),
            }),
            other => self.structure_command(other),
        }
    }

    /// The layer commands that change the stack's structure or masks.
    fn structure_command(&mut self, command: Command) -> Result<(), ModelError> {
        match command {
            Command::AddLayer { kind, name } => self.change("Add layer", |st, cx| {
                if count_layers(&st.stack.layers) >= MAX_LAYERS {
                    return Err(command_error(format!(
                        "a document holds at most {MAX_LAYERS} layers"
                    )));
                }
                let layer = match kind {
                    LayerKind::Paint => Layer::paint(name, cx.tile_count),
                    LayerKind::Fill => Layer::fill(name, cx.primary),
                    LayerKind::Group => Layer::group(name, Vec::new()),
                };
                let (parent, at) = match st.selection.path.split_last() {
                    Some((&i, parent)) => (parent.to_vec(), i + 1),
                    None => (Vec::new(), st.stack.layers.len()),
                };
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                list.insert(at.min(list.len()), layer);
                st.selection.path = [parent, vec![at]].concat();
                st.selection.mask = false;
                Ok(())
            }),
            Command::DeleteLayer => self.change("Delete layer", |st, _| {
                let (parent, i) = split(&st.selection.path)?;
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                list.remove(i);
                st.selection.path = if list.is_empty() {
                    parent
                } else {
                    [parent, vec![i.saturating_sub(1).min(list.len() - 1)]].concat()
                };
                st.selection.mask = false;
                Ok(())
            }),
            Command::DuplicateLayer => self.change("Duplicate layer", |st, _| {
                if count_layers(&st.stack.layers) >= MAX_LAYERS {
                    return Err(command_error(format!(
                        "a document holds at most {MAX_LAYERS} layers"
                    )));
                }
                let (parent, i) = split(&st.selection.path)?;
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                let mut copy = list[i].clone().with_fresh_ids();
                // Never past what a project holds: the name is cut to leave room for " copy".
                copy.props.name = crate::model::check::fit_name(&copy.props.name, " copy", "copy");
                list.insert(i + 1, copy);
                st.selection.path = [parent, vec![i + 1]].concat();
                Ok(())
            }),
            Command::MergeDown => self.change("Merge down", |st, cx| {
                let (parent, i) = split(&st.selection.path)?;
                if i == 0 {
                    return Err(command_error(
                        "no layer is below the selected one to merge into",
                    ));
                }
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                let tiles = crate::model::layers::ops::merged(&list[i - 1..=i], cx.tile_count);
                let name = list[i - 1].props.name.clone();
                list.splice(
                    i - 1..=i,
                    [Layer {
                        props: crate::model::layers::LayerProps::named(name),
                        content: LayerContent::Paint(tiles),
                        mask: None,
                    }],
                );
                st.selection.path = [parent, vec![i - 1]].concat();
                st.selection.mask = false;
                Ok(())
            }),
            Command::Flatten => self.change("Flatten", |st, cx| {
                st.stack = LayerStack::from_maps(cx.maps, st.stack.base, "Flattened");
                st.selection.path = vec![0];
                st.selection.mask = false;
                Ok(())
            }),
            Command::MoveLayer(m) => self.change("Move layer", |st, _| moves::move_layer(st, m)),
            Command::MoveLayerTo { target, place } => self.change("Move layer", |st, _| {
                moves::move_layer_to(st, &target, place)
            }),
            other => self.group_command(other),
        }
    }

    /// Grouping and ungrouping.
    fn group_command(&mut self, command: Command) -> Result<(), ModelError> {
        match command {
            Command::Group => self.change("Group", |st, _| {
                let (parent, i) = split(&st.selection.path)?;
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                let layer = list.remove(i);
                list.insert(i, Layer::group("Group", vec![layer]));
                st.selection.mask = false;
                moves::check_depth(&st.stack)
            }),
            Command::Ungroup => self.change("Ungroup", |st, _| {
                let (parent, i) = split(&st.selection.path)?;
                let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
                let LayerContent::Group(children) = &list[i].content else {
                    return Err(command_error(format!(
                        "the layer \"{}\" is not a group",
                        list[i].props.name
                    )));
                };
                let children = children.clone();
                let n = children.len();
                list.splice(i..=i, children);
                st.selection.path = if n == 0 {
                    parent
                } else {
                    [parent, vec![i + n - 1]].concat()
                };
                st.selection.mask = false;
                Ok(())
            }),
            other => self.mask_command(other),
        }
    }

    /// The mask commands.
    fn mask_command(&mut self, command: Command) -> Result<(), ModelError> {
        match command {
            Command::AddMask => self.change("Add mask", |st, cx| {
                let layer = selected_mut(st)?;
                if layer.mask.is_none() {
                    layer.mask = Some(Mask::white(cx.tile_count));
                }
                Ok(())
            }),
            Command::DeleteMask => self.change("Delete mask", |st, _| {
                selected_mut(st)?.mask = None;
                st.selection.mask = false;
                Ok(())
            }),
            Command::InvertMask => self.mask_props("Invert mask", |m| {
                m.inverted = !m.inverted;
            }),
            Command::SetMaskEnabled(on) => {
                self.mask_props(if on { "Enable mask" } else { "Disable mask" }, |m| {
                    m.enabled = on;
                })
            }
            Command::MaskFromChannel { channel, threshold } => {
                self.change("Mask from channel", |st, cx| {
                    let tiles =
                        crate::model::layers::ops::mask_from_channel(cx.maps, channel, threshold);
                    let layer = selected_mut(st)?;
                    let mask = layer.mask.get_or_insert_with(|| Mask::white(cx.tile_count));
                    mask.tiles = tiles;
                    mask.inverted = false;
                    Ok(())
                })
            }
            Command::ApplyMask => self.change("Apply mask", |st, cx| {
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
                    *c = crate::model::layers::ChannelBlend {
                        enabled: true,
                        mode: crate::model::layers::LayerBlend::Normal,
                    };
                }
                layer.content =
                    LayerContent::Paint(crate::model::layers::ops::merged(&[bake], cx.tile_count));
                layer.mask = None;
                st.selection.mask = false;
                Ok(())
            }),
            other => Err(ModelError::Internal(format!(
                "{other:?} is not a layer command"
            ))),
        }
    }

    /// Sets the selected layer's opacity as one undo step, or, right after another change of
    /// the same layer's opacity (`run`), as part of that step.
    pub(super) fn set_opacity(
        &mut self,
        opacity: f32,
        run: Option<&[usize]>,
    ) -> Result<(), ModelError> {
        const LABEL: &str = "Layer opacity";
        let path = self.state.selection.path.clone();
        let opacity = opacity.clamp(0.0, 1.0);
        let joined = run == Some(path.as_slice()) && !self.stroking();
        match self.history.take_last(LABEL).filter(|_| joined) {
            Some(before) => {
                selected_mut(&mut self.state)?.props.opacity = opacity;
                self.commit(LABEL, before);
            }
            None => self.props(LABEL, |l| {
                l.props.opacity = opacity;
                Ok(())
            })?,
        }
        self.opacity_run = Some(path);
        Ok(())
    }

    fn select(&mut self, path: Vec<usize>, mask: bool) {
        self.end_stroke();
        self.state.selection = crate::model::layers::Selection { path, mask };
    }

    fn selected(&self) -> Result<&Layer, ModelError> {
        self.state
            .stack
            .layer(&self.state.selection.path)
            .ok_or_else(no_layer)
    }

    /// Changes the selected layer's settings as one undo step.
    fn props(
        &mut self,
        label: &str,
        f: impl FnOnce(&mut Layer) -> Result<(), ModelError>,
    ) -> Result<(), ModelError> {
        self.change(label, |st, _| f(selected_mut(st)?))
    }

    /// Changes the selected layer's mask's switches as one undo step.
    fn mask_props(&mut self, label: &str, f: impl FnOnce(&mut Mask)) -> Result<(), ModelError> {
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
    crate::model::texel::linear_to_srgb(kd.max_element()).clamp(0.0, 1.0)
}

pub(super) fn no_layer() -> ModelError {
    command_error("no layer is selected")
}

fn selected_mut(st: &mut State) -> Result<&mut Layer, ModelError> {
    st.stack.layer_mut(&st.selection.path).ok_or_else(no_layer)
}

/// The parent path and index of a layer's path.
pub(super) fn split(path: &[usize]) -> Result<(Vec<usize>, usize), ModelError> {
    path.split_last()
        .map(|(&i, parent)| (parent.to_vec(), i))
        .ok_or_else(no_layer)
}

/// Layers in `layers`, groups' children included.
pub fn count_layers(layers: &[Layer]) -> usize {
    layers
        .iter()
        .map(|l| {
            1 + match &l.content {
                LayerContent::Group(children) => count_layers(children),
                _ => 0,
            }
        })
        .sum()
}

/// The path of a layer named in a script.
fn resolve(stack: &LayerStack, r: &LayerRef) -> Result<Vec<usize>, ModelError> {
    match r {
        LayerRef::Index(i) if *i < stack.layers.len() => Ok(vec![*i]),
        LayerRef::Index(i) => Err(command_error(format!(
            "no layer has index {i} (the stack has {} at the top level)",
            stack.layers.len()
        ))),
        LayerRef::Name(name) => stack
            .walk()
            .into_iter()
            .rev()
            .find(|(_, l)| &l.props.name == name)
            .map(|(p, _)| p)
            .ok_or_else(|| command_error(format!("no layer is named \"{name}\""))),
        LayerRef::Id { id } => stack
            .path_of(crate::model::layers::LayerId(*id))
            .ok_or_else(|| command_error(format!("no layer has id {id}"))),
    }
}

/// What a layer command reads besides the state.
struct CommandContext<'a> {
    tile_count: usize,
    primary: MaterialValue,
    maps: &'a crate::model::maps::MaterialMaps,
}
