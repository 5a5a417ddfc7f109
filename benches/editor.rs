//! Criterion bench of the editor's CPU side, one frame at a time (egui_kittest, no window, no
//! GPU): the UI and the status bar's readout on a 4096^2 project (every tile painted), with the
//! cursor moving a point a frame over the side panel, the UV canvas or the viewport. Issue 17
//! asks that a frame over the canvas cost no more than one over the panel.
//!
//! `editor_frame_1m_triangles`: a 1024^2 project painted on a 1M-triangle mesh with UVs (the
//! built-in sphere at 1024 x 512, written as an OBJ), frames over the UV canvas with its
//! wireframe shown: the cursor moving (the view still), a pan a frame (middle drag) and a
//! wheel turn a frame (a zoom: the wireframe drawn again every frame).

#![expect(
    clippy::expect_used,
    reason = "bench set-up: a failed expectation is a failed bench"
)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use egui::{Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use kapaint::model::texel::{MaterialValue, Texel};
use kapaint::model::tile::TILE_TEXELS;
use kapaint::model::{Document, DocumentSettings, MaterialMaps, MeshRef, project};
use kapaint::ui::Editor;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::viewport::VIEWPORT_LABEL;

const SIDE: u32 = 4096;

/// A 4096^2 project whose every texel differs from its neighbours (n across its range), saved
/// to a temporary file.
fn project_file() -> std::path::PathBuf {
    painted_project(SIDE, None)
}

/// A `side`^2 project as [`project_file`]'s, painted on the mesh file `mesh` (the built-in
/// sphere without one).
fn painted_project(side: u32, mesh: Option<&std::path::Path>) -> std::path::PathBuf {
    let mut maps = MaterialMaps::new(side, side, MaterialValue::default()).expect("size");
    for id in 0..maps.tile_count() {
        let tile = maps.tile_mut(id);
        for i in 0..TILE_TEXELS {
            let h = (id * TILE_TEXELS + i) as u32;
            let f = |k: u32| (h.wrapping_mul(2_654_435_761).rotate_left(k) % 1000) as f32 / 1000.0;
            tile.set_texel(
                i,
                Texel::encode(MaterialValue::new(
                    glam::Vec3::new(f(0), f(5), f(9)),
                    glam::Vec3::splat(f(13) * 0.5),
                    (f(17) * 9.0).exp2() * 8.0,
                )),
            );
        }
    }
    let settings = DocumentSettings {
        mesh: mesh.map_or(MeshRef::Sphere, |m| {
            MeshRef::from_spec(&m.to_string_lossy())
        }),
        ..DocumentSettings::default()
    };
    let doc = Document::from_parts(maps, settings);
    let path = std::env::temp_dir().join(format!(
        "kapaint-bench-editor-{side}-{}.kapaint",
        std::process::id()
    ));
    project::save(&doc, &path).expect("saved");
    path
}

/// The editor on the project, opened, in a 1400 x 900 window.
fn editor(path: &std::path::Path, side: u32) -> Harness<'static, Editor> {
    let mut harness = Harness::builder()
        .with_size(Vec2::new(1400.0, 900.0))
        .with_max_steps(200)
        .build_ui_state(
            |ui, editor: &mut Editor| editor.frame(ui),
            Editor::new(None, Some(path.to_path_buf())),
        );
    let deadline = std::time::Instant::now() + Duration::from_mins(2);
    while harness.state().state.opening().is_some()
        || harness.state().state.doc().maps().width() != side
    {
        assert!(
            std::time::Instant::now() < deadline,
            "the project did not open"
        );
        std::thread::sleep(Duration::from_millis(20));
        harness.step();
    }
    // Let the thumbnails and the first readouts settle.
    for _ in 0..60 {
        harness.step();
    }
    harness
}

fn frames(c: &mut Criterion) {
    let path = project_file();
    let mut harness = editor(&path, SIDE);
    let canvas = harness.get_by_label(CANVAS_LABEL).rect().center();
    let viewport = harness.get_by_label(VIEWPORT_LABEL).rect().center();
    // The right panel, beside its widgets' labels (empty panel area).
    let panel = Pos2::new(1400.0 - 20.0, 880.0);
    let mut group = c.benchmark_group("editor_frame_4096");
    group
        .sample_size(40)
        .measurement_time(Duration::from_secs(6))
        .warm_up_time(Duration::from_secs(2));
    for (name, at) in [
        ("cursor_over_side_panel", panel),
        ("cursor_over_canvas", canvas),
        ("cursor_over_viewport", viewport),
    ] {
        let mut k = 0u32;
        group.bench_function(name, |b| {
            b.iter(|| {
                // A point a frame, back and forth: a new texel under the cursor most frames.
                k = k.wrapping_add(1);
                let dx = (k % 16) as f32 - 8.0;
                harness.hover_at(at + Vec2::new(dx, 0.0));
                harness.step();
            });
        });
    }
    group.finish();
    let _ = std::fs::remove_file(&path);
}

/// The middle button pressed (or released) at `at`: a pan on the canvas while it is held.
fn middle_button(harness: &mut Harness<'static, Editor>, at: Pos2, pressed: bool) {
    harness.event(egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Middle,
        pressed,
        modifiers: egui::Modifiers::NONE,
    });
}

/// Frames over the UV canvas of a project on a 1M-triangle mesh (see the module's notes).
fn huge_mesh_frames(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("kapaint-bench-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let obj = dir.join("sphere_1m.obj");
    let mesh = kapaint::mesh::uv_sphere(1024, 512);
    std::fs::write(&obj, kapaint::mesh::write_obj(&mesh)).expect("mesh written");
    let path = painted_project(1024, Some(&obj));
    let mut harness = editor(&path, 1024);
    let canvas = harness.get_by_label(CANVAS_LABEL).rect().center();
    let mut group = c.benchmark_group("editor_frame_1m_triangles");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(10))
        .warm_up_time(Duration::from_secs(2));
    let mut k = 0u32;
    group.bench_function("canvas_still", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            harness.hover_at(canvas + Vec2::new((k % 16) as f32 - 8.0, 0.0));
            harness.step();
        });
    });
    harness.hover_at(canvas);
    middle_button(&mut harness, canvas, true);
    group.bench_function("canvas_pan", |b| {
        b.iter(|| {
            // Back and forth, 3 points a frame.
            k = k.wrapping_add(1);
            let dx = ((k % 32) as f32 - 16.0).abs() * 3.0 - 24.0;
            harness.hover_at(canvas + Vec2::new(dx, 0.0));
            harness.step();
        });
    });
    middle_button(&mut harness, canvas, false);
    group.bench_function("canvas_zoom", |b| {
        b.iter(|| {
            // In and out in turn: the view changes every frame.
            k = k.wrapping_add(1);
            let dy = if k.is_multiple_of(2) { 40.0 } else { -40.0 };
            harness.event(egui::Event::MouseWheel {
                unit: egui::MouseWheelUnit::Point,
                delta: Vec2::new(0.0, dy),
                phase: egui::TouchPhase::Move,
                modifiers: egui::Modifiers::NONE,
            });
            harness.step();
        });
    });
    group.finish();
    let _ = std::fs::remove_file(&path);
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, frames, huge_mesh_frames);
criterion_main!(benches);
