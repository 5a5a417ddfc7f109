//! The editor's everyday controls, driven through egui_kittest: the light, the panels, the
//! canvas's fit, outline and legend, the brush's size on screen, colours, presets, history
//! and resizing the maps.

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

/// Wheel turns over `at`, a frame each, until the smooth scroll has settled.
fn wheel(harness: &mut Harness<'_, Editor>, at: Pos2, dy: f32) {
    harness.hover_at(at);
    harness.run();
    for _ in 0..4 {
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: Vec2::new(0.0, dy),
            phase: egui::TouchPhase::Move,
            modifiers: Modifiers::default(),
        });
        harness.run();
    }
    for _ in 0..30 {
        harness.step();
    }
}

#[test]
fn a_brush_sized_on_screen_keeps_its_size_at_any_zoom() {
    use kapaint::ui::screen_brush::BrushSize;
    let mut harness = editor();
    harness.state_mut().state.set_brush_size(BrushSize {
        on_screen: true,
        screen_radius: 20.0,
    });
    harness.run();
    assert!(harness.query_all_by_label("Radius on screen").count() > 0);
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    let centre = canvas.center();
    let radius_px = |h: &Harness<'_, Editor>| h.state().state.doc().settings().brush.radius_px;
    // On the canvas: the circle is 20 points whatever the zoom, and a stroke takes
    // 20 points' worth of texels.
    drag(&mut harness, centre, centre + Vec2::new(30.0, 0.0));
    let zoom = harness.state().state.canvas_zoom();
    let before = radius_px(&harness);
    assert!(
        (before - 20.0 / zoom).abs() < 1e-3 * before,
        "{before} at zoom {zoom}"
    );
    wheel(&mut harness, centre, 300.0);
    let zoomed = harness.state().state.canvas_zoom();
    assert!(zoomed > 1.3 * zoom, "zoomed in: {zoom} -> {zoomed}");
    harness.hover_at(centre);
    harness.run();
    let (_, circle) = harness.state().state.canvas_outline().expect("outline");
    assert!(
        (circle - 20.0).abs() < 0.01,
        "the circle stays 20 points: {circle}"
    );
    drag(&mut harness, centre, centre + Vec2::new(30.0, 0.0));
    let after = radius_px(&harness);
    assert!(
        (after - 20.0 / zoomed).abs() < 1e-3 * after,
        "{after} at zoom {zoomed}"
    );
    // ] grows the size on screen, not the texels.
    harness.key_press(egui::Key::CloseBracket);
    harness.run();
    assert_eq!(harness.state().state.brush_size().screen_radius, 25.0);
    assert_eq!(
        radius_px(&harness),
        after,
        "texels follow at the next stroke"
    );

    // In the viewport: closer, fewer texels under the same circle.
    let viewport = harness.get_by_label(VIEWPORT_LABEL).rect();
    let mid = viewport.center();
    drag(&mut harness, mid, mid + Vec2::new(10.0, 0.0));
    let far = radius_px(&harness);
    let per_point = harness
        .state()
        .state
        .texels_per_point()
        .expect("over the sphere");
    assert!(
        (far - 25.0 * per_point).abs() < 1e-3 * far,
        "{far} vs {per_point}"
    );
    wheel(&mut harness, mid, 300.0);
    drag(&mut harness, mid, mid + Vec2::new(10.0, 0.0));
    let near = radius_px(&harness);
    assert!(
        near < 0.8 * far,
        "closer, smaller in texels: {far} -> {near}"
    );
    // Off, the brush keeps its texels at any zoom.
    harness
        .state_mut()
        .state
        .set_brush_size(BrushSize::default());
    wheel(&mut harness, mid, -300.0);
    drag(&mut harness, mid, mid + Vec2::new(10.0, 0.0));
    assert_eq!(radius_px(&harness), near);
}

