//! The editor's PBR import (issue 20): File > Import PBR material, and the question after a
//! glTF mesh import, with a real glTF material (spot's mesh and texture, a normal map).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;

#[path = "common/gltf_asset.rs"]
#[expect(
    dead_code,
    reason = "the command runner and scratch folders serve the CLI tests"
)]
mod gltf_asset;

use egui::Modifiers;
use egui::accesskit::Role;
use egui_kittest::kittest::{NodeT as _, Queryable};
use gltf_asset::{Asset, write_asset};
use kapaint::ui::Editor;
use kapaint::ui::files::{FileDialogBackend, FilePurpose, FileRequest};
use kit::{editor, texels, wait_until};

/// Where the test's glTF asset is written (the system dialog's answer is a plain function).
fn asset_dir() -> std::path::PathBuf {
    std::env::temp_dir().join(format!("kapaint-editor-pbr-{}", std::process::id()))
}

fn answer(request: &FileRequest) -> Option<std::path::PathBuf> {
    match request.purpose {
        FilePurpose::ImportPbr | FilePurpose::ImportMesh => Some(asset_dir().join("spot.gltf")),
        _ => None,
    }
}

fn notice(text: &'static str) -> impl Fn(&Editor) -> bool {
    move |e: &Editor| e.state.notices().iter().any(|n| n.text.contains(text))
}

#[test]
fn a_gltf_material_imports_into_the_layer_with_its_normal_map_and_undoes() {
    let d = asset_dir();
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    write_asset(
        &d,
        &Asset {
            normal_scale: Some(1.0),
            ..Asset::default()
        },
    );
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);
    let before = texels(harness.state());

    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import PBR material…").click();
    harness.run_steps(2);
    wait_until(
        &mut harness,
        "material imported",
        notice("conversion error max"),
    );
    let doc = harness.state().state.doc();
    assert!(doc.normal().is_some(), "the normal map is kept");
    let report = doc.settings().import.clone().expect("the report is kept");
    assert_eq!(report.model, doc.settings().model.name());
    assert!(kit::changed(&before, &texels(harness.state())) > 0);
    assert!(harness.state().state.dirty());
    // The Layers panel says the material has a normal map.
    harness.run_steps(2);
    harness.get_by_label_contains("Normal map 1024x1024");
    // The canvas shows what each texel loses as a PBR material, with its scale.
    harness.get_by_label("Canvas shows").click();
    harness.run_steps(2);
    harness.get_by_label("PBR error").click();
    harness.run_steps(3);
    harness.get_by_label(kapaint::ui::canvas::PBR_ERROR_SCALE_LABEL);

    // One undo step puts the layer back, and takes the normal map and the report with it:
    // the document is as it was opened, so the title is clean again.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(kit::changed(&before, &texels(harness.state())), 0);
    let doc = harness.state().state.doc();
    assert!(doc.normal().is_none(), "undo takes the normal map back");
    assert!(doc.settings().import.is_none(), "and the import report");
    assert!(!harness.state().state.dirty(), "the title is clean again");
    assert!(
        harness
            .query_by_label_contains("Normal map 1024x1024")
            .is_none()
    );
    // Redo brings all three back.
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::Z);
    harness.run_steps(2);
    let doc = harness.state().state.doc();
    assert!(doc.normal().is_some() && doc.settings().import.is_some());
    assert!(harness.state().state.dirty());
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);

    // A glTF mesh import asks whether to bring its material in too.
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import mesh…").click();
    harness.run_steps(2);
    wait_until(&mut harness, "mesh imported", notice("mesh "));
    harness.run_steps(2);
    assert!(
        harness
            .state()
            .state
            .doc()
            .settings()
            .mesh
            .spec()
            .ends_with("spot.gltf"),
        "the mesh is the project's"
    );
    assert!(harness.state().state.dirty());
    harness
        .get_by_role_and_label(Role::Button, "Bring the material in")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "material imported again", |e| {
        e.state
            .notices()
            .iter()
            .filter(|n| n.text.contains("conversion error max"))
            .count()
            == 2
    });
    assert!(kit::changed(&before, &texels(harness.state())) > 0);
    undo_back_to_the_sphere(&mut harness);
    let _ = std::fs::remove_dir_all(&d);
}

