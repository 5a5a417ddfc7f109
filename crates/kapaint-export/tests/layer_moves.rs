//! What the Layers panel asks of the model: drag-and-drop moves, an opacity slider's drag as
//! one step, the picker on the selected layer, thumbnails, the "selected layer only" and
//! "mask" views, and the layer count in an export's manifest.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::{Vec2, Vec3};
use kapaint_model::brush::StrokePoint;
use kapaint_model::layers::{Compositor, ops, thumbnail};
use kapaint_model::texel::Texel;
use kapaint_model::{
    Document, DocumentSettings, LayerKind, LayerPlace, MaterialMaps, MaterialValue,
};
use kapaint_model::{
    HistoryCommand, LayerCommand, MaskCommand, PaintCommand, SettingsCommand, StrokeCommand,
};

fn document() -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    Document::new(192, 128, settings).expect("document")
}

fn add(doc: &mut Document, kind: LayerKind, name: &str) {
    doc.apply(LayerCommand::AddLayer {
        kind,
        name: name.into(),
    })
    .expect("add");
}

fn names(doc: &Document) -> Vec<String> {
    doc.stack()
        .walk()
        .iter()
        .map(|(p, l)| format!("{p:?}{}", l.props.name))
        .collect()
}

fn select(doc: &mut Document, path: &[usize]) {
    doc.apply(LayerCommand::SelectPath(path.to_vec()))
        .expect("select");
}

fn stroke(doc: &mut Document, from: Vec2, to: Vec2) {
    stroke_with(doc, kapaint_model::StrokeTool::Brush, from, to);
}

fn stroke_with(doc: &mut Document, tool: kapaint_model::StrokeTool, from: Vec2, to: Vec2) {
    let points = (0..=8)
        .map(|k| StrokePoint {
            pos: from.lerp(to, k as f32 / 8.0),
            pressure: 1.0,
        })
        .collect();
    doc.apply(StrokeCommand::Stroke { tool, points })
        .expect("stroke");
}

#[test]
fn a_dropped_layer_lands_above_below_or_into_its_target() {
    let mut doc = document();
    add(&mut doc, LayerKind::Paint, "A");
    add(&mut doc, LayerKind::Group, "G");
    add(&mut doc, LayerKind::Paint, "B");
    assert_eq!(names(&doc), ["[0]Layer 1", "[1]A", "[2]G", "[3]B"]);
    // B into the group G.
    doc.apply(LayerCommand::MoveLayerTo {
        target: vec![2],
        place: LayerPlace::Into,
    })
    .expect("into");
    assert_eq!(names(&doc), ["[0]Layer 1", "[1]A", "[2]G", "[2, 0]B"]);
    assert_eq!(doc.selection().path, [2, 0]);
    // Layer 1 (below the group, in the list the group is in) above B, inside the group: the
    // target's path is counted before the move.
    select(&mut doc, &[0]);
    doc.apply(LayerCommand::MoveLayerTo {
        target: vec![2, 0],
        place: LayerPlace::Above,
    })
    .expect("above");
    assert_eq!(names(&doc), ["[0]A", "[1]G", "[1, 0]B", "[1, 1]Layer 1"]);
    assert_eq!(doc.selection().path, [1, 1]);
    // Back out, below A.
    doc.apply(LayerCommand::MoveLayerTo {
        target: vec![0],
        place: LayerPlace::Below,
    })
    .expect("below");
    assert_eq!(names(&doc), ["[0]Layer 1", "[1]A", "[2]G", "[2, 0]B"]);
    // A group does not go into itself or its children, nor into a paint layer.
    select(&mut doc, &[2]);
    for (target, place) in [
        (vec![2], LayerPlace::Into),
        (vec![2, 0], LayerPlace::Above),
        (vec![0], LayerPlace::Into),
        (vec![9], LayerPlace::Above),
    ] {
        let before = names(&doc);
        let steps = doc.history().undo_steps().count();
        assert!(
            doc.apply(LayerCommand::MoveLayerTo { target, place })
                .is_err(),
            "refused"
        );
        assert_eq!(names(&doc), before, "nothing moved");
        assert_eq!(doc.history().undo_steps().count(), steps);
    }
    // Each move is one step, undone exactly.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(names(&doc), ["[0]A", "[1]G", "[1, 0]B", "[1, 1]Layer 1"]);
}

