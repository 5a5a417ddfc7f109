//! Mesh > Bake from high poly (issue 57): the high mesh chosen through the file chooser, maps
//! for the masks baked on a worker and kept as one undo step saying where they came from, then
//! the normal map.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;

use egui::Modifiers;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::mesh::bakes::BakeMap;
use kapaint::ui::Editor;
use kapaint::ui::files::{FileDialogBackend, FilePurpose, FileRequest};
use kit::{editor, wait_until};

/// Where the test's high mesh is written (the system dialog's answer is a plain function).
fn high_path() -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "kapaint-editor-bake-high-{}.obj",
        std::process::id()
    ))
}

fn answer(request: &FileRequest) -> Option<std::path::PathBuf> {
    (request.purpose == FilePurpose::HighMesh).then(high_path)
}

/// Writes a finer sphere than the default document's as the high mesh; returns it as the
/// editor will load it.
fn write_high() -> kapaint::mesh::Mesh {
    let fine = kapaint::mesh::uv_sphere(128, 64);
    std::fs::write(high_path(), kapaint::mesh::write_obj(&fine)).expect("writes");
    kapaint::mesh::open(&high_path()).expect("loads")
}

/// Mesh > Bake from high poly…, then Add high mesh… (answered with `high`), until the dialog
/// holds it and its window has settled.
fn open_with_high(harness: &mut Harness<'static, Editor>, high: &std::path::Path) {
    harness.get_by_label("Mesh").click();
    harness.run_steps(2);
    harness.get_by_label("Bake from high poly…").click();
    harness.run_steps(2);
    assert!(harness.state().state.bake_high_dialog().is_some());
    harness.get_by_label("Add high mesh…").click();
    wait_until(harness, "the high mesh chosen", |e| {
        e.state
            .bake_high_dialog()
            .is_some_and(|d| d.highs.iter().any(|h| h == high))
    });
    // The window grows by the mesh's line: let it settle before clicking in it.
    harness.run_steps(3);
}

#[test]
fn maps_and_the_normal_map_bake_from_a_high_mesh_each_one_undo_step() {
    let loaded = write_high();
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);

    open_with_high(&mut harness, &high_path());
    assert_eq!(
        harness
            .state()
            .state
            .bake_high_dialog()
            .map(|d| d.highs.clone()),
        Some(vec![high_path()])
    );
    // The maps for the masks: curvature alone (no rays), then Bake.
    harness.get_by_label("Maps for the masks:").click();
    harness.run_steps(2);
    harness.get_by_label("Ambient occlusion").click();
    harness.run_steps(2);
    let dialog = harness
        .state()
        .state
        .bake_high_dialog()
        .expect("open")
        .clone();
    assert_eq!(dialog.maps(), [kapaint::mesh::bakes::HighMap::Curvature]);
    harness.get_by_label("Bake").click();
    wait_until(&mut harness, "curvature baked", |e| {
        e.state.doc().bake_of(BakeMap::Curvature).is_some()
    });
    let doc = harness.state().state.doc();
    let bake = doc.bake_of(BakeMap::Curvature).expect("kept");
    let from = bake.from_high.as_ref().expect("from the high mesh");
    assert_eq!(from.mesh_hash, loaded.content_hash());
    assert!(
        harness
            .state()
            .state
            .notices()
            .iter()
            .any(|n| n.text.contains("baked curvature") && n.text.contains("missed 0")),
        "a line on what the rays found"
    );
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert!(
        harness
            .state()
            .state
            .doc()
            .bake_of(BakeMap::Curvature)
            .is_none(),
        "one undo step"
    );

    // The normal map, from the dialog opened again (it keeps nothing but its defaults).
    open_with_high(&mut harness, &high_path());
    assert!(harness.state().state.doc().normal().is_none());
    harness.get_by_label("Bake").click();
    wait_until(&mut harness, "the normal map baked", |e| {
        e.state.doc().normal().is_some()
    });
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert!(
        harness.state().state.doc().normal().is_none(),
        "one undo step"
    );
    let _ = std::fs::remove_file(high_path());
}

/// Where the cancel test's high mesh is written.
fn big_path() -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "kapaint-editor-bake-high-big-{}.obj",
        std::process::id()
    ))
}

fn answer_big(request: &FileRequest) -> Option<std::path::PathBuf> {
    (request.purpose == FilePurpose::HighMesh).then(big_path)
}

/// Cancel while the rays run: nothing is kept, the history is as it was, and the cancel is
/// said as information, not as an error.
#[test]
fn a_cancelled_bake_from_high_poly_keeps_nothing() {
    let fine = kapaint::mesh::uv_sphere(512, 256);
    std::fs::write(big_path(), kapaint::mesh::write_obj(&fine)).expect("writes");
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer_big);
    let steps = harness.state().state.doc().history().undo_steps().count();
    open_with_high(&mut harness, &big_path());
    // AO and curvature, 64 rays a texel: long enough to cancel.
    harness.get_by_label("Maps for the masks:").click();
    harness.run_steps(2);
    harness.get_by_label("Bake").click();
    wait_until(&mut harness, "the bake running", |e| e.state.busy());
    harness.run_steps(2);
    assert!(
        harness.state().state.busy(),
        "the bake ended before the test looked"
    );
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "Cancel")
        .click();
    harness.step();
    wait_until(&mut harness, "cancelled", |e| !e.state.busy());
    let doc = harness.state().state.doc();
    assert!(doc.bakes().is_empty(), "nothing kept");
    assert_eq!(doc.history().undo_steps().count(), steps);
    let notices = harness.state().state.notices();
    assert!(
        notices
            .iter()
            .all(|n| n.level != kapaint::ui::NoticeLevel::Error),
        "{:?}",
        notices.iter().map(|n| &n.text).collect::<Vec<_>>()
    );
    let _ = std::fs::remove_file(big_path());
}