/// Undo takes the material back, then the mesh: the sphere again, and a clean title.
fn undo_back_to_the_sphere(harness: &mut egui_kittest::Harness<'_, Editor>) {
    for _ in 0..2 {
        harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
        harness.run_steps(2);
    }
    let doc = harness.state().state.doc();
    assert_eq!(doc.settings().mesh, kapaint::model::MeshRef::Sphere);
    let surface = doc.surface().expect("a surface");
    assert_eq!(
        surface.mesh,
        kapaint::mesh::builtin("sphere").expect("sphere"),
        "the sphere's bake is back"
    );
    assert!(!harness.state().state.dirty());
}

/// Where the second test's texture set is written.
fn set_dir() -> std::path::PathBuf {
    std::env::temp_dir().join(format!("kapaint-editor-pbr-set-{}", std::process::id()))
}

fn answer_set(request: &FileRequest) -> Option<std::path::PathBuf> {
    (request.purpose == FilePurpose::ImportPbr).then(|| set_dir().join("Bricks_ORM.png"))
}

/// File > Import PBR material, until the editor asks about the material's size.
fn import(harness: &mut egui_kittest::Harness<'static, Editor>) {
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import PBR material…").click();
    harness.run_steps(2);
    wait_until(harness, "the size question", |e| {
        e.state.size_prompt().is_some()
    });
    harness.run_steps(2);
}

#[test]
fn a_texture_set_imports_from_any_one_of_its_images() {
    let d = set_dir();
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    image::RgbImage::from_pixel(32, 32, image::Rgb([200, 80, 60]))
        .save(d.join("Bricks_BaseColor.png"))
        .expect("base");
    image::RgbImage::from_pixel(32, 32, image::Rgb([255, 200, 0]))
        .save(d.join("Bricks_ORM.png"))
        .expect("orm");
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer_set);
    // The set is 32x32, the new project 1024x1024 and unpainted: the editor asks, adopting
    // first (regression: it resampled the material to the maps without a word).
    import(&mut harness);
    let prompt = harness.state().state.size_prompt().expect("asked");
    assert_eq!((prompt.size, prompt.project), ((32, 32), (1024, 1024)));
    assert!(prompt.adopt_by_default);
    harness.get_by_label_contains("the project's maps are 1024x1024");
    // The set by its name, not the image clicked (regression: "Bricks_BaseColor.png is
    // 32x32").
    harness.get_by_label_contains("The texture set Bricks is 32x32");
    harness.get_by_label("Resample to 1024x1024");
    harness.get_by_label("Adopt 32x32").click();
    harness.run_steps(2);
    wait_until(&mut harness, "set imported", notice("conversion error max"));
    let doc = harness.state().state.doc();
    assert_eq!((doc.maps().width(), doc.maps().height()), (32, 32));
    assert!(
        doc.settings()
            .import
            .as_ref()
            .is_some_and(|r| r.notes.iter().all(|n| !n.contains("resampled"))),
        "nothing resampled: {:?}",
        doc.settings().import
    );
    let doc = harness.state().state.doc();
    assert!(doc.normal().is_none(), "the set has no normal map");
    let report = doc.settings().import.clone().expect("report");
    assert!(
        report.source.contains("Bricks_BaseColor.png"),
        "{}",
        report.source
    );
    // A dielectric everywhere: k_s is the dielectric F0 at the roughness' lobe height (the
    // document's mapping, height-fitted), and the export reads F0 back.
    let v = doc.maps().value(3, 3);
    let c = kapaint::pbr::convert::Conversion::for_model(
        doc.settings().model,
        doc.settings().n_mapping(),
    );
    let height = c.height(200.0 / 255.0);
    assert!(height < 0.5, "a rough texel's lobe is lowered: {height}");
    assert!((v.ks.x - 0.04 * height).abs() < 1e-3, "{v:?}");
    assert!(c.pbr(v).metallic < 1e-3, "{:?}", c.pbr(v));
    // Two undo steps: the material, then the maps' size.
    for _ in 0..2 {
        harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
        harness.run_steps(2);
    }
    let doc = harness.state().state.doc();
    assert_eq!((doc.maps().width(), doc.maps().height()), (1024, 1024));
    assert!(doc.settings().import.is_none());
    // A project that holds paint: resampling is the default, and Enter takes it.
    harness
        .state_mut()
        .state
        .apply_command(kapaint::model::document::PaintCommand::Fill(
            kapaint::model::document::FillRegion::All,
        ));
    harness.run_steps(2);
    import(&mut harness);
    assert!(
        !harness
            .state()
            .state
            .size_prompt()
            .expect("asked")
            .adopt_by_default
    );
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
    wait_until(&mut harness, "set resampled", |e| {
        e.state
            .doc()
            .settings()
            .import
            .as_ref()
            .is_some_and(|r| r.notes.iter().any(|n| n.contains("resampled")))
    });
    let doc = harness.state().state.doc();
    assert_eq!((doc.maps().width(), doc.maps().height()), (1024, 1024));
    // Cancel imports nothing.
    let before = texels(harness.state());
    import(&mut harness);
    harness.get_by_label("Cancel").click();
    harness.run_steps(4);
    assert!(harness.state().state.size_prompt().is_none());
    assert_eq!(kit::changed(&before, &texels(harness.state())), 0);
    let _ = std::fs::remove_dir_all(&d);
}

