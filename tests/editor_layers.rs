//! The Layers tab driven as an artist would, through egui_kittest: add a layer, paint it, hide
//! it (the maps return bit-exactly to the state below), reorder by button and by drag, mask
//! it, the layer hotkeys, the layer views, and undo of everything.

use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::ui::Editor;
use kapaint::ui::LayerView;
use kapaint::ui::canvas::CANVAS_LABEL;

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

/// The layers' names, bottom first, top level only.
fn names(harness: &Harness<'_, Editor>) -> Vec<String> {
    let doc = harness.state().state.doc();
    doc.stack()
        .layers
        .iter()
        .map(|l| l.props.name.clone())
        .collect()
}

/// The centre of the named layer's row in the list (its name's label; the list comes before
/// the selected layer's settings, which repeat the name).
fn row(harness: &Harness<'_, Editor>, name: &str) -> Pos2 {
    harness
        .get_all_by_label(name)
        .next()
        .unwrap_or_else(|| panic!("no row for {name}"))
        .rect()
        .center()
}

/// Clicks the widget labelled `label` on the same row as the layer `name`.
fn click_in_row(harness: &mut Harness<'_, Editor>, name: &str, label: &str) {
    let y = row(harness, name).y;
    let at = harness
        .get_all_by_label(label)
        .map(|n| n.rect().center())
        .find(|c| (c.y - y).abs() < 8.0)
        .unwrap_or_else(|| panic!("no {label} on the row of {name}"));
    harness.hover_at(at);
    harness.run();
    harness.event(egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: Modifiers::NONE,
    });
    harness.event(egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: Modifiers::NONE,
    });
    harness.run();
}

fn click(harness: &mut Harness<'_, Editor>, label: &str) {
    harness.get_by_label(label).click();
    harness.run();
}

/// A stroke across the canvas, offset from its centre.
fn stroke(harness: &mut Harness<'_, Editor>, from: Vec2, to: Vec2) {
    let centre = harness.get_by_label(CANVAS_LABEL).rect().center();
    drag(harness, centre + from, centre + to);
}

#[test]
fn add_paint_hide_reorder_mask_and_undo_everything_from_the_panel() {
    let mut harness = editor();
    let original = texels(harness.state());
    assert_eq!(names(&harness), ["Layer 1"]);

    click(&mut harness, "+ Paint");
    assert_eq!(names(&harness), ["Layer 1", "Layer 2"]);
    assert_eq!(harness.state().state.doc().selection().path, [1]);
    stroke(&mut harness, Vec2::new(-60.0, 0.0), Vec2::new(60.0, 0.0));
    let painted = texels(harness.state());
    assert!(changed(&original, &painted) > 100, "the stroke painted");

    // The eye hides the layer: the maps return bit-exactly to the state below; again shows it.
    click_in_row(&mut harness, "Layer 2", "👁");
    assert!(!harness.state().state.doc().stack().layers[1].props.visible);
    let hidden = texels(harness.state());
    assert_eq!(changed(&original, &hidden), 0, "hidden: the state below");
    click_in_row(&mut harness, "Layer 2", "–");
    let shown = texels(harness.state());
    assert_eq!(changed(&painted, &shown), 0, "shown again");

    // A third layer, then moved under the second.
    click(&mut harness, "+ Paint");
    stroke(&mut harness, Vec2::new(0.0, -60.0), Vec2::new(0.0, 60.0));
    assert_eq!(names(&harness), ["Layer 1", "Layer 2", "Layer 3"]);
    click(&mut harness, "Down");
    assert_eq!(names(&harness), ["Layer 1", "Layer 3", "Layer 2"]);

    // A mask on Layer 2, painted black by the eraser where the stroke crossed: the layer
    // below shows there.
    click_in_row(&mut harness, "Layer 2", "Layer 2");
    assert_eq!(harness.state().state.doc().selection().path, [2]);
    click(&mut harness, "Add mask");
    let before_mask = texels(harness.state());
    click(&mut harness, "Paint the mask");
    assert!(harness.state().state.doc().selection().mask);
    harness.key_press(egui::Key::E);
    stroke(&mut harness, Vec2::new(-20.0, 0.0), Vec2::new(20.0, 0.0));
    let masked = texels(harness.state());
    assert!(
        changed(&before_mask, &masked) > 50,
        "the mask hid part of the layer"
    );

    // Undo everything: back to the new document, bit-exact, one layer.
    let steps = harness.state().state.doc().history().undo_steps().count();
    assert!(steps >= 8, "every change was a step ({steps})");
    for _ in 0..steps {
        harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
        harness.run();
    }
    let undone = texels(harness.state());
    assert_eq!(changed(&original, &undone), 0, "undo restored every texel");
    assert_eq!(names(&harness), ["Layer 1"]);
}

