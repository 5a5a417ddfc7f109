//! A mesh the project keeps inside itself (an unwrapped mesh), and maps baked from a mesh:
//! saved and read back as they were, an undo step when set, dropped when the mesh changes,
//! and refused when the file says one thing and holds another.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::io::{Cursor, Read, Write};
use std::sync::Arc;

use kapaint_mesh::unwrap::{UnwrapOptions, unwrap};
use kapaint_model::document::AttachedMesh;
use kapaint_model::project::{self, from_reader, to_bytes};
use kapaint_model::surface::Surface;
use kapaint_model::{Document, DocumentSettings, HistoryCommand, ImportCommand, MeshRef};

/// A torus without UVs, unwrapped.
fn unwrapped() -> kapaint_mesh::Mesh {
    let mut torus = kapaint_mesh::torus(1.0, 0.35, 32, 16);
    torus.uvs = None;
    let mut mesh = unwrap(&torus, UnwrapOptions::for_size(256), None)
        .expect("unwraps")
        .mesh;
    mesh.name = "torus, unwrapped".into();
    mesh
}

fn kept_document() -> Document {
    let mesh = unwrapped();
    let settings = DocumentSettings {
        mesh: MeshRef::Embedded(mesh.name.clone()),
        ..DocumentSettings::default()
    };
    Document::new(256, 256, settings)
        .expect("document")
        .with_embedded_mesh(Some(Arc::new(mesh)))
}

/// The archive's entries, by name.
fn entries(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).expect("zip");
    (0..zip.len())
        .map(|i| {
            let mut e = zip.by_index(i).expect("entry");
            let mut data = Vec::new();
            e.read_to_end(&mut data).expect("read");
            (e.name().expect("name").to_string(), data)
        })
        .collect()
}

/// The archive with `edit` applied to its manifest (JSON).
fn with_manifest(bytes: &[u8], edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for (name, data) in entries(bytes) {
        out.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start");
        if name == "manifest.json" {
            let mut json: serde_json::Value = serde_json::from_slice(&data).expect("json");
            edit(&mut json);
            out.write_all(&serde_json::to_vec(&json).expect("json"))
                .expect("write");
        } else {
            out.write_all(&data).expect("write");
        }
    }
    out.finish().expect("finish").into_inner()
}

fn version(bytes: &[u8]) -> u64 {
    let manifest = entries(bytes)
        .into_iter()
        .find(|(n, _)| n == "manifest.json")
        .expect("manifest")
        .1;
    serde_json::from_slice::<serde_json::Value>(&manifest).expect("json")["version"]
        .as_u64()
        .expect("version")
}

#[test]
fn a_kept_mesh_reads_back_as_the_same_mesh_and_attaches() {
    let doc = kept_document();
    let bytes = to_bytes(&doc).expect("saves");
    assert_eq!(version(&bytes), 3, "a kept mesh is version 3");
    let mut back = from_reader(Cursor::new(&bytes)).expect("reads");
    assert!(
        **back.embedded_mesh().expect("held") == **doc.embedded_mesh().expect("held"),
        "the same mesh"
    );
    assert_eq!(
        back.settings().mesh,
        MeshRef::Embedded("torus, unwrapped".into())
    );
    project::attach_own_mesh(&mut back).expect("the kept mesh attaches");
    assert!(back.surface().is_some());
    // Saved again, byte for byte the same mesh entry.
    let again = to_bytes(&back).expect("saves");
    let mesh_of = |b: &[u8]| {
        entries(b)
            .into_iter()
            .find(|(n, _)| n == project::MESH_FILE)
            .expect("mesh.obj")
            .1
    };
    assert_eq!(mesh_of(&bytes), mesh_of(&again));
    // A project without a kept mesh is still written as version 2, as before.
    let plain = Document::new(64, 64, DocumentSettings::default()).expect("document");
    assert_eq!(version(&to_bytes(&plain).expect("saves")), 2);
}

/// A change to a manifest.
type Edit = Box<dyn Fn(&mut serde_json::Value)>;