fn teapot(request: &FileRequest) -> Option<std::path::PathBuf> {
    matches!(request.purpose, FilePurpose::ImportMesh).then(|| {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/teapot.obj")
    })
}

/// Steps the editor until a button labelled `label` shows.
fn wait_for_button(harness: &mut egui_kittest::Harness<'_, Editor>, label: &str) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness
        .query_by_role_and_label(Role::Button, label)
        .is_none()
    {
        assert!(std::time::Instant::now() < deadline, "no {label:?} button");
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
}

/// File > Import mesh with a mesh that has no UVs (the teapot) asks whether to unwrap it;
/// Cancel leaves the project as it was, "Unwrap automatically" gives it an atlas the project
/// keeps (saved inside it, there again when it reopens), and Undo takes it back.
#[test]
fn a_mesh_without_uvs_is_unwrapped_on_request_and_kept() {
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(teapot);
    let import = |harness: &mut egui_kittest::Harness<'_, Editor>| {
        harness.get_by_label("File").click();
        harness.run_steps(2);
        harness.get_by_label("Import mesh…").click();
        harness.run_steps(2);
        wait_for_button(harness, "Unwrap automatically");
    };
    import(&mut harness);
    assert!(
        harness
            .query_by_role_and_label(Role::Button, "Keep its UVs")
            .is_none(),
        "the teapot has no UVs to keep"
    );
    harness
        .get_by_role_and_label(Role::Button, "Cancel")
        .click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().state.doc().settings().mesh,
        kapaint::model::MeshRef::Sphere
    );
    assert!(!harness.state().state.dirty(), "Cancel changed nothing");

    import(&mut harness);
    harness
        .get_by_role_and_label(Role::Button, "Unwrap automatically")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "mesh unwrapped", notice("unwrapped: "));
    harness.run_steps(2);
    let doc = harness.state().state.doc();
    assert_eq!(
        doc.settings().mesh,
        kapaint::model::MeshRef::Embedded("teapot.obj, unwrapped".into())
    );
    let surface = doc.surface().expect("baked");
    assert_eq!(surface.mesh.triangles.len(), 6320);
    assert_eq!(kapaint::mesh::unwrap::uv_overlap(&surface.mesh, 1024), 0.0);
    assert!(harness.state().state.dirty());

    // Saved and reopened, the project paints on the same unwrapped teapot.
    let dir = kit::scratch("editor-unwrap");
    let path = dir.join("teapot.kapaint");
    kapaint::model::project::save(doc, &path).expect("saves");
    let kept = doc.embedded_mesh().expect("kept").clone();
    let reopened = kit::editor_on(&path);
    let doc = reopened.state().state.doc();
    assert!(**doc.embedded_mesh().expect("kept") == *kept);
    assert_eq!(
        doc.surface().expect("baked").mesh.triangles.len(),
        6320,
        "the teapot, not the sphere"
    );

    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    let doc = harness.state().state.doc();
    assert_eq!(doc.settings().mesh, kapaint::model::MeshRef::Sphere);
    assert!(doc.embedded_mesh().is_none());
    let _ = std::fs::remove_dir_all(&dir);
}

