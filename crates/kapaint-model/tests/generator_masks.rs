//! Generator masks through the document, as scripts drive them: `SetMaskGenerator` on the
//! selected layer's mask, paint over a generator, one undo step per change (a drag's previews
//! joined), bakes read through levels, parameters saved and read back (version 4), and bad
//! parameters refused.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::io::{Cursor, Read, Write};
use std::sync::Arc;

use glam::Vec2;
use kapaint_model::brush::StrokePoint;
use kapaint_model::generator::{Generator, Levels, Noise, NoiseKind, Space};
use kapaint_model::project::{from_reader, to_bytes};
use kapaint_model::texel::Texel;
use kapaint_model::{Command, Document, HistoryCommand, LayerCommand, MaskCommand};

#[path = "common/layer_doc.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod layer_doc;
use layer_doc::{document, run, texels};

/// A rust layer over the base, selected: what a generator mask shapes.
fn rust_layer() -> Document {
    let mut doc = document();
    // Its mesh attached, as every path that lays a generator has it (the editor, `paint`,
    // opening a project).
    kapaint_model::project::attach_own_mesh(&mut doc).expect("the sphere");
    run(
        &mut doc,
        r#"(commands: [AddLayer(kind: Fill, name: "Rust"), SetPrimary((kd: (0.4, 0.15, 0.05), ks: (0.02, 0.02, 0.02), n: 3.0)), SetLayerFill((kd: (0.4, 0.15, 0.05), ks: (0.02, 0.02, 0.02), n: 3.0))])"#,
    );
    doc
}

const NOISE: &str =
    "SetMaskGenerator(Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space: Object))";

fn noise(scale: f32) -> Generator {
    Generator::Noise(Noise {
        kind: NoiseKind::Perlin,
        scale,
        octaves: 4,
        seed: 1,
        space: Space::Object,
    })
}

/// The selected layer's mask values over the whole map, row by row.
fn mask_values(doc: &Document) -> Vec<u16> {
    let layer = doc.selected_layer().expect("selected");
    let mask = layer.mask.as_ref().expect("mask");
    let (w, h) = (doc.maps().width() as usize, doc.maps().height() as usize);
    let tiles_x = w.div_ceil(64);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| mask.value((y / 64) * tiles_x + x / 64, (y % 64) * 64 + x % 64))
        .collect()
}

