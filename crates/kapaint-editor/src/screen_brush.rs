//! The brush's size on screen: an option that keeps a brush the same size in screen points
//! whatever the map's resolution, the canvas's zoom or the camera's distance.
//!
//! The model paints in texels, so the editor turns the size on screen into texels at the
//! place a stroke starts (the canvas's zoom, or the size of a screen point on the surface
//! under the cursor) and keeps it for the stroke. The outlines draw the size on screen.

use glam::Vec3;

use super::project;
use kapaint_model::brush::BrushSettings;

/// How the brush's size is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushSize {
    /// The size follows the screen (`screen_radius`), not the map (the brush's texels).
    pub on_screen: bool,
    /// The radius on screen, in points, `[1, 1024]`.
    pub screen_radius: f32,
}

impl Default for BrushSize {
    fn default() -> Self {
        Self {
            on_screen: false,
            screen_radius: 24.0,
        }
    }
}

/// Smallest and largest radius on screen, in points.
pub const SCREEN_RADIUS_RANGE: std::ops::RangeInclusive<f32> = 1.0..=1024.0;

/// Screen points per world unit at `at`, seen by `camera` in `picture`: the projected length
/// of a short step across the view there.
pub fn points_per_world(
    camera: &kapaint_core::render::Camera,
    picture: egui::Rect,
    at: Vec3,
) -> Option<f32> {
    let view_proj = camera.view_proj(picture.width() / picture.height().max(1.0));
    let step = camera.eye().distance(at).max(1e-6) * 0.01;
    let across = camera.rotation() * Vec3::X * step;
    let a = project(view_proj, picture, at)?;
    let b = project(view_proj, picture, at + across)?;
    let d = a.distance(b) / step;
    (d.is_finite() && d > 0.0).then_some(d)
}

impl BrushSize {
    /// This size with its radius on screen kept in range.
    #[must_use]
    pub fn clamped(self) -> Self {
        let (lo, hi) = (*SCREEN_RADIUS_RANGE.start(), *SCREEN_RADIUS_RANGE.end());
        Self {
            screen_radius: if self.screen_radius.is_finite() {
                self.screen_radius.clamp(lo, hi)
            } else {
                Self::default().screen_radius
            },
            ..self
        }
    }

    /// The brush radius in texels that the size on screen gives where a screen point is
    /// `texels_per_point` texels.
    pub(crate) fn radius_in_texels(self, texels_per_point: Option<f32>) -> Option<f32> {
        Some((self.screen_radius * texels_per_point?).clamp(0.5, 4096.0))
    }

    /// Before a stroke starts: with the size on screen, the brush with its radius in texels
    /// from the view under the cursor, if that changes it.
    pub(crate) fn fitted_brush(
        self,
        brush: &BrushSettings,
        texels_per_point: Option<f32>,
    ) -> Option<BrushSettings> {
        if !self.on_screen {
            return None;
        }
        let radius = self.radius_in_texels(texels_per_point)?;
        ((brush.radius_px - radius).abs() > 1e-3 * radius).then(|| BrushSettings {
            radius_px: radius,
            ..brush.clone()
        })
    }

    /// The `[` and `]` keys: the radius shrinks or grows by `by`, on screen or in texels.
    pub(crate) fn scale(&mut self, brush: &mut BrushSettings, by: f32) {
        if self.on_screen {
            *self = Self {
                screen_radius: self.screen_radius * by,
                ..*self
            }
            .clamped();
        } else {
            brush.radius_px = (brush.radius_px * by).clamp(0.5, 2048.0);
        }
    }

    /// The brush radius row of the tool panel: in texels, or on screen with what it is in
    /// texels under the cursor.
    pub(crate) fn radius_ui(
        &mut self,
        ui: &mut egui::Ui,
        brush: &mut BrushSettings,
        texels_per_point: Option<f32>,
    ) {
        let mut size = *self;
        if size.on_screen {
            ui.add(
                egui::Slider::new(&mut size.screen_radius, SCREEN_RADIUS_RANGE)
                    .logarithmic(true)
                    .suffix(" px")
                    .text("Radius on screen"),
            )
            .on_hover_text("[ and ] change the size; a stroke takes it in texels where it starts");
        } else {
            ui.add(
                egui::Slider::new(&mut brush.radius_px, 0.5..=512.0)
                    .logarithmic(true)
                    .text("Radius"),
            )
            .on_hover_text("In texels of the map; [ and ] change the size");
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut size.on_screen, "Size on screen")
                .on_hover_text(
                    "The brush keeps its size on screen at any zoom or map resolution, \
                 rather than its size in texels",
                );
            if size.on_screen
                && let Some(texels) = size.radius_in_texels(texels_per_point)
            {
                ui.weak(format!("= {texels:.1} texels here"));
            }
        });
        if size != *self {
            *self = size.clamped();
        }
    }
}
