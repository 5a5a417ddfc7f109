//! Paint dabs: the coverage update and the per-tile, run-by-run blend of the enabled channels.

use std::sync::Arc;

use glam::Vec3;

use super::{Coverage, FROM_BLEND_STEPS, Footprint, NTables, PaintTarget, n_tables, pre_tile};
use crate::model::brush::BlendMode;
use crate::model::history::History;
use crate::model::maps::{MaterialMaps, TexelRect, TileId};
use crate::model::texel::{decode_unorm, encode_unorm};
use crate::model::tile::{TILE_SIZE, Tile};

/// Applies one paint dab with footprint `fp` and dab alpha `alpha` (flow times pressure).
///
/// The tiles under the dab are independent, so they are painted in parallel; each writes
/// only the enabled channels.
pub fn paint_dab(
    maps: &mut MaterialMaps,
    history: &mut History,
    coverage: &mut Coverage,
    target: &PaintTarget,
    opacity: f32,
    alpha: f32,
    fp: &impl Footprint,
) {
    use rayon::prelude::*;
    if alpha <= 0.0 || opacity <= 0.0 || target.channels.is_empty() {
        return;
    }
    let mut ids = fp.tiles(maps);
    ids.sort_unstable();
    ids.dedup();
    if ids.is_empty() {
        return;
    }
    let rects: Vec<TexelRect> = ids.iter().map(|&id| maps.tile_rect(id)).collect();
    let pres: Vec<Arc<Tile>> = ids.iter().map(|&id| pre_tile(history, maps, id)).collect();
    history.save_before_write(maps, &ids);
    let covs = coverage.tiles_mut(maps.tile_count(), &ids);
    // Only the enabled channels change (the energy guard too adjusts only the enabled one;
    // the others are rewritten with the values they hold).
    let tiles = maps.tiles_mut_many_in(&ids, target.channels);
    let tables = n_tables();
    let work: Vec<_> = tiles
        .into_iter()
        .zip(covs)
        .zip(pres)
        .zip(rects)
        .zip(ids)
        .collect();
    work.into_par_iter()
        .for_each(|((((tile, cov), pre), rect), id)| {
            paint_tile(
                tile,
                cov,
                &pre,
                target,
                opacity,
                alpha,
                tables,
                (fp, id, rect),
            );
        });
}

/// Paints one tile: coverage update and blend of the enabled channels, run by run.
#[expect(
    clippy::too_many_arguments,
    reason = "the hot loop's inputs, passed once per tile"
)]
fn paint_tile(
    tile: &mut Tile,
    cov: &mut [f32],
    pre: &Tile,
    target: &PaintTarget,
    opacity: f32,
    alpha: f32,
    tables: &NTables,
    (fp, id, rect): (&impl Footprint, TileId, TexelRect),
) {
    if target.energy_guard {
        // The guard couples k_d and k_s: take the general per-texel path.
        fp.visit_tile(id, rect, |i, w| {
            let c = cov[i];
            if c < opacity {
                let next = c + (opacity - c) * (w * alpha).min(1.0);
                cov[i] = next;
                tile.set_texel(i, target.blend(pre.texel(i), next));
            }
        });
        return;
    }
    let mode = target.mode;
    let ch = target.channels;
    let Tile { kd, ks, n } = tile;
    let mut kd = ch.kd.then(|| kd.data_mut());
    let mut ks = ch.ks.then(|| ks.data_mut());
    let mut n = ch.n.then(|| n.data_mut());
    let rgb_pattern =
        |t: [u16; 3]| -> [f32; 3 * TILE_SIZE] { std::array::from_fn(|k| f32::from(t[k % 3])) };
    let kd_t = rgb_pattern(crate::model::texel::encode_rgb(target.kd));
    let ks_t = rgb_pattern(crate::model::texel::encode_rgb(target.ks));
    let (pre_kd, pre_ks) = (PreRgb::new(&pre.kd), PreRgb::new(&pre.ks));
    let mut a_run = [0.0_f32; TILE_SIZE];
    let mut a3 = [0.0_f32; 3 * TILE_SIZE];
    fp.visit_runs(id, rect, |start, weights| {
        let len = weights.len();
        let a_run = &mut a_run[..len];
        // Coverage rises towards the opacity; a texel already at it keeps its value (and
        // re-blending it at the same coverage rewrites the same stored value).
        for ((c, &w), a) in cov[start..start + len]
            .iter_mut()
            .zip(weights)
            .zip(a_run.iter_mut())
        {
            let next = *c + (opacity - *c) * (w * alpha).min(1.0);
            *c = c.max(next);
            *a = *c;
        }
        if ch.kd || ch.ks {
            for (a3, &a) in a3.chunks_exact_mut(3).zip(a_run.iter()) {
                a3.fill(a);
            }
        }
        let a3 = &a3[..3 * len];
        if let Some(kd) = kd.as_deref_mut() {
            blend_rgb_run(
                &mut kd[start..start + len],
                pre_kd.run(start, len),
                (&kd_t, target.kd),
                (a_run, a3),
                mode,
            );
        }
        if let Some(ks) = ks.as_deref_mut() {
            blend_rgb_run(
                &mut ks[start..start + len],
                pre_ks.run(start, len),
                (&ks_t, target.ks),
                (a_run, a3),
                mode,
            );
        }
        if let Some(n) = n.as_deref_mut() {
            blend_n_run(
                &mut n[start..start + len],
                &pre.n,
                start,
                target.n_blend,
                a_run,
                mode,
                tables,
            );
        }
    });
}