#[test]
fn a_noise_generator_adds_a_mask_that_shapes_the_layer_in_one_undo_step() {
    let mut doc = rust_layer();
    let rust_everywhere = texels(&doc);
    let steps = doc.history().undo_steps().count();
    run(&mut doc, &format!("(commands: [{NOISE}])"));
    assert_eq!(
        doc.history().undo_steps().count(),
        steps + 1,
        "one undo step"
    );
    let layer = doc.selected_layer().expect("selected");
    assert_eq!(
        layer.mask.as_ref().and_then(|m| m.generator()),
        Some(&noise(8.0))
    );
    let values = mask_values(&doc);
    let (lo, hi) = values
        .iter()
        .fold((u16::MAX, 0), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    assert!(
        lo < 20_000 && hi > 45_000,
        "noise spans the range: {lo}..{hi}"
    );
    // The layer shows in part: the composite differs from both the base and the full fill.
    let now = texels(&doc);
    assert_ne!(now, rust_everywhere);
    run(&mut doc, "(commands: [Undo])");
    assert!(doc.selected_layer().expect("selected").mask.is_none());
    assert_eq!(texels(&doc), rust_everywhere, "undo, bit-exact");
    run(&mut doc, "(commands: [Redo])");
    assert_eq!(texels(&doc), now, "redo, bit-exact");
}

#[test]
fn the_composite_follows_the_generator_texel_by_texel() {
    let mut doc = rust_layer();
    run(&mut doc, &format!("(commands: [{NOISE}])"));
    let values = mask_values(&doc);
    let maps = doc.maps();
    let base = doc.stack().base;
    let w = maps.width() as usize;
    for (i, &m) in values.iter().enumerate().step_by(997) {
        let t = maps.texel((i % w) as u32, (i / w) as u32);
        let kd = Texel::decode(t).kd.x;
        let a = f32::from(m) / 65535.0;
        let expect = base.kd.x * (1.0 - a) + 0.4 * a;
        assert!((kd - expect).abs() < 2e-3, "texel {i}: {kd} vs {expect}");
    }
}

#[test]
fn paint_over_a_generator_adds_and_removes_and_none_keeps_what_shows() {
    let mut doc = rust_layer();
    run(&mut doc, &format!("(commands: [{NOISE}, SelectMask])"));
    let before = mask_values(&doc);
    // White paint makes the mask 1 where it lands, black 0; elsewhere the generator shows.
    let stroke = |doc: &mut Document, y: f32| {
        let points = (0..=8)
            .map(|k| StrokePoint {
                pos: Vec2::new(10.0 + 20.0 * k as f32, y),
                pressure: 1.0,
            })
            .collect();
        doc.apply(kapaint_model::StrokeCommand::Stroke {
            tool: kapaint_model::StrokeTool::Brush,
            points,
        })
        .expect("stroke");
    };
    run(
        &mut doc,
        "(commands: [SetPrimary((kd: (1.0, 1.0, 1.0), ks: (1.0, 1.0, 1.0), n: 10.0))])",
    );
    stroke(&mut doc, 30.0);
    run(
        &mut doc,
        "(commands: [SetPrimary((kd: (0.0, 0.0, 0.0), ks: (0.0, 0.0, 0.0), n: 10.0))])",
    );
    stroke(&mut doc, 100.0);
    let after = mask_values(&doc);
    let w = doc.maps().width() as usize;
    assert_eq!(after[30 * w + 90], u16::MAX, "white paint adds");
    assert_eq!(after[100 * w + 90], 0, "black paint removes");
    assert_eq!(
        after[64 * w + 90],
        before[64 * w + 90],
        "the generator elsewhere"
    );
    // A new generator keeps the paint over it.
    doc.apply(MaskCommand::SetMaskGenerator(Some(noise(3.0))))
        .expect("set");
    let other = mask_values(&doc);
    assert_eq!(other[30 * w + 90], u16::MAX);
    assert_eq!(other[100 * w + 90], 0);
    assert_ne!(other[64 * w + 90], before[64 * w + 90]);
    // None: the mask becomes the pixels it showed.
    let shown = texels(&doc);
    run(&mut doc, "(commands: [SetMaskGenerator(None)])");
    let mask = doc
        .selected_layer()
        .expect("layer")
        .mask
        .clone()
        .expect("mask");
    assert!(mask.generator.is_none());
    assert_eq!(mask_values(&doc), other);
    assert_eq!(texels(&doc), shown);
}

#[test]
fn a_drag_of_previews_is_one_undo_step_ending_at_the_full_result() {
    let mut doc = rust_layer();
    run(&mut doc, &format!("(commands: [{NOISE}])"));
    let steps = doc.history().undo_steps().count();
    let set = texels(&doc);
    for s in [8.5, 9.0, 9.5] {
        doc.apply(MaskCommand::PreviewMaskGenerator(noise(s)))
            .expect("preview");
        let layer = doc.selected_layer().expect("layer");
        assert!(
            layer
                .mask
                .as_ref()
                .and_then(|m| m.generator.as_ref())
                .expect("made")
                .is_coarse()
        );
    }
    doc.apply(MaskCommand::SetMaskGenerator(Some(noise(10.0))))
        .expect("set");
    assert_eq!(
        doc.history().undo_steps().count(),
        steps + 1,
        "the drag is one step"
    );
    let layer = doc.selected_layer().expect("layer");
    let made = layer
        .mask
        .as_ref()
        .and_then(|m| m.generator.as_ref())
        .expect("made");
    assert!(!made.is_coarse());
    // The full result is what setting it directly gives.
    let dragged = texels(&doc);
    let mut direct = rust_layer();
    run(
        &mut direct,
        "(commands: [SetMaskGenerator(Noise(kind: Perlin, scale: 10.0, octaves: 4, seed: 1, space: Object))])",
    );
    assert_eq!(dragged, texels(&direct));
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), set, "one undo takes the whole drag back");
    // Two changes in a script are two steps.
    doc.apply(MaskCommand::SetMaskGenerator(Some(noise(5.0))))
        .expect("set");
    doc.apply(MaskCommand::SetMaskGenerator(Some(noise(6.0))))
        .expect("set");
    assert_eq!(doc.history().undo_steps().count(), steps + 2);
}

