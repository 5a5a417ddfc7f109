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
use crate::layers::edit::{self, Components, LayerEdit, Planes, PrePlanes, TileTargets, set_run};
use crate::maps::MaterialMaps;
use crate::paint::{Coverage, Footprint};
use crate::texel::decode_unorm;
use crate::tile::{TILE_SIZE, Tile, TileSpans};

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
    let mut out = [0.0; 7];
    decode_tile_run(tile, i, out.each_mut().map(std::slice::from_mut), blend);
    out
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

/// Texels `i..` of a composite tile as the layer kernels blend them (`k_d`, `k_s`, `n` in
/// blend space), a component into each of `out` (all of one length), a plane at a time.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn decode_tile_run(tile: &Tile, i: usize, out: [&mut [f32]; 7], blend: &[f32]) {
    let [r0, g0, b0, r1, g1, b1, n] = out;
    tile.kd.decode_rgb_into(i, [r0, g0, b0]);
    tile.ks.decode_rgb_into(i, [r1, g1, b1]);
    tile.n.decode_into(i, n, |bits| blend[bits as usize]);
}

/// Row `y` of the map (clamped to it) from column `x0` for as many texels as `out` holds
/// (columns clamped too), as targets: a tile at a time, with the row's texels in a plain
/// loop. A mask's gray goes to the first component only.
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
    mut out: [&mut [f32]; 7],
    blend: &[f32],
) {
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    let y = y.clamp(0, h - 1) as u32;
    let len = out[0].len();
    let mut k = 0;
    while k < len {
        let x = x0 + k as i64;
        if x < 0 || x >= w {
            let edge = x.clamp(0, w - 1) as u32;
            set_run(&mut out, k, value_at(tiles, mask, maps, (edge, y), blend));
            k += 1;
            continue;
        }
        // The run inside one tile.
        let (id, i) = maps.locate(x as u32, y);
        let in_tile = TILE_SIZE - (x as usize % TILE_SIZE);
        let n = in_tile.min(len - k).min((w - x) as usize);
        if let Some(m) = mask {
            let plane = m[id].get();
            for (j, o) in out[0][k..k + n].iter_mut().enumerate() {
                *o = decode_unorm(plane.get(i + j));
            }
        } else {
            let run = out.each_mut().map(|c| &mut c[k..k + n]);
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
                targets.run_mut(start, end),
                self.blend,
            );
            // Texels whose source is off the map (for the whole stroke: the offset is fixed)
            // are not written: all of the run but columns `inside`.
            let len = (end - start) as i64;
            let inside = if (0..h).contains(&sy) {
                (-sx0).clamp(0, len) as usize..(w - sx0).clamp(0, len) as usize
            } else {
                0..0
            };
            let run = &mut cover[start..end];
            run[..inside.start].fill(0.0);
            run[inside.end.max(inside.start)..].fill(0.0);
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
    let dab = (fp, strength, step);
    match planes {
        // The source is the composite: the layer's own tiles are read in place.
        Planes::Paint(tiles) => {
            let prepare = SmudgeTile::new((maps, None), dab);
            edit::edit_each_in_place(tiles, target, ids, &prepare)
        }
        Planes::Mask(tiles) => mask_now(tiles, |planes, now| {
            let prepare = SmudgeTile::new((maps, Some(now)), dab);
            edit::edit_each(planes, target, ids, &prepare)
        }),
    }
}

/// Runs `f` on a mask's planes and the same planes as they are now (what a smudge dab on a
/// mask blends from and writes relative to, the dabs before it included: all of them, as it
/// reads its neighbours).
pub(super) fn mask_now<R>(
    tiles: &mut [SharedMaskTile],
    f: impl FnOnce((Planes<'_>, PrePlanes<'_>), &[SharedMaskTile]) -> R,
) -> R {
    let now = tiles.to_vec();
    f((Planes::Mask(tiles), PrePlanes::Mask(&now)), &now)
}

/// A smudge dab's tile for [`edit::edit_each`]: each texel's coverage, and its target
/// blended from the composite (or the mask) one step behind (a struct, not a closure, so that
/// it is compiled into the vectorised kernel).
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

impl<'a, F> SmudgeTile<'a, F> {
    /// A dab through `fp` at `strength`, the brush having moved `step` texels since the last,
    /// reading the composite (or `mask`, as it is now).
    fn new(
        (maps, mask): (&'a MaterialMaps, Option<&'a [SharedMaskTile]>),
        (fp, strength, step): (&'a F, f32, Vec2),
    ) -> Self {
        // Texel centres are whole texels apart, so every texel reads its four neighbours at
        // the same whole offset and with the same bilinear weights. Texel (x, y) reads the
        // point (x, y) - step between texel centres: (x + ix, y + iy) and its right and lower
        // neighbours, at (fx, fy) between them.
        let back = -step;
        let (ix, iy) = (back.x.floor(), back.y.floor());
        let (fx, fy) = (back.x - ix, back.y - iy);
        Self {
            fp,
            maps,
            tiles: maps.tiles(),
            mask,
            blend: crate::paint::n_blend_table(),
            strength,
            offset: (ix as i64, iy as i64),
            weights: [
                (1.0 - fx) * (1.0 - fy),
                fx * (1.0 - fy),
                (1.0 - fx) * fy,
                fx * fy,
            ],
        }
    }
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
        // The worker's rows taken and put back (not borrowed in a closure: `LocalKey::with`
        // left out of line would hold the whole body, compiled for the baseline).
        let mut rows = SOURCE_ROWS.take().unwrap_or_default();
        // Source row r is map row rect.y0 + r + iy, column c map column rect.x0 + c + ix:
        // each texel of it decoded once, for the run above it and the run on it.
        rows.reset();
        // A mask's gray is its only component.
        let components = if self.mask.is_some() { 1 } else { 7 };
        // The run's body inlined too (a closure left out of line is compiled for the
        // baseline).
        self.fp.visit_runs(
            id,
            rect,
            #[inline(always)]
            |start, dab| {
                let (y, x0) = (start / TILE_SIZE, start % TILE_SIZE);
                let n = dab.len();
                for r in [y, y + 1] {
                    rows.ensure(
                        (r, x0, x0 + n + 1),
                        #[inline(always)]
                        |(row, c0), out| {
                            let sy = i64::from(rect.y0) + row as i64 + self.offset.1;
                            let sx = i64::from(rect.x0) + c0 as i64 + self.offset.0;
                            decode_row(self.tiles, self.mask, self.maps, (sx, sy), out, self.blend);
                        },
                    );
                }
                let [w0, w1, w2, w3] = self.weights;
                for c in 0..components {
                    // The run's taps: texel k's at k and k + 1 of its row and the row below.
                    let top = &rows.row(c, y)[x0..=x0 + n];
                    let bottom = &rows.row(c, y + 1)[x0..=x0 + n];
                    let out = &mut targets.plane_mut(c)[start..start + n];
                    for ((((o, &tl), &tr), &bl), &br) in out
                        .iter_mut()
                        .zip(top)
                        .zip(&top[1..])
                        .zip(bottom)
                        .zip(&bottom[1..])
                    {
                        *o = tl * w0 + tr * w1 + bl * w2 + br * w3;
                    }
                }
                let run = &mut cover[start..start + n];
                for (c, &wgt) in run.iter_mut().zip(dab) {
                    *c = (wgt * self.strength).min(1.0);
                }
                let first = run.iter().position(|&a| a > 0.0);
                if let (Some(first), Some(last)) = (first, run.iter().rposition(|&a| a > 0.0)) {
                    written.include_run(start + first, start + last + 1);
                }
            },
        );
        SOURCE_ROWS.set(Some(rows));
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
    data: Components<{ SOURCE_STRIDE * SOURCE_STRIDE }>,
}

impl SourceRows {
    fn reset(&mut self) {
        self.ranges.clear();
        self.ranges.resize(SOURCE_STRIDE, (0, 0));
    }

    /// Makes columns `c0..c1` of row `r` decoded, through `decode((r, c), out)` for the
    /// columns from `c` that are not yet.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn ensure(
        &mut self,
        (r, c0, c1): (usize, usize, usize),
        decode: impl Fn((usize, usize), [&mut [f32]; 7]),
    ) {
        let row = r * SOURCE_STRIDE;
        let (lo, hi) = self.ranges[r];
        if lo >= hi {
            decode((r, c0), self.data.run_mut(row + c0, row + c1));
            self.ranges[r] = (c0, c1);
            return;
        }
        // Grown at either end (a gap between is decoded too, keeping one range a row).
        if c0 < lo {
            decode((r, c0), self.data.run_mut(row + c0, row + lo));
        }
        if c1 > hi {
            decode((r, hi), self.data.run_mut(row + hi, row + c1));
        }
        self.ranges[r] = (lo.min(c0), hi.max(c1));
    }

    /// Component `c` of row `r`.
    fn row(&self, c: usize, r: usize) -> &[f32] {
        &self.data.plane(c)[r * SOURCE_STRIDE..(r + 1) * SOURCE_STRIDE]
    }
}

thread_local! {
    /// A worker's [`SourceRows`], kept from tile to tile (taken while in use).
    static SOURCE_ROWS: std::cell::Cell<Option<Box<SourceRows>>> = const { std::cell::Cell::new(None) };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each texel of a source row is decoded once, however the runs that read it overlap,
    /// and every column a run asks for holds its own decoded value.
    #[test]
    fn source_rows_decode_each_texel_once() {
        let decoded = std::cell::RefCell::new(vec![0_u32; SOURCE_STRIDE * SOURCE_STRIDE]);
        let decode = |(r, c0): (usize, usize), mut out: [&mut [f32]; 7]| {
            for k in 0..out[0].len() {
                decoded.borrow_mut()[r * SOURCE_STRIDE + c0 + k] += 1;
                set_run(&mut out, k, [(r * 100 + c0 + k) as f32; 7]);
            }
        };
        let mut rows = SourceRows::default();
        rows.reset();
        // A disc's runs: growing, shrinking, one off to the side, and the last column.
        for &(r, c0, c1) in &[(3, 10, 20), (3, 5, 25), (3, 8, 12), (3, 40, 45), (4, 0, 65)] {
            rows.ensure((r, c0, c1), decode);
            for c in c0..c1 {
                assert_eq!(rows.row(6, r)[c], (r * 100 + c) as f32);
            }
        }
        assert!(decoded.borrow().iter().all(|&n| n <= 1));
        // Reset between tiles: decoded afresh.
        rows.reset();
        rows.ensure((3, 10, 12), decode);
        assert_eq!(decoded.borrow()[3 * SOURCE_STRIDE + 10], 2);
    }
}
