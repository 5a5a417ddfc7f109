//! The commands that change the stack's structure: add, delete, duplicate, merge, flatten,
//! group and ungroup. Each changes the state it is given; the caller makes it one undo step.

use super::paths::{CommandContext, MAX_LAYERS, command_error, count_layers, no_layer, split};
use super::{LayerKind, moves};
use crate::ModelError;
use crate::layers::{Layer, LayerContent, LayerStack, State};

/// Refuses one more layer past [`MAX_LAYERS`].
fn check_room(st: &State) -> Result<(), ModelError> {
    if count_layers(&st.stack.layers) >= MAX_LAYERS {
        return Err(command_error(format!(
            "a document holds at most {MAX_LAYERS} layers"
        )));
    }
    Ok(())
}

/// Adds a layer above the selected one and selects it.
pub(super) fn add(
    st: &mut State,
    cx: &CommandContext,
    kind: LayerKind,
    name: String,
) -> Result<(), ModelError> {
    check_room(st)?;
    let layer = match kind {
        LayerKind::Paint => Layer::paint(name, cx.tile_count),
        LayerKind::Fill => Layer::fill(name, cx.primary),
        LayerKind::Group => Layer::group(name, Vec::new()),
    };
    let (parent, at) = match st.selected_path().split_last() {
        Some((&i, parent)) => (parent.to_vec(), i + 1),
        None => (Vec::new(), st.stack.layers.len()),
    };
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    list.insert(at.min(list.len()), layer);
    st.select_path(&[parent, vec![at]].concat());
    st.selection.mask = false;
    Ok(())
}

/// Deletes the selected layer and selects the one below it (or its group).
pub(super) fn delete(st: &mut State) -> Result<(), ModelError> {
    let (parent, i) = split(&st.selected_path())?;
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    list.remove(i);
    let below = if list.is_empty() {
        parent
    } else {
        [parent, vec![i.saturating_sub(1).min(list.len() - 1)]].concat()
    };
    st.select_path(&below);
    st.selection.mask = false;
    Ok(())
}

/// Copies the selected layer (new ids) above itself and selects the copy.
pub(super) fn duplicate(st: &mut State) -> Result<(), ModelError> {
    check_room(st)?;
    let (parent, i) = split(&st.selected_path())?;
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    let mut copy = list[i].clone().with_fresh_ids();
    // Never past what a project holds: the name is cut to leave room for " copy".
    copy.props.name = crate::check::fit_name(&copy.props.name, " copy", "copy");
    list.insert(i + 1, copy);
    st.select_path(&[parent, vec![i + 1]].concat());
    Ok(())
}

/// Merges the selected layer into the one below it: a paint layer of what both showed.
pub(super) fn merge_down(st: &mut State, cx: &CommandContext) -> Result<(), ModelError> {
    let (parent, i) = split(&st.selected_path())?;
    if i == 0 {
        return Err(command_error(
            "no layer is below the selected one to merge into",
        ));
    }
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    let tiles = crate::layers::ops::merged(&list[i - 1..=i], cx.tile_count);
    let name = list[i - 1].props.name.clone();
    list.splice(
        i - 1..=i,
        [Layer {
            props: crate::layers::LayerProps::named(name),
            content: LayerContent::Paint(tiles),
            mask: None,
        }],
    );
    st.select_path(&[parent, vec![i - 1]].concat());
    st.selection.mask = false;
    Ok(())
}

/// One paint layer of the composite in place of the whole stack.
pub(super) fn flatten(st: &mut State, cx: &CommandContext) {
    st.stack = LayerStack::from_maps(cx.maps, st.stack.base, "Flattened");
    st.select_path(&[0]);
    st.selection.mask = false;
}

/// Puts the selected layer into a new group in its place.
pub(super) fn group(st: &mut State) -> Result<(), ModelError> {
    let (parent, i) = split(&st.selected_path())?;
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    let layer = list.remove(i);
    list.insert(i, Layer::group("Group", vec![layer]));
    // The new group is selected, where the layer was.
    st.select_path(&[parent, vec![i]].concat());
    st.selection.mask = false;
    moves::check_depth(&st.stack)
}

/// Replaces the selected group by its layers, selecting the top one.
pub(super) fn ungroup(st: &mut State) -> Result<(), ModelError> {
    let (parent, i) = split(&st.selected_path())?;
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
    st.select_path(&if n == 0 {
        parent
    } else {
        [parent, vec![i + n - 1]].concat()
    });
    st.selection.mask = false;
    Ok(())
}