#[test]
fn opacity_changes_of_two_layers_are_two_undo_steps() {
    // Regression: a second layer's opacity change took the first layer's step off the
    // history and dropped it.
    let mut doc = rust_layer();
    let steps = doc.history().undo_steps().count();
    doc.apply(LayerCommand::SetLayerOpacity(0.5))
        .expect("opacity");
    run(&mut doc, "(commands: [SelectPath([0])])");
    doc.apply(LayerCommand::SetLayerOpacity(0.25))
        .expect("opacity");
    assert_eq!(doc.history().undo_steps().count(), steps + 2);
    doc.apply(HistoryCommand::Undo).expect("undo");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.stack().layers.iter().all(|l| l.props.opacity == 1.0));
}

#[test]
fn bad_generator_parameters_are_refused_in_scripts() {
    #[derive(serde::Deserialize)]
    struct Script {
        #[expect(dead_code, reason = "parsing is the test")]
        commands: Vec<Command>,
    }
    for bad in [
        "SetMaskGenerator(Ao(black: 0.9, white: 0.2, invert: false))",
        "SetMaskGenerator(Ao(black: NaN, white: 0.2, invert: false))",
        "SetMaskGenerator(Curvature(black: 0.0, white: inf, invert: false))",
        "SetMaskGenerator(Noise(kind: Perlin, scale: 0.0, octaves: 4, seed: 1, space: Object))",
        "SetMaskGenerator(Noise(kind: Perlin, scale: 8.0, octaves: 9, seed: 1, space: Object))",
        "SetMaskGenerator(Noise(kind: Perlin, scale: NaN, octaves: 1, seed: 1, space: Object))",
        "SetMaskGenerator(Gradient(axis: Y, from: 0.5, to: 0.5))",
        "SetMaskGenerator(Blend(op: Min, a: None, b: Ao(black: 0.0, white: 1.0)))",
    ] {
        let script = format!("(commands: [{bad}])");
        assert!(ron::from_str::<Script>(&script).is_err(), "{bad} parsed");
    }
}

#[test]
fn the_ao_generator_reads_the_ao_bake_through_its_levels() {
    use kapaint_mesh::bakes::{BakeMap, BakeOptions, bake_map};
    use kapaint_model::document::{AttachedBake, AttachedMesh};
    use kapaint_model::surface::Surface;
    let mut doc =
        kapaint_model::Document::new(128, 128, kapaint_model::DocumentSettings::default())
            .expect("doc");
    let surface =
        Arc::new(Surface::new(kapaint_mesh::torus(1.0, 0.35, 32, 16), 128, 128).expect("bake"));
    doc.apply(kapaint_model::ImportCommand::SetMesh(AttachedMesh {
        surface: Arc::clone(&surface),
        mesh: kapaint_model::MeshRef::Builtin("torus".into()),
    }))
    .expect("mesh");
    run(
        &mut doc,
        r#"(commands: [AddLayer(kind: Fill, name: "Dirt")])"#,
    );
    // No bake yet: the generator is refused, naming the bake that makes what it reads (it read
    // a flat 0.5 through its levels before).
    let ao_mask = MaskCommand::SetMaskGenerator(Some(Generator::Ao(Levels {
        black: 0.2,
        white: 0.9,
        gamma: 1.0,
        invert: true,
        relative: false,
    })));
    let e = doc.apply(ao_mask.clone()).expect_err("no AO bake");
    assert!(e.to_string().contains("kapaint bake"), "{e}");
    let unmasked = texels(&doc);
    let ao = Arc::new(
        bake_map(
            &surface.mesh,
            &surface.bake,
            BakeMap::Ao,
            BakeOptions {
                rays: 16,
                max_distance: None,
            },
            None,
        )
        .expect("bakes"),
    );
    doc.apply(kapaint_model::ImportCommand::SetBake(AttachedBake(
        Arc::clone(&ao),
    )))
    .expect("kept");
    doc.apply(ao_mask.clone()).expect("the bake is there");
    let baked = mask_values(&doc);
    let levels = Levels {
        black: 0.2,
        white: 0.9,
        gamma: 1.0,
        invert: true,
        relative: false,
    };
    for i in (0..baked.len()).step_by(131) {
        if surface.bake.triangle(i).is_none() {
            continue;
        }
        let expect = levels.apply(ao.value(i, 0));
        let got = f32::from(baked[i]) / 65535.0;
        assert!((got - expect).abs() < 1e-4, "texel {i}: {got} vs {expect}");
    }
    // Undo of the mask, then of the bake: as it was, and the generator refused again.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), unmasked);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(doc.apply(ao_mask).is_err());
}

