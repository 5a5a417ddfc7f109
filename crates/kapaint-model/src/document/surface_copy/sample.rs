//! Reading the composite (or a mask's gray) between texel centres, for the copy tools on the
//! mesh, whose sources fall anywhere on the map.

use std::sync::Arc;

use glam::Vec2;

use crate::document::copy_dab::value_at;
use crate::layers::SharedMaskTile;
use crate::maps::MaterialMaps;
use crate::texel::decode_unorm;
use crate::tile::{Plane, TILE_SIZE, Tile};

/// The composite's tiles (or a mask's), read bilinearly between texel centres as the layer
/// kernels blend them (`k_d`, `k_s`, `n` in blend space; a mask's gray in the first
/// component), clamped to the map.
pub(super) struct Sampler<'a> {
    tiles: &'a [Arc<Tile>],
    mask: Option<&'a [SharedMaskTile]>,
    maps: &'a MaterialMaps,
    /// `n`'s blend space, by its stored bits.
    blend: &'static [f32],
}

impl<'a> Sampler<'a> {
    /// Reads `tiles` (composite tiles of `maps`), or `mask`'s gray where one is given.
    pub(super) fn new(
        tiles: &'a [Arc<Tile>],
        mask: Option<&'a [SharedMaskTile]>,
        maps: &'a MaterialMaps,
    ) -> Self {
        Self {
            tiles,
            mask,
            maps,
            blend: crate::paint::n_blend_table(),
        }
    }

    /// The value at texel-unit point `at` (texel `(x, y)`'s centre at `(x + 0.5, y + 0.5)`).
    ///
    /// Most points have their four texels in one tile: that tile is found once and its four
    /// texels read directly; the others (a tile's last row or column, the map's border) read
    /// texel by texel, clamped to the map.
    #[inline]
    pub(super) fn sample(&self, at: Vec2) -> [f32; 7] {
        let p = at - 0.5;
        let (x, y) = (floor(p.x), floor(p.y));
        let (fx, fy) = (p.x - x as f32, p.y - y as f32);
        let last = (TILE_SIZE - 1) as i64;
        let (w, h) = (i64::from(self.maps.width()), i64::from(self.maps.height()));
        let inside = x >= 0 && y >= 0 && x + 1 < w && y + 1 < h;
        if !(inside && x % TILE_SIZE as i64 != last && y % TILE_SIZE as i64 != last) {
            return self.sample_clamped((x, y), (fx, fy));
        }
        let (id, i) = self.maps.locate(x as u32, y as u32);
        let at = [i, i + 1, i + TILE_SIZE, i + TILE_SIZE + 1];
        let weights = [
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        ];
        if let Some(mask) = self.mask {
            let gray = mix(mask[id].get(), at, weights, decode_unorm);
            return [gray, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        }
        let tile = &self.tiles[id];
        let [r0, g0, b0] = mix_rgb(&tile.kd, at, weights);
        let [r1, g1, b1] = mix_rgb(&tile.ks, at, weights);
        let n = mix(&tile.n, at, weights, |bits| self.blend[usize::from(bits)]);
        [r0, g0, b0, r1, g1, b1, n]
    }

    /// [`Self::sample`] texel by texel: the four texels from `(x, y)`, each clamped to the
    /// map, weighted by the fractions `(fx, fy)` (a zero weight not read).
    #[cold]
    fn sample_clamped(&self, (x0, y0): (i64, i64), (fx, fy): (f32, f32)) -> [f32; 7] {
        let (w, h) = (i64::from(self.maps.width()), i64::from(self.maps.height()));
        let mut out = [0.0_f32; 7];
        for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                let weight = wx * wy;
                if weight <= 0.0 {
                    continue;
                }
                let x = (x0 + dx).clamp(0, w - 1) as u32;
                let y = (y0 + dy).clamp(0, h - 1) as u32;
                let v = value_at(self.tiles, self.mask, self.maps, (x, y), self.blend);
                for (o, v) in out.iter_mut().zip(v) {
                    *o += v * weight;
                }
            }
        }
        out
    }
}

/// `v` rounded down (without the C library's `floorf`, which the baseline x86-64 target
/// calls out to); a non-finite `v` gives some integer (the caller clamps).
#[inline]
fn floor(v: f32) -> i64 {
    let t = v as i64;
    if t as f32 > v { t - 1 } else { t }
}

/// The texels `at` of a plane, decoded by `f` and weighted.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "a few instructions on the hottest path of the copy tools on the mesh, called out of line otherwise"
)]
fn mix<T: Copy + PartialEq>(
    plane: &Plane<T>,
    at: [usize; 4],
    weights: [f32; 4],
    f: impl Fn(T) -> f32,
) -> f32 {
    match plane {
        Plane::Uniform(v) => f(*v),
        Plane::Data(d) => at.iter().zip(weights).map(|(&i, wt)| f(d[i]) * wt).sum(),
    }
}

/// The texels `at` of an RGB plane (unorm16), weighted.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "a few instructions on the hottest path of the copy tools on the mesh, called out of line otherwise"
)]
fn mix_rgb(plane: &Plane<[u16; 3]>, at: [usize; 4], weights: [f32; 4]) -> [f32; 3] {
    match plane {
        Plane::Uniform(v) => v.map(decode_unorm),
        Plane::Data(d) => {
            let mut sum = [0.0_f32; 3];
            for (&i, wt) in at.iter().zip(weights) {
                for (s, c) in sum.iter_mut().zip(d[i]) {
                    *s += f32::from(c) * wt;
                }
            }
            sum.map(|s| s * (1.0 / 65535.0))
        }
    }
}
