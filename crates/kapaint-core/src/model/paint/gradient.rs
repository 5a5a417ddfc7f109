//! Gradients: a linear or radial blend between two targets over the whole map.

use glam::Vec2;

use super::{PaintTarget, pre_tile};
use crate::model::history::History;
use crate::model::maps::MaterialMaps;
use crate::model::tile::TILE_SIZE;

/// Shape of a gradient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum GradientShape {
    /// Along the line from start to end.
    Linear,
    /// Around the start, reaching the end value at the end point's distance.
    Radial,
}

/// Writes a gradient from `from` (at `start`) to `to` (at `end`) over the whole map, blended
/// at `opacity` with the targets' mode and channels.
#[expect(
    clippy::too_many_arguments,
    reason = "one call site per tool; a struct would only rename them"
)]
pub fn gradient(
    maps: &mut MaterialMaps,
    history: &mut History,
    from: &PaintTarget,
    to: &PaintTarget,
    shape: GradientShape,
    start: Vec2,
    end: Vec2,
    opacity: f32,
) {
    let axis = end - start;
    let len2 = axis.length_squared().max(1e-12);
    for id in 0..maps.tile_count() {
        let crate::model::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
        let pre = pre_tile(history, maps, id);
        let tile = history.tile_for_write(maps, id);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - start;
                let t = match shape {
                    GradientShape::Linear => p.dot(axis) / len2,
                    GradientShape::Radial => (p.length_squared() / len2).sqrt(),
                }
                .clamp(0.0, 1.0);
                let target = PaintTarget {
                    kd: from.kd.lerp(to.kd, t),
                    ks: from.ks.lerp(to.ks, t),
                    n_blend: from.n_blend + (to.n_blend - from.n_blend) * t,
                    ..*from
                };
                let i = (y - y0) as usize * TILE_SIZE + (x - x0) as usize;
                tile.set_texel(i, target.blend(pre.texel(i), opacity));
            }
        }
    }
}