/// While a bake runs the window redraws once a second for its progress, and not between: on a
/// software renderer each frame takes about 0.1 s of the CPU the bake runs on (four frames a
/// second, and the notices' two, made an AO bake in the editor take 1.4 times the CLI's).
/// Cancelling it is no error.
#[test]
fn a_running_bake_redraws_the_window_once_a_second() {
    use kapaint::mesh::bakes::BakeMap;
    let mut harness = editor();
    harness
        .state_mut()
        .state
        .bake(kapaint::ui::bake::BakeDialog {
            map: BakeMap::Ao,
            rays: 1024,
            ..Default::default()
        });
    let mut delays = Vec::new();
    for _ in 0..6 {
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
        let delay = harness.output().viewport_output[&egui::ViewportId::ROOT].repaint_delay;
        delays.push(delay);
    }
    let running = harness.state().state.busy();
    harness
        .get_by_role_and_label(Role::Button, "Cancel")
        .click();
    harness.step();
    assert!(running, "the bake ended before the test looked");
    // egui asks for the frame one predicted frame time early (kittest predicts 0.25 s): 1 s
    // reads 0.75 s here, and the 0.25 s it was before reads 0.
    let last = *delays.last().expect("steps");
    assert!(
        last >= std::time::Duration::from_millis(700),
        "the next frame is asked for in {last:?} ({delays:?})"
    );
    wait_until(&mut harness, "cancelled", |e| !e.state.busy());
    // Cancelled is what the user asked for: said as information, never as an error (it was
    // "bake AO: cancelled" in red).
    let notices = harness.state().state.notices();
    let said = notices.last().map(|n| (n.text.as_str(), n.level));
    assert_eq!(
        said,
        Some(("Bake cancelled", kapaint::ui::NoticeLevel::Info))
    );
    assert!(
        notices
            .iter()
            .all(|n| n.level != kapaint::ui::NoticeLevel::Error),
        "{:?}",
        notices.iter().map(|n| &n.text).collect::<Vec<_>>()
    );
}

/// Mesh > Bake bakes a map of the mesh on a worker and keeps it in the project as one undo
/// step.
#[test]
fn mesh_bake_keeps_a_map_of_the_mesh_as_one_undo_step() {
    use kapaint::mesh::bakes::BakeMap;
    let mut harness = editor();
    harness.get_by_role_and_label(Role::Button, "Mesh").click();
    harness.run_steps(2);
    harness.get_by_label("Bake…").click();
    harness.run_steps(2);
    harness.get_by_label("Map").click();
    harness.run_steps(2);
    // The map list's entry, not the "Bake all checked" checkbox of the same name.
    harness
        .get_by(|n| n.label().as_deref() == Some("curvature") && n.role() != Role::CheckBox)
        .click();
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::Button, "Bake").click();
    harness.run_steps(2);
    wait_until(&mut harness, "curvature baked", notice("baked curvature"));
    let doc = harness.state().state.doc();
    let bake = doc.bake_of(BakeMap::Curvature).expect("kept");
    assert_eq!(
        (bake.width, bake.height),
        (doc.maps().width(), doc.maps().height())
    );
    assert!(harness.state().state.dirty());
    // The canvas offers the bake to look at.
    harness.get_by_label("Canvas shows").click();
    harness.run_steps(2);
    harness.get_by_label("curvature bake").click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().state.canvas_channel(),
        kapaint::ui::canvas::CanvasChannel::Bake(BakeMap::Curvature)
    );
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert!(harness.state().state.doc().bakes().is_empty());
    assert!(!harness.state().state.dirty());
    // With the bake gone, the canvas shows k_d again.
    assert_eq!(
        harness.state().state.canvas_channel(),
        kapaint::ui::canvas::CanvasChannel::Kd
    );
}

/// Mesh > Unwrap automatically replaces the project's mesh's UVs on request (the built-in
/// sphere here), after saying what happens to what is painted; the project keeps the result.
#[test]
fn mesh_unwrap_on_request_replaces_the_uvs() {
    let mut harness = editor();
    harness.get_by_role_and_label(Role::Button, "Mesh").click();
    harness.run_steps(2);
    harness.get_by_label("Unwrap automatically…").click();
    harness.run_steps(2);
    wait_for_button(&mut harness, "Unwrap automatically");
    assert!(
        harness
            .query_by_label_contains("no longer sits on the same places")
            .is_some(),
        "the question says what happens to the paint"
    );
    harness
        .get_by_role_and_label(Role::Button, "Unwrap automatically")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "sphere unwrapped", notice("unwrapped: "));
    harness.run_steps(2);
    let doc = harness.state().state.doc();
    let sphere = kapaint::mesh::builtin("sphere").expect("sphere");
    assert_eq!(
        doc.settings().mesh,
        kapaint::model::MeshRef::Embedded(format!("{}, unwrapped", sphere.name))
    );
    let mesh = &doc.surface().expect("baked").mesh;
    assert_eq!(mesh.triangles.len(), sphere.triangles.len());
    assert_ne!(mesh.uvs, sphere.uvs, "new UVs");
    assert_eq!(kapaint::mesh::unwrap::uv_overlap(mesh, 1024), 0.0);
}

