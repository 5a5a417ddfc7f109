//! Tools on a layer: what a dab, fill, gradient or blur writes into a paint layer's planes or a
//! mask.
//!
//! Every write is relative to the texel as it was before the operation (`pre`), at the
//! operation's coverage `a` there, as on the flat maps: a paint layer's texel becomes
//! [`LayerStroke::apply`] of its pre-operation value and coverage, a mask's gray moves from its
//! pre-operation value towards the target gray by `a`.

use std::sync::Arc;

use rayon::prelude::*;

use super::{LayerStroke, LayerValue, PaintTile, SharedMaskTile, SharedPaintTile, Stamped};
use crate::brush::BlendMode;
use crate::paint::{n_bits_from_blend, n_bits_to_blend};
use crate::texel::{MaterialValue, decode_unorm, encode_unorm, n_to_blend};
use crate::tile::{Plane, TILE_SIZE, Tile, TileSpans, select_mut};

mod blur;
mod cover;
mod targets;
mod varying;

pub use blur::blur;
pub use cover::{Raise, edit_cover};
use cover::{Targets, cover_alpha, cover_channel, erase_channel};
pub use targets::{Components, TileTargets, set_run};
pub use varying::{Prepare, edit_each, edit_each_in_place, edit_varying};

/// A material as the layer kernels blend it: `k_d`, `k_s` linear, `n` in blend space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditValue {
    /// Seven components: `k_d` RGB, `k_s` RGB, `n` in blend space.
    pub c: [f32; 7],
}

impl EditValue {
    /// From a material value (sanitised first).
    pub fn of(value: MaterialValue) -> Self {
        let v = value.sanitized();
        Self {
            c: [
                v.kd.x,
                v.kd.y,
                v.kd.z,
                v.ks.x,
                v.ks.y,
                v.ks.z,
                n_to_blend(v.n),
            ],
        }
    }

    /// This material as a tile of one value, as layer tiles store it (`n` through the
    /// brushes' table from blend space).
    fn uniform_tile(&self) -> Tile {
        let c = &self.c;
        let rgb = |k: usize| [c[k], c[k + 1], c[k + 2]].map(encode_unorm);
        Tile {
            kd: Plane::Uniform(rgb(0)),
            ks: Plane::Uniform(rgb(3)),
            n: Plane::Uniform(n_bits_from_blend(c[6])),
        }
    }

    fn lerp(&self, other: &Self, t: f32) -> Self {
        Self {
            c: std::array::from_fn(|k| self.c[k] + (other.c[k] - self.c[k]) * t),
        }
    }
}

/// What an edit writes: a material (from, and to for gradients) into the enabled channels of a
/// paint layer, or a gray (from, to) into a mask.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerEdit {
    /// The material at `t = 0`.
    pub from: EditValue,
    /// The material at `t = 1` (gradients; the same as `from` otherwise).
    pub to: EditValue,
    /// Channels written on a paint layer (`k_d`, `k_s`, `n`).
    pub channels: [bool; 3],
    /// How a paint layer's texel takes the material.
    pub stroke: LayerStroke,
    /// The mask's stored gray at `t = 0` and `t = 1` (the caller maps white and black through
    /// the mask's inversion).
    pub gray: [f32; 2],
    /// Keep the layer's own `k_d + k_s <= 1` per colour channel where the edit writes and the
    /// layer holds both channels (the brushes' energy guard).
    pub energy_guard: bool,
}

/// The brushes' energy guard on texel `i` of a paint layer's tile: where the layer holds both
/// `k_d` and `k_s` (the channel being written, and the other one painted there), their sum per
/// colour channel is kept at most one, as on flat maps (the channel written gives way, or both
/// scale down when both are written). Layers below are not looked at: normal layers that each
/// keep it composite to values that keep it (a mix of two such values keeps it).
pub(crate) fn guard_texel(tile: &mut PaintTile, channels: [bool; 3], i: usize) {
    let (kd_on, ks_on) = (channels[0], channels[1]);
    let holds = |c: usize| tile.alpha[c].get(i) > 0;
    if !(kd_on || ks_on) || !holds(0) || !holds(1) {
        return;
    }
    let (kd0, ks0) = (tile.value.kd.get(i), tile.value.ks.get(i));
    let (mut kd, mut ks) = (kd0.map(decode_unorm), ks0.map(decode_unorm));
    crate::paint::guard_energy(&mut kd, &mut ks, kd_on, ks_on);
    let (kd, ks) = (kd.map(encode_unorm), ks.map(encode_unorm));
    if kd != kd0 {
        tile.value.kd.data_mut()[i] = kd;
    }
    if ks != ks0 {
        tile.value.ks.data_mut()[i] = ks;
    }
}

