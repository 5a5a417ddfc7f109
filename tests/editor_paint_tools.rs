//! Issue 56 in the editor, driven through egui_kittest: the Decal tool (an image chosen, a
//! click places it, a drag moves it, Enter commits, Escape takes it back, one undo step) and
//! the stencil (loaded from the panel, placed by right-drags on the canvas or on the viewport,
//! painted through), Image > Project image.

use egui::accesskit::Role;
use egui::{Modifiers, Vec2};
use egui_kittest::kittest::Queryable;
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::files::{FileDialogBackend, FilePurpose, FileRequest};
use kapaint::ui::viewport::VIEWPORT_LABEL;

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

/// The stand-in for the system dialog: spot's texture for an image, nothing else.
fn answer(request: &FileRequest) -> Option<std::path::PathBuf> {
    let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot");
    matches!(
        request.purpose,
        FilePurpose::ToolImage | FilePurpose::StencilImage | FilePurpose::ProjectImage
    )
    .then(|| spot.join("spot_texture.png"))
}

fn labels(editor: &Editor) -> Vec<String> {
    editor
        .state
        .doc()
        .history()
        .undo_steps()
        .map(|s| s.label.clone())
        .collect()
}

fn click(harness: &mut egui_kittest::Harness<'_, Editor>, at: egui::Pos2) {
    harness.hover_at(at);
    harness.run();
    harness.drag_at(at);
    harness.run();
    harness.drop_at(at);
    harness.run();
}

#[test]
fn a_decal_is_placed_moved_committed_and_taken_back_in_the_viewport() {
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);
    harness.key_press(egui::Key::D);
    harness.run();
    assert_eq!(harness.state().state.tools().active().name(), "decal");
    // The brush's settings are not the decal's: the panel shows the decal's own.
    assert_eq!(harness.query_all_by_label("Hardness").count(), 0);
    assert!(harness.query_all_by_label("Rotation").count() > 0);
    harness
        .get_by_role_and_label(Role::Button, "Choose…")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "decal image loaded", |e| {
        e.state
            .notices()
            .iter()
            .any(|n| n.text.contains("spot_texture.png"))
    });
    let blank = texels(harness.state());
    let centre = harness.get_by_label(VIEWPORT_LABEL).rect().center();
    click(&mut harness, centre);
    let placed = texels(harness.state());
    assert!(changed(&blank, &placed) > 100, "the decal is shown at once");
    assert_eq!(labels(harness.state()), ["Place decal"]);
    assert!(harness.state().state.tools().busy(), "waiting for Enter");
    // Dragged: moved over the surface, the same one step.
    drag(&mut harness, centre, centre + Vec2::new(60.0, 10.0));
    let moved = texels(harness.state());
    assert!(changed(&placed, &moved) > 100);
    assert_eq!(labels(harness.state()), ["Place decal"]);
    harness.key_press(egui::Key::Enter);
    harness.run();
    assert!(!harness.state().state.tools().busy(), "committed");
    assert_eq!(texels(harness.state()), moved);
    // A second one, taken back by Escape: the first stays, alone in the history.
    click(&mut harness, centre - Vec2::new(60.0, 0.0));
    assert_eq!(labels(harness.state()), ["Place decal", "Place decal"]);
    harness.key_press(egui::Key::Escape);
    harness.run();
    assert_eq!(labels(harness.state()), ["Place decal"]);
    assert_eq!(texels(harness.state()), moved);
    // Undo takes the committed decal out whole.
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(texels(harness.state()), blank);
}

/// The editor with the brush chosen (its settings shown) and a stencil loaded through the
/// panel.
fn editor_with_stencil() -> egui_kittest::Harness<'static, Editor> {
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);
    harness.key_press(egui::Key::B);
    harness.run();
    assert!(harness.query_all_by_label("Hardness").count() > 0);
    harness
        .get_by_role_and_label(Role::Button, "Load stencil…")
        .click();
    harness.run_steps(2);
    wait_until(&mut harness, "stencil loaded", |e| {
        e.state.doc().stencil().is_some()
    });
    harness
}