/// Opens File > Export (its shortcut) and chooses `preset` as a user does: open the list,
/// pick the name.
fn export_dialog_with(harness: &mut egui_kittest::Harness<'_, Editor>, preset: &str) {
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.step();
    harness.step();
    harness.get_by_label("Preset").click();
    harness.step();
    // The list is longer than its popup: the name is chosen by its accessibility action, as a
    // screen reader does (a pointer click lands where the scrolled-away row would be).
    harness
        .get_by_role_and_label(Role::Button, preset)
        .click_accesskit();
    harness.step();
    if harness
        .query_by_role_and_label(Role::Button, "16-bit")
        .is_some()
    {
        // Still open: close it as a user does, on the box.
        harness.get_by_label("Preset").click();
        harness.step();
    }
    assert!(
        harness
            .query_by_role_and_label(Role::Button, "16-bit")
            .is_none(),
        "the list closed"
    );
}

/// File > Export with an engine preset: the dialog names the layout and where occlusion will
/// come from, and the set is written in the engine's names, said so in the notice.
#[test]
fn an_engine_preset_exports_from_the_dialog_with_its_layout_and_occlusion() {
    let dir = std::env::temp_dir().join(format!("kapaint-editor-engine-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("crate");
    let mut harness = editor();
    export_dialog_with(&mut harness, "unreal");
    // The plan arrives from a worker (after the one of the preset shown first).
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness
        .query_by_label_contains("unreal PBR textures")
        .is_none()
    {
        assert!(
            std::time::Instant::now() < deadline,
            "no plan: {:?}",
            texts(&harness)
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
    harness.get_by_label_contains("unreal PBR textures");
    harness.get_by_label_contains("Occlusion: white: the project has no AO bake");
    harness.get_by_label_contains("{name}_OcclusionRoughnessMetallic.png");
    kit::type_export_folder(&mut harness, &out.display().to_string());
    harness
        .get_by_role_and_label(Role::Button, "Export")
        .click();
    harness.step();
    wait_until(&mut harness, "exported", notice("as unreal PBR textures"));
    for file in [
        "crate_BaseColor.png",
        "crate_OcclusionRoughnessMetallic.png",
        "material.json",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let orm = image::open(out.join("crate_OcclusionRoughnessMetallic.png"))
        .expect("ORM")
        .to_rgb8();
    assert!(orm.pixels().all(|p| p.0[0] == 255), "white occlusion");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every text the window shows (labels and values), for a failure's message.
fn texts(harness: &egui_kittest::Harness<'_, Editor>) -> Vec<String> {
    harness
        .root()
        .children_recursive()
        .filter_map(|n| n.accesskit_node().label().or(n.accesskit_node().value()))
        .collect()
}

/// File > Export with `gltf-pbr`, the `.glb` and its Basis Universal textures ticked: the
/// `.glb`'s images are KTX2 files, and the notice says how they were encoded.
#[test]
fn a_basisu_glb_exports_from_the_dialog() {
    let dir = std::env::temp_dir().join(format!("kapaint-editor-basisu-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("sphere");
    let mut harness = editor();
    export_dialog_with(&mut harness, "gltf-pbr");
    // Basis Universal is offered only once the .glb is asked for.
    let basisu = "with Basis Universal textures (KHR_texture_basisu: ETC1S or UASTC)";
    assert!(
        harness.get_by_label(basisu).accesskit_node().is_disabled(),
        "before the .glb"
    );
    harness
        .get_by_label("Also write model.glb (the mesh with this material)")
        .click();
    harness.step();
    harness.get_by_label(basisu).click();
    harness.step();
    kit::type_export_folder(&mut harness, &out.display().to_string());
    harness
        .get_by_role_and_label(Role::Button, "Export")
        .click();
    harness.step();
    wait_until(
        &mut harness,
        "exported",
        notice("model.glb textures base_color "),
    );
    let glb = std::fs::read(out.join("model.glb")).expect("model.glb");
    let glb = gltf::binary::Glb::from_slice(&glb).expect("a GLB");
    let json: serde_json::Value = serde_json::from_slice(&glb.json).expect("JSON");
    assert_eq!(json["extensionsRequired"][0], "KHR_texture_basisu");
    assert!(
        json["images"]
            .as_array()
            .expect("images")
            .iter()
            .all(|i| i["mimeType"] == "image/ktx2"),
        "{json}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
