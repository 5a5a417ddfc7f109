//! The commands that change the layer stack and the selected layer's mask, and the names
//! they give layers, their kinds and places.

use serde::{Deserialize, Serialize};

use crate::paint::projection::Projection;
use crate::paint_image::PaintImage;
use crate::texel::{Channel, Channels, MaterialValue};

/// Every channel: what a projection fill fills unless it says otherwise.
fn all_channels() -> Channels {
    Channels::ALL
}

/// The layer stack: selection, properties and structure; each change is one undo step.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LayerCommand {
    /// Adds a layer above the selected one (in its group) and selects it.
    AddLayer {
        /// Paint, fill (the primary material) or group.
        kind: LayerKind,
        /// Its name.
        #[serde(deserialize_with = "crate::check::layer_name")]
        name: String,
    },
    /// Selects a layer by index (0: the bottom of the top level), name (the topmost of that
    /// name, at any depth) or id; tools then paint its content.
    SelectLayer(LayerRef),
    /// Selects the layer at a path of indices into groups (the Layers panel).
    SelectPath(Vec<usize>),
    /// Sets the selected layer's opacity (clamped to `[0, 1]`).
    SetLayerOpacity(#[serde(deserialize_with = "crate::check::layer_opacity")] f32),
    /// Shows or hides the selected layer.
    SetLayerVisible(bool),
    /// Locks or unlocks the selected layer against painting.
    SetLayerLocked(bool),
    /// Renames the selected layer.
    RenameLayer(#[serde(deserialize_with = "crate::check::layer_name")] String),
    /// Sets the blend mode of one of the selected layer's channels.
    SetLayerBlend {
        /// The channel.
        channel: Channel,
        /// Its mode (for `n`: Normal, Multiply, Add, Min, Max).
        mode: crate::layers::LayerBlend,
    },
    /// Which of its channels the selected layer lays over the layers below.
    SetLayerChannels(Channels),
    /// Sets a fill layer's material (a projection fill becomes a fill of that material).
    SetLayerFill(MaterialValue),
    /// Makes the selected fill layer a projection fill: `image` laid through `projection`
    /// (its colour into `k_d`, its luminance into `k_s`, its gray into `n`, as `ProjectImage`
    /// paints them) in the `channels` it names, its alpha the layer's coverage; laid again
    /// whenever the mesh changes.
    SetLayerProjection {
        /// The image (a relative path from the script's folder).
        image: PaintImage,
        /// How it is laid on the surface.
        projection: Projection,
        /// The channels it fills (all by default).
        #[serde(default = "all_channels")]
        channels: Channels,
    },
    /// Adds a projection fill (as `SetLayerProjection` makes one) above the selected layer
    /// and selects it: one undo step.
    AddProjectionFill {
        /// Its name.
        #[serde(deserialize_with = "crate::check::layer_name")]
        name: String,
        /// The image (a relative path from the script's folder).
        image: PaintImage,
        /// How it is laid on the surface.
        projection: Projection,
        /// The channels it fills (all by default).
        #[serde(default = "all_channels")]
        channels: Channels,
    },
    /// Moves the selected layer.
    MoveLayer(LayerMove),
    /// Moves the selected layer next to or into another (the Layers panel's drag and drop).
    MoveLayerTo {
        /// The path of the layer it lands by (as the stack is before the move).
        target: Vec<usize>,
        /// Above or below that layer in its list, or at the top of that group.
        place: LayerPlace,
    },
    /// Deletes the selected layer.
    DeleteLayer,
    /// Duplicates the selected layer above itself and selects the copy.
    DuplicateLayer,
    /// Merges the selected layer into the one below it (a paint layer of what both showed).
    MergeDown,
    /// Flattens every layer into one paint layer of the composite.
    Flatten,
    /// Puts the selected layer into a new group in its place.
    Group,
    /// Replaces the selected group by its layers.
    Ungroup,
}

/// The selected layer's mask; each change is one undo step.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaskCommand {
    /// Adds a white mask to the selected layer.
    AddMask,
    /// Deletes the selected layer's mask.
    DeleteMask,
    /// Bakes the selected layer's mask into it (a paint layer) and deletes the mask.
    ApplyMask,
    /// Tools paint the selected layer's mask.
    SelectMask,
    /// Tools paint the selected layer's content.
    SelectContent,
    /// Inverts the selected layer's mask.
    InvertMask,
    /// Enables or disables the selected layer's mask.
    SetMaskEnabled(bool),
    /// Makes the selected layer's mask white where a channel of the composite is above a
    /// threshold (`k_d`, `k_s`: their mean; `n`: the exponent), black elsewhere.
    MaskFromChannel {
        /// The channel read.
        channel: Channel,
        /// The threshold.
        #[serde(deserialize_with = "crate::check::finite_f32")]
        threshold: f32,
    },
    /// Makes the selected layer's mask by a generator (a mask is added if the layer has
    /// none), keeping what is painted over the generator it had; `None` turns the mask back
    /// into pixels, keeping what it showed.
    SetMaskGenerator(
        #[serde(deserialize_with = "super::script::mask_generator")]
        Option<crate::generator::Generator>,
    ),
    /// The editor's drag of a generator parameter: the mask made coarsely by `generator`
    /// (one value per 4 x 4 texels), joining the step of the previews before it; the
    /// `SetMaskGenerator` that ends the drag joins it too.
    #[serde(skip_deserializing)]
    PreviewMaskGenerator(crate::generator::Generator),
}

/// A layer's kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerKind {
    /// Painted planes.
    Paint,
    /// One material over the whole map, shaped by its mask.
    Fill,
    /// A folder of layers.
    Group,
}

/// A layer named in a script: its index in the top-level list, its name, or its id
/// (`(id: 7)`, as `kapaint layers` prints it: the same layer whatever moved).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum LayerRef {
    /// Index from the bottom of the top-level list.
    Index(usize),
    /// Name (the topmost layer of that name, at any depth).
    Name(String),
    /// Id, at any depth.
    Id {
        /// The layer's id.
        id: u64,
    },
}

/// Where [`LayerCommand::MoveLayer`] moves a layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerMove {
    /// One place up in its list.
    Up,
    /// One place down in its list.
    Down,
    /// The top of its list.
    Top,
    /// The bottom of its list.
    Bottom,
    /// Into the group just above it, at that group's bottom.
    IntoGroup,
    /// Out of its group, just above it.
    OutOfGroup,
}

/// Where [`LayerCommand::MoveLayerTo`] puts a layer, relative to its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerPlace {
    /// Just above the target, in the target's list.
    Above,
    /// Just below the target, in the target's list.
    Below,
    /// At the top of the target group's children.
    Into,
}
