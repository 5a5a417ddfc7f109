//! The script format is a contract: every command name a script has ever used reads into the
//! room that now holds it, with the same meaning, and the documented scripts still parse.

use glam::{Vec2, Vec3};
use kapaint_model::brush::{BrushSettings, StrokePoint, SurfacePoint, SurfacePos};
use kapaint_model::layers::LayerBlend;
use kapaint_model::paint::GradientShape;
use kapaint_model::{
    Channel, Channels, Command, FillRegion, HistoryCommand, LayerCommand, LayerKind, LayerMove,
    LayerPlace, LayerRef, MaskCommand, MaterialValue, PaintCommand, SettingsCommand, StrokeCommand,
    StrokeTool,
};
use kapaint_reflectance::{AmbientApprox, ShadingModel};

const GREY: &str = "(kd: (0.5, 0.5, 0.5), ks: (0.1, 0.1, 0.1), n: 20.0)";

fn grey() -> MaterialValue {
    MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.1), 20.0)
}

fn parse(text: &str) -> Command {
    ron::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// Every flat name scripts use, with the command it must mean.
fn every_name() -> Vec<(String, Command)> {
    [
        settings_and_strokes(),
        tools_and_history(),
        layers_and_masks(),
    ]
    .concat()
}

/// The settings and strokes.
fn settings_and_strokes() -> Vec<(String, Command)> {
    let point = StrokePoint {
        pos: Vec2::new(3.0, 4.0),
        pressure: 0.5,
    };
    let on_mesh = SurfacePoint {
        pos: SurfacePos {
            point: Vec3::new(0.0, 1.0, 0.0),
            normal: Vec3::Y,
        },
        pressure: 1.0,
    };
    let p = "(pos: (3.0, 4.0), pressure: 0.5)";
    let m = "(pos: (point: (0.0, 1.0, 0.0), normal: (0.0, 1.0, 0.0)), pressure: 1.0)";
    let all = Channels::ALL;
    vec![
        // settings
        (
            "SetBrush(())".into(),
            SettingsCommand::SetBrush(BrushSettings::default()).into(),
        ),
        (
            format!("SetPrimary({GREY})"),
            SettingsCommand::SetPrimary(grey()).into(),
        ),
        (
            format!("SetSecondary({GREY})"),
            SettingsCommand::SetSecondary(grey()).into(),
        ),
        (
            "SwapMaterials".into(),
            SettingsCommand::SwapMaterials.into(),
        ),
        (
            "SetChannels((kd: true, ks: true, n: true))".into(),
            SettingsCommand::SetChannels(all).into(),
        ),
        (
            "SetModel(Phong)".into(),
            SettingsCommand::SetModel(ShadingModel::Phong).into(),
        ),
        (
            "SetApprox(Fast)".into(),
            SettingsCommand::SetApprox(AmbientApprox::Fast).into(),
        ),
        // strokes
        (
            "BeginStroke(Eraser)".into(),
            StrokeCommand::BeginStroke(StrokeTool::Eraser).into(),
        ),
        (
            format!("StrokeTo({p})"),
            StrokeCommand::StrokeTo(point).into(),
        ),
        ("EndStroke".into(), StrokeCommand::EndStroke.into()),
        ("AbortStroke".into(), StrokeCommand::AbortStroke.into()),
        (
            format!("Stroke(tool: Blur, points: [{p}])"),
            StrokeCommand::Stroke {
                tool: StrokeTool::Blur,
                points: vec![point],
            }
            .into(),
        ),
        (
            format!("SurfaceStrokeTo({m})"),
            StrokeCommand::SurfaceStrokeTo(on_mesh).into(),
        ),
        (
            format!("SurfaceStroke(tool: Brush, points: [{m}])"),
            StrokeCommand::SurfaceStroke {
                tool: StrokeTool::Brush,
                points: vec![on_mesh],
            }
            .into(),
        ),
    ]
}

/// The one-click tools and the history.
fn tools_and_history() -> Vec<(String, Command)> {
    vec![
        (
            "Fill(All)".into(),
            PaintCommand::Fill(FillRegion::All).into(),
        ),
        (
            "Fill(Island(x: 1, y: 2))".into(),
            PaintCommand::Fill(FillRegion::Island { x: 1, y: 2 }).into(),
        ),
        (
            "Gradient(shape: Radial, start: (1.0, 2.0), end: (3.0, 4.0))".into(),
            PaintCommand::Gradient {
                shape: GradientShape::Radial,
                start: Vec2::new(1.0, 2.0),
                end: Vec2::new(3.0, 4.0),
            }
            .into(),
        ),
        (
            "Pick(x: 5, y: 6)".into(),
            PaintCommand::Pick { x: 5, y: 6 }.into(),
        ),
        (
            "PickLayer(x: 5, y: 6)".into(),
            PaintCommand::PickLayer { x: 5, y: 6 }.into(),
        ),
        // history
        ("Undo".into(), HistoryCommand::Undo.into()),
        ("Redo".into(), HistoryCommand::Redo.into()),
        (
            "HistoryJump(3)".into(),
            HistoryCommand::HistoryJump(3).into(),
        ),
    ]
}

/// The layer and mask rooms.
fn layers_and_masks() -> Vec<(String, Command)> {
    let all = Channels::ALL;
    vec![
        (
            "AddLayer(kind: Fill, name: \"dirt\")".into(),
            LayerCommand::AddLayer {
                kind: LayerKind::Fill,
                name: "dirt".into(),
            }
            .into(),
        ),
        (
            "SelectLayer(2)".into(),
            LayerCommand::SelectLayer(LayerRef::Index(2)).into(),
        ),
        (
            "SelectLayer(\"dirt\")".into(),
            LayerCommand::SelectLayer(LayerRef::Name("dirt".into())).into(),
        ),
        (
            "SelectLayer((id: 7))".into(),
            LayerCommand::SelectLayer(LayerRef::Id { id: 7 }).into(),
        ),
        (
            "SelectPath([1, 0])".into(),
            LayerCommand::SelectPath(vec![1, 0]).into(),
        ),
        (
            "SetLayerOpacity(0.25)".into(),
            LayerCommand::SetLayerOpacity(0.25).into(),
        ),
        (
            "SetLayerVisible(false)".into(),
            LayerCommand::SetLayerVisible(false).into(),
        ),
        (
            "SetLayerLocked(true)".into(),
            LayerCommand::SetLayerLocked(true).into(),
        ),
        (
            "RenameLayer(\"rust\")".into(),
            LayerCommand::RenameLayer("rust".into()).into(),
        ),
        (
            "SetLayerBlend(channel: N, mode: Max)".into(),
            LayerCommand::SetLayerBlend {
                channel: Channel::N,
                mode: LayerBlend::Lighten,
            }
            .into(),
        ),
        (
            "SetLayerChannels((kd: true, ks: true, n: true))".into(),
            LayerCommand::SetLayerChannels(all).into(),
        ),
        (
            format!("SetLayerFill({GREY})"),
            LayerCommand::SetLayerFill(grey()).into(),
        ),
        (
            "MoveLayer(IntoGroup)".into(),
            LayerCommand::MoveLayer(LayerMove::IntoGroup).into(),
        ),
        (
            "MoveLayerTo(target: [0, 1], place: Into)".into(),
            LayerCommand::MoveLayerTo {
                target: vec![0, 1],
                place: LayerPlace::Into,
            }
            .into(),
        ),
        ("DeleteLayer".into(), LayerCommand::DeleteLayer.into()),
        ("DuplicateLayer".into(), LayerCommand::DuplicateLayer.into()),
        ("MergeDown".into(), LayerCommand::MergeDown.into()),
        ("Flatten".into(), LayerCommand::Flatten.into()),
        ("Group".into(), LayerCommand::Group.into()),
        ("Ungroup".into(), LayerCommand::Ungroup.into()),
        // masks
        ("AddMask".into(), MaskCommand::AddMask.into()),
        ("DeleteMask".into(), MaskCommand::DeleteMask.into()),
        ("ApplyMask".into(), MaskCommand::ApplyMask.into()),
        ("SelectMask".into(), MaskCommand::SelectMask.into()),
        ("SelectContent".into(), MaskCommand::SelectContent.into()),
        ("InvertMask".into(), MaskCommand::InvertMask.into()),
        (
            "SetMaskEnabled(false)".into(),
            MaskCommand::SetMaskEnabled(false).into(),
        ),
        (
            "MaskFromChannel(channel: Kd, threshold: 0.5)".into(),
            MaskCommand::MaskFromChannel {
                channel: Channel::Kd,
                threshold: 0.5,
            }
            .into(),
        ),
    ]
}

#[test]
fn every_script_name_reads_into_its_room_with_its_meaning() {
    let names = every_name();
    for (text, expected) in &names {
        assert_eq!(&parse(text), expected, "{text}");
    }
    // Each name once (Fill and SelectLayer are there twice and three times for their forms).
    let mut distinct: Vec<&str> = names
        .iter()
        .map(|(t, _)| t.split(['(', ' ']).next().unwrap_or(t))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), 47, "{distinct:?}");
}

