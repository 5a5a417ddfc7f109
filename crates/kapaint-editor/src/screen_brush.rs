//! The brush's size on screen: an option that keeps a brush the same size in screen points
//! whatever the map's resolution, the canvas's zoom or the camera's distance.
//!
//! The model paints in texels, so the editor turns the size on screen into texels at the
//! place a stroke starts (the canvas's zoom, or the size of a screen point on the surface
//! under the cursor) and keeps it for the stroke. The outlines draw the size on screen.

use glam::Vec3;

use super::{EditorState, project};
use kapaint_core::model::SettingsCommand;

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

impl EditorState {
    /// How the brush's size is given.
    pub fn brush_size(&self) -> BrushSize {
        self.tool_panel.brush_size
    }

    /// Sets how the brush's size is given (the radius on screen kept in range).
    pub fn set_brush_size(&mut self, size: BrushSize) {
        let (lo, hi) = (*SCREEN_RADIUS_RANGE.start(), *SCREEN_RADIUS_RANGE.end());
        self.tool_panel.brush_size = BrushSize {
            screen_radius: if size.screen_radius.is_finite() {
                size.screen_radius.clamp(lo, hi)
            } else {
                BrushSize::default().screen_radius
            },
            ..size
        };
    }

    /// Texels per screen point under the cursor this frame, if it is over the map or the mesh.
    pub fn texels_per_point(&self) -> Option<f32> {
        self.pointer.texels_per_point
    }

    /// The brush radius in texels that the size on screen gives under the cursor.
    pub(super) fn screen_radius_in_texels(&self) -> Option<f32> {
        let scale = self.pointer.texels_per_point?;
        Some((self.tool_panel.brush_size.screen_radius * scale).clamp(0.5, 4096.0))
    }

    /// Before a stroke starts: with the size on screen, sets the brush's radius in texels
    /// from the view under the cursor.
    pub(super) fn fit_brush_to_screen(&mut self) {
        if !self.tool_panel.brush_size.on_screen {
            return;
        }
        let Some(radius) = self.screen_radius_in_texels() else {
            return;
        };
        let mut brush = self.doc.settings().brush.clone();
        if (brush.radius_px - radius).abs() > 1e-3 * radius {
            brush.radius_px = radius;
            self.apply(SettingsCommand::SetBrush(brush));
        }
    }

    /// The `[` and `]` keys: the radius shrinks or grows by 1.25, on screen or in texels.
    pub(super) fn scale_brush(
        &mut self,
        brush: &mut kapaint_core::model::brush::BrushSettings,
        by: f32,
    ) {
        if self.tool_panel.brush_size.on_screen {
            let size = BrushSize {
                screen_radius: self.tool_panel.brush_size.screen_radius * by,
                ..self.tool_panel.brush_size
            };
            self.set_brush_size(size);
        } else {
            brush.radius_px = (brush.radius_px * by).clamp(0.5, 2048.0);
        }
    }

    /// The brush radius row of the panel: in texels, or on screen with what it is in texels
    /// under the cursor.
    pub(super) fn brush_radius_ui(
        &mut self,
        ui: &mut egui::Ui,
        brush: &mut kapaint_core::model::brush::BrushSettings,
    ) {
        let mut size = self.tool_panel.brush_size;
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
                && let Some(texels) = self.screen_radius_in_texels()
            {
                ui.weak(format!("= {texels:.1} texels here"));
            }
        });
        if size != self.tool_panel.brush_size {
            self.set_brush_size(size);
        }
    }
}
