//! The editor driven as a user would, through egui_kittest: widgets found by role and label,
//! strokes dragged on the UV canvas and on the 3D viewport, undo checked bit-exactly, the
//! compare split and the export dialog. No GPU is needed: the viewport picks and paints on
//! the CPU and shows a placeholder where the preview would be.

use egui::accesskit::Role;
use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::viewport::{Compare, VIEWPORT_LABEL};

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

#[test]
#[expect(
    clippy::too_many_lines,
    reason = "one scripted session, step by step, as a user works"
)]
fn a_scripted_editing_session() {
    let mut harness = editor();

    // New project (Ctrl+N): the dialog offers resolution, base preset and mesh.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::N);
    harness.run();
    assert!(
        harness.state().state.new_dialog().is_some(),
        "Ctrl+N opens the New dialog"
    );
    harness.get_by_label("Width");
    harness.get_by_label("× Height");
    harness.get_by_label("Base preset");
    harness.get_by_role_and_label(Role::ComboBox, "Mesh");
    harness
        .state_mut()
        .state
        .set_new_dialog(kapaint::ui::NewDialog {
            width: 512,
            height: 512,
            preset: 0,
            mesh: "torus".into(),
        });
    harness.run();
    harness
        .get_by_role_and_label(Role::Button, "Create")
        .click();
    harness.step();
    assert!(
        harness.state().state.new_dialog().is_none(),
        "Create closes it"
    );
    // The mesh is baked on a worker; the window keeps drawing meanwhile.
    for _ in 0..500 {
        if harness.state().state.doc().maps().width() == 512 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
        harness.step();
    }
    harness.run();
    let doc = &harness.state().state.doc();
    assert_eq!(doc.maps().width(), 512);
    assert_eq!(
        doc.settings().mesh.spec(),
        "torus",
        "the project names its mesh"
    );
    assert!(doc.surface().is_some_and(|s| !s.mesh.triangles.is_empty()));
    assert!(!harness.state().state.dirty(), "nothing to save yet");
    let fresh = texels(harness.state());

    // Pick the brush as a user would: the button labelled "Brush".
    harness.get_by_label("Brush").click();
    harness.run();

    // A stroke across the middle of the UV canvas changes the maps.
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    drag(
        &mut harness,
        canvas.center() - Vec2::new(60.0, 10.0),
        canvas.center() + Vec2::new(60.0, 20.0),
    );
    let painted = texels(harness.state());
    assert_ne!(painted, fresh, "the canvas stroke changed nothing");
    assert_eq!(
        harness.state().state.doc().history().undo_steps().count(),
        1,
        "one stroke, one step"
    );
    // The history panel counts it in English: "1 step", not "1 steps".
    harness.get_by_label_contains("1 step, ");
    assert!(harness.query_by_label_contains("1 steps").is_none());

    // Undo restores the maps bit-exactly.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert!(
        texels(harness.state()) == fresh,
        "undo did not restore the maps"
    );
    // Redo brings the stroke back.
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::Z);
    harness.run();
    assert!(
        texels(harness.state()) == painted,
        "redo did not restore the stroke"
    );

    // A stroke on the sphere in the viewport (picked on the CPU).
    let viewport = harness.get_by_label(VIEWPORT_LABEL).rect();
    drag(
        &mut harness,
        viewport.center() - Vec2::new(30.0, 0.0),
        viewport.center() + Vec2::new(30.0, 10.0),
    );
    let on_mesh = texels(harness.state());
    assert_ne!(on_mesh, painted, "the viewport stroke changed nothing");
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert!(
        texels(harness.state()) == painted,
        "undo of the mesh stroke"
    );

    // Hotkeys: [ shrinks the brush, E picks the eraser.
    let radius = harness.state().state.doc().settings().brush.radius_px;
    harness.key_press(egui::Key::OpenBracket);
    harness.run();
    assert!(harness.state().state.doc().settings().brush.radius_px < radius);
    // Shift+[ and Shift+] arrive as `{` and `}` with Shift held, as egui reports them.
    let hardness = harness.state().state.doc().settings().brush.hardness;
    harness.key_press_modifiers(Modifiers::SHIFT, egui::Key::OpenCurlyBracket);
    harness.run();
    let softer = harness.state().state.doc().settings().brush.hardness;
    assert!(softer < hardness, "Shift+[ softens: {hardness} -> {softer}");
    harness.key_press_modifiers(Modifiers::SHIFT, egui::Key::CloseCurlyBracket);
    harness.run();
    let harder = harness.state().state.doc().settings().brush.hardness;
    assert!(harder > softer, "Shift+] hardens: {softer} -> {harder}");
    harness.key_press(egui::Key::E);
    harness.run();
    assert_eq!(
        harness.state().state.tools().active(),
        kapaint::tools::ToolKind::ERASER
    );

    // The built-in grain stamp shapes the brush, and Round takes it off again.
    harness.get_by_label("Grain").click();
    harness.run();
    assert!(harness.state().state.doc().settings().brush.stamp.is_some());
    harness.get_by_label("Round").click();
    harness.run();
    assert!(harness.state().state.doc().settings().brush.stamp.is_none());

    // The recent-files list keeps each project once, newest first, at most RECENT_MAX.
    let mut recent = Vec::new();
    for i in 0..12 {
        kapaint::ui::push_recent(
            &mut recent,
            std::path::Path::new(&format!("/nowhere/{i}.kapaint")),
        );
    }
    kapaint::ui::push_recent(&mut recent, std::path::Path::new("/nowhere/5.kapaint"));
    assert_eq!(recent.len(), kapaint::ui::RECENT_MAX);
    assert_eq!(recent[0], std::path::PathBuf::from("/nowhere/5.kapaint"));
    assert_eq!(
        recent.iter().filter(|p| p.ends_with("5.kapaint")).count(),
        1
    );

    // Compare: split, side by side and difference, each side with its own model.
    harness.get_by_label("Split").click();
    harness.run();
    assert_eq!(harness.state().state.comparison().mode, Compare::Split);
    harness.get_by_label("Side by side").click();
    harness.run();
    assert_eq!(harness.state().state.comparison().mode, Compare::SideBySide);
    harness.get_by_label("Difference").click();
    harness.run();
    let c = harness.state().state.comparison();
    assert_eq!(c.mode, Compare::Difference);
    assert_ne!(
        c.left.model, c.right.model,
        "Phong against Blinn-Phong by default"
    );
    assert!(harness.query_all_by_label("Heat scale").count() > 0);
    harness.get_by_label("Split").click();
    harness.run();

    // The export dialog opens from its hotkey and offers the presets. (Its preview is
    // planned on a worker thread and the dialog repaints until it arrives, so frames are
    // stepped, not run until idle: on a loaded machine that takes more than a few frames.)
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.step();
    harness.step();
    harness.get_by_role_and_label(Role::Button, "Export");
    harness.get_by_label("Preset");
    // Its preview (computed on a worker thread): the packed layout of the painted maps, the
    // memory report and the estimated k_a error.
    for _ in 0..200 {
        harness.step();
        if harness.query_by_label("Packed layout").is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    harness.get_by_label("Packed layout");
    harness.get_by_label("kd_n.png");
    harness.get_by_label_contains("Estimated k_a error");
    harness.get_by_label_contains("Memory: set");
}

