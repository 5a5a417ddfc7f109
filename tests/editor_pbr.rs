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
use egui_kittest::kittest::Queryable;
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
    harness.get_by_label("Import PBR material (glTF)…").click();
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

    // One undo step puts the layer back.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(kit::changed(&before, &texels(harness.state())), 0);

    // A glTF mesh import asks whether to bring its material in too.
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import mesh…").click();
    harness.run_steps(2);
    wait_until(&mut harness, "mesh imported", notice("mesh "));
    harness.run_steps(2);
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
    let _ = std::fs::remove_dir_all(&d);
}