/// The pre-stroke RGB values of a tile as flat components, a uniform plane expanded once
/// per tile so runs can read it like data.
#[expect(
    clippy::large_enum_variant,
    reason = "lives on the stack, once per painted tile"
)]
pub(super) enum PreRgb<'a> {
    Uniform([u16; 3 * TILE_SIZE]),
    Data(&'a [[u16; 3]]),
}

impl<'a> PreRgb<'a> {
    pub(super) fn new(plane: &'a crate::model::tile::Plane<[u16; 3]>) -> Self {
        match plane {
            crate::model::tile::Plane::Uniform(p) => {
                Self::Uniform(std::array::from_fn(|k| p[k % 3]))
            }
            crate::model::tile::Plane::Data(d) => Self::Data(d),
        }
    }

    pub(super) fn run(&self, start: usize, len: usize) -> &[u16] {
        match self {
            Self::Uniform(row) => &row[..3 * len],
            Self::Data(d) => d[start..start + len].as_flattened(),
        }
    }
}

/// Blends a run of unorm16 RGB texels towards a target. Normal mode works on the flat
/// components (`target16` repeats the target's three, `alpha.1` each texel's alpha three
/// times) so it vectorises; it is exact at alpha 0 and 1, and a convex mix stays in range.
pub(super) fn blend_rgb_run(
    out: &mut [[u16; 3]],
    pre: &[u16],
    (target16, target): (&[f32; 3 * TILE_SIZE], Vec3),
    (alpha, alpha3): (&[f32], &[f32]),
    mode: BlendMode,
) {
    if mode == BlendMode::Normal {
        let out = out.as_flattened_mut();
        for (((o, &p), &t), &a) in out.iter_mut().zip(pre).zip(target16).zip(alpha3) {
            let p = f32::from(p);
            *o = round_u16(p + (t - p) * a);
        }
    } else {
        for ((o, p), &a) in out.iter_mut().zip(pre.chunks_exact(3)).zip(alpha) {
            *o = [0, 1, 2].map(|c| encode_unorm(mode.apply(decode_unorm(p[c]), target[c], a)));
        }
    }
}

/// Rounds `v` in `[0, 65535]` to the nearest integer (ties to even) without a saturating
/// conversion: adding 2^23 leaves the integer in the low mantissa bits, which vectorises.
#[inline]
fn round_u16(v: f32) -> u16 {
    (v + 8_388_608.0).to_bits() as u16
}

/// Blends a run of half-float `n` texels in log space through the lookup tables.
pub(super) fn blend_n_run(
    out: &mut [u16],
    pre: &crate::model::tile::Plane<u16>,
    start: usize,
    target: f32,
    alpha: &[f32],
    mode: BlendMode,
    tables: &NTables,
) {
    use crate::model::tile::Plane;
    let from = &tables.from_blend[..=FROM_BLEND_STEPS];
    // Normal mode mixes convexly, so `u` stays in [0, 1]; the other modes clamp in `apply`.
    // The table index is rounded with the 2^23 trick (see `round_u16`), clamped by `min`.
    let to_bits = |u: f32| {
        let i = (u.max(0.0) * FROM_BLEND_STEPS as f32 + 8_388_608.0).to_bits() & 0x7F_FFFF;
        from[(i as usize).min(FROM_BLEND_STEPS)]
    };
    match (pre, mode) {
        (Plane::Uniform(bits), BlendMode::Normal) => {
            let u = tables.to_blend[*bits as usize];
            let d = target - u;
            for (o, &a) in out.iter_mut().zip(alpha) {
                *o = to_bits(u + d * a);
            }
        }
        (Plane::Data(d), BlendMode::Normal) => {
            for ((o, &bits), &a) in out
                .iter_mut()
                .zip(&d[start..start + alpha.len()])
                .zip(alpha)
            {
                let u = tables.to_blend[bits as usize];
                *o = to_bits(u + (target - u) * a);
            }
        }
        _ => {
            for (k, (o, &a)) in out.iter_mut().zip(alpha).enumerate() {
                let u = tables.to_blend[pre.get(start + k) as usize];
                *o = to_bits(mode.apply(u, target, a));
            }
        }
    }
}
