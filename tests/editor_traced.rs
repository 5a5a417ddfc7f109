//! The traced views in the editor, driven through egui_kittest: chosen from the view list, they
//! accumulate on a worker while the UI thread stays light, and start again when the camera
//! moves.

use egui_kittest::kittest::Queryable;
use kapaint::render::ViewMode;

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

/// CPU seconds this thread has run (not the wall clock: the trace runs beside it on the
/// other cores, and a busy machine stretches wall time, not this).
fn thread_cpu_seconds() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

#[test]
fn the_traced_view_accumulates_beside_a_light_ui_thread_and_restarts_on_a_move() {
    let mut harness = editor();
    harness.get_by_label("View mode").click();
    harness.run();
    harness.get_by_label("k_a traced").click();
    // A traced view asks for frames while it accumulates: step, never run to rest.
    harness.run_steps(2);
    assert_eq!(
        harness.state().state.frame_settings().view,
        ViewMode::KaTraced
    );
    // Frames while it accumulates: each costs the UI thread little CPU.
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(2);
    let mut worst = 0.0_f64;
    let mut frames = 0;
    let reached = loop {
        let before = thread_cpu_seconds();
        harness.step();
        worst = worst.max(thread_cpu_seconds() - before);
        frames += 1;
        match harness.state().state.traced_status() {
            Some((samples, Some(error))) if samples >= 32 => break (samples, error),
            _ => {}
        }
        assert!(
            std::time::Instant::now() < deadline,
            "no 32 samples in 2 minutes"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    eprintln!(
        "{frames} frames to {} samples (std. error {:.2} %): worst UI-thread frame {:.1} ms CPU",
        reached.0,
        reached.1 * 100.0,
        worst * 1000.0
    );
    assert!(worst < 0.05, "a frame took {:.1} ms of CPU", worst * 1000.0);
    assert!(reached.1 < 0.05, "std. error {}", reached.1);
    // Orbit the camera: the trace starts again from no samples.
    right_drag(
        &mut harness,
        egui::Modifiers::default(),
        egui::Vec2::new(60.0, 0.0),
    );
    let after = harness.state().state.traced_status();
    assert!(
        after.is_none_or(|(s, _)| s < reached.0),
        "{after:?} after a move, {reached:?} before"
    );
    // Another view stops it.
    harness.get_by_label("View mode").click();
    harness.run_steps(2);
    harness.get_by_label("k_a").click();
    harness.run();
    assert_eq!(harness.state().state.traced_status(), None);
}

/// The AO stand-in's error view on a project without an AO bake says what it needs and offers
/// the untraced view; a click there switches to it.
#[test]
fn the_ao_view_without_a_bake_offers_the_untraced_view() {
    let mut harness = editor();
    harness.get_by_label("View mode").click();
    harness.run();
    harness.get_by_label("k_a × AO error").click();
    harness.run_steps(3);
    assert_eq!(harness.state().state.traced_status(), None);
    harness.get_by_label("Show view-average error").click();
    harness.run_steps(3);
    assert_eq!(
        harness.state().state.frame_settings().view,
        ViewMode::KaViewError
    );
}