/// Where the matching test's high mesh is written.
fn named_path() -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "kapaint-editor-bake-high-named-{}.obj",
        std::process::id()
    ))
}

fn answer_named(request: &FileRequest) -> Option<std::path::PathBuf> {
    (request.purpose == FilePurpose::HighMesh).then(named_path)
}

/// "Match parts by name" against a document whose mesh names no parts: the job says there are
/// no pairs, as an error, and keeps nothing.
#[test]
fn matching_by_name_without_pairs_says_so_and_keeps_nothing() {
    let text = format!(
        "o body_high\n{}",
        kapaint::mesh::write_obj(&kapaint::mesh::uv_sphere(32, 16))
    );
    std::fs::write(named_path(), text).expect("writes");
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer_named);
    let steps = harness.state().state.doc().history().undo_steps().count();
    open_with_high(&mut harness, &named_path());
    harness
        .get_by_label("Match parts by name (X_low with X_high)")
        .click();
    harness.run_steps(2);
    assert!(
        harness
            .state()
            .state
            .bake_high_dialog()
            .is_some_and(|d| d.by_name)
    );
    harness.get_by_label("Bake").click();
    wait_until(&mut harness, "the job refused", |e| {
        e.state
            .notices()
            .iter()
            .any(|n| n.text.contains("no pairs"))
    });
    let state = &harness.state().state;
    let refusal = state
        .notices()
        .iter()
        .find(|n| n.text.contains("no pairs"))
        .expect("said");
    assert_eq!(refusal.level, kapaint::ui::NoticeLevel::Error);
    assert!(refusal.text.contains("body_high"), "{}", refusal.text);
    assert_eq!(state.doc().history().undo_steps().count(), steps);
    let _ = std::fs::remove_file(named_path());
}

/// Where the cage test's files are written.
fn cage_dir() -> std::path::PathBuf {
    std::env::temp_dir().join(format!("kapaint-editor-cage-{}", std::process::id()))
}

fn answer_cage(request: &FileRequest) -> Option<std::path::PathBuf> {
    (request.purpose == FilePurpose::Cage).then(|| cage_dir().join("cage.obj"))
}

/// A cage chosen in the dialog is read on a worker and drawn as it is (the dialog holds it);
/// one of another topology is refused with an error and not drawn.
#[test]
fn a_chosen_cage_is_read_for_the_preview_and_a_wrong_one_refused() {
    let dir = cage_dir();
    std::fs::create_dir_all(&dir).expect("dir");
    let low_obj = dir.join("low.obj");
    std::fs::write(
        &low_obj,
        kapaint::mesh::write_obj(&kapaint::mesh::uv_sphere(32, 16)),
    )
    .expect("writes");
    let low = kapaint::mesh::open(&low_obj).expect("loads");
    let mut cage = low.clone();
    for p in &mut cage.positions {
        *p *= 1.05;
    }
    std::fs::write(dir.join("cage.obj"), kapaint::mesh::write_obj(&cage)).expect("writes");
    let project = dir.join("low.kapaint");
    let made = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["new", "--size", "64", "--mesh"])
        .arg(&low_obj)
        .arg("--out")
        .arg(&project)
        .output()
        .expect("runs");
    assert!(made.status.success(), "{made:?}");
    let mut harness = kit::editor_on(&project);
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer_cage);
    harness.get_by_label("Mesh").click();
    harness.run_steps(2);
    harness.get_by_label("Bake from high poly…").click();
    harness.run_steps(2);
    harness.get_by_label("Choose…").click();
    wait_until(&mut harness, "the cage read", |e| {
        e.state
            .bake_high_dialog()
            .is_some_and(|d| d.cage_mesh.is_some())
    });
    let dialog = harness.state().state.bake_high_dialog().expect("open");
    assert_eq!(
        dialog.cage_mesh.as_ref().map(|c| c.positions.clone()),
        Some(cage.positions.clone())
    );
    harness.run_steps(2);

    // Another topology: refused, not drawn.
    std::fs::write(
        dir.join("cage.obj"),
        kapaint::mesh::write_obj(&kapaint::mesh::uv_sphere(16, 8)),
    )
    .expect("writes");
    harness.get_by_label("Choose…").click();
    wait_until(&mut harness, "the cage refused", |e| {
        e.state
            .notices()
            .iter()
            .any(|n| n.text.contains("topology"))
    });
    let state = &harness.state().state;
    assert!(
        state
            .bake_high_dialog()
            .is_some_and(|d| d.cage_mesh.is_none())
    );
    let _ = std::fs::remove_dir_all(&dir);
}
