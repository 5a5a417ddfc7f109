//! Dabs and fills: where they land ([`Footprint`]) and what they write ([`PaintTarget`]).
//!
//! A stroke keeps a coverage value per texel, the alpha it has reached so far. Each dab raises
//! coverage towards the brush opacity by its flow; the texel is then the blend of its value
//! *before the stroke* (kept by the open history transaction) with the target at that
//! coverage. Overlapping dabs (or mirrored copies of one) therefore never exceed the opacity,
//! and a stroke's result does not depend on dab order.

use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3};

use super::brush::{BlendMode, BrushSettings};
use super::history::History;
use super::maps::{MaterialMaps, TileId};
use super::texel::{
    MaterialValue, Texel, decode_n, decode_unorm, encode_unorm, n_from_blend, n_to_blend,
};
use super::tile::{TILE_SIZE, TILE_TEXELS, Tile};

/// A tile's texel rectangle `(x0, y0, x1, y1)`, exclusive ends.
pub type TileRect = (u32, u32, u32, u32);

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
    fn visit_runs(&self, id: TileId, rect: TileRect, f: impl FnMut(usize, &[f32]));

    /// Calls `f(index_in_tile, weight)` for every texel of tile `id` with a positive weight.
    fn visit_tile(&self, id: TileId, rect: TileRect, mut f: impl FnMut(usize, f32)) {
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
    fn bounds(&self, maps: &MaterialMaps) -> Option<(u32, u32, u32, u32)> {
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
        Some((
            lo.x as u32,
            lo.y as u32,
            hi.x.min(w) as u32,
            hi.y.min(h) as u32,
        ))
    }
}

