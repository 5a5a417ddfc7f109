//! Layers through the document, as scripts and the editor drive them: the issue's contract,
//! painting on a layer and on its mask, hiding a layer, and undo and redo of every kind of
//! layer operation, bit-exact.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::{Vec2, Vec3};
use kapaint_model::brush::StrokePoint;
use kapaint_model::layers::LayerContent;
use kapaint_model::texel::{Channel, Channels, Texel};
use kapaint_model::{Command, Document, MaterialValue};
use kapaint_model::{
    HistoryCommand, LayerCommand, MaskCommand, PaintCommand, SettingsCommand, StrokeCommand,
};

#[path = "common/layer_doc.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod layer_doc;
use layer_doc::{document, run, texels};

fn stroke(doc: &mut Document, from: Vec2, to: Vec2) {
    let points = (0..=8)
        .map(|k| StrokePoint {
            pos: from.lerp(to, k as f32 / 8.0),
            pressure: 1.0,
        })
        .collect();
    doc.apply(StrokeCommand::Stroke {
        tool: kapaint_model::StrokeTool::Brush,
        points,
    })
    .expect("stroke");
}

#[test]
fn a_new_document_is_its_base_and_one_empty_paint_layer_selected() {
    let doc = document();
    let stack = doc.stack();
    assert_eq!(stack.layers.len(), 1);
    assert_eq!(stack.layers[0].props.name, "Layer 1");
    assert!(
        matches!(&stack.layers[0].content, LayerContent::Paint(t) if t.iter().all(Option::is_none))
    );
    assert_eq!(doc.selection().path, vec![0]);
    assert!(!doc.selection().mask);
    // An empty layer costs no tile memory, and the composite is the base.
    assert_eq!(stack.heap_bytes(), 0);
    assert_eq!(doc.maps().uniform_texel(), Some(Texel::encode(stack.base)));
}

#[test]
fn hiding_a_painted_layer_returns_the_maps_to_the_state_below_bit_exactly() {
    let mut doc = document();
    stroke(&mut doc, Vec2::new(20.0, 20.0), Vec2::new(150.0, 90.0));
    let below = texels(&doc);
    run(
        &mut doc,
        r#"(commands: [AddLayer(kind: Paint, name: "Rust"), SetPrimary((kd: (0.4, 0.15, 0.05), ks: (0.02, 0.02, 0.02), n: 3.0))])"#,
    );
    stroke(&mut doc, Vec2::new(10.0, 100.0), Vec2::new(180.0, 10.0));
    let painted = texels(&doc);
    assert_ne!(painted, below);
    let version = doc.version();
    doc.apply(LayerCommand::SetLayerVisible(false))
        .expect("hide");
    assert_eq!(texels(&doc), below, "hidden: the layers below, exactly");
    assert_ne!(doc.version(), version, "hiding is a change to save");
    doc.apply(LayerCommand::SetLayerVisible(true))
        .expect("show");
    assert_eq!(texels(&doc), painted);
    // Undo of the show and the hide.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), below);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), painted);
}

