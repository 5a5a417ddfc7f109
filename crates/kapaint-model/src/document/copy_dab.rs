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
use crate::tile::{TILE_SIZE, TILE_TEXELS, Tile, TileSpans};

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
/// `n` in blend space).
#[inline]
fn edit_value(tile: &Tile, i: usize, blend: &[f32]) -> [f32; 7] {
    let kd = tile.kd.get(i).map(decode_unorm);
    let ks = tile.ks.get(i).map(decode_unorm);
    [
        kd[0],
        kd[1],
        kd[2],
        ks[0],
        ks[1],
        ks[2],
        blend[tile.n.get(i) as usize],
    ]
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

/// Row `y` of the map (clamped to it) from column `x0` for `out.len()` texels (columns
/// clamped too), as targets: a tile at a time, with the row's texels in a plain loop.
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
            let tile = &tiles[id];
            for (j, o) in run.iter_mut().enumerate() {
                *o = edit_value(tile, i + j, blend);
            }
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
    let blend = crate::paint::n_blend_table();
    let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rose = raise.raise(id, cover);
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        for (y, x0, x1) in rose.rows() {
            let sy = i64::from(rect.y0) + y as i64 + oy;
            let sx0 = i64::from(rect.x0) + x0 as i64 + ox;
            let (start, end) = (y * TILE_SIZE + x0, y * TILE_SIZE + x1);
            decode_row(
                &source.tiles,
                mask,
                maps,
                (sx0, sy),
                &mut targets[start..end],
                blend,
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
    };
    edit::edit_varying((planes, pre), target, ids, covers, &prepare)
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
    from_now(planes, |planes, pre, mask| {
        smudge_from(
            (planes, pre, mask),
            target,
            (maps, ids),
            (fp, strength, step),
            covers,
        )
    })
}

/// Runs `f` on the planes, the same planes as they are now (what a smudge dab blends from:
/// the dabs before it included), and a mask's own planes as they are now.
pub(super) fn from_now<R>(
    planes: Planes<'_>,
    f: impl FnOnce(Planes<'_>, PrePlanes<'_>, Option<&[SharedMaskTile]>) -> R,
) -> R {
    match planes {
        Planes::Paint(tiles) => {
            let now = tiles.to_vec();
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
    let tiles = maps.tiles();
    let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        let mut rows = [[[0.0_f32; 7]; TILE_SIZE + 1]; 2];
        fp.visit_runs(id, rect, |start, dab| {
            let (y, x0) = (start / TILE_SIZE, start % TILE_SIZE);
            let sy = i64::from(rect.y0) + y as i64 + iy;
            let sx = i64::from(rect.x0) + x0 as i64 + ix;
            let n = dab.len();
            for (r, row) in rows.iter_mut().enumerate() {
                decode_row(
                    tiles,
                    mask,
                    maps,
                    (sx, sy + r as i64),
                    &mut row[..=n],
                    blend,
                );
            }
            for (k, &wgt) in dab.iter().enumerate() {
                let a = (wgt * strength).min(1.0);
                let i = start + k;
                cover[i] = a;
                if a > 0.0 {
                    let taps = [rows[0][k], rows[0][k + 1], rows[1][k], rows[1][k + 1]];
                    targets[i] = std::array::from_fn(|c| {
                        taps.iter().zip(weights).map(|(t, w)| t[c] * w).sum()
                    });
                    written.include(i);
                }
            }
        });
        written
    };
    edit::edit_varying((planes, pre), target, ids, covers, &prepare)
}
