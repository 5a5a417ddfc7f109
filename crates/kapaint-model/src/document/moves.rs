//! Moving layers: up and down their list, into and out of groups, and by drag and drop. The
//! selection is the layer's id, so it follows the layer without repair.

use super::paths::{command_error, no_layer, split};
use super::{LayerMove, LayerPlace};
use crate::ModelError;
use crate::layers::{LayerContent, LayerStack, State};
use crate::project::layers::MAX_DEPTH;

/// Moves the selected layer within its list, or into or out of a group.
pub(super) fn move_layer(st: &mut State, m: LayerMove) -> Result<(), ModelError> {
    let (parent, i) = split(&st.selected_path())?;
    let list = st.stack.list_mut(&parent).ok_or_else(no_layer)?;
    let last = list.len() - 1;
    let to = match m {
        LayerMove::Up => (i + 1).min(last),
        LayerMove::Down => i.saturating_sub(1),
        LayerMove::Top => last,
        LayerMove::Bottom => 0,
        LayerMove::IntoGroup => {
            let Some(LayerContent::Group(_)) = list.get(i + 1).map(|l| &l.content) else {
                return Err(command_error("no group is just above the selected layer"));
            };
            let layer = list.remove(i);
            if let LayerContent::Group(children) = &mut list[i].content {
                children.insert(0, layer);
            }
            return check_depth(&st.stack);
        }
        LayerMove::OutOfGroup => {
            let (grand, g) = split(&parent)
                .map_err(|_| command_error("the selected layer is not in a group"))?;
            let layer = list.remove(i);
            let outer = st.stack.list_mut(&grand).ok_or_else(no_layer)?;
            outer.insert(g + 1, layer);
            return Ok(());
        }
    };
    let layer = list.remove(i);
    list.insert(to, layer);
    Ok(())
}

/// Moves the selected layer above or below `target`, or into it (a group), as the stack is
/// before the move. A group cannot go into itself or its own children.
pub(super) fn move_layer_to(
    st: &mut State,
    target: &[usize],
    place: LayerPlace,
) -> Result<(), ModelError> {
    let from = st.selected_path();
    let target_layer = st
        .stack
        .layer(target)
        .ok_or_else(|| command_error(format!("no layer is at {target:?}")))?;
    if place == LayerPlace::Into && !matches!(target_layer.content, LayerContent::Group(_)) {
        return Err(command_error(format!(
            "the layer \"{}\" is not a group",
            target_layer.props.name
        )));
    }
    if target.starts_with(&from) {
        if target == from.as_slice() && place != LayerPlace::Into {
            return Ok(());
        }
        return Err(command_error("a group cannot go into itself"));
    }
    let (parent, i) = split(&from)?;
    let layer = st.stack.list_mut(&parent).ok_or_else(no_layer)?.remove(i);
    // Taking the layer out shifts its later siblings (and what is inside them) down by one.
    let mut target = target.to_vec();
    if target.len() > parent.len() && target.starts_with(&parent) && target[parent.len()] > i {
        target[parent.len()] -= 1;
    }
    let (list_path, at) = match place {
        LayerPlace::Into => {
            let len = match st.stack.layer(&target).map(|l| &l.content) {
                Some(LayerContent::Group(children)) => children.len(),
                _ => 0,
            };
            (target, len)
        }
        LayerPlace::Above | LayerPlace::Below => {
            let (p, t) = split(&target)?;
            (p, if place == LayerPlace::Above { t + 1 } else { t })
        }
    };
    let list = st.stack.list_mut(&list_path).ok_or_else(no_layer)?;
    let at = at.min(list.len());
    list.insert(at, layer);
    check_depth(&st.stack)
}

/// An error when groups nest deeper than a project can store.
pub(super) fn check_depth(stack: &LayerStack) -> Result<(), ModelError> {
    let deepest = stack.walk().iter().map(|(p, _)| p.len()).max().unwrap_or(0);
    if deepest > MAX_DEPTH {
        return Err(command_error(format!(
            "layer groups cannot nest deeper than {MAX_DEPTH}"
        )));
    }
    Ok(())
}