#[test]
fn the_brush_outline_lies_on_the_surface_under_the_cursor() {
    use kapaint::render::Camera;
    let camera = Camera::default().orbit(0.4, 0.3);
    let picture = egui::Rect::from_min_size(Pos2::new(100.0, 50.0), Vec2::new(400.0, 300.0));
    let facing = (camera.eye() - camera.target).normalize();
    // Facing the camera, the outline is a circle around the picture's centre.
    let circle = kapaint::ui::brush_outline(&camera, picture, camera.target, facing, 0.1);
    assert_eq!(circle.len(), 48);
    let radii: Vec<f32> = circle
        .iter()
        .map(|p| p.distance(picture.center()))
        .collect();
    let (lo, hi) = radii
        .iter()
        .fold((f32::MAX, 0.0_f32), |(l, h), r| (l.min(*r), h.max(*r)));
    assert!(lo > 5.0 && hi / lo < 1.02, "a circle: radii {lo}..{hi}");
    // Seen edge-on (normal across the view), it flattens into a thin ellipse.
    let across = facing.cross(glam::Vec3::Y).normalize();
    let edge = kapaint::ui::brush_outline(&camera, picture, camera.target, across, 0.1);
    let spread = |f: fn(&Pos2) -> f32, pts: &[Pos2]| {
        let v: Vec<f32> = pts.iter().map(f).collect();
        v.iter().copied().fold(f32::MIN, f32::max) - v.iter().copied().fold(f32::MAX, f32::min)
    };
    let (wide, tall) = (spread(|p| p.x, &edge), spread(|p| p.y, &edge));
    assert!(
        wide.min(tall) < 0.2 * wide.max(tall),
        "edge-on: {wide} x {tall}"
    );
}

