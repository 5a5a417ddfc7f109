//! The editor driven as a user would, through egui_kittest: widgets found by role and label,
//! strokes dragged on the UV canvas and on the 3D viewport, undo checked bit-exactly, the
//! compare split and the export dialog. No GPU is needed: the viewport picks and paints on
//! the CPU and shows a placeholder where the preview would be.

use egui::accesskit::Role;
use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::model::texel::Texel;
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::files::{FileDialogBackend, FilePurpose, FileRequest};
use kapaint::ui::viewport::{Compare, VIEWPORT_LABEL};

fn texels(editor: &Editor) -> Vec<Texel> {
    let maps = editor.state.doc().maps();
    let mut out = Vec::with_capacity(maps.texel_count());
    maps.for_each_texel(|_, _, t| out.push(t));
    out
}

/// The editor on a new default document in a 1400 x 900 window, its first frame drawn.
fn editor() -> Harness<'static, Editor> {
    // The status bar's exact value arrives from a worker whenever it is done and asks for a
    // frame then: a few more steps than a UI that only reacts to input.
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .with_max_steps(16)
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, None),
        );
    harness.run();
    harness
}

/// Drags the primary button from `a` to `b` in steps, a frame per step.
fn drag(harness: &mut Harness<'_, Editor>, a: Pos2, b: Pos2) {
    harness.hover_at(a);
    harness.run();
    harness.drag_at(a);
    harness.run();
    for i in 1..=8 {
        harness.hover_at(a + (b - a) * (i as f32 / 8.0));
        harness.run();
    }
    harness.drop_at(b);
    harness.run();
}

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
    harness.get_by_label("Resolution");
    harness.get_by_label("Base preset");
    harness.get_by_label("Mesh");
    harness
        .state_mut()
        .state
        .set_new_dialog(kapaint::ui::NewDialog {
            size: 512,
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
        kapaint::tools::ToolKind::Eraser
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
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
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

/// Texels that differ between two snapshots of the maps.
fn changed(a: &[Texel], b: &[Texel]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
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
    for kind in kapaint::tools::ToolKind::ALL {
        harness.get_by_label(kind.label()).click();
        harness.run();
        assert_eq!(harness.state().state.tools().active(), kind);
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
}

#[test]
fn the_shortcut_sheet_shows_the_keymap_the_keys_run() {
    let mut harness = editor();
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("Keyboard shortcuts").click();
    harness.run();
    for binding in kapaint::ui::keys::KEYMAP {
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
        kapaint::tools::ToolKind::Blur
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

/// The light's yaw and pitch are shown and edited in degrees.
#[test]
fn light_angles_are_in_degrees() {
    let harness = editor();
    let l = kapaint::render::Lighting::default().light.normalize();
    let (yaw, pitch) = (
        f64::from(l.x.atan2(l.z).to_degrees()),
        f64::from(l.y.asin().to_degrees()),
    );
    assert!(yaw.abs() > 5.0 && pitch.abs() > 5.0, "{yaw} {pitch}");
    let values: Vec<f64> = harness
        .get_all_by_role(Role::Slider)
        .filter_map(|n| egui_kittest::kittest::NodeT::accesskit_node(&n).numeric_value())
        .collect();
    for angle in [yaw, pitch] {
        assert!(
            values.iter().any(|v| (v - angle).abs() < 0.05),
            "no slider shows {angle} degrees: {values:?}"
        );
    }
}

/// Home fits the map in the UV canvas again after zooming (F stays the fill tool).
#[test]
fn home_fits_the_canvas() {
    let mut harness = editor();
    let fitted = harness.state().state.canvas_zoom();
    assert!(fitted > 0.0);
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    harness.hover_at(canvas.center() + Vec2::new(30.0, 20.0));
    harness.run();
    for _ in 0..10 {
        harness.input_mut().events.push(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: Vec2::new(0.0, 120.0),
            phase: egui::TouchPhase::Move,
            modifiers: Modifiers::NONE,
        });
        harness.step();
    }
    harness.run();
    let zoomed = harness.state().state.canvas_zoom();
    assert!(
        zoomed > fitted * 1.5,
        "the wheel zoomed: {fitted} -> {zoomed}"
    );
    harness.key_press(egui::Key::Home);
    harness.run();
    let back = harness.state().state.canvas_zoom();
    // The panel is the same but for a pixel or two of layout since the first frame.
    assert!(
        (back - fitted).abs() < fitted * 0.02,
        "Home fits again: {back} vs {fitted}"
    );
}

/// The n false-colour view shows its scale in the viewport, as `kapaint render` does.
#[test]
fn the_n_false_colour_view_has_a_legend() {
    use kapaint::ui::viewport::N_LEGEND_LABEL;
    let mut harness = editor();
    assert!(harness.query_by_label(N_LEGEND_LABEL).is_none());
    harness.get_by_label("View mode").click();
    harness.run();
    harness.get_by_label("n false colour").click();
    harness.run();
    harness.get_by_label(N_LEGEND_LABEL);
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
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
    harness.step();
    harness.step();
    let field = harness
        .get_all_by_role(Role::TextInput)
        .find(|n| n.value().as_deref() == Some("export"))
        .expect("the folder field");
    field.focus();
    harness.step();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness.step();
    harness
        .get_all_by_role(Role::TextInput)
        .find(|n| n.value().as_deref() == Some("export"))
        .expect("the folder field")
        .type_text(&folder);
    harness.step();
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
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
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

/// Steps the harness until `done` holds (a worker's job), for at most a minute.
fn wait_until(harness: &mut Harness<'_, Editor>, what: &str, done: impl Fn(&Editor) -> bool) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while !done(harness.state()) {
        let notices: Vec<String> = harness
            .state()
            .state
            .notices()
            .iter()
            .map(|n| n.text.clone())
            .collect();
        assert!(std::time::Instant::now() < deadline, "{what}: {notices:?}");
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
}

/// A fresh folder for a test.
#[expect(clippy::expect_used, reason = "a test helper: no folder, no test")]
fn scratch(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The editor with kapaint's own file dialog (as where no desktop portal runs), starting in
/// `dir`.
fn editor_without_portal(dir: &std::path::Path) -> Harness<'static, Editor> {
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::Builtin);
    files.set_last_dir(dir.to_path_buf());
    harness
}

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
    harness.run();
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
    harness.run();
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
            FilePurpose::ImportMesh | FilePurpose::NewMesh => spot.join("spot_triangulated.obj"),
            FilePurpose::ImportImage(_) | FilePurpose::StampImage => spot.join("spot_texture.png"),
            FilePurpose::ExportFolder => std::env::temp_dir().join("kapaint-export-choice"),
            FilePurpose::OpenProject | FilePurpose::SaveProject => return None,
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

    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
    harness.run_steps(2);
    harness.get_by_role_and_label(Role::Button, "…").click();
    harness.run_steps(2);
    let chosen = std::env::temp_dir()
        .join("kapaint-export-choice")
        .join("set")
        .display()
        .to_string();
    wait_until(&mut harness, "export folder chosen", |e| {
        e.state.export_folder() == Some(chosen.as_str())
    });
}

/// A 2048^2 project of noise (every tile stored, so opening it takes a while).
#[expect(clippy::expect_used, reason = "a test helper: no project, no test")]
fn noisy_project(path: &std::path::Path) -> kapaint::model::Document {
    use kapaint::model::texel::MaterialValue;
    let mut maps =
        kapaint::model::MaterialMaps::new(2048, 2048, MaterialValue::default()).expect("maps");
    let mut seed = 0x2545_f491_u32;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    for id in 0..maps.tile_count() {
        let tile = maps.tile_mut(id);
        for i in 0..64 * 64 {
            let r = next();
            let half = |v: u32| u16::try_from(v & 0x7fff).unwrap_or(0);
            let n = half::f16::from_f32((r >> 20) as f32).to_bits();
            tile.set_texel(
                i,
                Texel {
                    kd: [half(r), half(r >> 3), half(r >> 7)],
                    ks: [half(r >> 11); 3],
                    n,
                },
            );
        }
    }
    let doc =
        kapaint::model::Document::from_parts(maps, kapaint::model::DocumentSettings::default());
    kapaint::model::project::save(&doc, path).expect("saved");
    doc
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

/// A right-button drag across the viewport, with `modifiers` held, over a few frames.
fn right_drag(harness: &mut Harness<'_, Editor>, modifiers: Modifiers, by: Vec2) {
    let a = harness.get_by_label(VIEWPORT_LABEL).rect().center();
    let button = |pos, pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Secondary,
        pressed,
        modifiers,
    };
    harness.event(egui::Event::ModifiersChanged(modifiers));
    harness.event(egui::Event::PointerMoved(a));
    harness.step();
    harness.event(button(a, true));
    harness.step();
    for i in 1..=6 {
        harness.event(egui::Event::PointerMoved(a + by * (i as f32 / 6.0)));
        harness.step();
    }
    harness.event(button(a + by, false));
    harness.event(egui::Event::ModifiersChanged(Modifiers::default()));
    harness.step();
    harness.step();
}

#[test]
fn shift_right_drag_turns_the_light_not_the_camera() {
    let mut harness = editor();
    let before = harness.state().state.frame_settings();
    right_drag(&mut harness, Modifiers::SHIFT, Vec2::new(80.0, -40.0));
    let after = harness.state().state.frame_settings();
    assert_eq!(after.camera, before.camera, "the camera stays");
    let (l0, l1) = (before.lighting.direction(), after.lighting.direction());
    assert!(l0.angle_between(l1) > 0.5, "the light turned: {l0} -> {l1}");
    assert!(l1.y > l0.y, "dragging up raises it: {l0} -> {l1}");
    // Without Shift the right button still orbits.
    right_drag(&mut harness, Modifiers::default(), Vec2::new(80.0, 0.0));
    assert_ne!(harness.state().state.frame_settings().camera, after.camera);
}

#[test]
fn the_light_can_follow_the_camera() {
    let mut harness = editor();
    let settings = |h: &Harness<'_, Editor>| h.state().state.frame_settings();
    // By default the light stays put in the world while the camera orbits.
    let before = settings(&harness);
    right_drag(&mut harness, Modifiers::default(), Vec2::new(120.0, 0.0));
    let orbited = settings(&harness);
    assert_ne!(orbited.camera, before.camera);
    assert!(
        orbited
            .lighting
            .direction()
            .distance(before.lighting.direction())
            < 1e-5
    );
    // Following: switched on without a jump, then it turns with the camera.
    harness.get_by_label("Light follows camera").click();
    harness.run();
    let on = settings(&harness);
    assert!(
        on.lighting
            .direction()
            .distance(orbited.lighting.direction())
            < 1e-4
    );
    right_drag(&mut harness, Modifiers::default(), Vec2::new(-200.0, 30.0));
    let turned = settings(&harness);
    let relative =
        |s: &kapaint::render::FrameSettings| s.camera.rotation().inverse() * s.lighting.direction();
    assert!(
        turned
            .lighting
            .direction()
            .angle_between(on.lighting.direction())
            > 0.5
    );
    assert!(relative(&turned).distance(relative(&on)) < 1e-4);
}

#[test]
fn the_right_panel_keeps_its_width_in_every_compare_mode() {
    let mut harness = editor();
    let width = |h: &Harness<'_, Editor>| {
        egui::containers::panel::PanelState::load(&h.ctx, egui::Id::new("view"))
            .map(|s| s.size().x)
            .expect("the right panel")
    };
    let single = width(&harness);
    for (mode, label) in Compare::ALL {
        harness.get_by_label(label).click();
        harness.run();
        harness.run();
        assert!(
            (width(&harness) - single).abs() < 0.5,
            "{mode:?}: {} against {single}",
            width(&harness)
        );
    }
}

#[test]
fn the_canvas_shows_the_brush_outline_at_its_zoom() {
    let mut harness = editor();
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    harness.hover_at(canvas.center());
    harness.run();
    let (centre, radius) = harness
        .state()
        .state
        .canvas_outline()
        .expect("a brush outline over the canvas");
    assert!(centre.distance(canvas.center()) < 0.5);
    let state = &harness.state().state;
    let want = state.doc().settings().brush.radius_px * state.canvas_zoom();
    assert!(
        (radius - want).abs() < 0.01 * want,
        "{radius} against {want}"
    );
    // A larger brush (] is 1.25 times), a larger circle.
    harness.key_press(egui::Key::CloseBracket);
    harness.run();
    let (_, larger) = harness.state().state.canvas_outline().expect("outline");
    assert!((larger / radius - 1.25).abs() < 0.01, "{larger} / {radius}");
    // None with the picker, nor off the canvas.
    harness.key_press(egui::Key::I);
    harness.run();
    assert!(harness.state().state.canvas_outline().is_none());
}