/// The archive's manifest, edited by `edit`.
fn with_manifest(bytes: &[u8], edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..zip.len() {
        let mut e = zip.by_index(i).expect("entry");
        let name = e.name().expect("name").to_string();
        let mut data = Vec::new();
        e.read_to_end(&mut data).expect("read");
        out.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start");
        if name == "manifest.json" {
            let mut json: serde_json::Value = serde_json::from_slice(&data).expect("json");
            edit(&mut json);
            data = serde_json::to_vec(&json).expect("json");
        }
        out.write_all(&data).expect("write");
    }
    out.finish().expect("finish").into_inner()
}

#[test]
fn generators_save_as_parameters_in_version_4_and_read_back_bit_exact() {
    let mut doc = rust_layer();
    run(&mut doc, &format!("(commands: [{NOISE}])"));
    let bytes = to_bytes(&doc).expect("saves");
    let manifest: serde_json::Value = {
        let mut zip = zip::ZipArchive::new(Cursor::new(&bytes)).expect("zip");
        serde_json::from_reader(zip.by_name("manifest.json").expect("manifest")).expect("json")
    };
    assert_eq!(manifest["version"], 4);
    let mask = &manifest["layers"][1]["mask"];
    assert_eq!(mask["generator"]["Noise"]["scale"], 8.0);
    let back = from_reader(Cursor::new(&bytes)).expect("reads");
    assert_eq!(texels(&back), texels(&doc));
    assert_eq!(
        back.stack().layers[1]
            .mask
            .as_ref()
            .and_then(|m| m.generator()),
        Some(&noise(8.0))
    );
    // A plain project stays version 2.
    assert_eq!(
        serde_json::from_reader::<_, serde_json::Value>(
            zip::ZipArchive::new(Cursor::new(to_bytes(&rust_layer()).expect("saves")))
                .expect("zip")
                .by_name("manifest.json")
                .expect("manifest")
        )
        .expect("json")["version"],
        2
    );
    // Out-of-range parameters, or a generator in a version 3 file: refused.
    for edit in [
        (|m: &mut serde_json::Value| {
            m["layers"][1]["mask"]["generator"]["Noise"]["octaves"] = 99.into();
        }) as fn(&mut serde_json::Value),
        |m| m["layers"][1]["mask"]["generator"]["Noise"]["scale"] = (-1.0).into(),
        |m| m["version"] = 3.into(),
    ] {
        let bad = with_manifest(&bytes, edit);
        assert!(from_reader(Cursor::new(&bad)).is_err());
    }
}