#[test]
fn the_stencil_is_loaded_placed_by_right_drags_and_painted_through() {
    let mut harness = editor_with_stencil();
    let stencil = |e: &Editor| {
        let s = e.state.doc().stencil().expect("stencil");
        (s.center, s.size, s.rotation)
    };
    let width = harness.state().state.doc().maps().width() as f32;
    let (centre, size, rotation) = stencil(harness.state());
    assert_eq!(centre, glam::Vec2::splat(width / 2.0));
    assert_eq!((size, rotation), (width / 2.0, 0.0));
    // A right-drag moves it, with Shift scales it, with Ctrl turns it.
    let canvas = harness.get_by_label(CANVAS_LABEL).rect().center();
    let per_point = harness.state().state.canvas_zoom().recip();
    right_drag_from(
        &mut harness,
        canvas,
        Modifiers::default(),
        Vec2::new(40.0, 0.0),
    );
    let (moved, _, _) = stencil(harness.state());
    let want = 40.0 * per_point;
    assert!(
        (moved.x - centre.x - want).abs() < 0.1 * want && (moved.y - centre.y).abs() < 1.0,
        "{moved} from {centre}, {want} texels right"
    );
    right_drag_from(&mut harness, canvas, Modifiers::SHIFT, Vec2::new(30.0, 0.0));
    let (_, larger, _) = stencil(harness.state());
    assert!(larger > 1.2 * size, "{larger} from {size}");
    right_drag_from(
        &mut harness,
        canvas,
        Modifiers::COMMAND,
        Vec2::new(30.0, 0.0),
    );
    let (_, _, turned) = stencil(harness.state());
    assert!(turned > 5.0, "{turned}");
    // Painted through: a stroke paints, and the stencil stays for the next.
    let before = texels(harness.state());
    drag(&mut harness, canvas, canvas + Vec2::new(40.0, 0.0));
    assert!(changed(&before, &texels(harness.state())) > 0);
    assert!(harness.state().state.doc().stencil().is_some());
    // Clear takes it away.
    harness.get_by_role_and_label(Role::Button, "Clear").click();
    harness.run();
    assert!(harness.state().state.doc().stencil().is_none());
}

#[test]
fn a_stencil_on_the_viewport_follows_the_camera_moves_by_a_drag_on_it_and_holds_strokes_back() {
    let mut harness = editor_with_stencil();
    let stencil = |e: &Editor| {
        e.state
            .doc()
            .stencil()
            .map(|s| (**s).clone())
            .expect("stencil")
    };
    assert!(
        stencil(harness.state()).view.is_none(),
        "on the canvas first"
    );
    // On the viewport: over the middle of its picture, half its width wide.
    // (Below the brush's settings: scrolled to first, as a user would.)
    harness.get_by_label("Viewport").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Viewport").click();
    harness.run_steps(2);
    let viewport = harness.get_by_label(VIEWPORT_LABEL).rect();
    let placed = stencil(harness.state());
    let view = placed.view.expect("on the screen");
    assert!(
        (view.size.x - viewport.width()).abs() < 1.0
            && (view.size.y - viewport.height()).abs() < 1.0,
        "{:?} for a viewport of {:?}",
        view.size,
        viewport.size()
    );
    assert_eq!(placed.center, view.size * 0.5);
    // A right-drag that starts on it moves it, and the camera stays.
    right_drag_from(
        &mut harness,
        viewport.center(),
        Modifiers::default(),
        Vec2::new(40.0, 0.0),
    );
    let moved = stencil(harness.state());
    assert!(
        (moved.center.x - placed.center.x - 40.0).abs() < 4.0
            && (moved.center.y - placed.center.y).abs() < 1.0,
        "{} from {}",
        moved.center,
        placed.center
    );
    assert_eq!(moved.view, placed.view, "the camera did not move");
    // One that starts off it orbits the camera; the stencil stays where it is on the screen,
    // on the new view.
    let corner = viewport.min + Vec2::new(12.0, viewport.height() - 12.0);
    right_drag_from(
        &mut harness,
        corner,
        Modifiers::default(),
        Vec2::new(40.0, 0.0),
    );
    let orbited = stencil(harness.state());
    assert_eq!(orbited.center, moved.center);
    let eye = |s: &kapaint::model::paint::Stencil| s.view.expect("view").eye;
    assert!(
        eye(&orbited).distance(eye(&moved)) > 0.05,
        "the camera orbited"
    );
    // A right-drag on the canvas leaves a stencil on the viewport alone (it moved it).
    let canvas = harness.get_by_label(CANVAS_LABEL).rect().center();
    right_drag_from(
        &mut harness,
        canvas,
        Modifiers::default(),
        Vec2::new(40.0, 0.0),
    );
    assert_eq!(stencil(harness.state()).center, orbited.center);
    // A stroke on the mesh through it paints; with the stencil moved off the picture, the
    // same stroke is held back.
    let centre = viewport.center();
    let before = texels(harness.state());
    drag(&mut harness, centre, centre + Vec2::new(30.0, 0.0));
    let painted = texels(harness.state());
    assert!(changed(&before, &painted) > 0, "painted through");
    let image = harness
        .state()
        .state
        .doc()
        .stencil_image()
        .cloned()
        .expect("image");
    harness
        .state_mut()
        .state
        .apply_command(kapaint::model::SettingsCommand::SetStencil {
            image,
            center: glam::Vec2::splat(-10_000.0),
            size: orbited.size,
            rotation: 0.0,
            opacity: 1.0,
            tiled: false,
            view: orbited.view,
        });
    harness.run();
    drag(
        &mut harness,
        centre + Vec2::new(0.0, 20.0),
        centre + Vec2::new(30.0, 20.0),
    );
    assert_eq!(changed(&painted, &texels(harness.state())), 0, "held back");
    // Back on the canvas, the viewport's right button orbits wherever it starts.
    harness.get_by_label("Canvas").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Canvas").click();
    harness.run_steps(2);
    assert!(stencil(harness.state()).view.is_none());
}

