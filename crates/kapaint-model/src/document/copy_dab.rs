//! The strokes that paint what the maps hold: clone (what was at the source before the
//! stroke, aligned) and smudge (what is under the brush, dragged along).
//!
//! Both read the composite (what the artist sees) and write the selected layer's planes with
//! the layer engine's per-texel targets; on a mask they read and write the mask's gray. A
//! clone dab raises the stroke's coverage as the brush does, each texel it rose at taking its
//! pre-stroke value towards its source at that coverage (so overlapping dabs never add up
//! past the opacity); a smudge dab moves each texel towards what lay one dab-step behind it,
//! at the dab's weight times the strength, `n` in blend space (log space) as every `n` blend.

use std::sync::Arc;

use glam::Vec2;

use crate::layers::SharedMaskTile;
use crate::layers::edit::{self, LayerEdit, Planes, PrePlanes, TileTargets};
use crate::maps::MaterialMaps;
use crate::paint::{Coverage, Footprint};
use crate::texel::decode_unorm;
use crate::tile::{Plane, TILE_SIZE, TILE_TEXELS, Tile, TileSpans};

/// What a clone stroke reads: the composite and the mask as they were before it.
pub(super) struct CloneSource {
    /// The composite's tiles before the stroke.
    pub(super) tiles: Vec<Arc<Tile>>,
    /// Texels from a stroke's point to its source (whole texels: a copy, not a resample).
    pub(super) offset: Vec2,
    /// On the mesh: object units from a stroke's point to its source (the source is then
    /// found in object space, see `surface_clone`).
    pub(super) object: Option<glam::Vec3>,
}

/// The value of a composite tile's texel `i`, as the layer kernels blend it (`k_d`, `k_s`,
/// `n` in blend space): [`decode_tile_run`] of one texel.
#[inline]
fn edit_value(tile: &Tile, i: usize, blend: &[f32]) -> [f32; 7] {
    let mut out = [[0.0; 7]];
    decode_tile_run(tile, i, &mut out, blend);
    out[0]
}

/// A mask's stored gray at texel `(x, y)`.
#[inline]
fn mask_gray(tiles: &[SharedMaskTile], maps: &MaterialMaps, x: u32, y: u32) -> f32 {
    let (id, i) = maps.locate(x, y);
    decode_unorm(tiles[id].get().get(i))
}

/// What a texel of the map holds as a target: the composite's value, or the mask's gray.
#[inline]
pub(super) fn value_at(
    tiles: &[Arc<Tile>],
    mask: Option<&[SharedMaskTile]>,
    maps: &MaterialMaps,
    (x, y): (u32, u32),
    blend: &[f32],
) -> [f32; 7] {
    if let Some(m) = mask {
        [mask_gray(m, maps, x, y), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    } else {
        let (id, i) = maps.locate(x, y);
        edit_value(&tiles[id], i, blend)
    }
}

/// Texels `i..i + out.len()` of a composite tile as the layer kernels blend them (`k_d`,
/// `k_s`, `n` in blend space), a plane at a time.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn decode_tile_run(tile: &Tile, i: usize, out: &mut [[f32; 7]], blend: &[f32]) {
    let n = out.len();
    for (plane, first) in [(&tile.kd, 0), (&tile.ks, 3)] {
        match plane {
            Plane::Uniform(v) => {
                let v = v.map(decode_unorm);
                for o in out.iter_mut() {
                    o[first..first + 3].copy_from_slice(&v);
                }
            }
            Plane::Data(d) => {
                for (o, v) in out.iter_mut().zip(&d[i..i + n]) {
                    for c in 0..3 {
                        o[first + c] = decode_unorm(v[c]);
                    }
                }
            }
        }
    }
    match &tile.n {
        Plane::Uniform(bits) => {
            let v = blend[*bits as usize];
            for o in out.iter_mut() {
                o[6] = v;
            }
        }
        Plane::Data(d) => {
            for (o, &bits) in out.iter_mut().zip(&d[i..i + n]) {
                o[6] = blend[bits as usize];
            }
        }
    }
}