/// Opening lays a project's generator masks on its mesh and makes its composite from the
/// layers there: what was saved, computed again, not read from the stored composite.
#[test]
fn a_project_with_generator_masks_opens_with_them_made_on_its_mesh() {
    use kapaint_model::project;
    let settings = kapaint_model::DocumentSettings {
        mesh: kapaint_model::MeshRef::Builtin("torus".into()),
        ..kapaint_model::DocumentSettings::default()
    };
    let mut doc = Document::new(128, 128, settings).expect("doc");
    project::attach_own_mesh(&mut doc).expect("torus");
    run(
        &mut doc,
        &format!(r#"(commands: [AddLayer(kind: Fill, name: "Dirt"), {NOISE}])"#),
    );
    let bytes = to_bytes(&doc).expect("saves");
    let mut back = from_reader(Cursor::new(&bytes)).expect("reads");
    let computed = |d: &Document| d.stack().heap_bytes();
    assert!(back.surface().is_some(), "the torus is attached");
    assert!(computed(&back) > 0, "the masks were made on opening");
    assert_eq!(texels(&back), texels(&doc));
    // The stored composite is not what opens: a `kd` made white in the file changes nothing.
    let white = with_manifest(&bytes, |m| {
        m["kd"] = serde_json::json!({"kind": "uniform", "value": [65535, 65535, 65535]});
    });
    let opened = from_reader(Cursor::new(&white)).expect("reads");
    assert_eq!(texels(&opened), texels(&doc));
    // A change computes them on the mesh, as in the document saved.
    for d in [&mut doc, &mut back] {
        d.apply(MaskCommand::SetMaskGenerator(Some(noise(3.0))))
            .expect("set");
    }
    assert_eq!(texels(&back), texels(&doc));
}

#[test]
fn the_dust_smart_mask_settles_on_what_faces_up() {
    let dust = kapaint_model::generator::preset::builtin()
        .into_iter()
        .find(|p| p.name == "Dust")
        .expect("shipped");
    let mut doc = rust_layer();
    doc.apply(MaskCommand::SetMaskGenerator(Some(dust.mask)))
        .expect("applies");
    // The builtin sphere's map: the top rows face up, the bottom half faces down.
    let values = mask_values(&doc);
    let (w, h) = (doc.maps().width() as usize, doc.maps().height() as usize);
    let top = values[..w * h / 8].iter().filter(|&&v| v > 0).count();
    let bottom = values[w * h / 2..].iter().filter(|&&v| v > 0).count();
    assert!(top > w * h / 64, "dust on top: {top} texels");
    assert_eq!(bottom, 0, "no dust underneath");
}

/// The fraction of `mesh`'s surface texels (at 256^2, unwrapped first where it has no UVs)
/// that the curvature part of the shipped Edge wear smart mask marks (above one half).
fn edge_wear_fraction(mesh: kapaint_mesh::Mesh) -> f64 {
    use kapaint_mesh::bakes::{BakeMap, BakeOptions, bake_map};
    let size = 256;
    let mesh = if mesh.uvs.is_some() {
        mesh
    } else {
        kapaint_mesh::unwrap::unwrap(
            &mesh,
            kapaint_mesh::unwrap::UnwrapOptions::for_size(size),
            None,
        )
        .expect("unwraps")
        .mesh
    };
    let surface = kapaint_model::surface::Surface::new(mesh, size, size).expect("bakes");
    let baked = bake_map(
        &surface.mesh,
        &surface.bake,
        BakeMap::Curvature,
        BakeOptions::default(),
        None,
    )
    .expect("curvature");
    let edge = kapaint_model::generator::preset::builtin()
        .into_iter()
        .find(|p| p.name == "Edge wear")
        .expect("shipped");
    let Generator::Blend { a, .. } = edge.mask else {
        panic!("Edge wear is a blend: {:?}", edge.mask);
    };
    let Generator::Curvature(levels) = a.resolved(&[Arc::new(baked.clone())]) else {
        panic!("its first part reads curvature: {a:?}");
    };
    let (mut on, mut all) = (0_u64, 0_u64);
    for i in 0..surface.bake.len() {
        if surface.bake.coverage(i) == kapaint_mesh::bake::Coverage::Empty {
            continue;
        }
        all += 1;
        on += u64::from(levels.apply(baked.value(i, 0)) > 0.5);
    }
    on as f64 / all as f64
}

/// Edge wear marks a mesh's edges, not its body: its levels sit in each mesh's own spread of
/// curvature (fixed levels sat at the smooth teapot's and cow's mean and covered them whole).
#[test]
fn edge_wear_finds_the_edges_of_smooth_and_sharp_meshes_alike() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/meshes");
    let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/testdata/spot/spot_triangulated.obj");
    let meshes = [
        (
            "teapot",
            kapaint_mesh::open(&data.join("teapot.obj")).expect("teapot"),
        ),
        ("spot", kapaint_mesh::open(&spot).expect("spot")),
        (
            "suzanne",
            kapaint_mesh::open(&data.join("suzanne.obj")).expect("suzanne"),
        ),
    ];
    for (name, mesh) in meshes {
        let f = edge_wear_fraction(mesh);
        eprintln!("Edge wear marks {:.2} % of the {name}", 100.0 * f);
        assert!(
            (0.002..=0.2).contains(&f),
            "Edge wear marks {:.1} % of the {name}",
            100.0 * f
        );
    }
}