#[test]
fn pen_pressure_scales_the_dab() {
    let mut harness = editor();
    assert!(harness.state().state.doc().settings().brush.pressure_size);
    let fresh = texels(harness.state());
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    let dab = |harness: &mut Harness<'_, Editor>, force: Option<f32>| {
        harness.hover_at(centre);
        harness.run();
        if let Some(force) = force {
            harness.event(egui::Event::Touch {
                device_id: egui::TouchDeviceId(1),
                id: egui::TouchId(1),
                phase: egui::TouchPhase::Move,
                pos: centre,
                force: Some(force),
            });
        }
        harness.drag_at(centre);
        harness.run();
        harness.drop_at(centre);
        harness.run();
    };
    // A mouse paints at full pressure.
    dab(&mut harness, None);
    let full = changed(&fresh, &texels(harness.state()));
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(texels(harness.state()), fresh, "undone");
    // A pen pressed lightly paints a smaller dab.
    dab(&mut harness, Some(0.3));
    let light = changed(&fresh, &texels(harness.state()));
    assert!(full > 0 && light > 0, "both dabs paint: {full}, {light}");
    assert!(
        light * 3 < full,
        "pressure 0.3 covers less: {light} of {full} texels"
    );
}

#[test]
fn opening_another_project_never_drops_unsaved_work() {
    let mut harness = editor();
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 10.0));
    assert!(harness.state().state.dirty(), "painted");
    let painted = texels(harness.state());
    let elsewhere = std::path::PathBuf::from("/nowhere/other.kapaint");
    harness.state_mut().state.open(elsewhere.clone());
    harness.run();
    assert_eq!(
        harness.state().state.pending_open(),
        Some(elsewhere.as_path())
    );
    harness.get_by_label("Discard and open");
    harness.get_by_label("Save, then open");
    harness.get_by_label("Cancel").click();
    harness.run();
    assert_eq!(harness.state().state.pending_open(), None);
    assert_eq!(texels(harness.state()), painted, "the work is still there");
}

#[test]
fn a_settings_change_is_unsaved_work() {
    let mut harness = editor();
    assert!(!harness.state().state.dirty(), "a fresh document");
    // Switch the shading model: no texel changes, but the project stores the model.
    harness.get_by_label("Blinn-Phong (11)").click();
    harness.run();
    assert_eq!(
        harness.state().state.doc().settings().model,
        kapaint::reflectance::ShadingModel::BlinnPhong
    );
    assert!(
        harness.state().state.dirty(),
        "a changed setting must count as unsaved"
    );
    // So opening another project asks first.
    let elsewhere = std::path::PathBuf::from("/nowhere/other.kapaint");
    harness.state_mut().state.open(elsewhere.clone());
    harness.run();
    assert_eq!(
        harness.state().state.pending_open(),
        Some(elsewhere.as_path())
    );
    harness.get_by_label("Discard and open");
}

