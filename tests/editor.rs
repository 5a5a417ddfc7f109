//! The editor driven as a user would, through egui_kittest: widgets found by role and label,
//! strokes dragged on the UV canvas and on the 3D viewport, undo checked bit-exactly, the
//! compare split and the export dialog. No GPU is needed: the viewport picks and paints on
//! the CPU and shows a placeholder where the preview would be.

#![allow(clippy::expect_used)]

use egui::accesskit::Role;
use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::model::texel::Texel;
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::viewport::{Compare, VIEWPORT_LABEL};

fn texels(editor: &Editor) -> Vec<Texel> {
    let maps = &editor.state.doc.maps;
    let mut out = Vec::with_capacity(maps.texel_count());
    maps.for_each_texel(|_, _, t| out.push(t));
    out
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
fn a_scripted_editing_session() {
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, None),
        );
    harness.run();
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
        harness.state().state.doc.history.undo_steps().count(),
        1,
        "one stroke, one step"
    );

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
    let radius = harness.state().state.doc.settings.brush.radius_px;
    harness.key_press(egui::Key::OpenBracket);
    harness.run();
    assert!(harness.state().state.doc.settings.brush.radius_px < radius);
    harness.key_press(egui::Key::E);
    harness.run();
    assert_eq!(harness.state().state.tool, kapaint::ui::Tool::Eraser);

    // Compare split.
    harness.get_by_label("Split").click();
    harness.run();
    assert_eq!(harness.state().state.viewport.compare, Compare::Split);

    // The export dialog opens from its hotkey and offers the presets.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
    harness.run();
    harness.get_by_role_and_label(Role::Button, "Export");
    harness.get_by_label("Preset");
}
