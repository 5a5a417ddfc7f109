//! Flattening a [`LayerStack`] into [`MaterialMaps`], tile by tile.
//!
//! Per texel, bottom-up: the base (opaque), then each visible layer's enabled channels laid on
//! with their blend mode at `coverage x opacity x mask` (W3C source-over with a separable
//! blend, [`Covered::under`]). `k_d` and `k_s` composite as linear values, `n` in the log space
//! the brushes use. A group composites its children onto nothing first, then lays the result
//! over what is below like one layer. The result is encoded as the maps store it.
//!
//! [`Compositor`] keeps, per tile, a signature of everything that tile's composite depends on
//! (the stack's settings and the stamps of every layer's and mask's tile there) and
//! recomposites only the tiles whose signature changed. A tile is computed by the same
//! function either way, so the incremental result is bit-identical to flattening the whole
//! stack from scratch; a recomposited tile that comes out the same is not written, so the
//! maps' dirty tiles (and the GPU upload) stay the ones that really changed.

use std::hash::{Hash, Hasher};

use glam::Vec3;
use rayon::prelude::*;

use super::{Covered, Layer, LayerContent, LayerStack};
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

/// Lays `layers` (bottom first) over `state` at texel `i` of tile `id`.
fn apply(state: &mut State, layers: &[Layer], id: usize, i: usize) {
    for layer in layers.iter().filter(|l| l.props.visible) {
        let cover = layer.props.opacity.clamp(0.0, 1.0) * masked(layer, id, i);
        if cover <= 0.0 {
            continue;
        }
        // The layer's values and, per channel, its coverage here.
        let (v, alpha) = match &layer.content {
            LayerContent::Paint(tiles) => {
                let Some(tile) = &tiles[id] else { continue };
                let tile = tile.get();
                let a = |c: usize| decode_unorm(tile.alpha[c].get(i)) * cover;
                (values(tile.value.texel(i)), [a(0), a(1), a(2)])
            }
            LayerContent::Fill(value) => (values(Texel::encode(*value)), [cover; 3]),
            LayerContent::Group(children) => {
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
                continue;
            }
        };
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
}

/// Whether every input of tile `id` is one value over the tile (then one texel stands for
/// all).
fn uniform_inputs(layers: &[Layer], id: usize) -> bool {
    layers.iter().filter(|l| l.props.visible).all(|layer| {
        let mask = layer
            .mask
            .as_ref()
            .is_none_or(|m| !m.enabled || m.tiles[id].get().uniform().is_some());
        let content = match &layer.content {
            LayerContent::Paint(tiles) => tiles[id].as_ref().is_none_or(|t| {
                let t = t.get();
                t.value.kd.uniform().is_some()
                    && t.value.ks.uniform().is_some()
                    && t.value.n.uniform().is_some()
                    && t.alpha.iter().all(|a| a.uniform().is_some())
            }),
            LayerContent::Fill(_) => true,
            LayerContent::Group(children) => uniform_inputs(children, id),
        };
        mask && content
    })
}

/// The composite of texel `i` of tile `id`, as stored.
fn texel(stack: &LayerStack, base: &[f32; 7], id: usize, i: usize) -> Texel {
    let mut state: State = base.map(Covered::opaque);
    apply(&mut state, &stack.layers, id, i);
    let v = state.map(|c| c.value);
    Texel {
        kd: encode_rgb(Vec3::new(v[0], v[1], v[2])),
        ks: encode_rgb(Vec3::new(v[3], v[4], v[5])),
        n: encode_n(n_from_blend(v[6])),
    }
}

/// The composite of tile `id`, compacted (a tile of one value is stored as one value).
pub fn composite_tile(stack: &LayerStack, id: usize) -> Tile {
    let base = values(Texel::encode(stack.base));
    if uniform_inputs(&stack.layers, id) {
        return Tile::uniform(texel(stack, &base, id, 0));
    }
    let mut tile = Tile::uniform(Texel::default());
    for i in 0..TILE_TEXELS {
        tile.set_texel(i, texel(stack, &base, id, i));
    }
    tile.compact();
    tile
}

/// Hashes everything about the stack but its tiles: sizes, base, and per layer its settings,
/// kind, fill value and mask switches, in order.
fn hash_settings(layers: &[Layer], h: &mut impl Hasher) {
    layers.len().hash(h);
    for layer in layers {
        let p = &layer.props;
        (p.visible, p.opacity.to_bits(), p.channels).hash(h);
        layer.mask.as_ref().map(|m| (m.enabled, m.inverted)).hash(h);
        match &layer.content {
            LayerContent::Paint(_) => 0u8.hash(h),
            LayerContent::Fill(v) => {
                1u8.hash(h);
                Texel::encode(*v).hash(h);
            }
            LayerContent::Group(children) => {
                2u8.hash(h);
                hash_settings(children, h);
            }
        }
    }
}

/// Hashes the stamps of every layer's and mask's tile `id`, in order.
fn hash_tiles(layers: &[Layer], id: usize, h: &mut impl Hasher) {
    for layer in layers {
        if let Some(m) = &layer.mask {
            m.tiles[id].stamp().hash(h);
        }
        match &layer.content {
            LayerContent::Paint(tiles) => tiles[id].as_ref().map_or(0, |t| t.stamp()).hash(h),
            LayerContent::Fill(_) => {}
            LayerContent::Group(children) => hash_tiles(children, id, h),
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
        let settings = {
            let mut h = std::hash::DefaultHasher::new();
            (stack.width, stack.height, Texel::encode(stack.base)).hash(&mut h);
            hash_settings(&stack.layers, &mut h);
            h.finish()
        };
        let signature = |id: usize| {
            let mut h = std::hash::DefaultHasher::new();
            settings.hash(&mut h);
            hash_tiles(&stack.layers, id, &mut h);
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
