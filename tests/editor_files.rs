//! The editor's files, driven through egui_kittest: saving and opening through kapaint's own
//! file dialog where no desktop portal runs, every file request reaching its command, and a
//! project named at start opening on a worker.

use egui::accesskit::Role;
use egui::{Modifiers, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::files::{FileDialogBackend, FilePurpose, FileRequest};

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

#[test]
fn untitled_work_is_saved_through_the_in_app_file_dialog() {
    let dir = scratch("save-dialog");
    let mut harness = editor_without_portal(&dir);
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::S);
    harness.run();
    assert_eq!(
        harness.state().state.file_dialog_open_for(),
        Some(FilePurpose::SaveProject),
        "Ctrl+S on an untitled project asks where"
    );
    harness.get_by_label_contains("Save project");
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.step();
    let saved = dir.join("material.kapaint");
    wait_until(&mut harness, "saved", |e| !e.state.dirty());
    assert_eq!(harness.state().state.path(), Some(saved.as_path()));
    assert_eq!(
        harness.state().state.window_title(),
        "material.kapaint - kapaint"
    );
    let doc = kapaint::model::project::load(&saved).expect("the saved project loads");
    assert_eq!(
        doc.maps().uniform_texel(),
        None,
        "the stroke is in the saved file"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_quit_prompt_saves_untitled_work_then_closes() {
    let dir = scratch("quit-dialog");
    let mut harness = editor_without_portal(&dir);
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    harness.get_by_label("The material has unsaved changes.");
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.run_steps(2);
    assert!(!harness.state().state.closing(), "not before it is saved");
    harness.get_by_label_contains("Save project");
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.step();
    wait_until(&mut harness, "saved, then closing", |e| e.state.closing());
    assert!(dir.join("material.kapaint").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_project_opens_through_the_in_app_file_dialog() {
    let dir = scratch("open-dialog");
    let project = dir.join("other.kapaint");
    let doc = kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
        .expect("document");
    kapaint::model::project::save(&doc, &project).expect("saved");
    let mut harness = editor_without_portal(&dir);
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::O);
    harness.run();
    harness.get_by_label_contains("Open project");
    harness.get_by_label_contains("other.kapaint").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "Open").click();
    // The project opens as a job (a spinner repaints until it is done): stepped until it
    // is, not run to a still frame within a fixed count (a busy machine took longer).
    harness.step();
    wait_until(&mut harness, "opened", |e| {
        e.state.path() == Some(project.as_path())
    });
    assert_eq!(harness.state().state.doc().maps().width(), 64);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every place that asks for a file gets its answer: Import mesh, Import image, the brush
/// stamp's Load, New > File and the export folder (answered here by a stand-in for the
/// system dialog).
#[test]
fn every_file_request_reaches_its_command() {
    fn answer(request: &FileRequest) -> Option<std::path::PathBuf> {
        let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot");
        Some(match request.purpose {
            FilePurpose::ImportMesh
            | FilePurpose::NewMesh
            | FilePurpose::HighMesh
            | FilePurpose::Cage => spot.join("spot_triangulated.obj"),
            FilePurpose::ImportImage(_)
            | FilePurpose::StampImage
            | FilePurpose::ToolImage
            | FilePurpose::StencilImage
            | FilePurpose::ProjectImage => spot.join("spot_texture.png"),
            FilePurpose::ExportFolder => std::env::temp_dir().join("kapaint-export-choice"),
            FilePurpose::OpenProject | FilePurpose::SaveProject | FilePurpose::ImportPbr => {
                return None;
            }
        })
    }
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);
    let notice = |text: &'static str| {
        move |e: &Editor| e.state.notices().iter().any(|n| n.text.contains(text))
    };

    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Import mesh…").click();
    harness.run_steps(2);
    wait_until(
        &mut harness,
        "mesh imported",
        notice("spot_triangulated.obj"),
    );

    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness
        .get_by_label_contains("Import image into k_s")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "image imported", notice("imported into k_s"));

    harness.key_press(egui::Key::B);
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::Button, "Load…").click();
    harness.run_steps(2);
    wait_until(&mut harness, "stamp loaded", notice("stamp "));

    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::N);
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::Button, "File…").click();
    harness.run_steps(2);
    wait_until(&mut harness, "mesh chosen for New", |e| {
        e.state
            .new_dialog()
            .is_some_and(|d| d.mesh.ends_with("spot_triangulated.obj"))
    });

    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::Button, "…").click();
    harness.run_steps(2);
    // A folder that is not there yet: the set goes into it.
    let chosen = std::env::temp_dir()
        .join("kapaint-export-choice")
        .display()
        .to_string();
    wait_until(&mut harness, "export folder chosen", |e| {
        e.state.export_folder() == Some(chosen.as_str())
    });
}