#[test]
fn ctrl_click_on_the_mesh_sets_the_clone_source_and_its_marker_shows_there() {
    let mut harness = editor();
    harness.key_press(egui::Key::S);
    harness.run();
    assert!(harness.state().state.viewport_clone_marker().is_none());
    let centre = harness.get_by_label(VIEWPORT_LABEL).rect().center();
    let ctrl_click = |pressed| egui::Event::PointerButton {
        pos: centre,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: Modifiers::COMMAND,
    };
    harness.event(egui::Event::ModifiersChanged(Modifiers::COMMAND));
    harness.event(egui::Event::PointerMoved(centre));
    harness.step();
    harness.event(ctrl_click(true));
    harness.step();
    harness.event(ctrl_click(false));
    harness.event(egui::Event::ModifiersChanged(Modifiers::default()));
    harness.run();
    let (source, offset) = harness
        .state()
        .state
        .doc()
        .surface_clone_source()
        .expect("a source on the mesh");
    assert!(offset.is_none());
    assert!(
        (source.length() - 1.0).abs() < 0.02,
        "on the sphere: {source}"
    );
    assert_eq!(labels(harness.state()), Vec::<String>::new(), "no step");
    // The marker sits where the source was picked, wherever the pointer is.
    harness.hover_at(centre + Vec2::new(50.0, 30.0));
    harness.run();
    let marker = harness
        .state()
        .state
        .viewport_clone_marker()
        .expect("the marker");
    assert!(marker.distance(centre) < 2.0, "{marker:?} vs {centre:?}");
    // A clone stroke on the mesh from there: one step, and the marker then follows the
    // pointer at the stroke's offset.
    let from = centre + Vec2::new(-60.0, 40.0);
    drag(&mut harness, from, from + Vec2::new(30.0, 0.0));
    assert_eq!(labels(harness.state()), ["Clone stroke"]);
    harness.hover_at(from);
    harness.run();
    let marker = harness
        .state()
        .state
        .viewport_clone_marker()
        .expect("the marker");
    assert!(
        marker.distance(centre) < 6.0,
        "at the pointer plus the offset, back at the source: {marker:?} vs {centre:?}"
    );
}

/// Opens Image > Project image.
fn open_project_image(harness: &mut egui_kittest::Harness<'_, Editor>) {
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::System);
    files.set_system_dialog(answer);
    harness.get_by_label("Image").click();
    harness.run_steps(2);
    harness.get_by_label("Project image…").click();
    harness.run_steps(2);
}

