//! Fills and gradients: the commands that write a whole region in one undo step.

use glam::Vec2;

use super::{Document, FillRegion};
use crate::model::ModelError;
use crate::model::paint::{self, GradientShape};

impl Document {
    pub(super) fn fill(&mut self, region: FillRegion) -> Result<(), ModelError> {
        self.end_stroke();
        let target = self.target_for(self.settings.primary);
        let opacity = self.settings.brush.opacity;
        match region {
            FillRegion::All => {
                self.history.begin("Fill");
                paint::fill_all(&mut self.maps, &mut self.history, &target, opacity);
            }
            FillRegion::Similar {
                x,
                y,
                channel,
                tolerance,
            } => {
                if x >= self.maps.width() || y >= self.maps.height() {
                    return Err(ModelError::Command(format!(
                        "fill seed ({x}, {y}) is outside the map"
                    )));
                }
                let mask =
                    paint::flood_region(&self.maps, x, y, channel, tolerance.clamp(0.0, 1.0));
                self.history.begin("Fill similar");
                paint::fill_mask(&mut self.maps, &mut self.history, &target, opacity, &mask);
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
                self.history.begin(label);
                paint::fill_mask(&mut self.maps, &mut self.history, &target, opacity, &mask);
            }
        }
        self.history.end();
        Ok(())
    }

    pub(super) fn gradient(&mut self, shape: GradientShape, start: Vec2, end: Vec2) {
        self.end_stroke();
        if !(start.is_finite() && end.is_finite()) {
            return;
        }
        let from = self.target_for(self.settings.primary);
        let to = self.target_for(self.settings.secondary);
        self.history.begin("Gradient");
        paint::gradient(
            &mut self.maps,
            &mut self.history,
            &from,
            &to,
            shape,
            start,
            end,
            self.settings.brush.opacity,
        );
        self.history.end();
    }
}