#[test]
fn script_checks_still_refuse_bad_values_and_unknown_names() {
    for bad in [
        "SetLayerOpacity(NaN)",
        "RenameLayer(\"\")",
        "Gradient(shape: Linear, start: (inf, 0.0), end: (1.0, 1.0))",
        "MaskFromChannel(channel: N, threshold: NaN)",
        "Stroke(tool: Brush, points: [(pos: (NaN, 1.0), pressure: 1.0)])",
    ] {
        assert!(ron::from_str::<Command>(bad).is_err(), "{bad} parsed");
    }
    // What a worker makes from a file has no script name.
    for worker_made in [
        "ImportChannel",
        "ImportMaterial",
        "SetNormal",
        "SetMesh",
        "Resize",
    ] {
        let e = ron::from_str::<Command>(worker_made).expect_err(worker_made);
        assert!(e.to_string().contains("SetPrimary"), "{worker_made}: {e}");
    }
}

/// The RON scripts of a markdown file.
fn ron_blocks(doc: &str) -> Vec<String> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs")
        .join(doc);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{doc}: {e}"));
    text.split("```ron\n")
        .skip(1)
        .filter_map(|rest| rest.split("```").next())
        .map(str::to_owned)
        .collect()
}

#[test]
fn the_documented_scripts_parse() {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Script {
        commands: Vec<Command>,
    }
    let mut seen = 0;
    for doc in ["cli.md", "layers.md"] {
        for block in ron_blocks(doc) {
            let script: Script =
                ron::from_str(&block).unwrap_or_else(|e| panic!("{doc}: {e}\n{block}"));
            assert!(!script.commands.is_empty(), "{doc}");
            seen += 1;
        }
    }
    assert!(seen >= 2, "the documented scripts were not found");
}
