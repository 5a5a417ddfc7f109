//! Fills and gradients: the commands that write a whole region of the selected layer or mask
//! in one undo step.

use glam::Vec2;

use super::{Document, FillRegion};
use crate::ModelError;
use crate::layers::LayerStroke;
use crate::layers::edit::{self, LayerEdit};
use crate::paint::{self, GradientShape};

impl Document {
    pub(super) fn fill(&mut self, region: FillRegion) -> Result<(), ModelError> {
        self.end_stroke();
        self.check_paintable()?;
        let (w, h) = (self.maps.width(), self.maps.height());
        let (mask, label) = match region {
            FillRegion::All => (None, "Fill"),
            FillRegion::Similar {
                x,
                y,
                channel,
                tolerance,
            } => {
                if x >= w || y >= h {
                    return Err(ModelError::Command(format!(
                        "fill seed ({x}, {y}) is outside the map"
                    )));
                }
                let mask =
                    paint::flood_region(&self.maps, x, y, channel, tolerance.clamp(0.0, 1.0));
                (Some(mask), "Fill similar")
            }
            FillRegion::Island { x, y } | FillRegion::Part { x, y } => {
                let surface = self.require_surface("filling a UV island or mesh part")?;
                let (mask, label) = if matches!(region, FillRegion::Island { .. }) {
                    (surface.island_mask(x, y), "Fill island")
                } else {
                    (surface.part_mask(x, y), "Fill part")
                };
                let mask = mask.ok_or_else(|| {
                    ModelError::Command(format!("no part of the mesh is at texel ({x}, {y})"))
                })?;
                (Some(mask), label)
            }
        };
        let stroke = LayerStroke::Brush(self.settings.brush.blend);
        let target = self.layer_edit(self.settings.primary, self.settings.primary, stroke);
        let opacity = self.settings.brush.opacity;
        self.edit_planes(label, |mut planes, pre, count| {
            if mask.is_none() && edit::fill_uniform(planes.reborrow(), &target, opacity, count) {
                return;
            }
            let mask = mask.as_deref();
            edit::edit_texels(planes, pre, &target, (w, h), |x, y| {
                mask.is_none_or(|m| m[y as usize * w as usize + x as usize])
                    .then_some((opacity, 0.0))
            });
        })
    }

    pub(super) fn gradient(
        &mut self,
        shape: GradientShape,
        start: Vec2,
        end: Vec2,
    ) -> Result<(), ModelError> {
        self.end_stroke();
        if !(start.is_finite() && end.is_finite()) {
            return Ok(());
        }
        self.check_paintable()?;
        let stroke = LayerStroke::Brush(self.settings.brush.blend);
        let mut target: LayerEdit =
            self.layer_edit(self.settings.primary, self.settings.secondary, stroke);
        // On a mask, white to black (as shown).
        target.gray = [self.stored_gray(1.0), self.stored_gray(0.0)];
        let opacity = self.settings.brush.opacity;
        let (w, h) = (self.maps.width(), self.maps.height());
        let axis = end - start;
        let len2 = axis.length_squared().max(1e-12);
        self.edit_planes("Gradient", |planes, pre, _| {
            edit::edit_texels(planes, pre, &target, (w, h), |x, y| {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - start;
                let t = match shape {
                    GradientShape::Linear => p.dot(axis) / len2,
                    GradientShape::Radial => (p.length_squared() / len2).sqrt(),
                };
                Some((opacity, t.clamp(0.0, 1.0)))
            });
        })
    }
}
