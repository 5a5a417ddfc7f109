//! Finding layers: the selected one, a path's parent, a layer a script names; and the errors
//! when there is none. A leaf that the layer, structure and move commands share.

use super::LayerRef;
use crate::ModelError;
use crate::layers::{Layer, LayerContent, LayerStack, State};
use crate::texel::MaterialValue;

pub use crate::check::MAX_LAYERS;

/// A command's refusal, in the user's words.
pub(super) fn command_error(text: impl Into<String>) -> ModelError {
    ModelError::Command(text.into())
}

/// The refusal when no layer is selected.
pub(super) fn no_layer() -> ModelError {
    command_error("no layer is selected")
}

/// The selected layer.
pub(super) fn selected_mut(st: &mut State) -> Result<&mut Layer, ModelError> {
    let path = st.selected_path();
    st.stack.layer_mut(&path).ok_or_else(no_layer)
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
pub(super) fn resolve(stack: &LayerStack, r: &LayerRef) -> Result<Vec<usize>, ModelError> {
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
            .path_of(crate::layers::LayerId(*id))
            .ok_or_else(|| command_error(format!("no layer has id {id}"))),
    }
}

/// What a layer command reads besides the state.
pub(super) struct CommandContext<'a> {
    pub(super) tile_count: usize,
    pub(super) primary: MaterialValue,
    pub(super) maps: &'a crate::maps::MaterialMaps,
}