#[test]
fn a_file_that_says_one_thing_and_holds_another_is_refused() {
    let bytes = to_bytes(&kept_document()).expect("saves");
    let cases: [(&str, Edit); 4] = [
        (
            "manifest lists none",
            Box::new(|m| {
                m.as_object_mut().expect("object").remove("mesh");
            }),
        ),
        (
            "the manifest says 1",
            Box::new(|m| m["mesh"]["triangles"] = 1.into()),
        ),
        ("keeps no mesh", Box::new(|m| m["version"] = 2.into())),
        (
            "settings name another mesh",
            Box::new(|m| m["settings"]["mesh"] = "Sphere".into()),
        ),
    ];
    for (says, edit) in cases {
        let edited = with_manifest(&bytes, edit);
        let e = from_reader(Cursor::new(&edited)).expect_err(says);
        assert!(e.contains(says), "{says}: {e}");
    }
    // A document whose settings name a kept mesh it does not hold is never written.
    let settings = DocumentSettings {
        mesh: MeshRef::Embedded("gone".into()),
        ..DocumentSettings::default()
    };
    let orphan = Document::new(64, 64, settings).expect("document");
    assert!(to_bytes(&orphan).is_err());
}

#[test]
fn setting_a_kept_mesh_is_one_undo_step() {
    let mut doc = Document::new(256, 256, DocumentSettings::default()).expect("document");
    let mesh = unwrapped();
    let surface = Arc::new(Surface::new(mesh.clone(), 256, 256).expect("bakes"));
    doc.apply(ImportCommand::SetMesh(AttachedMesh {
        mesh: MeshRef::Embedded(mesh.name.clone()),
        surface,
    }))
    .expect("sets");
    assert!(**doc.embedded_mesh().expect("kept") == mesh);
    assert!(to_bytes(&doc).is_ok());
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.embedded_mesh().is_none());
    assert_eq!(doc.settings().mesh, MeshRef::Sphere);
    assert_eq!(version(&to_bytes(&doc).expect("saves")), 2);
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert!(doc.embedded_mesh().is_some());
}

fn ao_of(doc: &Document) -> Arc<kapaint_mesh::bakes::Baked> {
    let surface = doc.surface().expect("attached");
    Arc::new(
        kapaint_mesh::bakes::bake_map(
            &surface.mesh,
            &surface.bake,
            kapaint_mesh::bakes::BakeMap::Ao,
            kapaint_mesh::bakes::BakeOptions {
                rays: 8,
                max_distance: Some(2.0),
            },
            None,
        )
        .expect("bakes"),
    )
}

#[test]
fn a_bake_is_kept_read_back_and_dropped_with_its_mesh() {
    use kapaint_mesh::bakes::BakeMap;
    use kapaint_model::document::AttachedBake;
    let mut doc = kept_document();
    project::attach_own_mesh(&mut doc).expect("attaches");
    let ao = ao_of(&doc);
    doc.apply(ImportCommand::SetBake(AttachedBake(Arc::clone(&ao))))
        .expect("kept");
    assert!(doc.bake_of(BakeMap::Ao).is_some());
    let bytes = to_bytes(&doc).expect("saves");
    assert_eq!(version(&bytes), 3);
    let back = from_reader(Cursor::new(&bytes)).expect("reads");
    assert_eq!(**back.bake_of(BakeMap::Ao).expect("read back"), *ao);
    // Listed twice, or of another size: refused.
    let twice = with_manifest(&bytes, |m| {
        let entry = m["bakes"][0].clone();
        m["bakes"].as_array_mut().expect("list").push(entry);
    });
    let e = from_reader(Cursor::new(&twice)).expect_err("twice");
    assert!(e.contains("listed twice"), "{e}");
    let unknown = with_manifest(&bytes, |m| m["bakes"][0]["map"] = "shadow".into());
    assert!(from_reader(Cursor::new(&unknown)).is_err());
    let no_rays = with_manifest(&bytes, |m| m["bakes"][0]["rays"] = 0.into());
    assert!(from_reader(Cursor::new(&no_rays)).is_err());
    // Another mesh: the bake goes with the old one; undo brings both back.
    let sphere = kapaint_mesh::uv_sphere(32, 16);
    let surface = Arc::new(Surface::new(sphere, 256, 256).expect("bakes"));
    doc.apply(ImportCommand::SetMesh(AttachedMesh {
        mesh: MeshRef::Sphere,
        surface,
    }))
    .expect("sets");
    assert!(doc.bakes().is_empty(), "a bake of another mesh is stale");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.bake_of(BakeMap::Ao).is_some());
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.bakes().is_empty(), "undo takes the bake back");
    // A bake of another mesh is refused.
    let mut other = Document::new(256, 256, DocumentSettings::default()).expect("document");
    project::attach_own_mesh(&mut other).expect("the sphere");
    let e = other
        .apply(ImportCommand::SetBake(AttachedBake(ao)))
        .expect_err("another mesh");
    assert!(e.to_string().contains("another mesh"), "{e}");
}