#[test]
fn groups_nest_no_deeper_than_a_project_stores() {
    let mut doc = document();
    let mut refused = None;
    for k in 0..20 {
        if let Err(e) = doc.apply(LayerCommand::Group) {
            refused = Some((k, e.to_string()));
            break;
        }
    }
    let (k, e) = refused.expect("grouping stops");
    assert_eq!(k, 15, "15 groups around the layer, then an error");
    assert!(e.contains("deeper than 16"), "{e}");
    // And the document still saves and loads.
    let bytes = kapaint_model::project::to_bytes(&doc).expect("saves");
    kapaint_model::project::from_reader(std::io::Cursor::new(bytes)).expect("loads");
}

#[test]
fn an_opacity_drag_is_one_undo_step() {
    let mut doc = document();
    stroke(&mut doc, Vec2::new(10.0, 10.0), Vec2::new(150.0, 100.0));
    let row =
        |doc: &Document| -> Vec<Texel> { (0..192).map(|x| doc.maps().texel(x, 60)).collect() };
    let painted = row(&doc);
    let steps = doc.history().undo_steps().count();
    for v in [0.9, 0.7, 0.4, 0.25] {
        doc.apply(LayerCommand::SetLayerOpacity(v))
            .expect("opacity");
    }
    assert_eq!(doc.history().undo_steps().count(), steps + 1, "one step");
    assert!((doc.stack().layers[0].props.opacity - 0.25).abs() < 1e-6);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!((doc.stack().layers[0].props.opacity - 1.0).abs() < 1e-6);
    assert_eq!(row(&doc), painted, "undo restores the whole drag");
    // Anything between two changes makes them two steps.
    doc.apply(LayerCommand::SetLayerOpacity(0.5))
        .expect("opacity");
    doc.apply(LayerCommand::SetLayerVisible(true))
        .expect("show");
    doc.apply(LayerCommand::SetLayerOpacity(0.6))
        .expect("opacity");
    assert_eq!(doc.history().undo_steps().count(), steps + 3);
}

#[test]
fn the_picker_reads_the_selected_layer_or_the_composite() {
    let mut doc = document();
    let red = MaterialValue::new(Vec3::new(0.8, 0.1, 0.1), Vec3::splat(0.2), 500.0);
    doc.apply(SettingsCommand::SetPrimary(red))
        .expect("primary");
    doc.apply(SettingsCommand::SetChannels(
        kapaint_model::texel::Channels {
            kd: true,
            ks: false,
            n: false,
        },
    ))
    .expect("channels");
    stroke(&mut doc, Vec2::new(10.0, 64.0), Vec2::new(180.0, 64.0));
    doc.apply(LayerCommand::SetLayerOpacity(0.5))
        .expect("opacity");
    let blank = MaterialValue::new(Vec3::ZERO, Vec3::ONE, 1.0);
    doc.apply(SettingsCommand::SetPrimary(blank))
        .expect("primary");
    // The layer: its k_d (covered), the primary's k_s and n (not covered).
    doc.apply(PaintCommand::PickLayer { x: 96, y: 64 })
        .expect("pick");
    let p = doc.settings().primary;
    assert!((p.kd - red.kd).abs().max_element() < 1e-3, "{p:?}");
    assert_eq!((p.ks, p.n), (blank.ks, blank.n));
    // The composite: half the red over the base.
    doc.apply(PaintCommand::Pick { x: 96, y: 64 })
        .expect("pick");
    let c = doc.settings().primary;
    assert!((c.kd.x - 0.65).abs() < 1e-2, "{c:?}");
    assert!(
        doc.apply(PaintCommand::PickLayer { x: 999, y: 0 }).is_err(),
        "outside the map"
    );
}