#[test]
fn the_contract_script_builds_a_base_a_masked_rust_layer_and_a_gloss_layer() {
    let mut doc = document();
    // The script of docs/layers.md (strokes shortened).
    run(
        &mut doc,
        r#"(commands: [
            SetPrimary((kd: (0.6, 0.6, 0.62), ks: (0.3, 0.3, 0.3), n: 200.0)),
            Fill(All),
            AddLayer(kind: Paint, name: "Rust"),
            SetPrimary((kd: (0.35, 0.12, 0.04), ks: (0.02, 0.02, 0.02), n: 4.0)),
            Fill(All),
            AddMask,
            InvertMask,
            SelectMask,
            SetPrimary((kd: (1.0, 1.0, 1.0), ks: (0.0, 0.0, 0.0), n: 1.0)),
            Stroke(tool: Brush, points: [(pos: (40.0, 64.0), pressure: 1.0), (pos: (150.0, 64.0), pressure: 1.0)]),
            SelectContent,
            AddLayer(kind: Paint, name: "Gloss"),
            SetLayerChannels((kd: false, ks: false, n: true)),
            SetLayerOpacity(0.5),
            SetLayerBlend(channel: N, mode: Normal),
            SetPrimary((kd: (0.0, 0.0, 0.0), ks: (0.0, 0.0, 0.0), n: 1000.0)),
            Fill(All),
            SelectLayer("Rust"),
            SetLayerBlend(channel: Kd, mode: Multiply),
            SetLayerBlend(channel: Kd, mode: Normal),
        ])"#,
    );
    let names: Vec<_> = doc
        .stack()
        .layers
        .iter()
        .map(|l| l.props.name.clone())
        .collect();
    assert_eq!(names, ["Layer 1", "Rust", "Gloss"]);
    let m = doc.maps();
    // Outside the mask stroke: the base fill's k_d; inside it: rust.
    let outside = m.value(5, 5);
    let inside = m.value(95, 64);
    assert!((outside.kd.x - 0.6).abs() < 1e-3, "{outside:?}");
    assert!((inside.kd.x - 0.35).abs() < 1e-3, "{inside:?}");
    // The gloss layer changes only n: half of 1000 over 200 in log space, not the mean.
    let expected = {
        let u = |n: f32| (1.0 + n).ln();
        f32::midpoint(u(200.0), u(1000.0)).exp() - 1.0
    };
    assert!(
        (outside.n - expected).abs() / expected < 0.01,
        "{} vs {expected}",
        outside.n
    );
    assert!(outside.n < 500.0, "a linear mean would give 600");
    // Selecting by name selects; the mask commands acted on Rust's mask.
    assert_eq!(doc.selection().path, vec![1]);
    let rust = &doc.stack().layers[1];
    let mask = rust.mask.as_ref().expect("mask");
    assert!(mask.inverted && mask.enabled);
}

#[test]
fn a_paint_layer_fill_is_opaque_in_the_enabled_channels_only() {
    let mut doc = document();
    doc.apply(SettingsCommand::SetChannels(Channels {
        kd: false,
        ks: false,
        n: true,
    }))
    .expect("channels");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::splat(0.9),
        Vec3::splat(0.9),
        500.0,
    )))
    .expect("primary");
    doc.apply(PaintCommand::Fill(kapaint_model::FillRegion::All))
        .expect("fill");
    let v = doc.maps().value(3, 3);
    assert!((v.kd.x - 0.5).abs() < 1e-3, "k_d stays the base's: {v:?}");
    assert!((v.n - 500.0).abs() < 1.0, "{v:?}");
    // Uniform fills cost no per-texel memory.
    assert_eq!(doc.stack().heap_bytes(), 0);
}

/// Applies `command` after a setup, checks undo gives back the state before it and redo the
/// state after it, both bit-exact (maps and stack settings).
fn check_undo(doc: &mut Document, command: Command) {
    let label = format!("{command:?}");
    let before = (
        texels(doc),
        doc.stack().walk().len(),
        doc.selection().clone(),
    );
    let steps = doc.history().undo_steps().count();
    doc.apply(command)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!(
        doc.history().undo_steps().count(),
        steps + 1,
        "{label}: one step"
    );
    let after = (
        texels(doc),
        doc.stack().walk().len(),
        doc.selection().clone(),
    );
    let after_stack = doc.stack().clone();
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(
        (
            texels(doc),
            doc.stack().walk().len(),
            doc.selection().clone()
        ),
        before,
        "{label}: undo"
    );
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert_eq!(
        (
            texels(doc),
            doc.stack().walk().len(),
            doc.selection().clone()
        ),
        after,
        "{label}: redo"
    );
    assert!(*doc.stack() == after_stack, "{label}: the stack after redo");
}