#[test]
fn the_layer_hotkeys_add_duplicate_and_merge_down() {
    let mut harness = editor();
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::N);
    harness.run();
    assert_eq!(names(&harness), ["Layer 1", "Layer 2"], "Ctrl+Shift+N");
    assert!(
        harness.state().state.new_dialog().is_none(),
        "Ctrl+Shift+N is not Ctrl+N"
    );
    stroke(&mut harness, Vec2::new(-40.0, 10.0), Vec2::new(40.0, 10.0));
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::J);
    harness.run();
    assert_eq!(
        names(&harness),
        ["Layer 1", "Layer 2", "Layer 2 copy"],
        "Ctrl+J"
    );
    let shown = texels(harness.state());
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::E);
    harness.run();
    assert_eq!(names(&harness).len(), 2, "Ctrl+E merged the copy down");
    assert!(
        harness.state().state.export_folder().is_none(),
        "Ctrl+E is no longer export"
    );
    let merged = texels(harness.state());
    // What showed stays, but for rounding: the merged layer stores one value and coverage
    // where two were, in the same 16 bits.
    let d = |x: u16, y: u16| (i32::from(x) - i32::from(y)).abs();
    let worst = shown
        .iter()
        .zip(&merged)
        .flat_map(|(a, b)| (0..3).map(move |k| d(a.kd[k], b.kd[k]).max(d(a.ks[k], b.ks[k]))))
        .max();
    assert!(
        worst <= Some(1),
        "a merge keeps what showed ({worst:?} codes)"
    );
    assert!(shown.iter().zip(&merged).all(|(a, b)| d(a.n, b.n) <= 1));
}

#[test]
fn a_layer_dragged_by_its_handle_lands_where_it_is_dropped() {
    let mut harness = editor();
    click(&mut harness, "+ Paint");
    click(&mut harness, "+ Paint");
    assert_eq!(names(&harness), ["Layer 1", "Layer 2", "Layer 3"]);
    // Layer 3's handle (the top row) onto the lower part of Layer 1's row: below it.
    let handle_y = row(&harness, "Layer 3").y;
    let handle = harness
        .get_all_by_label("☰")
        .map(|n| n.rect().center())
        .find(|c| (c.y - handle_y).abs() < 8.0)
        .expect("Layer 3's handle");
    let target = harness
        .get_all_by_label("Layer 1")
        .next()
        .expect("Layer 1's row")
        .rect();
    let drop = Pos2::new(target.center().x, target.bottom() + 4.0);
    drag(&mut harness, handle, drop);
    assert_eq!(names(&harness), ["Layer 3", "Layer 1", "Layer 2"]);
    assert_eq!(
        harness.state().state.doc().history().undo_steps().count(),
        3
    );
}

#[test]
fn alt_click_on_a_mask_shows_it_alone_and_the_viewport_says_what_is_painted() {
    let mut harness = editor();
    click(&mut harness, "Add mask");
    assert!(harness.state().state.doc().stack().layers[0].mask.is_some());
    assert_eq!(
        harness.state().state.painting_text().as_deref(),
        Some("Painting \"Layer 1\"")
    );
    let mask = harness.get_by_label("Mask of Layer 1").rect();
    harness.event(egui::Event::ModifiersChanged(Modifiers::ALT));
    harness.hover_at(mask.center());
    harness.run();
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: mask.center(),
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::ALT,
        });
    }
    harness.event(egui::Event::ModifiersChanged(Modifiers::NONE));
    harness.run();
    let state = &harness.state().state;
    assert!(state.doc().selection().mask, "tools paint the mask");
    assert_eq!(state.layer_view(), LayerView::Mask);
    assert_eq!(
        state.painting_text().as_deref(),
        Some("Painting the mask of \"Layer 1\" · showing mask")
    );
}

