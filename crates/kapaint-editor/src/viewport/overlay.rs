//! What is drawn over the viewport: the split divider, the sides' labels, the heat scale and
//! the legend of the `n` false-colour view.

use egui::{Color32, Pos2, Rect, Sense};

use super::{Compare, Viewport};

impl Viewport {
    /// The split's divider: a handle over the line that drags it (drawn on top of the
    /// viewport, so it wins over painting there).
    pub(super) fn divider_ui(&mut self, ui: &mut egui::Ui, rect: Rect) {
        let x = rect.min.x + rect.width() * self.comparison.split_at;
        let handle = Rect::from_min_max(
            Pos2::new(x - 5.0, rect.min.y),
            Pos2::new(x + 5.0, rect.max.y),
        );
        let response = ui
            .interact(handle, ui.id().with("split divider"), Sense::drag())
            .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
        response.widget_info(|| {
            egui::WidgetInfo::labeled(egui::WidgetType::Other, true, DIVIDER_LABEL)
        });
        if response.dragged()
            && let Some(p) = response.interact_pointer_pos()
        {
            self.comparison.split_at = ((p.x - rect.min.x) / rect.width().max(1.0)).clamp(0.0, 1.0);
        }
    }

    /// The sides' labels, the divider and the heatmap's scale bar.
    pub(super) fn labels_ui(&self, painter: &egui::Painter, rect: Rect) {
        let c = &self.comparison;
        let font = egui::FontId::proportional(13.0);
        let label = |pos: Pos2, align, text: String| {
            painter.text(pos, align, text, font.clone(), Color32::WHITE);
        };
        let top_left = rect.min + egui::vec2(8.0, 8.0);
        let top_right = Pos2::new(rect.max.x - 8.0, rect.min.y + 8.0);
        match c.mode {
            Compare::Single => {}
            Compare::Split => {
                let x = rect.min.x + rect.width() * c.split_at;
                painter.line_segment(
                    [Pos2::new(x, rect.min.y), Pos2::new(x, rect.max.y)],
                    egui::Stroke::new(1.5, Color32::WHITE),
                );
                label(top_left, egui::Align2::LEFT_TOP, c.left.label());
                label(top_right, egui::Align2::RIGHT_TOP, c.right.label());
            }
            Compare::SideBySide => {
                label(top_left, egui::Align2::LEFT_TOP, c.left.label());
                let mid = Pos2::new(rect.center().x + 8.0, rect.min.y + 8.0);
                label(mid, egui::Align2::LEFT_TOP, c.right.label());
            }
            Compare::ThreeWay => {
                for (i, model) in kapaint_reflectance::ShadingModel::ALL
                    .into_iter()
                    .enumerate()
                {
                    let side = super::Side { model, ..c.left };
                    let x = rect.min.x + rect.width() * i as f32 / 3.0 + 8.0;
                    label(
                        Pos2::new(x, rect.min.y + 8.0),
                        egui::Align2::LEFT_TOP,
                        side.label(),
                    );
                }
            }
            Compare::Difference => {
                label(
                    top_left,
                    egui::Align2::LEFT_TOP,
                    format!("|{} - {}|", c.left.label(), c.right.label()),
                );
                heat_scale_ui(painter, rect, c.diff_max);
            }
        }
    }
}

/// The divider's accessible name.
pub const DIVIDER_LABEL: &str = "Split divider";

/// The heatmap's scale bar along the bottom of `rect`: the ramp from 0 to `max`.
fn heat_scale_ui(painter: &egui::Painter, rect: Rect, max: f32) {
    heat_bar(painter, rect, "0", &format!("{max:.3}"));
}

/// The heat ramp as a scale bar along the bottom of `rect`, `low` and `high` under its ends.
pub(crate) fn heat_bar(painter: &egui::Painter, rect: Rect, low: &str, high: &str) {
    let bar = scale_bar(rect);
    ramp_ui(painter, bar, kapaint_core::render::heat_ramp);
    tick(painter, bar, 0.0, low);
    tick(painter, bar, 1.0, high);
}

/// The accessible name of the `n` false-colour legend.
pub const N_LEGEND_LABEL: &str = "n false-colour scale, 0 to 16384, logarithmic";

/// The `n` false-colour view's legend along the bottom of `rect`: the ramp over
/// `ln(1 + n) / ln(1 + 16384)`, with ticks at 0, 10, 100, 1000 and 16384.
pub(super) fn n_legend_ui(ui: &egui::Ui, painter: &egui::Painter, rect: Rect) {
    let bar = scale_bar(rect);
    ramp_ui(painter, bar, |t| {
        let span = (1.0 + f64::from(kapaint_model::texel::N_MAX)).ln() as f32;
        kapaint_core::render::n_false_colour((t * span).exp() - 1.0)
    });
    let span = (1.0 + f64::from(kapaint_model::texel::N_MAX)).ln() as f32;
    for n in [0.0_f32, 10.0, 100.0, 1000.0, 16384.0] {
        tick(painter, bar, (1.0 + n).ln() / span, &format!("{n}"));
    }
    ui.interact(bar, ui.id().with("n legend"), Sense::hover())
        .widget_info(|| egui::WidgetInfo::labeled(egui::WidgetType::Other, true, N_LEGEND_LABEL));
}