#[test]
fn every_layer_operation_is_one_undo_step_and_undo_and_redo_are_bit_exact() {
    use kapaint_model::layers::LayerBlend;
    use kapaint_model::{LayerKind, LayerMove, LayerRef};
    let mut doc = document();
    stroke(&mut doc, Vec2::new(10.0, 10.0), Vec2::new(120.0, 100.0));
    let add = |kind, name: &str| LayerCommand::AddLayer {
        kind,
        name: name.into(),
    };
    check_undo(&mut doc, add(LayerKind::Paint, "Two").into());
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.1, 0.7, 0.2),
        Vec3::splat(0.2),
        900.0,
    )))
    .expect("primary");
    stroke(&mut doc, Vec2::new(100.0, 10.0), Vec2::new(20.0, 110.0));
    let commands: Vec<Command> = vec![
        LayerCommand::SetLayerOpacity(0.4).into(),
        LayerCommand::SetLayerBlend {
            channel: Channel::Kd,
            mode: LayerBlend::Screen,
        }
        .into(),
        LayerCommand::SetLayerBlend {
            channel: Channel::N,
            mode: LayerBlend::Add,
        }
        .into(),
        LayerCommand::SetLayerChannels(Channels {
            kd: true,
            ks: false,
            n: true,
        })
        .into(),
        LayerCommand::RenameLayer("Renamed".into()).into(),
        LayerCommand::SetLayerLocked(true).into(),
        LayerCommand::SetLayerLocked(false).into(),
        MaskCommand::AddMask.into(),
        MaskCommand::InvertMask.into(),
        MaskCommand::MaskFromChannel {
            channel: Channel::N,
            threshold: 100.0,
        }
        .into(),
        MaskCommand::SetMaskEnabled(false).into(),
        MaskCommand::SetMaskEnabled(true).into(),
        LayerCommand::DuplicateLayer.into(),
        LayerCommand::MoveLayer(LayerMove::Down).into(),
        LayerCommand::MoveLayer(LayerMove::Top).into(),
        MaskCommand::ApplyMask.into(),
        LayerCommand::Group.into(),
        LayerCommand::Ungroup.into(),
        add(LayerKind::Fill, "Fill").into(),
        LayerCommand::SetLayerFill(MaterialValue::new(Vec3::splat(0.2), Vec3::ZERO, 2.0)).into(),
        MaskCommand::AddMask.into(),
        MaskCommand::DeleteMask.into(),
        add(LayerKind::Group, "Folder").into(),
    ];
    for c in commands {
        check_undo(&mut doc, c);
    }
    // Selecting is not a step.
    doc.apply(LayerCommand::SelectLayer(LayerRef::Name("Renamed".into())))
        .expect("select");
    assert_eq!(doc.selection().path, vec![1]);
    for c in [
        LayerCommand::SetLayerVisible(false),
        LayerCommand::SetLayerVisible(true),
        LayerCommand::MergeDown,
        LayerCommand::DeleteLayer,
        LayerCommand::Flatten,
    ] {
        check_undo(&mut doc, c.into());
    }
    // A stroke on a mask is one step too.
    doc.apply(MaskCommand::AddMask).expect("mask");
    doc.apply(MaskCommand::SelectMask).expect("select mask");
    let steps = doc.history().undo_steps().count();
    stroke(&mut doc, Vec2::new(10.0, 60.0), Vec2::new(180.0, 60.0));
    assert_eq!(doc.history().undo_steps().count(), steps + 1);
}