#[test]
fn the_primary_colour_is_typed_in_srgb_and_recent_materials_come_back() {
    use kapaint::model::texel::srgb_to_linear;
    let mut harness = editor();
    let kd = |h: &Harness<'_, Editor>| h.state().state.doc().settings().primary.kd;
    // Hex, in sRGB: #ff8000 is linear (1, 0.216, 0).
    let hex = harness.get_by_role(Role::TextInput);
    hex.focus();
    harness.run();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness.get_by_role(Role::TextInput).type_text("#ff8000");
    harness.run();
    let orange = kd(&harness);
    let want = glam::Vec3::new(1.0, srgb_to_linear(128.0 / 255.0), 0.0);
    assert!(
        (orange - want).abs().max_element() < 1e-6,
        "{orange} against {want}"
    );
    // The RGB and HSV fields show the same colour in sRGB.
    let field = |h: &Harness<'_, Editor>, name: &str| {
        use egui_kittest::kittest::NodeT as _;
        h.get_by_label(name).accesskit_node().value()
    };
    for (name, want) in [
        ("R", "255"),
        ("G", "128"),
        ("B", "0"),
        ("H", "30°"),
        ("S", "100%"),
    ] {
        assert_eq!(field(&harness, name).as_deref(), Some(want), "{name}");
    }
    // A stroke lays it and it joins the recent materials; so does the next one.
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    let centre = canvas.center();
    drag(&mut harness, centre, centre + Vec2::new(30.0, 0.0));
    // The secondary swatch swaps the materials.
    let secondary = harness.state().state.doc().settings().secondary;
    harness.get_by_label("Secondary").click();
    harness.run();
    assert_eq!(harness.state().state.doc().settings().primary, secondary);
    drag(&mut harness, centre, centre + Vec2::new(0.0, 30.0));
    let recent = harness.state().state.recent_materials().to_vec();
    assert_eq!(recent.len(), 2, "{recent:?}");
    assert_eq!((recent[0], recent[1].kd), (secondary, orange));
    // A click on a recent swatch makes it the primary again.
    harness.get_by_label("Recent material 2").click();
    harness.run();
    assert_eq!(kd(&harness), orange);
}