#[test]
fn escape_abandons_a_stroke_under_way() {
    let mut harness = editor();
    let before = texels(harness.state());
    let a = harness.get_by_label(CANVAS_LABEL).rect().center();
    let b = a + Vec2::new(60.0, 20.0);
    harness.hover_at(a);
    harness.run();
    harness.drag_at(a);
    harness.run();
    for i in 1..=6 {
        harness.hover_at(a + (b - a) * (i as f32 / 6.0));
        harness.run();
    }
    assert_ne!(texels(harness.state()), before, "painting");
    harness.key_press(egui::Key::Escape);
    harness.run();
    assert_eq!(texels(harness.state()), before, "Escape undid the stroke");
    harness.drop_at(b);
    harness.run();
    assert_eq!(
        texels(harness.state()),
        before,
        "and the release adds nothing"
    );
    assert_eq!(
        harness.state().state.doc().history().undo_steps().count(),
        0
    );
}

#[test]
fn a_gradient_dragged_in_the_viewport_lays_a_gradient() {
    let mut harness = editor();
    let primary = harness.state().state.doc().settings().primary;
    let before = texels(harness.state());
    harness.get_by_label("Gradient").click();
    harness.run();
    // Its options: linear or radial.
    harness.get_by_label("Radial");
    let viewport = harness.get_by_label(VIEWPORT_LABEL).rect();
    drag(
        &mut harness,
        viewport.center() - Vec2::new(40.0, 0.0),
        viewport.center() + Vec2::new(40.0, 10.0),
    );
    assert_ne!(texels(harness.state()), before, "a gradient was laid");
    assert_eq!(
        harness.state().state.doc().settings().primary,
        primary,
        "not a pick"
    );
}

#[test]
fn every_tool_and_its_options_are_in_the_panel() {
    let mut harness = editor();
    for tool in kapaint::tools::Tools::all() {
        harness.get_by_label(tool.label).click();
        harness.run();
        assert_eq!(harness.state().state.tools().active(), tool.kind);
    }
    harness.get_by_label("Blur").click();
    harness.run();
    assert!(harness.query_all_by_label("Blur radius").count() > 0);
    harness.get_by_label("Fill").click();
    harness.run();
    // The tool's button and its mode's combo box.
    assert_eq!(harness.query_all_by_label("Fill").count(), 2);
    // The stroke's options, each changing the brush it names.
    harness.get_by_label("Brush").click();
    harness.run();
    let brush = |h: &Harness<'_, Editor>| h.state().state.doc().settings().brush.clone();
    for (label, on) in [
        (
            "U",
            (|b| b.mirror_u) as fn(&kapaint::model::brush::BrushSettings) -> bool,
        ),
        ("V", |b| b.mirror_v),
        ("X", |b| b.mirror_x),
        ("Y", |b| b.mirror_y),
        ("Z", |b| b.mirror_z),
        ("Front faces only", |b| b.front_faces_only),
    ] {
        let before = on(&brush(&harness));
        harness.get_by_role_and_label(Role::CheckBox, label).click();
        harness.run();
        assert_ne!(on(&brush(&harness)), before, "{label}");
    }
    assert!(harness.query_all_by_label("Lazy mouse").count() > 0);
    harness.get_by_label("Blend").click();
    harness.run();
    harness.get_by_label("Multiply").click();
    harness.run();
    assert_eq!(
        brush(&harness).blend,
        kapaint::model::brush::BlendMode::Multiply
    );
}

#[test]
fn f1_opens_the_shortcut_sheet() {
    let mut harness = editor();
    harness.key_press(egui::Key::F1);
    harness.run();
    harness.get_by_label("Keyboard shortcuts");
    harness.get_by_label("keyboard shortcuts (this sheet)");
    // Keys as the keyboard prints them: `[` and `]` for the brush size, never egui's names.
    harness.get_by_label("[");
    harness.get_by_label("]");
    for name in ["OpenBracket", "CloseBracket"] {
        assert!(
            harness.query_all_by_label_contains(name).next().is_none(),
            "the sheet says {name}"
        );
    }
}

#[test]
fn the_shortcut_sheet_shows_the_keymap_the_keys_run() {
    let mut harness = editor();
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("Keyboard shortcuts").click();
    harness.run();
    for binding in kapaint::ui::keys::keymap() {
        assert!(
            harness.query_all_by_label(binding.description).count() > 0,
            "the sheet lacks {}",
            binding.description
        );
    }
    // And the keys do what the sheet says: R makes the blur tool active.
    harness.key_press(egui::Key::R);
    harness.run();
    assert_eq!(
        harness.state().state.tools().active(),
        kapaint::tools::ToolKind::BLUR
    );
}