#[test]
fn the_n_blend_refuses_modes_n_has_not_and_a_locked_layer_refuses_paint() {
    use kapaint_model::layers::LayerBlend;
    let mut doc = document();
    let err = doc
        .apply(LayerCommand::SetLayerBlend {
            channel: Channel::N,
            mode: LayerBlend::Screen,
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("Normal, Multiply, Add, Min, Max"), "{err}");
    doc.apply(LayerCommand::SetLayerLocked(true)).expect("lock");
    let before = texels(&doc);
    let err = doc
        .apply(PaintCommand::Fill(kapaint_model::FillRegion::All))
        .unwrap_err()
        .to_string();
    assert!(err.contains("locked"), "{err}");
    assert_eq!(texels(&doc), before);
    // A fill layer's content has no pixels to paint.
    doc.apply(LayerCommand::AddLayer {
        kind: kapaint_model::LayerKind::Fill,
        name: "F".into(),
    })
    .expect("fill layer");
    let err = doc
        .apply(StrokeCommand::BeginStroke(kapaint_model::StrokeTool::Brush))
        .unwrap_err()
        .to_string();
    assert!(err.contains("no pixels to paint"), "{err}");
}

#[test]
fn the_eraser_on_a_layer_uncovers_the_layers_below() {
    let mut doc = document();
    let base = texels(&doc);
    stroke(&mut doc, Vec2::new(20.0, 64.0), Vec2::new(170.0, 64.0));
    assert_ne!(texels(&doc), base);
    doc.apply(StrokeCommand::Stroke {
        tool: kapaint_model::StrokeTool::Eraser,
        points: (0..=16)
            .map(|k| StrokePoint {
                pos: Vec2::new(20.0 + 150.0 * k as f32 / 16.0, 64.0),
                pressure: 1.0,
            })
            .collect(),
    })
    .expect("erase");
    // Where the eraser passed at full strength, the base shows again exactly.
    let m = doc.maps();
    assert_eq!(m.texel(95, 64), Texel::encode(doc.stack().base));
}

fn layered() -> Document {
    let mut doc = document();
    stroke(&mut doc, Vec2::new(20.0, 20.0), Vec2::new(150.0, 90.0));
    run(
        &mut doc,
        r#"(commands: [
            AddLayer(kind: Paint, name: "Rust"),
            SetPrimary((kd: (0.35, 0.12, 0.04), ks: (0.02, 0.02, 0.02), n: 4.0)),
            Stroke(tool: Brush, points: [(pos: (10.0, 100.0), pressure: 1.0), (pos: (180.0, 10.0), pressure: 1.0)]),
            AddMask,
            SelectMask,
            Stroke(tool: Eraser, points: [(pos: (60.0, 10.0), pressure: 1.0), (pos: (60.0, 120.0), pressure: 1.0)]),
            SelectContent,
            SetLayerOpacity(0.75),
            SetLayerBlend(channel: N, mode: Max),
            Group,
            AddLayer(kind: Fill, name: "Gloss"),
            SetLayerChannels((kd: false, ks: false, n: true)),
            SetLayerOpacity(0.3),
        ])"#,
    );
    doc
}