/// A bake from a high mesh keeps where it came from (version 6): read back as it was; a
/// damaged account of it (a distance that is not positive, samples other than 1, 4 or 16, a
/// bad hash) or one in an older version is refused.
#[test]
fn a_bake_from_a_high_mesh_says_where_it_came_from() {
    use kapaint_mesh::bakes::{BakeMap, HighMap, HighOptions, HighSource, bake_from_high};
    let mut doc = kept_document();
    project::attach_own_mesh(&mut doc).expect("attaches");
    let surface = doc.surface().expect("attached").clone();
    let high = kapaint_mesh::torus(1.0, 0.37, 96, 48);
    let source = HighSource::of(&high, None);
    let bake = |map| {
        let options = HighOptions {
            rays: 8,
            samples: 4,
            ..HighOptions::new(map)
        };
        bake_from_high(&surface.mesh, &surface.bake, &high, None, options, None).expect("bakes")
    };
    // What a project does not keep, or the normal map among other maps: refused.
    for (bakes, want) in [
        (vec![bake(HighMap::Height)], "no height map"),
        (
            vec![bake(HighMap::Id(kapaint_mesh::bakes::IdSource::Piece))],
            "no id map",
        ),
        (
            vec![
                bake(HighMap::Ao),
                bake(HighMap::Normal(kapaint_mesh::bakes::NormalSpace::Tangent)),
            ],
            "among other maps",
        ),
        (vec![], "no map was baked"),
    ] {
        let e = ImportCommand::keep_high(bakes, surface.mesh_hash, &source).expect_err(want);
        assert!(e.contains(want), "{e}");
    }
    let keep = ImportCommand::keep_high(vec![bake(HighMap::Ao)], surface.mesh_hash, &source)
        .expect("a project keeps AO");
    doc.apply(keep).expect("kept");
    let baked = (**doc.bake_of(BakeMap::Ao).expect("kept")).clone();
    let from = baked.from_high.clone().expect("from the high mesh");
    assert_eq!((from.mesh.as_str(), from.samples), ("torus", 4));
    assert_eq!(from.mesh_hash, high.content_hash());
    let bytes = to_bytes(&doc).expect("saves");
    assert_eq!(version(&bytes), 6);
    let back = from_reader(Cursor::new(&bytes)).expect("reads");
    assert_eq!(**back.bake_of(BakeMap::Ao).expect("read back"), baked);
    for (edit, want) in [
        (
            Box::new(|m: &mut serde_json::Value| m["bakes"][0]["high"]["front"] = (-1.0).into())
                as Box<dyn Fn(&mut serde_json::Value)>,
            "not a positive number",
        ),
        (
            Box::new(|m: &mut serde_json::Value| m["bakes"][0]["high"]["samples"] = 3.into()),
            "1, 4 or 16",
        ),
        (
            Box::new(|m: &mut serde_json::Value| m["bakes"][0]["high"]["mesh_hash"] = "xyz".into()),
            "16 hex digits",
        ),
        (
            Box::new(|m: &mut serde_json::Value| m["version"] = 5.into()),
            "version 6",
        ),
    ] {
        let damaged = with_manifest(&bytes, edit);
        let e = from_reader(Cursor::new(&damaged)).expect_err(want);
        assert!(e.contains(want), "{e}");
    }
}
