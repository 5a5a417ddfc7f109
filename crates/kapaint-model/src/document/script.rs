//! The names scripts give commands: one flat list, as the script format has always had it
//! (`SetPrimary((...))`, `AddLayer(kind: Paint, name: "dirt")`), read into the room each
//! belongs to. The script format is a contract: a name here never changes meaning.

use glam::Vec2;
use serde::Deserialize;

use super::command::{
    Command, FillRegion, HistoryCommand, LayerCommand, LayerKind, LayerMove, LayerPlace, LayerRef,
    MaskCommand, PaintCommand, SettingsCommand, StrokeCommand, StrokeTool,
};
use crate::brush::{BrushSettings, StrokePoint, SurfacePoint};
use crate::paint::GradientShape;
use crate::texel::{Channel, Channels, MaterialValue};
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// A command as a script names it (see [`Command`] for what each does; the commands made by
/// workers from files have no script name).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum ScriptCommand {
    SetBrush(BrushSettings),
    SetPrimary(MaterialValue),
    SetSecondary(MaterialValue),
    SwapMaterials,
    SetChannels(Channels),
    SetModel(ShadingModel),
    SetApprox(AmbientApprox),
    BeginStroke(StrokeTool),
    StrokeTo(StrokePoint),
    EndStroke,
    AbortStroke,
    Stroke {
        tool: StrokeTool,
        points: Vec<StrokePoint>,
    },
    SurfaceStrokeTo(SurfacePoint),
    SurfaceStroke {
        tool: StrokeTool,
        points: Vec<SurfacePoint>,
    },
    Fill(FillRegion),
    Gradient {
        shape: GradientShape,
        #[serde(deserialize_with = "crate::check::finite_vec2")]
        start: Vec2,
        #[serde(deserialize_with = "crate::check::finite_vec2")]
        end: Vec2,
    },
    Pick {
        x: u32,
        y: u32,
    },
    PickLayer {
        x: u32,
        y: u32,
    },
    Undo,
    Redo,
    HistoryJump(usize),
    AddLayer {
        kind: LayerKind,
        #[serde(deserialize_with = "crate::check::layer_name")]
        name: String,
    },
    SelectLayer(LayerRef),
    SelectPath(Vec<usize>),
    SetLayerOpacity(#[serde(deserialize_with = "crate::check::layer_opacity")] f32),
    SetLayerVisible(bool),
    SetLayerLocked(bool),
    RenameLayer(#[serde(deserialize_with = "crate::check::layer_name")] String),
    SetLayerBlend {
        channel: Channel,
        mode: crate::layers::LayerBlend,
    },
    SetLayerChannels(Channels),
    SetLayerFill(MaterialValue),
    MoveLayer(LayerMove),
    MoveLayerTo {
        target: Vec<usize>,
        place: LayerPlace,
    },
    DeleteLayer,
    DuplicateLayer,
    MergeDown,
    Flatten,
    AddMask,
    DeleteMask,
    ApplyMask,
    SelectMask,
    SelectContent,
    InvertMask,
    SetMaskEnabled(bool),
    MaskFromChannel {
        channel: Channel,
        #[serde(deserialize_with = "crate::check::finite_f32")]
        threshold: f32,
    },
    SetMaskGenerator(crate::generator::MaskGenerator),
    Group,
    Ungroup,
}

impl<'de> Deserialize<'de> for Command {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        ScriptCommand::deserialize(deserializer).map(Self::from)
    }
}

impl From<ScriptCommand> for Command {
    fn from(command: ScriptCommand) -> Self {
        use ScriptCommand as S;
        match command {
            S::SetBrush(b) => SettingsCommand::SetBrush(b).into(),
            S::SetPrimary(v) => SettingsCommand::SetPrimary(v).into(),
            S::SetSecondary(v) => SettingsCommand::SetSecondary(v).into(),
            S::SwapMaterials => SettingsCommand::SwapMaterials.into(),
            S::SetChannels(c) => SettingsCommand::SetChannels(c).into(),
            S::SetModel(m) => SettingsCommand::SetModel(m).into(),
            S::SetApprox(a) => SettingsCommand::SetApprox(a).into(),
            S::BeginStroke(tool) => StrokeCommand::BeginStroke(tool).into(),
            S::StrokeTo(p) => StrokeCommand::StrokeTo(p).into(),
            S::EndStroke => StrokeCommand::EndStroke.into(),
            S::AbortStroke => StrokeCommand::AbortStroke.into(),
            S::Stroke { tool, points } => StrokeCommand::Stroke { tool, points }.into(),
            S::SurfaceStrokeTo(p) => StrokeCommand::SurfaceStrokeTo(p).into(),
            S::SurfaceStroke { tool, points } => {
                StrokeCommand::SurfaceStroke { tool, points }.into()
            }
            S::Fill(region) => PaintCommand::Fill(region).into(),
            S::Gradient { shape, start, end } => {
                PaintCommand::Gradient { shape, start, end }.into()
            }
            S::Pick { x, y } => PaintCommand::Pick { x, y }.into(),
            S::PickLayer { x, y } => PaintCommand::PickLayer { x, y }.into(),
            S::Undo => HistoryCommand::Undo.into(),
            S::Redo => HistoryCommand::Redo.into(),
            S::HistoryJump(steps) => HistoryCommand::HistoryJump(steps).into(),
            S::AddLayer { kind, name } => LayerCommand::AddLayer { kind, name }.into(),
            S::SelectLayer(r) => LayerCommand::SelectLayer(r).into(),
            S::SelectPath(path) => LayerCommand::SelectPath(path).into(),
            S::SetLayerOpacity(o) => LayerCommand::SetLayerOpacity(o).into(),
            S::SetLayerVisible(v) => LayerCommand::SetLayerVisible(v).into(),
            S::SetLayerLocked(v) => LayerCommand::SetLayerLocked(v).into(),
            S::RenameLayer(name) => LayerCommand::RenameLayer(name).into(),
            S::SetLayerBlend { channel, mode } => {
                LayerCommand::SetLayerBlend { channel, mode }.into()
            }
            S::SetLayerChannels(c) => LayerCommand::SetLayerChannels(c).into(),
            S::SetLayerFill(v) => LayerCommand::SetLayerFill(v).into(),
            S::MoveLayer(m) => LayerCommand::MoveLayer(m).into(),
            S::MoveLayerTo { target, place } => LayerCommand::MoveLayerTo { target, place }.into(),
            S::DeleteLayer => LayerCommand::DeleteLayer.into(),
            S::DuplicateLayer => LayerCommand::DuplicateLayer.into(),
            S::MergeDown => LayerCommand::MergeDown.into(),
            S::Flatten => LayerCommand::Flatten.into(),
            S::Group => LayerCommand::Group.into(),
            S::Ungroup => LayerCommand::Ungroup.into(),
            S::AddMask => MaskCommand::AddMask.into(),
            S::DeleteMask => MaskCommand::DeleteMask.into(),
            S::ApplyMask => MaskCommand::ApplyMask.into(),
            S::SelectMask => MaskCommand::SelectMask.into(),
            S::SelectContent => MaskCommand::SelectContent.into(),
            S::InvertMask => MaskCommand::InvertMask.into(),
            S::SetMaskEnabled(on) => MaskCommand::SetMaskEnabled(on).into(),
            S::MaskFromChannel { channel, threshold } => {
                MaskCommand::MaskFromChannel { channel, threshold }.into()
            }
            S::SetMaskGenerator(g) => MaskCommand::SetMaskGenerator(g.0).into(),
        }
    }
}