/// The planes an edit writes into.
pub enum Planes<'a> {
    /// A paint layer's tiles.
    Paint(&'a mut [Option<SharedPaintTile>]),
    /// A mask's tiles.
    Mask(&'a mut [SharedMaskTile]),
}

impl Planes<'_> {
    /// The same planes, borrowed again for a call that consumes them.
    pub fn reborrow(&mut self) -> Planes<'_> {
        match self {
            Self::Paint(t) => Planes::Paint(t),
            Self::Mask(t) => Planes::Mask(t),
        }
    }
}

/// The same planes as they were before the operation.
#[derive(Clone, Copy)]
pub enum PrePlanes<'a> {
    /// A paint layer's tiles.
    Paint(&'a [Option<SharedPaintTile>]),
    /// A mask's tiles.
    Mask(&'a [SharedMaskTile]),
}

/// A tile being written, created or copied on the first texel written.
enum Slot<'a> {
    Paint(
        &'a mut Option<SharedPaintTile>,
        Pre<&'a SharedPaintTile>,
        bool,
    ),
    Mask(&'a mut SharedMaskTile, &'a SharedMaskTile, bool),
}

/// Where a paint tile's pre-operation texels are read.
#[derive(Clone, Copy)]
enum Pre<T> {
    /// The tile as it was before the operation (none: transparent).
    Before(Option<T>),
    /// The tile being written itself: each texel holds its pre-operation value until it is
    /// written, and is written once (a smudge dab), so no copy of the tile is held.
    InPlace,
}

/// The data of a shared tile to write: copied (if shared) and stamped on the first write of an
/// operation, then written in place.
fn writable<'t, T: Clone>(tile: &'t mut Arc<Stamped<T>>, written: &mut bool) -> &'t mut T {
    if *written {
        // Unique since the first write: no copy, and the stamp stays.
        return &mut Arc::make_mut(tile).data;
    }
    *written = true;
    Stamped::write(tile)
}

/// A paint tile nobody painted yet (transparent), to write into.
pub(crate) fn empty_paint_tile() -> SharedPaintTile {
    Arc::new(Stamped::new(PaintTile::filled(
        MaterialValue::default(),
        [false; 3],
    )))
}

/// Component ranges of the three channels in an [`EditValue`].
const RANGES: [std::ops::Range<usize>; 3] = [0..3, 3..6, 6..7];

fn decode(channel: usize, bits: u16) -> f32 {
    if channel == 2 {
        n_bits_to_blend(bits)
    } else {
        decode_unorm(bits)
    }
}

fn encode(channel: usize, value: f32) -> u16 {
    if channel == 2 {
        n_bits_from_blend(value)
    } else {
        encode_unorm(value)
    }
}

/// The stored bits of component `k` of a tile's texel `i`.
fn component(tile: &crate::tile::Tile, k: usize, i: usize) -> u16 {
    match k {
        0..3 => tile.kd.get(i)[k],
        3..6 => tile.ks.get(i)[k - 3],
        _ => tile.n.get(i),
    }
}