impl super::Viewport {
    /// The traced view's status over `rect`: its samples and standard error, or why it does
    /// not fit with a button for the untraced view. Returns whether that button was clicked.
    pub(super) fn traced_ui(
        &self,
        ui: &mut egui::Ui,
        painter: &egui::Painter,
        rect: Rect,
        view: kapaint_core::render::ViewMode,
    ) -> bool {
        let font = egui::FontId::proportional(13.0);
        let at = Pos2::new(rect.min.x + 8.0, rect.max.y - 76.0);
        if let Some(why) = self.traced.refused() {
            let untraced = view.untraced().label();
            painter.text(
                rect.center() - egui::vec2(0.0, 24.0),
                egui::Align2::CENTER_CENTER,
                format!("{why}: showing {untraced} instead"),
                font,
                Color32::from_rgb(230, 120, 110),
            );
            let button = Rect::from_center_size(rect.center(), egui::vec2(200.0, 24.0));
            return ui
                .put(button, egui::Button::new(format!("Show {untraced}")))
                .clicked();
        }
        let text = match self.traced.status() {
            Some((samples, error)) => {
                let error =
                    error.map_or_else(String::new, |e| format!(" · std. error {:.2} %", e * 100.0));
                let state = if self.traced.running() && samples < super::traced::SAMPLES {
                    "tracing"
                } else {
                    "done"
                };
                format!(
                    "{} · {samples} samples per pixel{error} · {state}",
                    view.label()
                )
            }
            None => format!("{} · tracing the first samples…", view.label()),
        };
        painter.text(at, egui::Align2::LEFT_BOTTOM, text, font, Color32::WHITE);
        false
    }
}

/// The accessible name of the view-average error's scale bar.
pub const VIEW_ERROR_LEGEND_LABEL: &str =
    "view-average error scale, relative difference of k_a from k_a per view, 0 to 100 %";

/// The view-average error's scale along the bottom of `rect`: the heat ramp from no
/// difference to [`kapaint_core::render::VIEW_ERROR_TOP`].
pub(super) fn view_error_legend_ui(ui: &egui::Ui, painter: &egui::Painter, rect: Rect) {
    let top = kapaint_core::render::VIEW_ERROR_TOP * 100.0;
    heat_bar(painter, rect, "0 %", &format!("{top:.0} % or more"));
    ui.interact(
        scale_bar(rect),
        ui.id().with("view error legend"),
        Sense::hover(),
    )
    .widget_info(|| {
        egui::WidgetInfo::labeled(egui::WidgetType::Other, true, VIEW_ERROR_LEGEND_LABEL)
    });
}

/// Where a scale bar goes: along the bottom of `rect`.
pub(crate) fn scale_bar(rect: Rect) -> Rect {
    Rect::from_min_size(
        Pos2::new(rect.min.x + 16.0, rect.max.y - 56.0),
        egui::vec2((rect.width() - 32.0).clamp(40.0, 320.0), 12.0),
    )
}

/// Fills `bar` with `ramp(t)` (linear RGB) for `t` from 0 at the left to 1 at the right.
fn ramp_ui(painter: &egui::Painter, bar: Rect, ramp: impl Fn(f32) -> glam::Vec3) {
    let steps = 64;
    let srgb = kapaint_model::texel::linear_to_srgb8;
    for i in 0..steps {
        let t0 = i as f32 / steps as f32;
        let c = ramp(t0 + 0.5 / steps as f32);
        let x0 = bar.min.x + bar.width() * t0;
        painter.rect_filled(
            Rect::from_min_max(
                Pos2::new(x0, bar.min.y),
                Pos2::new(x0 + bar.width() / steps as f32 + 0.5, bar.max.y),
            ),
            0.0,
            Color32::from_rgb(srgb(c.x), srgb(c.y), srgb(c.z)),
        );
    }
}

/// A label under `bar` at `t` (0 left, 1 right), kept inside the bar's ends.
fn tick(painter: &egui::Painter, bar: Rect, t: f32, text: &str) {
    let align = if t <= 0.0 {
        egui::Align2::LEFT_TOP
    } else if t >= 1.0 {
        egui::Align2::RIGHT_TOP
    } else {
        egui::Align2::CENTER_TOP
    };
    painter.text(
        Pos2::new(bar.min.x + bar.width() * t.clamp(0.0, 1.0), bar.max.y + 2.0),
        align,
        text,
        egui::FontId::proportional(12.0),
        Color32::WHITE,
    );
}