/// Row `y` of the map (clamped to it) from column `x0` for `out.len()` texels (columns
/// clamped too), as targets: a tile at a time, with the row's texels in a plain loop.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn decode_row(
    tiles: &[Arc<Tile>],
    mask: Option<&[SharedMaskTile]>,
    maps: &MaterialMaps,
    (x0, y): (i64, i64),
    out: &mut [[f32; 7]],
    blend: &[f32],
) {
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    let y = y.clamp(0, h - 1) as u32;
    let mut k = 0;
    while k < out.len() {
        let x = x0 + k as i64;
        if x < 0 || x >= w {
            let edge = x.clamp(0, w - 1) as u32;
            out[k] = value_at(tiles, mask, maps, (edge, y), blend);
            k += 1;
            continue;
        }
        // The run inside one tile.
        let (id, i) = maps.locate(x as u32, y);
        let in_tile = TILE_SIZE - (x as usize % TILE_SIZE);
        let n = in_tile.min(out.len() - k).min((w - x) as usize);
        let run = &mut out[k..k + n];
        if let Some(m) = mask {
            let plane = m[id].get();
            for (j, o) in run.iter_mut().enumerate() {
                *o = [decode_unorm(plane.get(i + j)), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            }
        } else {
            decode_tile_run(&tiles[id], i, run, blend);
        }
        k += n;
    }
}

/// A clone dab raising the stroke's coverage by `raise` (see the module's notes). Texels
/// whose source lies off the map are not written. Returns, per tile of `ids`, the texels
/// written.
pub(super) fn clone_dab(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    target: &LayerEdit,
    coverage: &mut Coverage,
    (maps, ids): (&MaterialMaps, &[usize]),
    source: &CloneSource,
    raise: &impl edit::Raise,
) -> Vec<TileSpans> {
    let covers = coverage.tiles_mut(maps.tile_count(), ids);
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    let (ox, oy) = (source.offset.x as i64, source.offset.y as i64);
    let mask = match pre {
        PrePlanes::Mask(m) => Some(m),
        PrePlanes::Paint(_) => None,
    };
    let prepare = CloneTile {
        raise,
        maps,
        source,
        mask,
        blend: crate::paint::n_blend_table(),
        offset: (ox, oy),
        size: (w, h),
    };
    edit::edit_varying((planes, pre), target, ids, covers, &prepare)
}

/// A clone dab's tile for [`edit::edit_varying`]: the coverage raised, then each texel it
/// rose at targets its source (a struct, not a closure, so that it is compiled into the
/// vectorised kernel).
struct CloneTile<'a, R> {
    raise: &'a R,
    maps: &'a MaterialMaps,
    source: &'a CloneSource,
    mask: Option<&'a [SharedMaskTile]>,
    blend: &'a [f32],
    /// The source offset in whole texels.
    offset: (i64, i64),
    /// The map's size.
    size: (i64, i64),
}

impl<R: edit::Raise> edit::Prepare for CloneTile<'_, R> {
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn prepare(&self, id: usize, cover: &mut [f32], targets: &mut TileTargets) -> TileSpans {
        let ((ox, oy), (w, h)) = (self.offset, self.size);
        let rose = self.raise.raise(id, cover);
        let rect = self.maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        for (y, x0, x1) in rose.rows() {
            let sy = i64::from(rect.y0) + y as i64 + oy;
            let sx0 = i64::from(rect.x0) + x0 as i64 + ox;
            let (start, end) = (y * TILE_SIZE + x0, y * TILE_SIZE + x1);
            decode_row(
                &self.source.tiles,
                self.mask,
                self.maps,
                (sx0, sy),
                &mut targets[start..end],
                self.blend,
            );
            for (k, c) in cover[start..end].iter_mut().enumerate() {
                let sx = sx0 + k as i64;
                if sx < 0 || sy < 0 || sx >= w || sy >= h {
                    // Its source is off the map for the whole stroke (the offset is fixed).
                    *c = 0.0;
                }
            }
            written.include_run(start, end);
        }
        written
    }
}

/// A smudge dab through `fp` at `strength`, the brush having moved `step` texels since the
/// last dab: each texel moves towards what lay `step` behind it (see the module's notes).
/// Returns, per tile of `ids`, the texels written.
pub(super) fn smudge_dab(
    planes: Planes<'_>,
    target: &LayerEdit,
    (maps, ids): (&MaterialMaps, &[usize]),
    fp: &impl Footprint,
    strength: f32,
    step: Vec2,
) -> Vec<TileSpans> {
    let mut scratch: Vec<Vec<f32>> = ids.iter().map(|_| vec![0.0; TILE_TEXELS]).collect();
    let covers: Vec<&mut [f32]> = scratch.iter_mut().map(Vec::as_mut_slice).collect();
    from_now(planes, ids, |planes, pre, mask| {
        smudge_from(
            (planes, pre, mask),
            target,
            (maps, ids),
            (fp, strength, step),
            covers,
        )
    })
}

