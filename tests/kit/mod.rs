//! The editor under egui_kittest, as the editor test files drive it: a harness on a new
//! document, strokes dragged, waiting for a worker, scratch folders.

use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::model::texel::Texel;
use kapaint::ui::Editor;
use kapaint::ui::files::FileDialogBackend;
use kapaint::ui::viewport::VIEWPORT_LABEL;

pub fn texels(editor: &Editor) -> Vec<Texel> {
    let maps = editor.state.doc().maps();
    let mut out = Vec::with_capacity(maps.texel_count());
    maps.for_each_texel(|_, _, t| out.push(t));
    out
}

/// Drops the untitled recovery copies of test processes that have ended, once a process: an
/// editor test that failed after an autosave leaves one, and every editor made after it
/// would start behind the recovery offer (and fail for that alone). Copies of live processes
/// (this one, a real window a test drives) are left.
fn forget_copies_of_ended_runs() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let dir = kapaint::model::project::state_dir().join("untitled.kapaint-recovery");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return;
        };
        for entry in entries.flatten() {
            // A generation is named HOST-PID-START.
            let name = entry.file_name().to_string_lossy().into_owned();
            let pid = name.rsplit('-').nth(1).and_then(|p| p.parse::<u32>().ok());
            let ended = pid.is_some_and(|p| {
                p != std::process::id() && !std::path::Path::new(&format!("/proc/{p}")).exists()
            });
            if ended {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    });
}

/// The editor on a new default document in a 1400 x 900 window, its first frame drawn.
pub fn editor() -> Harness<'static, Editor> {
    forget_copies_of_ended_runs();
    // The status bar's exact value arrives from a worker whenever it is done and asks for a
    // frame then, and preset thumbnails are drawn a few a frame (again after the mesh
    // changes): more steps than a UI that only reacts to input.
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .with_max_steps(40)
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, None),
        );
    harness.run();
    harness
}

/// The editor started on the project at `path` (as `kapaint edit PATH`), its first frame drawn.
pub fn editor_on(path: &std::path::Path) -> Harness<'static, Editor> {
    forget_copies_of_ended_runs();
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .with_max_steps(40)
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, Some(path.to_path_buf())),
        );
    harness.run();
    harness
}

/// Drags the primary button from `a` to `b` in steps, a frame per step.
pub fn drag(harness: &mut Harness<'_, Editor>, a: Pos2, b: Pos2) {
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

/// Texels that differ between two snapshots of the maps.
pub fn changed(a: &[Texel], b: &[Texel]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// Steps the harness until `done` holds (a worker's job), for at most a minute.
pub fn wait_until(harness: &mut Harness<'_, Editor>, what: &str, done: impl Fn(&Editor) -> bool) {
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
pub fn scratch(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The editor with kapaint's own file dialog (as where no desktop portal runs), starting in
/// `dir`.
pub fn editor_without_portal(dir: &std::path::Path) -> Harness<'static, Editor> {
    let mut harness = editor();
    let files = harness.state_mut().state.files_mut();
    files.force(FileDialogBackend::Builtin);
    files.set_last_dir(dir.to_path_buf());
    harness
}

/// A 2048^2 project of noise (every tile stored, so opening it takes a while).
#[expect(clippy::expect_used, reason = "a test helper: no project, no test")]
pub fn noisy_project(path: &std::path::Path) -> kapaint::model::Document {
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

/// A right-button drag across the viewport, with `modifiers` held, over a few frames.
pub fn right_drag(harness: &mut Harness<'_, Editor>, modifiers: Modifiers, by: Vec2) {
    let a = harness.get_by_label(VIEWPORT_LABEL).rect().center();
    right_drag_from(harness, a, modifiers, by);
}

/// A right-button drag from `a`, with `modifiers` held, over a few frames.
pub fn right_drag_from(harness: &mut Harness<'_, Editor>, a: Pos2, modifiers: Modifiers, by: Vec2) {
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

/// The recovery copy (session folder) `copy` made to look like one an ended editor left: renamed
/// to a process that no longer runs, as after `kill -9`.
#[expect(clippy::expect_used, reason = "a test helper: no rename, no test")]
pub fn as_ended(copy: &std::path::Path) -> std::path::PathBuf {
    use kapaint::model::recovery::session::Owner;
    let gone = Owner {
        pid: 4_194_305,
        ..Owner::this_process().clone()
    };
    let to = copy.with_file_name(gone.file_name());
    std::fs::rename(copy, &to).expect("renamed");
    to
}

#[expect(
    clippy::expect_used,
    reason = "a test helper: no folder field, no test"
)]
/// Replaces the export dialog's folder (showing its default, `export`) with `folder`, as a
/// user does: focus the field, select all, type.
pub fn type_export_folder(harness: &mut Harness<'_, Editor>, folder: &str) {
    harness
        .get_all_by_role(egui::accesskit::Role::TextInput)
        .find(|n| n.value().as_deref() == Some("export"))
        .expect("the folder field")
        .focus();
    harness.step();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness.step();
    harness
        .get_all_by_role(egui::accesskit::Role::TextInput)
        .find(|n| n.value().as_deref() == Some("export"))
        .expect("the folder field")
        .type_text(folder);
    harness.step();
}
