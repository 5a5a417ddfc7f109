//! The mask generator in the Layers tab, driven as an artist would through egui_kittest: make
//! a fill layer's mask by noise, drag its scale (coarse while dragging, one undo step), apply a
//! smart mask in one step, and save one's own.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::model::generator::Generator;
use kapaint::ui::Editor;

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

/// The selected layer's mask generator.
fn generator(harness: &Harness<'_, Editor>) -> Option<Generator> {
    harness
        .state()
        .state
        .doc()
        .selected_layer()
        .and_then(|l| l.mask.as_ref())
        .and_then(|m| m.generator())
        .cloned()
}

fn choose(harness: &mut Harness<'_, Editor>, combo: &str, option: &str) {
    harness.get_by_role_and_label(Role::ComboBox, combo).click();
    harness.run();
    harness.get_by_label(option).click();
    harness.run();
}

#[test]
fn a_noise_mask_made_dragged_and_undone_from_the_panel() {
    let mut harness = editor();
    harness.get_by_label("+ Fill").click();
    harness.run();
    let filled = texels(harness.state());
    choose(&mut harness, "Mask made by", "Noise");
    let Some(Generator::Noise(noise)) = generator(&harness) else {
        panic!("a noise mask: {:?}", generator(&harness));
    };
    assert_eq!(noise.scale, 8.0);
    let made = texels(harness.state());
    assert!(changed(&filled, &made) > 1000, "the noise shapes the fill");
    harness.get_by_label("The mask as it applies");
    let steps = harness.state().state.doc().history().undo_steps().count();

    // Dragging the scale: coarse while the pointer is down, the full result on release, and
    // the whole drag one undo step.
    let slider = harness.get_by_role_and_label(Role::Slider, "Scale").rect();
    let (from, to) = (
        slider.center(),
        slider.center() + egui::Vec2::new(40.0, 0.0),
    );
    harness.hover_at(from);
    harness.run();
    harness.drag_at(from);
    harness.run();
    for i in 1..=6 {
        harness.hover_at(from + (to - from) * (i as f32 / 6.0));
        harness.run();
    }
    let coarse = harness
        .state()
        .state
        .doc()
        .selected_layer()
        .and_then(|l| l.mask.as_ref())
        .and_then(|m| m.generator.as_ref())
        .is_some_and(|g| g.is_coarse());
    assert!(coarse, "coarse while dragging");
    harness.drop_at(to);
    harness.run();
    let layer = harness.state().state.doc().selected_layer().cloned();
    let made_by = layer
        .and_then(|l| l.mask)
        .and_then(|m| m.generator)
        .expect("made");
    assert!(!made_by.is_coarse(), "the full result on release");
    let Generator::Noise(dragged) = made_by.generator() else {
        panic!("still noise");
    };
    assert!(dragged.scale > 8.0, "the scale grew: {}", dragged.scale);
    assert_eq!(
        harness.state().state.doc().history().undo_steps().count(),
        steps + 1,
        "the drag is one step"
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(
        changed(&made, &texels(harness.state())),
        0,
        "undo: before the drag"
    );

    // Paint only: the mask keeps what it showed, as pixels.
    choose(&mut harness, "Mask made by", "Paint only");
    assert!(generator(&harness).is_none());
    assert_eq!(changed(&made, &texels(harness.state())), 0);
}

/// The editor in a window tall enough for the Layers tab to show a smart mask's parameters and
/// the row that names it.
fn tall_editor() -> Harness<'static, Editor> {
    let mut harness = Harness::builder()
        .with_size(egui::Vec2::new(1400.0, 2000.0))
        .with_max_steps(40)
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, None),
        );
    harness.run();
    harness
}

#[test]
fn a_smart_mask_applies_in_one_step_and_saves_as_ones_own() {
    let dir = scratch("smart-masks");
    let mut harness = tall_editor();
    harness.state_mut().state.set_preset_dir(dir.clone());
    harness.get_by_label("+ Fill").click();
    harness.run();
    let steps = harness.state().state.doc().history().undo_steps().count();
    choose(&mut harness, "Smart mask", "Dust");
    let dust = kapaint::model::generator::preset::builtin()
        .into_iter()
        .find(|p| p.name == "Dust")
        .expect("shipped");
    assert_eq!(generator(&harness), Some(dust.mask.clone()));
    assert_eq!(
        harness.state().state.doc().history().undo_steps().count(),
        steps + 1
    );
    harness.get_by_label("Save as smart mask…").click();
    harness.run();
    harness
        .get_by_role_and_label(Role::TextInput, "Preset name")
        .type_text("My dust");
    harness.run();
    harness.get_by_label("Save").click();
    harness.run();
    let saved = kapaint::model::generator::preset::MaskPreset::load(&dir.join("masks/my-dust.ron"))
        .expect("saved");
    assert_eq!(saved.mask, dust.mask);
    assert!(
        harness
            .state()
            .state
            .mask_preset_names()
            .contains(&"My dust")
    );
    let _ = std::fs::remove_dir_all(&dir);
}