#[test]
fn a_version_2_project_keeps_the_stack_and_its_composite() {
    let doc = layered();
    let bytes = kapaint_model::project::to_bytes(&doc).expect("save");
    let back = kapaint_model::project::from_reader(std::io::Cursor::new(bytes)).expect("load");
    assert_eq!(texels(&back), texels(&doc), "the composite");
    let props = |d: &Document| {
        d.stack()
            .walk()
            .into_iter()
            .map(|(p, l)| {
                (
                    p,
                    l.props.clone(),
                    l.mask.as_ref().map(|m| (m.enabled, m.inverted)),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(props(&back), props(&doc));
    assert_eq!(back.stack().base, doc.stack().base);
    // The layers themselves came back: hiding the group shows the same thing in both.
    let mut a = doc;
    let mut b = back;
    for d in [&mut a, &mut b] {
        d.apply(LayerCommand::SelectPath(vec![1]))
            .expect("select group");
        d.apply(LayerCommand::SetLayerVisible(false)).expect("hide");
    }
    assert_eq!(texels(&a), texels(&b));
}

#[test]
fn malformed_layer_data_is_one_clear_error() {
    use std::io::Write;
    let doc = layered();
    let bytes = kapaint_model::project::to_bytes(&doc).expect("save");
    // Rewrites manifest.json with `edit` applied, keeping every other entry.
    let rewrite = |edit: &dyn Fn(&mut serde_json::Value)| -> String {
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes.clone())).expect("zip");
        let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        for i in 0..zip.len() {
            let mut f = zip.by_index(i).expect("entry");
            let name = f.name().expect("name").to_string();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut data).expect("read");
            if name == "manifest.json" {
                let mut v: serde_json::Value = serde_json::from_slice(&data).expect("json");
                edit(&mut v);
                data = serde_json::to_vec(&v).expect("json");
            }
            out.start_file(name, zip::write::SimpleFileOptions::default())
                .expect("start");
            out.write_all(&data).expect("write");
        }
        let bytes = out.finish().expect("finish").into_inner();
        match kapaint_model::project::from_reader(std::io::Cursor::new(bytes)) {
            Ok(_) => "loaded".into(),
            Err(e) => e,
        }
    };
    let unknown = rewrite(&|v| v["layers"][0]["kind"] = "sticker".into());
    assert!(unknown.contains("sticker"), "{unknown}");
    let many = rewrite(&|v| {
        let one = v["layers"][0].clone();
        v["layers"] = serde_json::Value::Array(vec![one; 5000]);
    });
    assert!(many.contains("more than 256 layers"), "{many}");
    // A mask image of the wrong size (the whole composite where an atlas of a few tiles
    // belongs) is refused: as an image the manifest names twice, before anything is decoded.
    let mask_file = rewrite(&|v| {
        v["layers"][1]["children"][0]["mask"]["gray"] = serde_json::json!({"kind": "image", "file": "kd.png", "encoding": "png-rgb16-unorm-linear"});
    });
    assert!(
        mask_file.contains("kd.png") && mask_file.contains("more than once"),
        "{mask_file}"
    );
    // Tile lists name tiles of the map, ascending.
    let outside = rewrite(&|v| v["width"] = 96.into());
    assert!(outside.contains("outside the map's 4 tiles"), "{outside}");
    let repeated = rewrite(&|v| {
        let tiles = &mut v["layers"][0]["planes"]["tiles"];
        let first = tiles[0].clone();
        tiles.as_array_mut().expect("a tile list").insert(0, first);
    });
    assert!(repeated.contains("not ascending"), "{repeated}");
    let fill_with_planes =
        rewrite(&|v| v["layers"][2]["planes"] = v["layers"][0]["planes"].clone());
    assert!(
        fill_with_planes.contains("not a paint layer"),
        "{fill_with_planes}"
    );
    let v1_with_layers = rewrite(&|v| v["version"] = 1.into());
    assert!(v1_with_layers.contains("version 1"), "{v1_with_layers}");
}

/// Strokes recomposite only the texels their dabs reach, in place: after brush strokes in
/// every blend mode, the eraser and blur, on layers, masks and inside a group, the maps are
/// bit for bit the stack flattened from scratch.
#[test]
fn strokes_recomposite_in_place_exactly_as_a_full_flatten() {
    use kapaint_model::layers::Compositor;
    let mut doc = layered();
    run(
        &mut doc,
        r#"(commands: [
            SetBrush((radius_px: 23.0, hardness: 0.3, flow: 0.6, spacing_percent: 10.0)),
            SelectLayer("Rust"),
            SetBrush((radius_px: 23.0, hardness: 0.3, flow: 0.6, spacing_percent: 10.0, blend: Multiply)),
            Stroke(tool: Brush, points: [(pos: (5.0, 5.0), pressure: 1.0), (pos: (120.0, 70.0), pressure: 0.6)]),
            SetBrush((radius_px: 17.0, blend: Add)),
            Stroke(tool: Brush, points: [(pos: (100.0, 5.0), pressure: 1.0), (pos: (30.0, 120.0), pressure: 1.0)]),
            SetBrush((radius_px: 31.0, blend: Normal, blur_radius_px: 3)),
            Stroke(tool: Blur, points: [(pos: (60.0, 60.0), pressure: 1.0), (pos: (140.0, 60.0), pressure: 1.0)]),
            SelectMask,
            Stroke(tool: Brush, points: [(pos: (150.0, 20.0), pressure: 1.0), (pos: (150.0, 110.0), pressure: 1.0)]),
            SelectContent,
            Stroke(tool: Eraser, points: [(pos: (0.0, 64.0), pressure: 1.0), (pos: (191.0, 64.0), pressure: 1.0)]),
            AddLayer(kind: Paint, name: "Top"),
            SetLayerBlend(channel: Kd, mode: Overlay),
            Stroke(tool: Brush, points: [(pos: (90.0, 0.0), pressure: 1.0), (pos: (91.0, 127.0), pressure: 1.0)]),
        ])"#,
    );
    let mut flat =
        kapaint_model::MaterialMaps::new(192, 128, MaterialValue::default()).expect("maps");
    Compositor::new().update(doc.stack(), &mut flat);
    let differing = (0..flat.tile_count())
        .filter(|&id| **flat.tile(id) != **doc.maps().tile(id))
        .count();
    assert_eq!(differing, 0, "tiles differing from a full flatten");
}