#[test]
fn the_primary_material_and_the_brush_are_saved_as_presets_of_ones_own() {
    let dir = scratch("own-presets");
    let mut harness = editor();
    harness.state_mut().state.set_preset_dir(dir.clone());
    harness.run();
    // Names show under the thumbnails, not only in tooltips.
    harness.get_by_label("Brass");
    harness.get_by_label("Red Plastic");
    // The primary material, as a preset.
    let primary = harness.state().state.doc().settings().primary;
    harness.get_by_label("Save primary as preset…").click();
    harness.run();
    harness.get_by_label("Preset name").type_text("Wet clay");
    harness.run();
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.run();
    let file = dir.join("wet-clay.ron");
    let saved = kapaint::model::preset::MaterialPreset::load(&file).expect("saved preset");
    assert_eq!((saved.name.as_str(), saved.value()), ("Wet clay", primary));
    assert!(harness.state().state.preset_names().contains(&"Wet clay"));
    harness.get_by_label("Wet clay");
    // The brush, as a named brush preset that a choice brings back.
    let mut brush = harness.state().state.doc().settings().brush.clone();
    brush.radius_px = 7.5;
    brush.jitter = 0.3;
    harness
        .state_mut()
        .state
        .apply_command(kapaint::model::SettingsCommand::SetBrush(brush.clone()));
    harness.run();
    harness.get_by_label("Save brush…").click();
    harness.run();
    harness.get_by_label("Preset name").type_text("Speckle");
    harness.run();
    harness.get_by_role_and_label(Role::Button, "Save").click();
    harness.run();
    let back = kapaint::model::brush::preset::BrushPreset::load(&dir.join("brushes/speckle.ron"))
        .expect("saved brush");
    assert_eq!(back.brush, brush);
    harness.get_by_label("Brush preset").click();
    harness.run();
    harness.get_by_label("Soft round").click();
    harness.run();
    assert_eq!(harness.state().state.doc().settings().brush.hardness, 0.0);
    harness.get_by_label("Brush preset").click();
    harness.run();
    harness.get_by_label("Speckle").click();
    harness.run();
    assert_eq!(harness.state().state.doc().settings().brush, brush);
    // Read again, the user's presets are listed with the shipped ones; a malformed file is
    // named in a notice and skipped.
    std::fs::write(dir.join("broken.ron"), "(name: \"Broken\", kd: (2, 0, 0))").expect("write");
    harness.state_mut().state.reload_presets();
    harness.run();
    let state = &harness.state().state;
    assert!(state.preset_names().contains(&"Wet clay"));
    assert!(!state.preset_names().contains(&"Broken"));
    assert!(state.brush_preset_names().contains(&"Speckle"));
    assert!(
        state
            .notices()
            .iter()
            .any(|n| n.is_error() && n.text.contains("broken.ron")),
        "{:?}",
        state.notices().iter().map(|n| &n.text).collect::<Vec<_>>()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_click_on_a_history_step_jumps_to_it_and_undone_steps_stay_listed() {
    let mut harness = editor();
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    let mut states = vec![texels(harness.state())];
    for i in 0..3 {
        let a = centre + Vec2::new(0.0, 25.0 * i as f32);
        drag(&mut harness, a, a + Vec2::new(40.0, 0.0));
        states.push(texels(harness.state()));
    }
    let steps = |h: &Harness<'_, Editor>| {
        let history = h.state().state.doc().history();
        (history.undo_steps().count(), history.redo_steps().count())
    };
    assert_eq!(steps(&harness), (3, 0));
    // Back to the first stroke: two steps undone, still listed.
    harness.get_by_label_contains("1. ").click();
    harness.run();
    assert_eq!(steps(&harness), (1, 2));
    assert_eq!(texels(harness.state()), states[1]);
    harness.get_by_label_contains("3. ");
    // Forward to the last, through the greyed step.
    harness.get_by_label_contains("3. ").click();
    harness.run();
    assert_eq!(texels(harness.state()), states[3]);
    // To the original, then a new edit drops the undone steps.
    harness.get_by_label("Original").click();
    harness.run();
    assert_eq!(texels(harness.state()), states[0]);
    assert_eq!(steps(&harness), (0, 3));
    drag(&mut harness, centre, centre + Vec2::new(0.0, 40.0));
    assert_eq!(steps(&harness), (1, 0));
    assert!(harness.query_by_label_contains("2. ").is_none());
}

#[test]
fn image_resize_shows_its_memory_first_and_is_one_undo_step() {
    let mut harness = editor();
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    let centre = canvas.center();
    drag(&mut harness, centre, centre + Vec2::new(40.0, 0.0));
    let painted = texels(harness.state());
    let zoom = harness.state().state.canvas_zoom();
    harness.get_by_label("Image").click();
    harness.run();
    harness.get_by_label("Resize…").click();
    harness.run();
    harness.get_by_label_contains("Now 1024x1024");
    harness.get_by_label_contains("Undo keeps the old maps");
    harness.get_by_label_contains("Peak while resampling");
    harness
        .state_mut()
        .state
        .set_resize_dialog(kapaint::ui::resize::ResizeDialog {
            width: 512,
            height: 512,
        });
    harness.run();
    harness.get_by_label_contains("up to 3.7 MB after");
    harness
        .get_by_role_and_label(Role::Button, "Resize")
        .click();
    // Frames are cheap (the viewport is not drawn again unchanged): wait on the job itself,
    // not on a count of frames.
    wait_until(&mut harness, "resized", |e| {
        e.state.doc().maps().width() == 512
    });
    harness.run();
    let state = &harness.state().state;
    assert_eq!(state.doc().maps().height(), 512);
    assert_eq!(state.doc().surface().map(|s| s.width()), Some(512));
    assert!(state.dirty());
    // The map keeps its place on screen: twice the points per texel.
    let ratio = state.canvas_zoom() / zoom;
    assert!((ratio - 2.0).abs() < 1e-3, "{ratio}");
    harness.get_by_label_contains("Resize 1024x1024 to 512x512");
    // One undo step brings the 1024^2 maps back, bit-exactly.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(texels(harness.state()), painted);
    assert!((harness.state().state.canvas_zoom() / zoom - 1.0).abs() < 1e-3);
}

/// Regression: the export dialog's measured set arrived from a worker above the folder row,
/// and the window grew under the pointer: a click aimed at "…" (or Export) as it arrived hit
/// the measurement instead (`every_file_request_reaches_its_command` waited for the folder in
/// vain about one run in eight here). The controls now sit above what is measured, so its
/// arrival moves none of them.
#[test]
fn the_export_dialogs_controls_sit_above_what_arrives_from_the_worker() {
    let mut harness = editor();
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::E);
    harness.run_steps(2);
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness.query_by_label("Packed layout").is_none() {
        assert!(
            std::time::Instant::now() < deadline,
            "the set was never measured"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
    harness.run_steps(2);
    let measured = harness.get_by_label("Packed layout").rect().min.y;
    for (name, button) in [
        ("the folder's button", folder_button(&harness)),
        ("Export", export_button(&harness)),
    ] {
        assert!(
            button.max.y < measured,
            "{name} ({button:?}) sits under the measured set (from y = {measured})"
        );
    }
}

/// The export dialog's folder button ("…" on the Folder row: the preset browser has "…"
/// buttons too, for thumbnails not drawn yet).
#[expect(clippy::expect_used, reason = "a test helper: no button, no test")]
fn folder_button(harness: &Harness<'_, Editor>) -> egui::Rect {
    let row = harness.get_by_label("Folder").rect().center().y;
    harness
        .get_all_by_role_and_label(Role::Button, "…")
        .map(|b| b.rect())
        .find(|r| (r.center().y - row).abs() < 12.0)
        .expect("the folder's button")
}

/// The export dialog's Export button.
fn export_button(harness: &Harness<'_, Editor>) -> egui::Rect {
    harness.get_by_role_and_label(Role::Button, "Export").rect()
}