/// Runs `f` on the planes, the same planes as they are now at tiles `ids` (what a smudge dab
/// blends from: the dabs before it included; a paint layer's other tiles are left out, as
/// only the tiles written are read), and a mask's own planes as they are now (all of them:
/// a smudge on a mask reads its neighbours).
pub(super) fn from_now<R>(
    planes: Planes<'_>,
    ids: &[usize],
    f: impl FnOnce(Planes<'_>, PrePlanes<'_>, Option<&[SharedMaskTile]>) -> R,
) -> R {
    match planes {
        Planes::Paint(tiles) => {
            let mut now = vec![None; tiles.len()];
            for &id in ids {
                now[id].clone_from(&tiles[id]);
            }
            f(Planes::Paint(tiles), PrePlanes::Paint(&now), None)
        }
        Planes::Mask(tiles) => {
            let now = tiles.to_vec();
            f(Planes::Mask(tiles), PrePlanes::Mask(&now), Some(&now))
        }
    }
}

/// [`smudge_dab`] once the planes as they are now are at hand.
fn smudge_from(
    (planes, pre, mask): (Planes<'_>, PrePlanes<'_>, Option<&[SharedMaskTile]>),
    target: &LayerEdit,
    (maps, ids): (&MaterialMaps, &[usize]),
    (fp, strength, step): (&impl Footprint, f32, Vec2),
    covers: Vec<&mut [f32]>,
) -> Vec<TileSpans> {
    let blend = crate::paint::n_blend_table();
    // Texel centres are whole texels apart, so every texel reads its four neighbours at the
    // same whole offset and with the same bilinear weights.
    // Texel (x, y) reads the point (x, y) - step between texel centres: (x + ix, y + iy)
    // and its right and lower neighbours, at (fx, fy) between them.
    let back = -step;
    let (ix, iy) = (back.x.floor(), back.y.floor());
    let (fx, fy) = (back.x - ix, back.y - iy);
    let (ix, iy) = (ix as i64, iy as i64);
    let weights = [
        (1.0 - fx) * (1.0 - fy),
        fx * (1.0 - fy),
        (1.0 - fx) * fy,
        fx * fy,
    ];
    let prepare = SmudgeTile {
        fp,
        maps,
        tiles: maps.tiles(),
        mask,
        blend,
        strength,
        offset: (ix, iy),
        weights,
    };
    edit::edit_varying((planes, pre), target, ids, covers, &prepare)
}

/// A smudge dab's tile for [`edit::edit_varying`]: each texel's coverage, and its target
/// blended from the composite one step behind (a struct, not a closure, so that it is
/// compiled into the vectorised kernel).
struct SmudgeTile<'a, F> {
    fp: &'a F,
    maps: &'a MaterialMaps,
    tiles: &'a [Arc<Tile>],
    mask: Option<&'a [SharedMaskTile]>,
    blend: &'a [f32],
    strength: f32,
    /// Whole texels from a texel to the top-left of the four it reads.
    offset: (i64, i64),
    /// The four taps' bilinear weights.
    weights: [f32; 4],
}

impl<F: Footprint> edit::Prepare for SmudgeTile<'_, F> {
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn prepare(&self, id: usize, cover: &mut [f32], targets: &mut TileTargets) -> TileSpans {
        let rect = self.maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        SOURCE_ROWS.with_borrow_mut(|rows| {
            // Source row r is map row rect.y0 + r + iy, column c map column rect.x0 + c + ix:
            // each texel of it decoded once, for the run above it and the run on it.
            rows.reset();
            let decode = |(r, c0): (usize, usize), out: &mut [[f32; 7]]| {
                let sy = i64::from(rect.y0) + r as i64 + self.offset.1;
                let sx = i64::from(rect.x0) + c0 as i64 + self.offset.0;
                decode_row(self.tiles, self.mask, self.maps, (sx, sy), out, self.blend);
            };
            self.fp.visit_runs(id, rect, |start, dab| {
                let (y, x0) = (start / TILE_SIZE, start % TILE_SIZE);
                let n = dab.len();
                rows.ensure((y, x0, x0 + n + 1), decode);
                rows.ensure((y + 1, x0, x0 + n + 1), decode);
                // The taps of a run as flat components: texel k's are at 7k, its right
                // neighbour's at 7k + 7, so the blend is one plain loop over the run.
                let top = rows.row(y)[x0..=x0 + n].as_flattened();
                let bottom = rows.row(y + 1)[x0..=x0 + n].as_flattened();
                let out = targets[start..start + n].as_flattened_mut();
                let len = out.len();
                let [w0, w1, w2, w3] = self.weights;
                for ((((o, &a), &b), &c), &d) in out
                    .iter_mut()
                    .zip(&top[..len])
                    .zip(&top[7..])
                    .zip(&bottom[..len])
                    .zip(&bottom[7..])
                {
                    *o = a * w0 + b * w1 + c * w2 + d * w3;
                }
                let run = &mut cover[start..start + n];
                for (c, &wgt) in run.iter_mut().zip(dab) {
                    *c = (wgt * self.strength).min(1.0);
                }
                let first = run.iter().position(|&a| a > 0.0);
                if let (Some(first), Some(last)) = (first, run.iter().rposition(|&a| a > 0.0)) {
                    written.include_run(start + first, start + last + 1);
                }
            });
        });
        written
    }
}

