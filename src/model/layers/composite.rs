//! Flattening a [`LayerStack`] into [`MaterialMaps`], tile by tile.
//!
//! Per texel, bottom-up: the base (opaque), then each visible layer's enabled channels laid on
//! with their blend mode at `coverage x opacity x mask` (W3C source-over with a separable
//! blend, [`Covered::under`]). `k_d` and `k_s` composite as linear values, `n` in the log space
//! the brushes use. A group composites its children onto nothing first, then lays the result
//! over what is below like one layer. The result is encoded as the maps store it.
//!
//! Only the layers that take part at a tile are visited there: visible, not masked out, and
//! with something at that tile (a paint layer's untouched tile is nothing). [`Compositor`]
//! keeps, per tile, a signature of everything that tile's composite depends on (those layers'
//! settings and the stamps of their tiles and mask tiles there) and recomposites only the
//! tiles whose signature changed: hiding a layer recomposites only where it has paint. A tile is computed by the same
//! function either way, so the incremental result is bit-identical to flattening the whole
//! stack from scratch; a recomposited tile that comes out the same is not written, so the
//! maps' dirty tiles (and the GPU upload) stay the ones that really changed.

use std::hash::{Hash, Hasher};

use glam::Vec3;
use rayon::prelude::*;

use super::{Covered, Layer, LayerContent, LayerStack, PaintTile};
use crate::model::maps::MaterialMaps;
use crate::model::texel::{
    Texel, decode_n, decode_rgb, decode_unorm, encode_n, encode_rgb, n_from_blend, n_to_blend,
};
use crate::model::tile::{TILE_TEXELS, Tile};

/// One texel being composited: `k_d` RGB, `k_s` RGB, `n` (log space).
type State = [Covered; 7];

/// The components of `k_d`, `k_s` and `n` in a [`State`].
const PARTS: [std::ops::Range<usize>; 3] = [0..3, 3..6, 6..7];

/// A stored texel as compositing values.
fn values(t: Texel) -> [f32; 7] {
    let kd = decode_rgb(t.kd);
    let ks = decode_rgb(t.ks);
    [
        kd.x,
        kd.y,
        kd.z,
        ks.x,
        ks.y,
        ks.z,
        n_to_blend(decode_n(t.n)),
    ]
}

/// A layer as it takes part at one tile: only visible layers that cover something there
/// (a paint layer's tile, a fill, a group with such children), each with what it needs.
enum Active<'a> {
    /// A paint layer's tile.
    Paint(&'a Layer, &'a PaintTile),
    /// A fill layer, its value as compositing values.
    Fill(&'a Layer, [f32; 7]),
    /// A group and its active children.
    Group(&'a Layer, Vec<Active<'a>>),
}

impl Active<'_> {
    fn layer(&self) -> &Layer {
        match self {
            Self::Paint(l, _) | Self::Fill(l, _) | Self::Group(l, _) => l,
        }
    }
}

/// The layers of `layers` that take part at tile `id`, bottom first.
fn active(layers: &[Layer], id: usize) -> Vec<Active<'_>> {
    layers
        .iter()
        .filter(|l| {
            let p = &l.props;
            let hidden_by_mask = l.mask.as_ref().is_some_and(|m| {
                m.enabled
                    && m.tiles[id]
                        .get()
                        .uniform()
                        .is_some_and(|v| if m.inverted { v == u16::MAX } else { v == 0 })
            });
            p.visible && p.opacity > 0.0 && p.channels.iter().any(|c| c.enabled) && !hidden_by_mask
        })
        .filter_map(|l| match &l.content {
            LayerContent::Paint(tiles) => tiles[id].as_ref().map(|t| Active::Paint(l, t.get())),
            LayerContent::Fill(v) => Some(Active::Fill(l, values(Texel::encode(*v)))),
            LayerContent::Group(children) => {
                let inner = active(children, id);
                (!inner.is_empty()).then_some(Active::Group(l, inner))
            }
        })
        .collect()
}

/// How much of `layer` its mask shows at texel `i` of tile `id` (1 without a mask).
fn masked(layer: &Layer, id: usize, i: usize) -> f32 {
    match &layer.mask {
        Some(mask) if mask.enabled => {
            let m = decode_unorm(mask.tiles[id].get().get(i));
            if mask.inverted { 1.0 - m } else { m }
        }
        _ => 1.0,
    }
}

/// Lays the source `v` at per-channel coverage `alpha` over `state` with `layer`'s modes.
fn lay(state: &mut State, layer: &Layer, v: &[f32; 7], alpha: [f32; 3]) {
    for (c, part) in PARTS.iter().enumerate() {
        let blend = layer.props.channels[c];
        if blend.enabled && alpha[c] > 0.0 {
            for k in part.clone() {
                let source = Covered {
                    value: v[k],
                    alpha: alpha[c],
                };
                state[k] = state[k].under(source, blend.mode);
            }
        }
    }
}