impl Slot<'_> {
    /// Writes texel `i` at coverage `a`, with the material or gray at gradient position `t`.
    fn write(&mut self, edit: &LayerEdit, i: usize, a: f32, t: f32) {
        let target = if t == 0.0 {
            edit.from
        } else {
            edit.from.lerp(&edit.to, t)
        };
        let gray = edit.gray[0] + (edit.gray[1] - edit.gray[0]) * t;
        self.write_target(
            edit,
            i,
            a,
            &Target {
                value: target,
                gray,
            },
        );
    }

    /// Writes texel `i` at coverage `a` with `target`: its material on a paint layer, its
    /// gray on a mask.
    fn write_target(&mut self, edit: &LayerEdit, i: usize, a: f32, target: &Target) {
        match self {
            Self::Paint(slot, pre, written) => {
                let target = &target.value;
                // The texel before the operation, read before the tile is written.
                let p = match *pre {
                    Pre::Before(p) => p,
                    Pre::InPlace => slot.as_ref(),
                };
                let (mut pre_alpha, mut pre_value) = ([0.0; 3], [0.0; 7]);
                if let Some(p) = p.map(|p| p.get()) {
                    for (ch, range) in RANGES.iter().enumerate() {
                        if edit.channels[ch] {
                            pre_alpha[ch] = decode_unorm(p.alpha[ch].get(i));
                            for k in range.clone() {
                                pre_value[k] = decode(ch, component(&p.value, k, i));
                            }
                        }
                    }
                }
                let tile = writable(slot.get_or_insert_with(empty_paint_tile), written);
                for (ch, range) in RANGES.iter().enumerate() {
                    if !edit.channels[ch] {
                        continue;
                    }
                    let mut alpha = pre_alpha[ch];
                    let mut values = [0_u16; 3];
                    for (s, k) in range.clone().enumerate() {
                        let out = edit.stroke.apply(
                            LayerValue {
                                value: pre_value[k],
                                alpha: pre_alpha[ch],
                            },
                            target.c[k],
                            a,
                        );
                        alpha = out.alpha;
                        values[s] = encode(ch, out.value);
                    }
                    tile.alpha[ch].data_mut()[i] = encode_unorm(alpha);
                    match ch {
                        0 => tile.value.kd.data_mut()[i] = values,
                        1 => tile.value.ks.data_mut()[i] = values,
                        _ => tile.value.n.data_mut()[i] = values[0],
                    }
                }
                if edit.energy_guard {
                    guard_texel(tile, edit.channels, i);
                }
            }
            Self::Mask(slot, pre, written) => {
                let g = target.gray;
                let p = decode_unorm(pre.get().get(i));
                let a = a.clamp(0.0, 1.0);
                writable(slot, written).data_mut()[i] = encode_unorm(p + (g - p) * a);
            }
        }
    }

    /// Writes texels `spans` at coverage `cover` (see [`edit_cover`]).
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn write_cover(
        &mut self,
        edit: &LayerEdit,
        spans: &TileSpans,
        cover: &[f32],
        varying: Option<&TileTargets>,
    ) {
        match self {
            Self::Paint(slot, pre, written) => {
                // A brush on a tile the layer did not have before the stroke: every texel it
                // reaches takes the target exactly (see `LayerStroke::apply`), so the tile
                // holds the target in one value per channel and the dabs write coverage only.
                let fresh = matches!(pre, Pre::Before(None))
                    && matches!(edit.stroke, LayerStroke::Brush(_))
                    && varying.is_none();
                let created = slot.is_none();
                let tile = writable(slot.get_or_insert_with(empty_paint_tile), written);
                if fresh && created {
                    tile.value = edit.from.uniform_tile();
                }
                let pre = match *pre {
                    Pre::Before(p) => Pre::Before(p.map(|p| p.get())),
                    Pre::InPlace => Pre::InPlace,
                };
                for (ch, range) in RANGES.iter().enumerate() {
                    if !edit.channels[ch] {
                        continue;
                    }
                    if fresh {
                        cover_alpha(&mut tile.alpha[ch], spans, cover);
                        continue;
                    }
                    let target = match varying {
                        None => Targets::Uniform(&edit.from.c[range.clone()]),
                        Some(v) => Targets::Varying(v, range.clone()),
                    };
                    let channel = (&mut *tile, pre, ch, target, spans, cover);
                    // One loop per mode, each with its arithmetic inlined.
                    match edit.stroke {
                        LayerStroke::Brush(mode) => match mode {
                            BlendMode::Normal => cover_channel(channel, |wa, v0, t| {
                                LayerStroke::value(BlendMode::Normal, wa, v0, t)
                            }),
                            BlendMode::Add => cover_channel(channel, |wa, v0, t| {
                                LayerStroke::value(BlendMode::Add, wa, v0, t)
                            }),
                            BlendMode::Subtract => cover_channel(channel, |wa, v0, t| {
                                LayerStroke::value(BlendMode::Subtract, wa, v0, t)
                            }),
                            BlendMode::Multiply => cover_channel(channel, |wa, v0, t| {
                                LayerStroke::value(BlendMode::Multiply, wa, v0, t)
                            }),
                        },
                        LayerStroke::Erase => {
                            erase_channel((&mut *tile, pre, ch, spans, cover));
                        }
                    }
                }
                if edit.energy_guard && edit.stroke != LayerStroke::Erase {
                    for i in spans.indices().filter(|&i| cover[i] > 0.0) {
                        guard_texel(tile, edit.channels, i);
                    }
                }
            }
            Self::Mask(slot, pre, written) => {
                let plane = writable(slot, written).data_mut();
                let pre = pre.get();
                for i in spans.indices() {
                    let a = cover[i];
                    // A varying target holds the gray first.
                    let g = varying.map_or(edit.gray[0], |v| v.plane(0)[i]);
                    if a > 0.0 {
                        let p = decode_unorm(pre.get(i));
                        plane[i] = encode_unorm(p + (g - p) * a.min(1.0));
                    }
                }
            }
        }
    }

    /// Stores uniform planes compactly after the writes.
    fn compact(&mut self) {
        match self {
            Self::Paint(Some(tile), _, written) if *written => {
                let t = writable(tile, written);
                t.value.compact();
                t.alpha.iter_mut().for_each(Plane::compact);
            }
            Self::Mask(tile, _, written) if *written => writable(tile, written).compact(),
            _ => {}
        }
    }
}

