//! What identifies a document's state and its layers: every stored change is an undo step and
//! undo brings the version back; a layer's id survives moves, grouping, undo and saves.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::Vec3;
use kapaint_model::{Document, MaterialValue};
use kapaint_model::{HistoryCommand, ImportCommand, LayerCommand};

#[path = "common/layer_doc.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod layer_doc;
use layer_doc::{document, run};

/// Everything a project stores changes through a command with an undo step: a material import
/// with its normal map and report, a normal map set or cleared, the mesh with its bake. Undo
/// back to a state brings its version back (what "unsaved changes" compares), so a document
/// undone to where it was opened is clean.
#[test]
fn imports_normal_maps_and_meshes_are_undo_steps_and_undo_restores_the_version() {
    use kapaint_model::document::{AttachedMesh, AttachedNormal, ImportedMaterial};
    use kapaint_model::normal::NormalMap;
    use kapaint_model::{MaterialMaps, MeshRef};
    use std::sync::Arc;
    let mut doc = document();
    let opened = doc.version();
    let maps = MaterialMaps::new(
        192,
        128,
        MaterialValue::new(Vec3::splat(0.3), Vec3::ONE, 9.0),
    )
    .expect("maps");
    let report: kapaint_model::provenance::ImportReport =
        serde_json::from_str(r#"{"source":"constant","model":"phong","n_mapping":"lobe","error":{"max":0.1,"mean":0.05,"p99":0.09}}"#)
            .expect("report");
    let normal = Arc::new(NormalMap::flat(192, 128).expect("normal"));
    doc.apply(ImportCommand::ImportMaterial(ImportedMaterial {
        maps: Arc::new(maps),
        normal: Some(Arc::clone(&normal)),
        report: Some(report.clone()),
    }))
    .expect("import");
    assert!(doc.normal().is_some());
    assert_eq!(doc.settings().import.as_ref(), Some(&report));
    let imported = doc.version();
    assert_ne!(imported, opened);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.normal().is_none() && doc.settings().import.is_none());
    assert_eq!(doc.version(), opened, "undone to where it was opened");
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert!(doc.normal().is_some() && doc.settings().import.is_some());
    assert_eq!(doc.version(), imported);

    // Clearing the normal map is a step of its own.
    doc.apply(ImportCommand::SetNormal(AttachedNormal(None)))
        .expect("clear");
    assert!(doc.normal().is_none());
    assert_eq!(doc.history().undo_steps().count(), 2);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.normal().is_some());

    // The mesh and its bake.
    let cube = kapaint_mesh::builtin("cube").expect("cube");
    let surface = Arc::new(kapaint_model::surface::Surface::new(cube, 192, 128).expect("bake"));
    let before = doc.version();
    doc.apply(ImportCommand::SetMesh(AttachedMesh {
        mesh: MeshRef::Builtin("cube".into()),
        surface: Arc::clone(&surface),
    }))
    .expect("mesh");
    assert_eq!(doc.settings().mesh, MeshRef::Builtin("cube".into()));
    assert!(Arc::ptr_eq(doc.surface().expect("surface"), &surface));
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(doc.settings().mesh, MeshRef::Sphere);
    assert!(doc.surface().is_none_or(|s| !Arc::ptr_eq(s, &surface)));
    assert_eq!(doc.version(), before);

    // A bake of another size is kapaint's own error, and changes nothing.
    let small = kapaint_mesh::builtin("cube").expect("cube");
    let small = Arc::new(kapaint_model::surface::Surface::new(small, 8, 8).expect("bake"));
    assert!(
        doc.apply(ImportCommand::SetMesh(AttachedMesh {
            mesh: MeshRef::Builtin("cube".into()),
            surface: small,
        }))
        .is_err()
    );
    assert_eq!(doc.version(), before);
}

