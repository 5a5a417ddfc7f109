//! The third model in the editor, driven through egui_kittest: the model buttons, the
//! approximation it ignores, the status bar's k_a by all three models and the three-way
//! compare.

use egui_kittest::kittest::Queryable;
use kapaint::reflectance::ShadingModel;
use kapaint::ui::canvas::CANVAS_LABEL;
use kapaint::ui::viewport::Compare;

#[expect(dead_code, reason = "each editor test file uses some of the helpers")]
mod kit;
use kit::*;

#[test]
fn cook_torrance_is_chosen_compared_and_read_out_like_the_others() {
    let mut harness = editor();
    harness.get_by_label("Cook-Torrance").click();
    harness.run();
    assert_eq!(
        harness.state().state.doc().settings().model,
        ShadingModel::CookTorrance
    );
    // The status bar: k_a under the cursor by all three models, and the exact integral of
    // the current one, integrated on the worker (never on the UI thread).
    let before = kapaint::reflectance::exact::calls_on_this_thread();
    let canvas = harness.get_by_label(CANVAS_LABEL).rect();
    harness.hover_at(canvas.center());
    harness.run();
    harness.get_by_label_contains("eq.11 0.");
    harness.get_by_label_contains("CT 0.");
    let deadline = std::time::Instant::now() + std::time::Duration::from_mins(1);
    while harness.query_by_label_contains("exact 0.").is_none() {
        assert!(std::time::Instant::now() < deadline, "no exact value");
        std::thread::sleep(std::time::Duration::from_millis(50));
        harness.run();
    }
    assert_eq!(kapaint::reflectance::exact::calls_on_this_thread(), before);
    // The readout's CT value and the exact one agree to the fit's accuracy (4 decimals).
    let text = harness
        .query_by_label_contains("exact 0.")
        .and_then(|n| {
            let node = egui_kittest::kittest::NodeT::accesskit_node(&n);
            node.label().or_else(|| node.value())
        })
        .unwrap_or_default();
    let after = |key: &str| -> f64 {
        text.split(key)
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    };
    assert!((after("CT ") - after("exact ")).abs() <= 1e-4, "{text}");
    // All three side by side.
    harness.get_by_label("All three").click();
    harness.run();
    assert_eq!(harness.state().state.comparison().mode, Compare::ThreeWay);
    harness.get_by_label_contains("Phong, Blinn-Phong and Cook-Torrance");
}