/// With the cursor over the canvas the status bar shows `k_a` by the exact integral, but the
/// UI thread (here, the test's) never runs the integrator (45 to 320 ms a value): a worker
/// does, and the value shows when it arrives.
#[test]
fn the_exact_readout_never_integrates_on_the_ui_thread() {
    let mut harness = editor();
    let before = kapaint::reflectance::exact::calls_on_this_thread();
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    for k in 0..6 {
        harness.hover_at(canvas.center() + Vec2::new(k as f32 * 7.0, 3.0));
        harness.run();
    }
    assert_eq!(
        kapaint::reflectance::exact::calls_on_this_thread(),
        before,
        "a frame ran the exact integrator on the UI thread"
    );
    // The worker's value arrives within seconds and is shown.
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness.query_by_label_contains("exact 0.").is_none() {
        assert!(
            std::time::Instant::now() < deadline,
            "the exact value never arrived"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.run();
    }
    assert_eq!(kapaint::reflectance::exact::calls_on_this_thread(), before);
}

/// The window title names the project and marks unsaved work.
#[test]
fn the_title_names_the_project_and_marks_unsaved_work() {
    let mut harness = editor();
    assert_eq!(harness.state().state.window_title(), "untitled - kapaint");
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    drag(
        &mut harness,
        canvas.center() - Vec2::new(40.0, 0.0),
        canvas.center() + Vec2::new(40.0, 5.0),
    );
    assert_eq!(harness.state().state.window_title(), "untitled* - kapaint");
}

/// Dialogs open in the middle of the window, not at the top left over the tools.
#[test]
fn dialogs_open_centred() {
    let mut harness = editor();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::N);
    harness.run();
    harness.run();
    let title = harness.get_by_label("New project").rect();
    assert!(
        (title.center().x - 700.0).abs() < 120.0 && title.top() > 150.0,
        "the New dialog's title is at {title:?} in a 1400 x 900 window"
    );
}

/// Every pointer event of a frame is painted: a quick curved stroke whose events all arrive
/// in one frame paints the same texels as the same events spread over a frame each (egui
/// delivers several moves a frame when painting is slower than the mouse), the tail up to
/// the release point included.
#[test]
fn a_stroke_of_many_events_in_one_frame_paints_as_if_spread_over_many() {
    let path = |canvas: egui::Rect| -> Vec<Pos2> {
        // A half circle: one pointer position per frame would cut it to a straight line.
        (0..=36)
            .map(|k| {
                let t = std::f32::consts::PI * k as f32 / 36.0;
                canvas.center() + Vec2::new(-80.0 * t.cos(), -60.0 * t.sin())
            })
            .collect()
    };
    let paint = |one_frame: bool| {
        let mut harness = editor();
        let canvas = harness.get_by_label(CANVAS_LABEL).rect();
        let points = path(canvas);
        harness.hover_at(points[0]);
        harness.run();
        let events = std::iter::once(egui::Event::PointerButton {
            pos: points[0],
            button: egui::PointerButton::Primary,
            pressed: true,
            modifiers: Modifiers::NONE,
        })
        .chain(points[1..].iter().map(|p| egui::Event::PointerMoved(*p)))
        .chain(std::iter::once(egui::Event::PointerButton {
            pos: points[36],
            button: egui::PointerButton::Primary,
            pressed: false,
            modifiers: Modifiers::NONE,
        }));
        for event in events {
            harness.input_mut().events.push(event);
            if !one_frame {
                harness.step();
            }
        }
        harness.run();
        assert_eq!(
            harness.state().state.doc().history().undo_steps().count(),
            1,
            "one stroke, one step"
        );
        texels(harness.state())
    };
    let spread = paint(false);
    let at_once = paint(true);
    assert!(
        spread != texels(&Editor::new(None, None)),
        "nothing painted"
    );
    assert!(
        at_once == spread,
        "one frame of events painted other texels"
    );
}

