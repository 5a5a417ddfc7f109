//! Where a dab lands: the [`Footprint`] trait and the round texel-space [`DiscFootprint`].

use glam::Vec2;

use crate::brush::BrushSettings;
use crate::maps::{MaterialMaps, TexelRect, TileId};
use crate::tile::TILE_SIZE;

/// The texels a dab touches, grouped by tile, each with a weight in `(0, 1]`.
///
/// The 2D brush is a disc in texel space ([`DiscFootprint`]); the 3D brush on meshes is a
/// ball in object space whose texels come from a spatial index of the UV bake, and
/// implements the same trait.
pub trait Footprint: Sync {
    /// The tiles the footprint may touch.
    fn tiles(&self, maps: &MaterialMaps) -> Vec<TileId>;
    /// Calls `f(start, weights)` for runs of consecutive texels of tile `id`: texel indices
    /// `start..start + weights.len()` (row-major in the tile) with those weights (zero allowed).
    fn visit_runs(&self, id: TileId, rect: TexelRect, f: impl FnMut(usize, &[f32]));

    /// Calls `f(index_in_tile, weight)` for every texel of tile `id` with a positive weight.
    fn visit_tile(&self, id: TileId, rect: TexelRect, mut f: impl FnMut(usize, f32)) {
        self.visit_runs(id, rect, |start, weights| {
            for (k, &w) in weights.iter().enumerate() {
                if w > 0.0 {
                    f(start + k, w);
                }
            }
        });
    }
}

/// A round dab in texel space, shaped by the brush's hardness and optional stamp.
pub struct DiscFootprint<'a> {
    /// Centre in texel units.
    pub center: Vec2,
    /// Radius in texels.
    pub radius: f32,
    /// Falloff and stamp.
    pub brush: &'a BrushSettings,
}

impl DiscFootprint<'_> {
    fn bounds(&self, maps: &MaterialMaps) -> Option<TexelRect> {
        let lo = (self.center - self.radius).floor().max(Vec2::ZERO);
        let hi = (self.center + self.radius).ceil();
        let (w, h) = (maps.width() as f32, maps.height() as f32);
        if !(lo.is_finite() && hi.is_finite())
            || lo.x >= w
            || lo.y >= h
            || hi.x <= 0.0
            || hi.y <= 0.0
        {
            return None;
        }
        Some(TexelRect {
            x0: lo.x as u32,
            y0: lo.y as u32,
            x1: hi.x.min(w) as u32,
            y1: hi.y.min(h) as u32,
        })
    }
}

impl Footprint for DiscFootprint<'_> {
    fn tiles(&self, maps: &MaterialMaps) -> Vec<TileId> {
        let Some(TexelRect { x0, y0, x1, y1 }) = self.bounds(maps) else {
            return Vec::new();
        };
        let t = TILE_SIZE as u32;
        let mut ids = Vec::new();
        for ty in y0 / t..=(y1 - 1) / t {
            for tx in x0 / t..=(x1 - 1) / t {
                ids.push((ty * maps.tiles_x() + tx) as usize);
            }
        }
        ids
    }

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn visit_runs(&self, _id: TileId, rect: TexelRect, mut f: impl FnMut(usize, &[f32])) {
        let TexelRect { x0, y0, x1, y1 } = rect;
        let r = self.radius;
        let r2 = r * r;
        let inv_r = 1.0 / r;
        let ys = ((self.center.y - r).floor().max(y0 as f32) as u32).max(y0);
        let ye = ((self.center.y + r).ceil().min(y1 as f32) as u32).min(y1);
        let mut weights = [0.0_f32; TILE_SIZE];
        let inner2 = self.brush.hardness * self.brush.hardness * r2;
        let hard = r2 - inner2 <= r2 * 1e-4;
        let inv_ring = if hard { 0.0 } else { 1.0 / (r2 - inner2) };
        for y in ys..ye {
            let dy = y as f32 + 0.5 - self.center.y;
            let rem = r2 - dy * dy;
            if rem <= 0.0 {
                continue;
            }
            let half = rem.sqrt();
            let xs = ((self.center.x - half - 0.5).ceil().max(x0 as f32) as u32).max(x0);
            let xe = ((self.center.x + half - 0.5).floor() as i64 + 1)
                .clamp(i64::from(x0), i64::from(x1)) as u32;
            if xe <= xs {
                continue;
            }
            let run = &mut weights[..(xe - xs) as usize];
            let dy2 = dy * dy;
            let x_start = xs as f32 + 0.5 - self.center.x;
            if hard {
                for (k, w) in run.iter_mut().enumerate() {
                    let dx = x_start + k as f32;
                    *w = if dx * dx + dy2 < r2 { 1.0 } else { 0.0 };
                }
            } else {
                // BrushSettings::falloff_sq with its constants hoisted: clamping
                // (R^2 - d^2) / (R^2 - (hR)^2) into [0, 1] covers the core and the rim.
                for (k, w) in run.iter_mut().enumerate() {
                    let dx = x_start + k as f32;
                    let t = ((r2 - (dx * dx + dy2)) * inv_ring).clamp(0.0, 1.0);
                    *w = t * t * (3.0 - 2.0 * t);
                }
            }
            if let Some(stamp) = &self.brush.stamp {
                for (k, w) in run.iter_mut().enumerate() {
                    let dx = (xs + k as u32) as f32 + 0.5 - self.center.x;
                    *w *= stamp.sample(dx * inv_r, dy * inv_r);
                }
            }
            f((y - y0) as usize * TILE_SIZE + (xs - x0) as usize, run);
        }
    }
}
