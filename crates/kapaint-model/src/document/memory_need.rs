//! Which commands may write a whole layer, and so are refused when the memory could not hold
//! one more layer and its composite ([`super::Document`]'s memory check). Every command
//! answers by an exhaustive match, so a new command does not compile until it says.

use super::command::{
    Command, HistoryCommand, ImportCommand, LayerCommand, MaskCommand, PaintCommand,
    SettingsCommand, StrokeCommand,
};

impl Command {
    /// Whether the command may fill a whole layer, a mask or a merged layer.
    pub(crate) fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::Settings(c) => c.may_write_a_whole_layer(),
            Self::Stroke(c) => c.may_write_a_whole_layer(),
            Self::Paint(c) => c.may_write_a_whole_layer(),
            Self::Import(c) => c.may_write_a_whole_layer(),
            Self::History(c) => c.may_write_a_whole_layer(),
            Self::Layer(c) => c.may_write_a_whole_layer(),
            Self::Mask(c) => c.may_write_a_whole_layer(),
        }
    }
}

impl SettingsCommand {
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::SetBrush(_)
            | Self::SetPrimary(_)
            | Self::SetSecondary(_)
            | Self::SwapMaterials
            | Self::SetChannels(_)
            | Self::SetModel(_)
            | Self::SetApprox(_)
            | Self::SetStencil { .. }
            | Self::ClearStencil
            | Self::SetCloneSource(_)
            | Self::SetSurfaceCloneSource(_) => false,
        }
    }
}

impl StrokeCommand {
    /// A stroke's first dab is where its layer's memory is checked (a whole stroke may cover
    /// the map); the dabs after it write into tiles the stroke already holds.
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::BeginStroke(_) | Self::Stroke { .. } | Self::SurfaceStroke { .. } => true,
            Self::StrokeTo(_) | Self::EndStroke | Self::AbortStroke | Self::SurfaceStrokeTo(_) => {
                false
            }
        }
    }
}

impl PaintCommand {
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::Fill(_)
            | Self::Gradient { .. }
            | Self::ProjectImage { .. }
            | Self::PlaceDecal { .. }
            | Self::PreviewDecal(_) => true,
            Self::Pick { .. } | Self::PickLayer { .. } | Self::DropDecal => false,
        }
    }
}

impl ImportCommand {
    /// Channels and materials land in a layer; normals, meshes and bakes are kept beside the
    /// stack, and a resize replaces the maps with ones already made.
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::ImportChannel(_) | Self::ImportMaterial(_) => true,
            Self::SetNormal(_)
            | Self::SetMesh(_)
            | Self::SetBake(_)
            | Self::SetBakes(_)
            | Self::Resize(_) => false,
        }
    }
}

impl HistoryCommand {
    /// Undo and redo swap in tiles the history already holds.
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::Undo | Self::Redo | Self::HistoryJump(_) => false,
        }
    }
}

impl LayerCommand {
    /// Merging and flattening make new tiles, and a projection fill lays a whole layer of
    /// them; a new, duplicated or fill layer shares them or holds none.
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::MergeDown
            | Self::Flatten
            | Self::SetLayerProjection { .. }
            | Self::AddProjectionFill { .. } => true,
            Self::AddLayer { .. }
            | Self::SelectLayer(_)
            | Self::SelectPath(_)
            | Self::SetLayerOpacity(_)
            | Self::SetLayerVisible(_)
            | Self::SetLayerLocked(_)
            | Self::RenameLayer(_)
            | Self::SetLayerBlend { .. }
            | Self::SetLayerChannels(_)
            | Self::SetLayerFill(_)
            | Self::MoveLayer(_)
            | Self::MoveLayerTo { .. }
            | Self::DeleteLayer
            | Self::DuplicateLayer
            | Self::Group
            | Self::Ungroup => false,
        }
    }
}

impl MaskCommand {
    /// Every edit that makes a whole mask, laying a generator's included (the whitelist this
    /// match replaced had missed it). A generator's live preview is not an edit: it is
    /// dropped, never kept, when the memory runs short.
    fn may_write_a_whole_layer(&self) -> bool {
        match self {
            Self::AddMask
            | Self::ApplyMask
            | Self::InvertMask
            | Self::MaskFromChannel { .. }
            | Self::SetMaskGenerator(Some(_)) => true,
            Self::DeleteMask
            | Self::SelectMask
            | Self::SelectContent
            | Self::SetMaskEnabled(_)
            | Self::SetMaskGenerator(None)
            | Self::PreviewMaskGenerator(_) => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::{Generator, Levels};

    #[test]
    fn every_edit_that_makes_a_whole_layer_or_mask_is_checked() {
        let levels = Levels {
            black: 0.0,
            white: 1.0,
            gamma: 1.0,
            invert: false,
            relative: false,
        };
        let checked = [
            Command::Paint(PaintCommand::Fill(crate::FillRegion::All)),
            Command::Layer(LayerCommand::MergeDown),
            Command::Layer(LayerCommand::Flatten),
            Command::Mask(MaskCommand::AddMask),
            Command::Mask(MaskCommand::InvertMask),
            // Laying a generator makes a whole mask: the whitelist before the match missed it.
            Command::Mask(MaskCommand::SetMaskGenerator(Some(Generator::Ao(levels)))),
        ];
        for command in &checked {
            assert!(command.may_write_a_whole_layer(), "{command:?}");
        }
        let unchecked = [
            Command::History(HistoryCommand::Undo),
            Command::Stroke(StrokeCommand::EndStroke),
            Command::Layer(LayerCommand::DuplicateLayer),
            Command::Mask(MaskCommand::SetMaskGenerator(None)),
            Command::Mask(MaskCommand::PreviewMaskGenerator(Generator::Ao(levels))),
            Command::Settings(SettingsCommand::SwapMaterials),
        ];
        for command in &unchecked {
            assert!(!command.may_write_a_whole_layer(), "{command:?}");
        }
    }
}