#[test]
fn a_mask_being_painted_shows_alone_in_grey() {
    use kapaint::model::MaskCommand;
    let mut harness = editor();
    let state = &mut harness.state_mut().state;
    assert_eq!(state.shown_layer_view(), LayerView::Composite);
    state.apply_command(MaskCommand::AddMask);
    state.apply_command(MaskCommand::SelectMask);
    assert_eq!(
        state.shown_layer_view(),
        LayerView::Mask,
        "the mask is the target"
    );
    state.apply_command(MaskCommand::SelectContent);
    assert_eq!(state.shown_layer_view(), LayerView::Composite);
}

/// Two clicks of the primary button at `at`: a double click. The harness gives each pointer
/// event a frame of a quarter second, more than egui's 0.3 s between the clicks of a double
/// click, so that limit is raised for the test.
fn double_click(harness: &mut Harness<'_, Editor>, at: Pos2) {
    harness
        .ctx
        .options_mut(|o| o.input_options.max_double_click_delay = 2.0);
    harness.hover_at(at);
    harness.run();
    for _ in 0..2 {
        for pressed in [true, false] {
            harness.event(egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: Modifiers::NONE,
            });
        }
    }
    harness.run();
}

/// Double-clicks the row of `name`, selects what is there and types `text` (nothing sent
/// yet that ends the edit).
fn start_rename(harness: &mut Harness<'_, Editor>, name: &str, text: &str) {
    let at = row(harness, name);
    double_click(harness, at);
    assert!(
        harness.ctx.egui_wants_keyboard_input(),
        "the name field has the keyboard"
    );
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness.event(egui::Event::Text(text.into()));
    harness.run();
}

/// Whether the layer hotkeys work: Ctrl+Shift+N adds a layer (undone again).
fn keyboard_is_live(harness: &mut Harness<'_, Editor>) -> bool {
    let before = names(harness).len();
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::N);
    harness.run();
    let added = names(harness).len() == before + 1;
    if added {
        harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
        harness.run();
    }
    added
}

/// A rename in the list commits on Enter, Tab and a click elsewhere, cancels on Escape, and
/// gives the keyboard back every time (it kept it, and every shortcut, until a restart).
#[test]
fn renaming_a_layer_commits_or_cancels_and_never_traps_the_keyboard() {
    let mut harness = editor();
    start_rename(&mut harness, "Layer 1", "Rust");
    harness.key_press(egui::Key::Enter);
    harness.run();
    assert_eq!(names(&harness), ["Rust"], "Enter commits");
    assert!(keyboard_is_live(&mut harness), "shortcuts work after Enter");

    start_rename(&mut harness, "Rust", "Dirt");
    harness.key_press(egui::Key::Tab);
    harness.run();
    assert_eq!(names(&harness), ["Dirt"], "Tab commits");
    assert!(keyboard_is_live(&mut harness), "shortcuts work after Tab");

    start_rename(&mut harness, "Dirt", "Never");
    harness.key_press(egui::Key::Escape);
    harness.run();
    assert_eq!(names(&harness), ["Dirt"], "Escape cancels");
    assert!(
        keyboard_is_live(&mut harness),
        "shortcuts work after Escape"
    );

    start_rename(&mut harness, "Dirt", "Wear");
    let away = harness.get_by_label(CANVAS_LABEL).rect().center();
    harness.hover_at(away);
    harness.run();
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: away,
            button: egui::PointerButton::Secondary,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
    harness.run();
    assert_eq!(names(&harness), ["Wear"], "a click elsewhere commits");
    assert!(
        keyboard_is_live(&mut harness),
        "shortcuts work after a click away"
    );
    // One undo step a rename.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(names(&harness), ["Dirt"]);
}

/// Every key press of a frame runs, however many it holds (a held key's repeats, or presses
/// while a slow frame was drawn): eight Ctrl+Z in one frame undo eight steps.
#[test]
fn every_key_press_of_a_slow_frame_is_applied() {
    let mut harness = editor();
    for _ in 0..8 {
        harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::N);
        harness.run();
    }
    assert_eq!(names(&harness).len(), 9);
    for k in 0..8 {
        harness.event(egui::Event::Key {
            key: egui::Key::Z,
            pressed: true,
            modifiers: Modifiers::COMMAND,
            repeat: k > 0,
            physical_key: None,
        });
    }
    harness.step();
    harness.run();
    assert_eq!(names(&harness), ["Layer 1"], "eight presses, eight undos");
}