/// Row stride of [`SourceRows`]: a tile's columns and the one right of them.
const SOURCE_STRIDE: usize = TILE_SIZE + 1;

/// The source rows a smudge dab reads for one tile (its rows and the one below, its
/// columns and the one right), decoded as the runs ask for them, each texel once.
#[derive(Default)]
struct SourceRows {
    /// The decoded columns of each row, `lo..hi` (empty: `lo >= hi`).
    ranges: Vec<(usize, usize)>,
    data: Vec<[f32; 7]>,
}

impl SourceRows {
    fn reset(&mut self) {
        self.ranges.clear();
        self.ranges.resize(SOURCE_STRIDE, (0, 0));
        self.data.resize(SOURCE_STRIDE * SOURCE_STRIDE, [0.0; 7]);
    }

    /// Makes columns `c0..c1` of row `r` decoded, through `decode((r, c), out)` for the
    /// columns from `c` that are not yet.
    fn ensure(
        &mut self,
        (r, c0, c1): (usize, usize, usize),
        decode: impl Fn((usize, usize), &mut [[f32; 7]]),
    ) {
        let row = &mut self.data[r * SOURCE_STRIDE..(r + 1) * SOURCE_STRIDE];
        let (lo, hi) = self.ranges[r];
        if lo >= hi {
            decode((r, c0), &mut row[c0..c1]);
            self.ranges[r] = (c0, c1);
            return;
        }
        // Grown at either end (a gap between is decoded too, keeping one range a row).
        if c0 < lo {
            decode((r, c0), &mut row[c0..lo]);
        }
        if c1 > hi {
            decode((r, hi), &mut row[hi..c1]);
        }
        self.ranges[r] = (lo.min(c0), hi.max(c1));
    }

    fn row(&self, r: usize) -> &[[f32; 7]] {
        &self.data[r * SOURCE_STRIDE..(r + 1) * SOURCE_STRIDE]
    }
}

thread_local! {
    /// A worker's [`SourceRows`], kept from tile to tile.
    static SOURCE_ROWS: std::cell::RefCell<SourceRows> = std::cell::RefCell::new(SourceRows::default());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each texel of a source row is decoded once, however the runs that read it overlap,
    /// and every column a run asks for holds its own decoded value.
    #[test]
    fn source_rows_decode_each_texel_once() {
        let decoded = std::cell::RefCell::new(vec![0_u32; SOURCE_STRIDE * SOURCE_STRIDE]);
        let decode = |(r, c0): (usize, usize), out: &mut [[f32; 7]]| {
            for (k, o) in out.iter_mut().enumerate() {
                decoded.borrow_mut()[r * SOURCE_STRIDE + c0 + k] += 1;
                *o = [(r * 100 + c0 + k) as f32; 7];
            }
        };
        let mut rows = SourceRows::default();
        rows.reset();
        // A disc's runs: growing, shrinking, one off to the side, and the last column.
        for &(r, c0, c1) in &[(3, 10, 20), (3, 5, 25), (3, 8, 12), (3, 40, 45), (4, 0, 65)] {
            rows.ensure((r, c0, c1), decode);
            for c in c0..c1 {
                assert_eq!(rows.row(r)[c][0], (r * 100 + c) as f32);
            }
        }
        assert!(decoded.borrow().iter().all(|&n| n <= 1));
        // Reset between tiles: decoded afresh.
        rows.reset();
        rows.ensure((3, 10, 12), decode);
        assert_eq!(decoded.borrow()[3 * SOURCE_STRIDE + 10], 2);
    }
}