impl Footprint for DiscFootprint<'_> {
    fn tiles(&self, maps: &MaterialMaps) -> Vec<TileId> {
        let Some((x0, y0, x1, y1)) = self.bounds(maps) else {
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

    fn visit_runs(&self, _id: TileId, rect: TileRect, mut f: impl FnMut(usize, &[f32])) {
        let (x0, y0, x1, y1) = rect;
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

/// Lookup tables between stored `n` bits and the perceptual blend space.
struct NTables {
    to_blend: Vec<f32>,
    from_blend: Vec<u16>,
}

/// Resolution of the blend-space to bits table: finer than a half float's step everywhere.
const FROM_BLEND_STEPS: usize = 1 << 18;

fn n_tables() -> &'static NTables {
    static TABLES: OnceLock<NTables> = OnceLock::new();
    TABLES.get_or_init(|| NTables {
        to_blend: (0..=u16::MAX).map(|b| n_to_blend(decode_n(b))).collect(),
        from_blend: (0..=FROM_BLEND_STEPS)
            .map(|i| super::texel::encode_n(n_from_blend(i as f32 / FROM_BLEND_STEPS as f32)))
            .collect(),
    })
}

#[inline]
fn n_bits_to_blend(bits: u16) -> f32 {
    n_tables().to_blend[bits as usize]
}

#[inline]
fn n_bits_from_blend(u: f32) -> u16 {
    let i = (super::texel::unit(u) * FROM_BLEND_STEPS as f32 + 0.5) as usize;
    n_tables().from_blend[i.min(FROM_BLEND_STEPS)]
}

/// What a paint operation writes: per-channel targets in blend space, which channels, how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaintTarget {
    /// Target `k_d`.
    pub kd: Vec3,
    /// Target `k_s`.
    pub ks: Vec3,
    /// Target `n` in blend space.
    pub n_blend: f32,
    /// Channels written.
    pub channels: super::texel::Channels,
    /// Blend mode.
    pub mode: BlendMode,
    /// Keep `k_d + k_s <= 1` per colour channel.
    pub energy_guard: bool,
}

impl PaintTarget {
    /// A target from a material value.
    pub fn new(
        value: MaterialValue,
        channels: super::texel::Channels,
        mode: BlendMode,
        energy_guard: bool,
    ) -> Self {
        let v = value.sanitized();
        Self {
            kd: v.kd,
            ks: v.ks,
            n_blend: n_to_blend(v.n),
            channels,
            mode,
            energy_guard,
        }
    }

    /// The texel `pre` blended towards the target at alpha `a`.
    #[inline]
    pub fn blend(&self, pre: Texel, a: f32) -> Texel {
        let mut out = pre;
        let mode = self.mode;
        let mut kd = [0.0; 3];
        let mut ks = [0.0; 3];
        for c in 0..3 {
            kd[c] = decode_unorm(pre.kd[c]);
            ks[c] = decode_unorm(pre.ks[c]);
            if self.channels.kd {
                kd[c] = mode.apply(kd[c], self.kd[c], a);
            }
            if self.channels.ks {
                ks[c] = mode.apply(ks[c], self.ks[c], a);
            }
        }
        if self.energy_guard && (self.channels.kd || self.channels.ks) {
            guard_energy(&mut kd, &mut ks, self.channels.kd, self.channels.ks);
        }
        for c in 0..3 {
            out.kd[c] = encode_unorm(kd[c]);
            out.ks[c] = encode_unorm(ks[c]);
        }
        if self.channels.n {
            out.n = n_bits_from_blend(mode.apply(n_bits_to_blend(pre.n), self.n_blend, a));
        }
        out
    }
}

/// Keeps `k_d + k_s <= 1` per colour channel: the channel being painted gives way to the
/// other; when both are painted, both scale down together.
fn guard_energy(kd: &mut [f32; 3], ks: &mut [f32; 3], painting_kd: bool, painting_ks: bool) {
    for c in 0..3 {
        let sum = kd[c] + ks[c];
        if sum <= 1.0 {
            continue;
        }
        match (painting_kd, painting_ks) {
            (true, false) => kd[c] = 1.0 - ks[c],
            (false, true) => ks[c] = 1.0 - kd[c],
            _ => {
                kd[c] /= sum;
                ks[c] /= sum;
            }
        }
    }
}

/// Per-texel stroke coverage for the tiles a stroke touched, indexed by tile.
#[derive(Default, Debug)]
pub struct Coverage {
    tiles: Vec<Option<Box<[f32]>>>,
}

impl Coverage {
    /// Resets every texel to zero, keeping the allocations (a new stroke on the same tiles).
    pub fn clear(&mut self) {
        for tile in self.tiles.iter_mut().flatten() {
            tile.fill(0.0);
        }
    }

    /// Coverage slices for several tiles (sorted, unique ids), created at zero on first use.
    fn tiles_mut(&mut self, tile_count: usize, ids: &[TileId]) -> Vec<&mut [f32]> {
        if self.tiles.len() < tile_count {
            self.tiles.resize_with(tile_count, || None);
        }
        for &id in ids {
            self.tiles[id].get_or_insert_with(|| vec![0.0; TILE_TEXELS].into_boxed_slice());
        }
        super::tile::select_mut(&mut self.tiles, ids)
            .into_iter()
            .filter_map(|slot| slot.as_deref_mut())
            .collect()
    }
}

/// The pre-operation version of a tile: the one the open transaction saved, else the current.
fn pre_tile(history: &History, maps: &MaterialMaps, id: TileId) -> Arc<Tile> {
    history
        .saved_tile(id)
        .cloned()
        .unwrap_or_else(|| Arc::clone(maps.tile(id)))
}

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
    let rects: Vec<TileRect> = ids.iter().map(|&id| maps.tile_rect(id)).collect();
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
    (fp, id, rect): (&impl Footprint, TileId, TileRect),
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
    let kd_t = rgb_pattern(super::texel::encode_rgb(target.kd));
    let ks_t = rgb_pattern(super::texel::encode_rgb(target.ks));
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
enum PreRgb<'a> {
    Uniform([u16; 3 * TILE_SIZE]),
    Data(&'a [[u16; 3]]),
}

impl<'a> PreRgb<'a> {
    fn new(plane: &'a super::tile::Plane<[u16; 3]>) -> Self {
        match plane {
            super::tile::Plane::Uniform(p) => Self::Uniform(std::array::from_fn(|k| p[k % 3])),
            super::tile::Plane::Data(d) => Self::Data(d),
        }
    }

    fn run(&self, start: usize, len: usize) -> &[u16] {
        match self {
            Self::Uniform(row) => &row[..3 * len],
            Self::Data(d) => d[start..start + len].as_flattened(),
        }
    }
}

/// Blends a run of unorm16 RGB texels towards a target. Normal mode works on the flat
/// components (`target16` repeats the target's three, `alpha.1` each texel's alpha three
/// times) so it vectorises; it is exact at alpha 0 and 1, and a convex mix stays in range.
fn blend_rgb_run(
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
fn blend_n_run(
    out: &mut [u16],
    pre: &super::tile::Plane<u16>,
    start: usize,
    target: f32,
    alpha: &[f32],
    mode: BlendMode,
    tables: &NTables,
) {
    use super::tile::Plane;
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

/// Applies one blur dab: enabled channels move towards their local box average by the dab
/// weight times `strength`.
pub fn blur_dab(
    maps: &mut MaterialMaps,
    history: &mut History,
    channels: super::texel::Channels,
    kernel_px: u32,
    strength: f32,
    fp: &impl Footprint,
) {
    if channels.is_empty() || strength <= 0.0 {
        return;
    }
    let k = i64::from(kernel_px.max(1));
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    // Blurred values are computed from the state before this dab, then written.
    let mut writes: Vec<(TileId, usize, Texel)> = Vec::new();
    for id in fp.tiles(maps) {
        let rect = maps.tile_rect(id);
        fp.visit_tile(id, rect, |i, weight| {
            let x = i64::from(rect.0) + (i % TILE_SIZE) as i64;
            let y = i64::from(rect.1) + (i / TILE_SIZE) as i64;
            let mut sum = [0.0_f32; 7];
            let mut count = 0.0;
            for yy in (y - k).max(0)..=(y + k).min(h - 1) {
                for xx in (x - k).max(0)..=(x + k).min(w - 1) {
                    let t = maps.texel(xx as u32, yy as u32);
                    for c in 0..3 {
                        sum[c] += decode_unorm(t.kd[c]);
                        sum[3 + c] += decode_unorm(t.ks[c]);
                    }
                    sum[6] += n_bits_to_blend(t.n);
                    count += 1.0;
                }
            }
            let avg = sum.map(|s| s / count);
            let target = PaintTarget {
                kd: Vec3::new(avg[0], avg[1], avg[2]),
                ks: Vec3::new(avg[3], avg[4], avg[5]),
                n_blend: avg[6],
                channels,
                mode: BlendMode::Normal,
                energy_guard: false,
            };
            let pre = maps.tile(id).texel(i);
            writes.push((id, i, target.blend(pre, (weight * strength).min(1.0))));
        });
    }
    for (id, i, t) in writes {
        history.tile_for_write(maps, id).set_texel(i, t);
    }
}

/// Writes `target` over every texel of the maps at alpha `opacity`. A full-opacity normal
/// fill makes the written planes uniform: no per-texel work and no memory.
pub fn fill_all(
    maps: &mut MaterialMaps,
    history: &mut History,
    target: &PaintTarget,
    opacity: f32,
) {
    use super::tile::Plane;
    let uniform = opacity >= 1.0 && target.mode == BlendMode::Normal && !target.energy_guard;
    let value = Texel::encode(MaterialValue {
        kd: target.kd,
        ks: target.ks,
        n: n_from_blend(target.n_blend),
    });
    let value = Texel {
        n: n_bits_from_blend(target.n_blend),
        ..value
    };
    for id in 0..maps.tile_count() {
        if uniform {
            // Build the new tile from the old one's untouched planes: no copy of what is
            // overwritten.
            let old = maps.tile(id);
            let tile = Tile {
                kd: if target.channels.kd {
                    Plane::Uniform(value.kd)
                } else {
                    old.kd.clone()
                },
                ks: if target.channels.ks {
                    Plane::Uniform(value.ks)
                } else {
                    old.ks.clone()
                },
                n: if target.channels.n {
                    Plane::Uniform(value.n)
                } else {
                    old.n.clone()
                },
            };
            history.replace_for_write(maps, id, tile);
        } else {
            let pre = pre_tile(history, maps, id);
            let tile = history.tile_for_write(maps, id);
            for i in 0..TILE_TEXELS {
                tile.set_texel(i, target.blend(pre.texel(i), opacity));
            }
        }
    }
}

/// The 4-connected region around `(x, y)` whose `channel` stays within `tolerance` of the
/// seed's (in blend space, max over colour components), as a bit per texel.
pub fn flood_region(
    maps: &MaterialMaps,
    x: u32,
    y: u32,
    channel: super::texel::Channel,
    tolerance: f32,
) -> Vec<bool> {
    use super::texel::Channel;
    let (w, h) = (maps.width(), maps.height());
    let key = |t: Texel| -> [f32; 3] {
        match channel {
            Channel::Kd => t.kd.map(decode_unorm),
            Channel::Ks => t.ks.map(decode_unorm),
            Channel::N => [n_bits_to_blend(t.n); 3],
        }
    };
    let seed = key(maps.texel(x, y));
    let within = |t: Texel| {
        key(t)
            .iter()
            .zip(&seed)
            .all(|(a, b)| (a - b).abs() <= tolerance)
    };
    let mut inside = vec![false; (w * h) as usize];
    let mut stack = vec![(x, y)];
    while let Some((sx, sy)) = stack.pop() {
        // Scanline fill: extend left and right, queue the rows above and below.
        let row = (sy * w) as usize;
        if inside[row + sx as usize] || !within(maps.texel(sx, sy)) {
            continue;
        }
        let mut l = sx;
        while l > 0 && !inside[row + l as usize - 1] && within(maps.texel(l - 1, sy)) {
            l -= 1;
        }
        let mut r = sx;
        while r + 1 < w && !inside[row + r as usize + 1] && within(maps.texel(r + 1, sy)) {
            r += 1;
        }
        for xx in l..=r {
            inside[row + xx as usize] = true;
            if sy > 0 && !inside[row - w as usize + xx as usize] {
                stack.push((xx, sy - 1));
            }
            if sy + 1 < h && !inside[row + w as usize + xx as usize] {
                stack.push((xx, sy + 1));
            }
        }
    }
    inside
}

/// Writes `target` at alpha `opacity` over the texels of `mask` (row-major, one per texel).
pub fn fill_mask(
    maps: &mut MaterialMaps,
    history: &mut History,
    target: &PaintTarget,
    opacity: f32,
    mask: &[bool],
) {
    let w = maps.width() as usize;
    for id in 0..maps.tile_count() {
        let (x0, y0, x1, y1) = maps.tile_rect(id);
        let any = (y0..y1).any(|y| {
            mask[y as usize * w + x0 as usize..y as usize * w + x1 as usize].contains(&true)
        });
        if !any {
            continue;
        }
        let pre = pre_tile(history, maps, id);
        let tile = history.tile_for_write(maps, id);
        for y in y0..y1 {
            for x in x0..x1 {
                if mask[y as usize * w + x as usize] {
                    let i = (y - y0) as usize * TILE_SIZE + (x - x0) as usize;
                    tile.set_texel(i, target.blend(pre.texel(i), opacity));
                }
            }
        }
    }
}

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
        let (x0, y0, x1, y1) = maps.tile_rect(id);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::texel::Channels;

    #[test]
    fn disc_footprint_covers_the_disc_exactly() {
        let maps = MaterialMaps::new(300, 200, MaterialValue::default()).unwrap();
        let brush = BrushSettings {
            hardness: 1.0,
            ..BrushSettings::default()
        };
        let fp = DiscFootprint {
            center: Vec2::new(63.7, 64.2),
            radius: 20.3,
            brush: &brush,
        };
        let mut hits = std::collections::HashSet::new();
        for id in fp.tiles(&maps) {
            let rect = maps.tile_rect(id);
            fp.visit_tile(id, rect, |i, _| {
                hits.insert((
                    rect.0 + (i % TILE_SIZE) as u32,
                    rect.1 + (i / TILE_SIZE) as u32,
                ));
            });
        }
        for y in 0..200 {
            for x in 0..300 {
                let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(fp.center);
                assert_eq!(hits.contains(&(x, y)), d < fp.radius, "({x}, {y}) at {d}");
            }
        }
    }

    #[test]
    fn n_blend_tables_are_accurate() {
        for n in [0.0_f32, 0.3, 1.0, 77.0, 5000.0, 16384.0] {
            let bits = super::super::texel::encode_n(n);
            assert_eq!(n_bits_from_blend(n_bits_to_blend(bits)), bits, "n = {n}");
        }
    }

    #[test]
    fn energy_guard_keeps_the_sum_at_most_one() {
        let target = PaintTarget::new(
            MaterialValue::new(Vec3::splat(0.9), Vec3::splat(0.8), 10.0),
            Channels {
                kd: true,
                ks: false,
                n: false,
            },
            BlendMode::Normal,
            true,
        );
        let pre = Texel::encode(MaterialValue::new(Vec3::splat(0.1), Vec3::splat(0.8), 10.0));
        let out = target.blend(pre, 1.0).decode();
        assert!((out.kd.x + out.ks.x) <= 1.0 + 1e-4);
        assert!((out.ks.x - 0.8).abs() < 1e-4, "k_s untouched");
        // Untouched to the bit, every code, so a dab may mark only the enabled channels as
        // changed.
        for q in 0..=u16::MAX {
            let mut pre = Texel::encode(MaterialValue::new(Vec3::splat(0.3), Vec3::ZERO, 10.0));
            pre.ks = [q, q / 2, u16::MAX - q];
            let out = target.blend(pre, 0.7);
            assert_eq!((out.ks, out.n), (pre.ks, pre.n), "code {q}");
        }
    }

    #[test]
    fn run_blends_agree_with_the_per_texel_reference() {
        use super::super::tile::Plane;
        let tables = n_tables();
        let alphas: Vec<f32> = (0..TILE_SIZE).map(|k| k as f32 / 63.0).collect();
        let mut alpha3 = [0.0; 3 * TILE_SIZE];
        for (a3, &a) in alpha3.chunks_exact_mut(3).zip(&alphas) {
            a3.fill(a);
        }
        let pre_data: Vec<[u16; 3]> = (0..TILE_TEXELS)
            .map(|i| {
                let h = (i as u32).wrapping_mul(2_654_435_761);
                [h as u16, (h >> 8) as u16, (h >> 16) as u16]
            })
            .collect();
        let n_data: Vec<u16> = (0..TILE_TEXELS)
            .map(|i| super::super::texel::encode_n((i % 997) as f32 * 9.7))
            .collect();
        let planes = [
            (
                Plane::Uniform([12_345, 0, 65_535]),
                Plane::Uniform(n_data[5]),
            ),
            (
                Plane::Data(pre_data.into_boxed_slice()),
                Plane::Data(n_data.into_boxed_slice()),
            ),
        ];
        for mode in [
            BlendMode::Normal,
            BlendMode::Add,
            BlendMode::Subtract,
            BlendMode::Multiply,
        ] {
            let target = PaintTarget::new(
                MaterialValue::new(Vec3::new(0.9, 0.1, 0.5), Vec3::splat(0.3), 700.0),
                Channels::ALL,
                mode,
                false,
            );
            let pattern: [f32; 3 * TILE_SIZE] = std::array::from_fn(|k| {
                f32::from(super::super::texel::encode_rgb(target.kd)[k % 3])
            });
            for (rgb_plane, n_plane) in &planes {
                let start = 2 * TILE_SIZE;
                let pre = PreRgb::new(rgb_plane);
                let mut out = [[0_u16; 3]; TILE_SIZE];
                blend_rgb_run(
                    &mut out,
                    pre.run(start, TILE_SIZE),
                    (&pattern, target.kd),
                    (&alphas, &alpha3),
                    mode,
                );
                let mut out_n = [0_u16; TILE_SIZE];
                blend_n_run(
                    &mut out_n,
                    n_plane,
                    start,
                    target.n_blend,
                    &alphas,
                    mode,
                    tables,
                );
                for k in 0..TILE_SIZE {
                    let p = Texel {
                        kd: rgb_plane.get(start + k),
                        ks: [0; 3],
                        n: n_plane.get(start + k),
                    };
                    let want = target.blend(p, alphas[k]);
                    for (got, want) in out[k].iter().zip(want.kd) {
                        let diff = (i32::from(*got) - i32::from(want)).abs();
                        assert!(diff <= 1, "{mode:?} k_d at alpha {}", alphas[k]);
                    }
                    assert_eq!(out_n[k], want.n, "{mode:?} n at alpha {}", alphas[k]);
                    if mode == BlendMode::Normal && (k == 0 || k == TILE_SIZE - 1) {
                        assert_eq!(out[k], want.kd, "exact at alpha 0 and 1");
                    }
                }
            }
        }
    }
}