/// Chooses spot's texture in the Project image window and waits for it.
fn choose_spot(harness: &mut egui_kittest::Harness<'_, Editor>) {
    harness
        .get_by_role_and_label(Role::Button, "Choose…")
        .click();
    harness.run_steps(2);
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness.query_by_label("spot_texture.png").is_none() {
        assert!(
            std::time::Instant::now() < deadline,
            "the image did not load"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.step();
    }
}

/// Picks projection `kind` in the Project image window.
fn pick_kind(harness: &mut egui_kittest::Harness<'_, Editor>, kind: &str) {
    harness
        .get_by_role_and_label(Role::ComboBox, "Projection")
        .click();
    harness.run();
    harness.get_by_label(kind).click();
    harness.run();
}

#[test]
fn image_project_image_paints_the_chosen_image_through_a_projection_in_one_step() {
    let mut harness = editor();
    open_project_image(&mut harness);
    // Nothing to project before an image is chosen.
    harness
        .get_by_role_and_label(Role::Button, "Project")
        .click();
    harness.run_steps(2);
    assert!(labels(harness.state()).is_empty());
    choose_spot(&mut harness);
    let blank = texels(harness.state());
    harness
        .get_by_role_and_label(Role::Button, "Project")
        .click();
    harness.run_steps(2);
    let projected = texels(harness.state());
    assert!(
        changed(&blank, &projected) > 1000,
        "the image is laid on the mesh"
    );
    assert_eq!(labels(harness.state()), ["Project image"]);
    // Again, tri-planar: its own step.
    pick_kind(&mut harness, "Tri-planar");
    harness
        .get_by_role_and_label(Role::Button, "Project")
        .click();
    harness.run_steps(2);
    assert_eq!(labels(harness.state()), ["Project image", "Project image"]);
    assert!(changed(&projected, &texels(harness.state())) > 1000);
}

#[test]
fn a_projection_fill_is_added_edited_and_made_flat_from_the_window_and_the_layers_tab() {
    let mut harness = editor();
    open_project_image(&mut harness);
    choose_spot(&mut harness);
    let blank = texels(harness.state());
    assert!(harness.query_by_label("Update the fill").is_none());
    harness
        .get_by_role_and_label(Role::Button, "New fill layer")
        .click();
    harness.run_steps(2);
    assert_eq!(labels(harness.state()), ["Add projection fill"]);
    let filled = texels(harness.state());
    assert!(
        changed(&blank, &filled) > 1000,
        "the fill shows on the mesh"
    );
    let doc = harness.state().state.doc();
    let layer = doc.selected_layer().expect("selected");
    assert_eq!(layer.props.name, "spot_texture (projection)");
    assert!(matches!(
        layer.content,
        kapaint_model::layers::LayerContent::Projected(_)
    ));
    // The Layers tab names it; the window, open on it, updates it in one step.
    assert!(
        harness
            .query_by_label("Projection: spot_texture.png, Planar")
            .is_some()
    );
    pick_kind(&mut harness, "Spherical");
    harness
        .get_by_role_and_label(Role::Button, "Update the fill")
        .click();
    harness.run_steps(2);
    assert_eq!(
        labels(harness.state()),
        ["Add projection fill", "Fill projection"]
    );
    assert!(changed(&filled, &texels(harness.state())) > 1000);
    assert!(
        harness
            .query_by_label("Projection: spot_texture.png, Spherical")
            .is_some()
    );
    // A flat fill again, from the Layers tab.
    let flat = harness
        .get_all_by_label("Fill with the primary material")
        .next()
        .expect("the button")
        .rect()
        .center();
    harness.hover_at(flat);
    harness.run();
    harness
        .get_by_label("Fill with the primary material")
        .click();
    harness.run_steps(2);
    assert!(matches!(
        harness
            .state()
            .state
            .doc()
            .selected_layer()
            .expect("selected")
            .content,
        kapaint_model::layers::LayerContent::Fill(_)
    ));
    assert_eq!(labels(harness.state()).len(), 3);
}