/// Lays the active layers (bottom first) over `state` at texel `i` of tile `id`.
fn apply(state: &mut State, layers: &[Active<'_>], id: usize, i: usize) {
    for a in layers {
        let layer = a.layer();
        let cover = layer.props.opacity.clamp(0.0, 1.0) * masked(layer, id, i);
        if cover <= 0.0 {
            continue;
        }
        match a {
            Active::Paint(_, tile) => {
                let alpha = |c: usize| decode_unorm(tile.alpha[c].get(i)) * cover;
                lay(
                    state,
                    layer,
                    &values(tile.value.texel(i)),
                    [alpha(0), alpha(1), alpha(2)],
                );
            }
            Active::Fill(_, v) => lay(state, layer, v, [cover; 3]),
            Active::Group(_, children) => {
                let mut inner = [Covered::CLEAR; 7];
                apply(&mut inner, children, id, i);
                for (c, part) in PARTS.iter().enumerate() {
                    let blend = layer.props.channels[c];
                    if blend.enabled {
                        for k in part.clone() {
                            let source = Covered {
                                value: inner[k].value,
                                alpha: inner[k].alpha * cover,
                            };
                            state[k] = state[k].under(source, blend.mode);
                        }
                    }
                }
            }
        }
    }
}

/// Whether every input of the active layers at tile `id` is one value over the tile (then
/// one texel stands for all).
fn uniform_inputs(layers: &[Active<'_>], id: usize) -> bool {
    layers.iter().all(|a| {
        let mask = a
            .layer()
            .mask
            .as_ref()
            .is_none_or(|m| !m.enabled || m.tiles[id].get().uniform().is_some());
        mask && match a {
            Active::Paint(_, t) => {
                t.value.kd.uniform().is_some()
                    && t.value.ks.uniform().is_some()
                    && t.value.n.uniform().is_some()
                    && t.alpha.iter().all(|a| a.uniform().is_some())
            }
            Active::Fill(..) => true,
            Active::Group(_, children) => uniform_inputs(children, id),
        }
    })
}

/// The composite of texel `i` of tile `id`, as stored.
fn texel(layers: &[Active<'_>], base: &[f32; 7], id: usize, i: usize) -> Texel {
    let mut state: State = base.map(Covered::opaque);
    apply(&mut state, layers, id, i);
    let v = state.map(|c| c.value);
    Texel {
        kd: encode_rgb(Vec3::new(v[0], v[1], v[2])),
        ks: encode_rgb(Vec3::new(v[3], v[4], v[5])),
        n: encode_n(n_from_blend(v[6])),
    }
}

/// The composite of tile `id`, compacted (a tile of one value is stored as one value).
pub fn composite_tile(stack: &LayerStack, id: usize) -> Tile {
    composite_active(stack, &active(&stack.layers, id), id)
}

fn composite_active(stack: &LayerStack, layers: &[Active<'_>], id: usize) -> Tile {
    let base = values(Texel::encode(stack.base));
    if uniform_inputs(layers, id) {
        return Tile::uniform(texel(layers, &base, id, 0));
    }
    let mut tile = Tile::uniform(Texel::default());
    for i in 0..TILE_TEXELS {
        tile.set_texel(i, texel(layers, &base, id, i));
    }
    tile.compact();
    tile
}

/// Hashes what the composite of tile `id` depends on: per active layer, in order, its
/// settings, its fill value or its tile's stamp, its mask's switches and tile stamp, and its
/// active children.
fn hash_active(layers: &[Active<'_>], id: usize, h: &mut impl Hasher) {
    layers.len().hash(h);
    for a in layers {
        let l = a.layer();
        (l.props.opacity.to_bits(), l.props.channels).hash(h);
        l.mask
            .as_ref()
            .map(|m| (m.enabled, m.inverted, m.tiles[id].stamp()))
            .hash(h);
        match a {
            Active::Paint(_, _) => {
                let LayerContent::Paint(tiles) = &l.content else {
                    continue;
                };
                (0u8, tiles[id].as_ref().map_or(0, |t| t.stamp())).hash(h);
            }
            Active::Fill(_, v) => (1u8, v.map(f32::to_bits)).hash(h),
            Active::Group(_, children) => {
                2u8.hash(h);
                hash_active(children, id, h);
            }
        }
    }
}

/// Keeps [`MaterialMaps`] the composite of a [`LayerStack`], recompositing only the tiles
/// whose inputs changed.
#[derive(Clone, Debug, Default)]
pub struct Compositor {
    /// Per tile, the signature of the inputs it was composited from (0: never).
    signatures: Vec<u64>,
}

impl Compositor {
    /// A compositor that has composited nothing yet (its first update does every tile).
    pub fn new() -> Self {
        Self::default()
    }

    /// Brings `maps` up to date with `stack` (of the same size): recomposites the tiles whose
    /// inputs changed since the last update, in parallel, and writes those that came out
    /// different. Returns the tiles written, ascending.
    pub fn update(&mut self, stack: &LayerStack, maps: &mut MaterialMaps) -> Vec<usize> {
        let count = stack.tile_count();
        debug_assert_eq!(
            count,
            maps.tile_count(),
            "the stack and the maps differ in size"
        );
        if self.signatures.len() != count {
            self.signatures = vec![0; count];
        }
        let base = Texel::encode(stack.base);
        let signature = |id: usize| {
            let mut h = std::hash::DefaultHasher::new();
            (stack.width, stack.height, base).hash(&mut h);
            hash_active(&active(&stack.layers, id), id, &mut h);
            h.finish().max(1)
        };
        let stale: Vec<(usize, u64)> = (0..count)
            .into_par_iter()
            .map(|id| (id, signature(id)))
            .filter(|&(id, s)| self.signatures[id] != s)
            .collect();
        let tiles: Vec<(usize, u64, Tile)> = stale
            .into_par_iter()
            .map(|(id, s)| (id, s, composite_tile(stack, id)))
            .collect();
        let mut written = Vec::new();
        for (id, s, tile) in tiles {
            self.signatures[id] = s;
            if **maps.tile(id) != tile {
                maps.replace_tile(id, std::sync::Arc::new(tile));
                written.push(id);
            }
        }
        written
    }
}

#[cfg(test)]
mod tests;