/// What a texel is written towards: a material on a paint layer, a stored gray on a mask.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Target {
    /// The material (paint layers).
    value: EditValue,
    /// The mask's stored gray (masks).
    gray: f32,
}

/// Writes tiles `work` (each an id and the data its visitor needs) in parallel. For each
/// tile, `visit` calls its argument with `(texel index in the tile, coverage, t)` for every
/// texel to write.
pub fn edit_tiles<X: Send>(
    planes: Planes<'_>,
    pre: PrePlanes<'_>,
    edit: &LayerEdit,
    work: Vec<(usize, X)>,
    visit: impl Fn(usize, X, &mut dyn FnMut(usize, f32, f32)) + Sync,
) {
    let ids: Vec<usize> = work.iter().map(|(id, _)| *id).collect();
    slots(planes, pre, &ids)
        .into_par_iter()
        .zip(work)
        .for_each(|(mut slot, (id, data))| {
            visit(id, data, &mut |i, a, t| slot.write(edit, i, a, t));
            slot.compact();
        });
}

/// The tiles `ids` (sorted, unique) of `planes` to write, with their pre-operation tiles.
fn slots<'a>(planes: Planes<'a>, pre: PrePlanes<'a>, ids: &[usize]) -> Vec<Slot<'a>> {
    match (planes, pre) {
        (Planes::Paint(tiles), PrePlanes::Paint(pre)) => select_mut(tiles, ids)
            .into_iter()
            .zip(ids)
            .map(|(t, &id)| Slot::Paint(t, Pre::Before(pre[id].as_ref()), false))
            .collect(),
        (Planes::Mask(tiles), PrePlanes::Mask(pre)) => select_mut(tiles, ids)
            .into_iter()
            .zip(ids)
            .map(|(t, &id)| Slot::Mask(t, &pre[id], false))
            .collect(),
        _ => Vec::new(),
    }
}

pub use crate::tile::tile_texels;

/// A whole-map fill at full coverage in the normal mode as uniform tiles: no per-texel work
/// and no memory. Returns false when the fill needs the per-texel path.
pub fn fill_uniform(planes: Planes<'_>, edit: &LayerEdit, opacity: f32, tile_count: usize) -> bool {
    let normal = edit.stroke == LayerStroke::Brush(crate::brush::BlendMode::Normal);
    if opacity < 1.0 || !normal || edit.from != edit.to || edit.energy_guard {
        return false;
    }
    match planes {
        Planes::Paint(tiles) => {
            for slot in tiles.iter_mut().take(tile_count) {
                let mut fresh = PaintTile {
                    value: edit.from.uniform_tile(),
                    alpha: edit
                        .channels
                        .map(|c| Plane::Uniform(if c { u16::MAX } else { 0 })),
                };
                // Keep what the other channels held.
                if let Some(old) = slot.as_ref() {
                    let old = old.get();
                    for ch in 0..3 {
                        if !edit.channels[ch] {
                            fresh.alpha[ch] = old.alpha[ch].clone();
                            match ch {
                                0 => fresh.value.kd = old.value.kd.clone(),
                                1 => fresh.value.ks = old.value.ks.clone(),
                                _ => fresh.value.n = old.value.n.clone(),
                            }
                        }
                    }
                }
                *slot = Some(Arc::new(Stamped::new(fresh)));
            }
        }
        Planes::Mask(tiles) => {
            let g = encode_unorm(edit.gray[0]);
            for slot in tiles.iter_mut() {
                *slot = Arc::new(Stamped::new(Plane::Uniform(g)));
            }
        }
    }
    true
}

/// Writes every texel of a `width x height` map that `at(x, y)` gives a coverage and gradient
/// position for (fills and gradients).
pub fn edit_texels(
    planes: Planes<'_>,
    pre: PrePlanes<'_>,
    edit: &LayerEdit,
    (width, height): (u32, u32),
    at: impl Fn(u32, u32) -> Option<(f32, f32)> + Sync,
) {
    let tiles = (width as usize).div_ceil(TILE_SIZE) * (height as usize).div_ceil(TILE_SIZE);
    let work = (0..tiles).map(|id| (id, ())).collect();
    edit_tiles(planes, pre, edit, work, |id, (), write| {
        for (i, x, y) in tile_texels(width, height, id) {
            if let Some((a, t)) = at(x, y) {
                write(i, a, t);
            }
        }
    });
}