#[test]
fn a_project_named_at_start_opens_on_a_worker_and_takes_no_strokes_meanwhile() {
    let dir = scratch("open-at-start");
    let project = dir.join("big.kapaint");
    let saved = noisy_project(&project);
    // The editor is there at once, on an untitled placeholder (nothing can be saved over the
    // file), with the project opening on a worker.
    let editor = Editor::new(None, Some(project.clone()));
    assert_eq!(editor.state.opening(), Some(project.as_path()));
    assert_eq!(editor.state.path(), None);
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .with_max_steps(1)
        .build_ui_state(|ui, editor: &mut Editor| editor.frame(ui), editor);
    if harness.state().state.opening().is_some() {
        harness.get_by_label("Opening big.kapaint…");
        // A stroke on the document about to be replaced is refused, not painted and lost.
        let before = harness.state().state.doc().version();
        let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
        harness.drag_at(centre);
        harness.step();
        harness.hover_at(centre + Vec2::new(60.0, 20.0));
        harness.step();
        harness.drop_at(centre + Vec2::new(60.0, 20.0));
        harness.step();
        if harness.state().state.opening().is_some() {
            assert_eq!(harness.state().state.doc().version(), before);
        }
    } else {
        eprintln!("the project opened within a frame: the refusal was not exercised");
    }
    wait_until(&mut harness, "opened", |e| {
        e.state.path() == Some(project.as_path())
    });
    assert!(!harness.state().state.dirty());
    let mut want = Vec::new();
    saved.maps().for_each_texel(|_, _, t| want.push(t));
    assert!(texels(harness.state()) == want, "the project as saved");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_recovery_offer_at_start_takes_no_strokes_or_keys_meanwhile() {
    use kapaint::model::recovery::Autosaver;
    let dir = scratch("recovery-modal");
    let project = dir.join("work.kapaint");
    let mut doc =
        kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
            .expect("document");
    kapaint::model::project::save(&doc, &project).expect("saved");
    std::thread::sleep(std::time::Duration::from_millis(20));
    // Unsaved work since: a fill, in a recovery copy newer than the project.
    let mut autosaver = Autosaver::new(std::time::Duration::ZERO, Some(&project), &doc);
    doc.apply(kapaint::model::PaintCommand::Fill(
        kapaint::model::FillRegion::All,
    ))
    .expect("fill");
    let _ = autosaver.poll(&doc, std::time::Instant::now());
    autosaver.wait().expect("autosaved").expect("written");
    // Left by an editor that was killed.
    as_ended(&autosaver.session());
    let mut harness = editor_on(&project);
    harness.get_by_label_contains("found a recovery copy");
    let version = harness.state().state.doc().version();
    // A stroke on the canvas and Ctrl+S while the offer is up change nothing.
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::S);
    harness.run();
    assert_eq!(
        harness.state().state.doc().version(),
        version,
        "the placeholder took input"
    );
    assert_eq!(harness.state().state.file_dialog_open_for(), None);
    // Recover: the project comes back with the fill.
    harness
        .get_by_role_and_label(Role::Button, "Recover")
        .click();
    // The recovery runs on a worker behind a spinner: a few frames, then wait for it (a
    // `run()` here failed its 40 steps when the machine was busy).
    harness.run_steps(2);
    wait_until(&mut harness, "recovered", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 64
    });
    assert_eq!(
        harness.state().state.doc().maps().value(3, 3),
        doc.maps().value(3, 3)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_export_goes_into_the_folder_chosen_unless_it_holds_other_things() {
    use kapaint::export::set::SetKind;
    use kapaint::ui::export_folder_in;
    let dir = scratch("export-folder-choice");
    let kind = SetKind::Material;
    assert_eq!(
        export_folder_in(&dir, kind),
        dir,
        "an empty folder takes the set"
    );
    std::fs::write(dir.join("notes.txt"), "mine").expect("write");
    assert_eq!(
        export_folder_in(&dir, kind),
        dir.join("set"),
        "never over other files"
    );
    let set = dir.join("old-set");
    std::fs::create_dir(&set).expect("folder");
    std::fs::write(
        set.join("material.json"),
        r#"{"format": "kapaint-material", "files": [{"path": "kd.png"}]}"#,
    )
    .expect("write");
    std::fs::write(set.join("kd.png"), "png").expect("write");
    assert_eq!(
        export_folder_in(&set, kind),
        set,
        "a set is replaced after the prompt"
    );
    assert_eq!(
        export_folder_in(&set, SetKind::Pbr),
        set.join("set"),
        "never a set of another kind"
    );
    std::fs::write(set.join("notes.txt"), "mine").expect("write");
    assert_eq!(
        export_folder_in(&set, kind),
        set.join("set"),
        "never a set beside files no export wrote"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_first_save_of_untitled_work_takes_its_recovery_copy_along() {
    use kapaint::model::recovery;
    let dir = scratch("first-save-recovery");
    let mut harness = editor_without_portal(&dir);
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness
        .state_mut()
        .state
        .autosave_now()
        .expect("the untitled copy");
    let untitled = harness.state().state.recovery_copy();
    assert!(untitled.exists());
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::S);
    harness.run();
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.step();
    let saved = dir.join("material.kapaint");
    wait_until(&mut harness, "saved", |e| !e.state.dirty());
    // A second stroke, autosaved: its copy is the project's now, the untitled one is gone.
    drag(
        &mut harness,
        centre + Vec2::new(0.0, 60.0),
        centre + Vec2::new(40.0, 70.0),
    );
    assert!(harness.state().state.dirty(), "the second stroke painted");
    harness.state_mut().state.autosave_now().expect("autosaved");
    let copy = harness.state().state.recovery_copy();
    assert_eq!(
        copy.parent(),
        Some(recovery::recovery_path(Some(&saved)).as_path())
    );
    assert!(!untitled.exists(), "the untitled copy was left behind");
    // Killed now: `kapaint edit material.kapaint` offers the second stroke back.
    let want = texels(harness.state());
    drop(harness);
    let ended = as_ended(&copy);
    assert_eq!(recovery::offer(Some(&saved)), Some(ended.clone()));
    let back = recovery::load(&ended).expect("recovered");
    let mut got = Vec::new();
    back.maps().for_each_texel(|_, _, t| got.push(t));
    assert!(got == want, "the recovered copy is the work as it was");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A save makes the work safe: the recovery copy written before it goes, and no copy is
/// written after it until the work changes again, so a kill after Ctrl+S offers nothing (an
/// autosave falling due after the save used to leave a copy newer than the project, offered
/// at the next start as unsaved work).
#[test]
fn a_saved_project_leaves_no_recovery_copy_to_offer() {
    use kapaint::model::recovery;
    let dir = scratch("saved-no-offer");
    let path = dir.join("saved.kapaint");
    let doc = kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
        .expect("document");
    kapaint::model::project::save(&doc, &path).expect("saved");
    let mut harness = editor_on(&path);
    wait_until(&mut harness, "opened", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 64
    });
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness.state_mut().state.autosave_now().expect("autosaved");
    let copy = harness.state().state.recovery_copy();
    assert!(copy.exists(), "the stroke's copy");
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::S);
    harness.run();
    wait_until(&mut harness, "saved", |e| !e.state.dirty());
    assert!(!copy.exists(), "the copy of saved work was kept");
    // The autosave that falls due next finds nothing to protect.
    harness.state_mut().state.autosave_now().expect("autosaved");
    assert!(!harness.state().state.recovery_copy().exists());
    drop(harness);
    assert_eq!(recovery::offer(Some(&path)), None);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn save_as_moves_the_recovery_copy_to_the_new_project() {
    use kapaint::model::recovery;
    let dir = scratch("save-as-recovery");
    let (a, b) = (dir.join("A.kapaint"), dir.join("B.kapaint"));
    let doc = kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
        .expect("document");
    kapaint::model::project::save(&doc, &a).expect("saved");
    let mut harness = editor_on(&a);
    wait_until(&mut harness, "opened", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 64
    });
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    harness.state_mut().state.autosave_now().expect("autosaved");
    harness.state_mut().state.save_to(b.clone());
    wait_until(&mut harness, "saved as B", |e| !e.state.dirty());
    drag(
        &mut harness,
        centre + Vec2::new(0.0, 60.0),
        centre + Vec2::new(40.0, 70.0),
    );
    assert!(harness.state().state.dirty(), "the second stroke painted");
    harness.state_mut().state.autosave_now().expect("autosaved");
    let copy = harness.state().state.recovery_copy();
    assert_eq!(
        copy.parent(),
        Some(recovery::recovery_path(Some(&b)).as_path())
    );
    drop(harness);
    let ended = as_ended(&copy);
    // `kapaint edit A` offers nothing (B's work is not A's); `edit B` offers it.
    assert_eq!(recovery::offer(Some(&a)), None);
    assert!(!recovery::recovery_path(Some(&a)).exists());
    assert_eq!(recovery::offer(Some(&b)), Some(ended));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_layered_project_opens_clean_on_its_saved_selection() {
    use kapaint::model::{LayerCommand, MaskCommand, PaintCommand};
    use kapaint::model::{LayerKind, LayerRef};
    let dir = scratch("layered-clean");
    let project = dir.join("layered.kapaint");
    let mut doc =
        kapaint::model::Document::new(128, 128, kapaint::model::DocumentSettings::default())
            .expect("document");
    doc.apply(PaintCommand::Fill(kapaint::model::FillRegion::All))
        .expect("fill");
    doc.apply(LayerCommand::AddLayer {
        kind: LayerKind::Paint,
        name: "Scratches".into(),
    })
    .expect("layer");
    doc.apply(MaskCommand::AddMask).expect("mask");
    doc.apply(LayerCommand::AddLayer {
        kind: LayerKind::Group,
        name: "Folder".into(),
    })
    .expect("group");
    // Saved with "Scratches" selected (a group sits above it).
    doc.apply(LayerCommand::SelectLayer(LayerRef::Name(
        "Scratches".into(),
    )))
    .expect("select");
    kapaint::model::project::save(&doc, &project).expect("saved");
    let mut harness = editor_on(&project);
    wait_until(&mut harness, "opened", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 128
    });
    harness.run();
    let s = &harness.state().state;
    assert!(!s.dirty(), "a project opened and not changed is clean");
    assert_eq!(s.window_title(), "layered.kapaint - kapaint");
    let selected = s
        .doc()
        .stack()
        .layer(&s.doc().selection().path)
        .expect("a layer");
    assert_eq!(selected.props.name, "Scratches", "the saved selection");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Layers list is right from the first frame after an open: each paint layer shows the
/// memory its tiles hold (it showed 0.0 MB, a blank thumbnail and a group icon until the layer
/// was edited: the opened document's version equalled the one before, so the list kept what it
/// had made of that one).
#[test]
fn the_layers_list_is_right_from_the_first_frame_after_an_open() {
    use kapaint::model::{LayerCommand, LayerKind, PaintCommand};
    let dir = scratch("layers-after-open");
    let project = dir.join("painted.kapaint");
    let mut doc =
        kapaint::model::Document::new(512, 512, kapaint::model::DocumentSettings::default())
            .expect("document");
    doc.apply(LayerCommand::AddLayer {
        kind: LayerKind::Paint,
        name: "Rust".into(),
    })
    .expect("layer");
    // A gradient: every tile of its own (a flat fill is kept as uniform tiles of no size).
    doc.apply(PaintCommand::Gradient {
        shape: kapaint::model::paint::GradientShape::Linear,
        start: glam::Vec2::ZERO,
        end: glam::Vec2::splat(512.0),
    })
    .expect("gradient");
    kapaint::model::project::save(&doc, &project).expect("saved");
    let opened = kapaint::model::project::load(&project).expect("loads");
    let rust = opened
        .stack()
        .walk()
        .into_iter()
        .find(|(_, l)| l.props.name == "Rust")
        .map(|(_, l)| l.heap_bytes())
        .expect("the layer");
    let shown = format!("{:.1} MB", rust as f64 / 1e6);
    assert_ne!(shown, "0.0 MB", "the layer holds paint");

    let mut harness = editor_on(&project);
    wait_until(&mut harness, "opened", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 512
    });
    harness.step();
    assert!(
        harness.query_all_by_label(&shown).next().is_some(),
        "the Layers list shows {shown} for the painted layer"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_project_another_kapaint_has_open_asks_and_opens_read_only() {
    use kapaint::model::recovery::session::Owner;
    let dir = scratch("in-use");
    let project = dir.join("shared.kapaint");
    let doc = kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
        .expect("document");
    kapaint::model::project::save(&doc, &project).expect("saved");
    // Another editor's lock: process 1 runs on every Linux machine.
    if !std::path::Path::new("/proc/1").exists() {
        eprintln!("SKIPPED: this system does not say which processes run");
        return;
    }
    let other = Owner {
        pid: 1,
        start: 0,
        ..Owner::this_process().clone()
    };
    std::fs::write(dir.join(".shared.kapaint.lock"), other.file_name()).expect("lock");
    let mut harness = editor_on(&project);
    harness.get_by_label_contains("is open in another kapaint");
    harness
        .get_by_role_and_label(Role::Button, "Open read-only")
        .click();
    harness.step();
    wait_until(&mut harness, "opened", |e| {
        e.state.opening().is_none() && e.state.doc().maps().width() == 64
    });
    assert_eq!(
        harness.state().state.window_title(),
        "shared.kapaint [read-only] - kapaint"
    );
    // Save asks for another file: the other editor's project is never written.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::S);
    harness.run();
    assert_eq!(
        harness.state().state.file_dialog_open_for(),
        Some(FilePurpose::SaveProject)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// File > New with unsaved changes offers "Save, then create": the work is saved to its
/// project, then the new project (of any width and height, not only square) replaces it.
#[test]
fn new_offers_save_then_create_and_any_width_and_height() {
    let dir = scratch("save-then-new");
    let path = dir.join("work.kapaint");
    let doc = kapaint::model::Document::new(64, 64, kapaint::model::DocumentSettings::default())
        .expect("doc");
    kapaint::model::project::save(&doc, &path).expect("saved");
    let mut harness = editor_on(&path);
    wait_until(&mut harness, "opened", |e| {
        e.state.path() == Some(path.as_path())
    });
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::N);
    harness.run();
    assert!(harness.state().state.dirty(), "a layer added");
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::N);
    harness.run();
    harness
        .state_mut()
        .state
        .set_new_dialog(kapaint::ui::NewDialog {
            width: 512,
            height: 256,
            preset: 0,
            mesh: "sphere".into(),
        });
    harness.run();
    harness
        .get_by_role_and_label(Role::Button, "Save, then create")
        .click();
    harness.step();
    wait_until(&mut harness, "saved and created", |e| {
        let maps = e.state.doc().maps();
        (maps.width(), maps.height()) == (512, 256)
    });
    let saved = kapaint::model::project::load(&path).expect("loads");
    assert_eq!(
        saved.stack().layers.len(),
        2,
        "the added layer was saved first"
    );
    assert!(!harness.state().state.dirty());
}