#[test]
fn thumbnails_show_content_coverage_and_masks() {
    let mut doc = document();
    let stack = doc.stack().clone();
    let empty = thumbnail::content(&stack, &stack.layers[0], 8).expect("paint layer");
    assert_eq!(empty.len(), 64);
    assert!(empty.iter().all(|p| p[3] == 0), "nothing painted: clear");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::ZERO,
        10.0,
    )))
    .expect("primary");
    doc.apply(PaintCommand::Fill(kapaint_model::FillRegion::All))
        .expect("fill");
    doc.apply(MaskCommand::AddMask).expect("mask");
    doc.apply(MaskCommand::InvertMask).expect("invert");
    let stack = doc.stack();
    let content = thumbnail::content(stack, &stack.layers[0], 8).expect("paint layer");
    assert!(
        content.iter().all(|p| *p == [255, 0, 0, 255]),
        "red, opaque"
    );
    let mask = thumbnail::mask(stack, &stack.layers[0], 8).expect("mask");
    assert!(mask.iter().all(|p| *p == [0, 0, 0, 255]), "white, inverted");
    add(&mut doc, LayerKind::Group, "G");
    let stack = doc.stack();
    assert!(thumbnail::content(stack, &stack.layers[1], 8).is_none());
    assert!(thumbnail::mask(stack, &stack.layers[1], 8).is_none());
}

fn composite(stack: &kapaint_model::layers::LayerStack) -> MaterialMaps {
    let mut maps = MaterialMaps::new(stack.width, stack.height, stack.base).expect("maps");
    Compositor::new().update(stack, &mut maps);
    maps
}

#[test]
fn the_layer_views_show_one_layer_over_the_base_or_its_mask_in_grey() {
    let mut doc = document();
    let green = MaterialValue::new(Vec3::new(0.1, 0.7, 0.2), Vec3::splat(0.1), 80.0);
    doc.apply(SettingsCommand::SetPrimary(green))
        .expect("primary");
    stroke(&mut doc, Vec2::new(10.0, 30.0), Vec2::new(180.0, 30.0));
    add(&mut doc, LayerKind::Paint, "Top");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::ONE,
        Vec3::ONE,
        5.0,
    )))
    .expect("primary");
    doc.apply(PaintCommand::Fill(kapaint_model::FillRegion::All))
        .expect("fill");
    doc.apply(LayerCommand::SetLayerVisible(false))
        .expect("hide");
    doc.apply(MaskCommand::AddMask).expect("mask");
    doc.apply(MaskCommand::SelectMask).expect("mask");
    stroke_with(
        &mut doc,
        kapaint_model::StrokeTool::Eraser,
        Vec2::new(96.0, 0.0),
        Vec2::new(96.0, 127.0),
    );
    // Layer 1 alone: green over the base where painted, the base elsewhere; the hidden
    // layer above does not show.
    let alone = composite(&ops::layer_alone(doc.stack(), &[0]).expect("layer"));
    assert!((alone.value(96, 30).kd - green.kd).abs().max_element() < 1e-3);
    assert_eq!(
        alone.value(96, 120).kd,
        Texel::encode(doc.stack().base).decode().kd
    );
    // The hidden top layer alone shows (a view of it, not the composite).
    let top = composite(&ops::layer_alone(doc.stack(), &[1]).expect("layer"));
    assert_eq!(top.value(5, 5).kd, Vec3::ONE);
    // Its mask in grey: white where untouched, black under the eraser; inverted, the other
    // way round.
    let mask = composite(&ops::mask_alone(doc.stack(), &[1]).expect("mask"));
    assert_eq!(mask.value(5, 5).kd, Vec3::ONE);
    assert_eq!(mask.value(96, 64).kd, Vec3::ZERO);
    doc.apply(MaskCommand::InvertMask).expect("invert");
    let inverted = composite(&ops::mask_alone(doc.stack(), &[1]).expect("mask"));
    assert_eq!(inverted.value(5, 5).kd, Vec3::ZERO);
    assert_eq!(inverted.value(96, 64).kd, Vec3::ONE);
    assert!(ops::mask_alone(doc.stack(), &[0]).is_none(), "no mask");
}

#[test]
fn an_export_manifest_says_how_many_layers_it_flattened() {
    let mut doc = document();
    add(&mut doc, LayerKind::Group, "G");
    add(&mut doc, LayerKind::Paint, "In G");
    doc.apply(LayerCommand::MoveLayer(kapaint_model::LayerMove::Down))
        .expect("move");
    let dir = std::env::temp_dir().join(format!("kapaint-layer-count-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let preset = kapaint_export::preset::find("compact").expect("preset");
    let manifest = kapaint_export::set::export(&doc, &preset, &dir).expect("export");
    assert_eq!(manifest.layers, 3);
    let json = std::fs::read_to_string(dir.join("material.json")).expect("manifest");
    assert!(json.contains("\"layers\": 3"), "{json}");
    let _ = std::fs::remove_dir_all(&dir);
}