/// A version 2 project written before layer images became atlases (whole-map images, no tile
/// lists; made by the build of commit e3db8c6) opens as it was; saved again, it stores
/// atlases of the painted tiles and opens to the same stack and composite.
#[test]
fn a_project_with_whole_map_layer_images_opens_and_saves_as_atlases() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/layers_v2_full.kapaint");
    let old = kapaint_model::project::load(&path).expect("the old layout opens");
    let names: Vec<&str> = old
        .stack()
        .layers
        .iter()
        .map(|l| l.props.name.as_str())
        .collect();
    assert_eq!(names, ["Layer 1", "Rust", "Gloss"]);
    assert!(old.stack().layers[1].mask.is_some());
    assert!(old.stack().heap_bytes() > 0, "the painted tiles came back");
    let bytes = kapaint_model::project::to_bytes(&old).expect("save");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes.clone())).expect("zip");
    let manifest: serde_json::Value = {
        let mut text = String::new();
        std::io::Read::read_to_string(
            &mut zip.by_name("manifest.json").expect("manifest"),
            &mut text,
        )
        .expect("read");
        serde_json::from_str(&text).expect("json")
    };
    let tiles = manifest["layers"][0]["planes"]["tiles"]
        .as_array()
        .expect("a tile list");
    assert!(!tiles.is_empty() && tiles.len() < 6, "{tiles:?} of 6 tiles");
    let again = kapaint_model::project::from_reader(std::io::Cursor::new(bytes)).expect("reopen");
    for (a, b) in old.stack().layers.iter().zip(&again.stack().layers) {
        assert_eq!(a.props, b.props);
        if let (LayerContent::Paint(x), LayerContent::Paint(y)) = (&a.content, &b.content) {
            let same = x
                .iter()
                .zip(y)
                .all(|(s, t)| s.as_ref().map(|s| s.get()) == t.as_ref().map(|t| t.get()));
            assert!(same, "{}: the same painted tiles", a.props.name);
        }
        let masks = |l: &kapaint_model::layers::Layer| {
            l.mask
                .as_ref()
                .map(|m| m.tiles.iter().map(|t| t.get().clone()).collect::<Vec<_>>())
        };
        assert!(masks(a) == masks(b), "{}: the same mask", a.props.name);
    }
    let differing = (0..old.maps().tile_count())
        .filter(|&id| **old.maps().tile(id) != **again.maps().tile(id))
        .count();
    assert_eq!(differing, 0);
}