/// Exporting into a folder that holds a set asks to replace it (the dialog stays, with its
/// choices), replaces it on Replace, and the next export offers the same folder again.
#[test]
fn exporting_over_a_set_asks_then_replaces_and_keeps_the_choices() {
    let dir = std::env::temp_dir().join(format!("kapaint-replace-ui-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("set");
    let small = kapaint::model::Document::new(8, 8, kapaint::model::DocumentSettings::default())
        .expect("document");
    let separate = kapaint::export::preset::find("separate").expect("preset");
    kapaint::export::set::export(&small, &separate, &out).expect("a set is there");
    let folder = out.display().to_string();
    let folder_field = |harness: &Harness<'_, Editor>| {
        harness
            .get_all_by_role(Role::TextInput)
            .filter_map(|n| n.value())
            .collect::<Vec<_>>()
    };

    let mut harness = editor();
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.step();
    harness.step();
    kit::type_export_folder(&mut harness, &folder);
    assert!(
        folder_field(&harness).contains(&folder),
        "{:?}",
        folder_field(&harness)
    );
    harness
        .get_by_role_and_label(Role::Button, "Export")
        .click();
    harness.step();
    harness.step();
    // Asked, not refused: the dialog is still there.
    harness.get_by_label_contains("holds an exported set already");
    harness
        .get_by_role_and_label(Role::Button, "Replace")
        .click();
    harness.step();
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while !harness
        .state()
        .state
        .notices()
        .iter()
        .any(|n| n.text.starts_with("exported"))
    {
        assert!(
            std::time::Instant::now() < deadline,
            "no export: {:?}",
            harness
                .state()
                .state
                .notices()
                .iter()
                .map(|n| n.text.clone())
                .collect::<Vec<_>>()
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
    let manifest = std::fs::read_to_string(out.join("material.json")).expect("manifest");
    assert!(
        manifest.contains("\"width\": 1024"),
        "the new set replaced the old"
    );
    // The next export offers the same folder.
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.step();
    harness.step();
    assert!(
        folder_field(&harness).contains(&folder),
        "{:?}",
        folder_field(&harness)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The preset thumbnails follow the mesh: after opening a project on another mesh they are
/// drawn again on it (they kept the old mesh).
#[test]
fn preset_thumbnails_follow_the_mesh() {
    let dir = std::env::temp_dir().join(format!("kapaint-thumbs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("cube.kapaint");
    let settings = kapaint::model::DocumentSettings {
        mesh: kapaint::model::document::MeshRef::from_spec("cube"),
        ..kapaint::model::DocumentSettings::default()
    };
    let doc = kapaint::model::Document::new(64, 64, settings).expect("document");
    kapaint::model::project::save(&doc, &path).expect("save");

    let mut harness = editor();
    let current = |h: &Harness<'_, Editor>| {
        let (shown, mesh) = h.state().state.thumbnail_meshes();
        shown.iter().all(|s| *s == Some(mesh))
    };
    for _ in 0..40 {
        if current(&harness) {
            break;
        }
        harness.step();
    }
    assert!(current(&harness), "every thumbnail drawn");
    let (_, before) = harness.state().state.thumbnail_meshes();
    harness.state_mut().state.open(path);
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness.state().state.thumbnail_meshes().1 == before || !current(&harness) {
        assert!(
            std::time::Instant::now() < deadline,
            "the cube never arrived"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
        harness.step();
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_export_dialog_says_a_block_compressed_layout_is_chosen_at_export() {
    let mut harness = editor();
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.step();
    harness.step();
    harness
        .get_by_role_and_label(Role::ComboBox, "Preset")
        .click();
    harness.step();
    harness.get_by_label("ktx2").click();
    harness.step();
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness
        .query_by_label_contains("chosen at export by the measured k_a error")
        .is_none()
    {
        assert!(
            std::time::Instant::now() < deadline,
            "the ktx2 preview never said how blocks are chosen"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
    harness.get_by_label_contains("then n apart, then n apart with colour as BC6H");
}