/// A layer's id survives moves, grouping, undo and a save and load; a duplicate (and every
/// layer in a duplicated group) gets its own; a script selects by id whatever moved; a file
/// from before ids opens with one id a layer.
#[test]
fn layer_ids_survive_moves_grouping_undo_and_saves_and_copies_get_their_own() {
    use kapaint_model::document::LayerRef;
    use kapaint_model::project;
    let mut doc = document();
    run(
        &mut doc,
        r#"(commands: [AddLayer(kind: Paint, name: "A"), AddLayer(kind: Fill, name: "B"), AddLayer(kind: Paint, name: "C")])"#,
    );
    let id_of = |doc: &Document, name: &str| {
        doc.stack()
            .walk()
            .into_iter()
            .find(|(_, l)| l.props.name == name)
            .map(|(_, l)| l.props.id)
            .expect("layer")
    };
    let ids: Vec<_> = ["Layer 1", "A", "B", "C"]
        .iter()
        .map(|n| id_of(&doc, n))
        .collect();
    let unique: std::collections::BTreeSet<_> = ids.iter().collect();
    assert_eq!(unique.len(), 4);
    // Move A to the top and group it: the same id, at a new path.
    doc.apply(LayerCommand::SelectLayer(LayerRef::Name("A".into())))
        .expect("select");
    doc.apply(LayerCommand::MoveLayer(kapaint_model::LayerMove::Top))
        .expect("move");
    doc.apply(LayerCommand::Group).expect("group");
    assert_eq!(id_of(&doc, "A"), ids[1]);
    // A script's id selects A wherever it went.
    doc.apply(LayerCommand::SelectLayer(LayerRef::Name("B".into())))
        .expect("select");
    doc.apply(LayerCommand::SelectLayer(LayerRef::Id { id: ids[1].0 }))
        .expect("select by id");
    assert_eq!(
        doc.stack()
            .layer(&doc.selection().path)
            .expect("layer")
            .props
            .name,
        "A"
    );
    assert!(
        doc.apply(LayerCommand::SelectLayer(LayerRef::Id { id: u64::MAX }))
            .is_err()
    );
    // A copy of the group: new ids for the group and for A's copy inside it.
    doc.apply(LayerCommand::SelectLayer(LayerRef::Name("Group".into())))
        .expect("select group");
    let group = id_of(&doc, "Group");
    doc.apply(LayerCommand::DuplicateLayer).expect("duplicate");
    let all: Vec<_> = doc.stack().walk().iter().map(|(_, l)| l.props.id).collect();
    let unique: std::collections::BTreeSet<_> = all.iter().collect();
    assert_eq!(unique.len(), all.len(), "every layer its own id: {all:?}");
    assert_eq!(
        id_of(&doc, "Group"),
        group,
        "the first of that name is the original"
    );
    // Undo the copy, the group and the move: the ids are the ones they had.
    for _ in 0..3 {
        doc.apply(HistoryCommand::Undo).expect("undo");
    }
    let back: Vec<_> = ["Layer 1", "A", "B", "C"]
        .iter()
        .map(|n| id_of(&doc, n))
        .collect();
    assert_eq!(back, ids);
    // Saved and opened: the same ids.
    let dir = std::env::temp_dir().join(format!("kapaint-layer-ids-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("ids.kapaint");
    project::save(&doc, &path).expect("save");
    let opened = project::load(&path).expect("load");
    let reopened: Vec<_> = ["Layer 1", "A", "B", "C"]
        .iter()
        .map(|n| id_of(&opened, n))
        .collect();
    assert_eq!(reopened, ids);
    // A new layer after opening never takes an id the file holds.
    let mut opened = opened;
    opened
        .apply(LayerCommand::AddLayer {
            kind: kapaint_model::LayerKind::Paint,
            name: "D".into(),
        })
        .expect("add");
    assert!(!ids.contains(&id_of(&opened, "D")));
    let _ = std::fs::remove_dir_all(&dir);
    // A project saved before ids were kept: one id a layer.
    let old = kapaint_model::project::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data/layers_v2_full.kapaint"),
    )
    .expect("the old file opens");
    let all: Vec<_> = old.stack().walk().iter().map(|(_, l)| l.props.id).collect();
    let unique: std::collections::BTreeSet<_> = all.iter().collect();
    assert_eq!(unique.len(), all.len());
}

/// The selection is a layer, not a place: it follows the selected layer through every move
/// (up, into and out of groups, drag and drop), with no path to repair, and undo and redo
/// bring back the layer that was selected in the state they restore.
#[test]
fn the_selection_is_a_layer_and_follows_it() {
    use kapaint_model::{LayerMove, LayerPlace};
    let mut doc = document();
    run(
        &mut doc,
        r#"(commands: [
            AddLayer(kind: Paint, name: "A"),
            AddLayer(kind: Group, name: "G"),
            AddLayer(kind: Paint, name: "B"),
            SelectLayer("A"),
        ])"#,
    );
    let selected = |doc: &Document| {
        let path = doc.selection().path;
        doc.stack().layer(&path).map(|l| l.props.name.clone())
    };
    assert_eq!(selected(&doc).as_deref(), Some("A"));
    for (m, path) in [
        (LayerMove::Top, vec![3]),
        (LayerMove::Down, vec![2]),
        (LayerMove::Down, vec![1]),
        (LayerMove::IntoGroup, vec![1, 0]),
        (LayerMove::OutOfGroup, vec![2]),
        (LayerMove::Bottom, vec![0]),
    ] {
        doc.apply(LayerCommand::MoveLayer(m)).expect("move");
        assert_eq!(doc.selection().path, path, "{m:?}");
        assert_eq!(selected(&doc).as_deref(), Some("A"), "{m:?}");
    }
    // Dropped into the group from the Layers panel.
    let group = doc
        .stack()
        .walk()
        .into_iter()
        .find(|(_, l)| l.props.name == "G")
        .map(|(p, _)| p)
        .expect("group");
    doc.apply(LayerCommand::MoveLayerTo {
        target: group,
        place: LayerPlace::Into,
    })
    .expect("drop");
    assert_eq!(selected(&doc).as_deref(), Some("A"));
    // Select another layer, then undo the drop: the layer selected before it comes back.
    doc.apply(LayerCommand::SelectLayer(kapaint_model::LayerRef::Name(
        "B".into(),
    )))
    .expect("select B");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(selected(&doc).as_deref(), Some("A"));
    // Redo brings back the state undo left, with B selected, and A in the group again.
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert_eq!(selected(&doc).as_deref(), Some("B"));
    let a = doc
        .stack()
        .walk()
        .into_iter()
        .find(|(_, l)| l.props.name == "A");
    assert_eq!(a.map(|(p, _)| p.len()), Some(2), "inside the group again");
}
