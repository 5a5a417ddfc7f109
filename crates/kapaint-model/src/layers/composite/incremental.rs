//! Keeping the maps the composite of a stack as it changes: per tile, a signature of
//! everything its composite depends on, and recompositing only tiles (or the texels of them an
//! edit reached) whose signature changed.
#![expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]

use std::hash::{Hash, Hasher};

use rayon::prelude::*;

use super::{Active, CompositeTile, active_at, composite_spans, runs};
use crate::layers::LayerStack;
use crate::maps::MaterialMaps;
use crate::texel::{Channels, Texel};
use crate::tile::{Plane, Tile, TileSpans};
use kapaint_base::simd::{Kernel, vectorized};

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
            .map(|m| (m.enabled, m.inverted, m.stamps(id)))
            .hash(h);
        match a {
            Active::Paint(_, tile) => (0u8, tile.stamp()).hash(h),
            Active::Fill(_, v) => (1u8, v.map(f32::to_bits)).hash(h),
            Active::Group(_, children) => {
                2u8.hash(h);
                hash_active(children, id, h);
            }
        }
    }
}

/// The signature of tile `id`'s inputs (never 0).
fn signature(stack: &LayerStack, id: usize) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    (stack.width, stack.height, Texel::encode(stack.base)).hash(&mut h);
    hash_active(&active_at(&stack.layers, id, false), id, &mut h);
    h.finish().max(1)
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
        let stale: Vec<(usize, u64)> = (0..count)
            .into_par_iter()
            .map(|id| (id, signature(stack, id)))
            .filter(|&(id, s)| self.signatures[id] != s)
            .collect();
        self.write(stack, maps, stale)
    }

    /// As [`Self::update`], looking only at `ids` (the tiles a stroke touched: no other
    /// tile's inputs changed).
    pub fn update_tiles(
        &mut self,
        stack: &LayerStack,
        maps: &mut MaterialMaps,
        ids: &[usize],
    ) -> Vec<usize> {
        let count = stack.tile_count();
        if self.signatures.len() != count {
            self.signatures = vec![0; count];
        }
        let stale: Vec<(usize, u64)> = ids
            .par_iter()
            .map(|&id| (id, signature(stack, id)))
            .filter(|&(id, s)| self.signatures[id] != s)
            .collect();
        self.write(stack, maps, stale)
    }

    /// Whether each of tiles `ids` is composited from `stack` as it is now. Asked before an
    /// edit that writes only part of those tiles, it says which of them
    /// [`Self::update_regions`] may then recomposite only in part.
    pub fn current(&self, stack: &LayerStack, ids: &[usize]) -> Vec<bool> {
        // A few dozen tiles of a dab: cheaper than handing them to other threads.
        ids.iter()
            .map(|&id| self.signatures.get(id) == Some(&signature(stack, id)))
            .collect()
    }

    /// As [`Self::update_tiles`] after an edit that wrote only texels `spans` of each tile `id`
    /// of `regions` (in one layer's planes or mask), where those tiles were [`Self::current`]
    /// before it: only those texels are recomposited, into the maps' tiles in place. The
    /// result is bit-identical to recompositing the whole tiles.
    pub fn update_regions(
        &mut self,
        stack: &LayerStack,
        maps: &mut MaterialMaps,
        regions: &[(usize, TileSpans)],
    ) -> Vec<usize> {
        let count = stack.tile_count();
        if self.signatures.len() != count {
            self.signatures = vec![0; count];
        }
        // Each region's signature is taken in the same parallel pass that recomposites it
        // where it changed (no serial stretch for the other threads to fall asleep in).
        let ids: Vec<usize> = regions.iter().map(|r| r.0).collect();
        let signatures = &self.signatures;
        let results = maps.edit_tiles_par(&ids, |k, tile| {
            let (id, spans) = (regions[k].0, &regions[k].1);
            let s = signature(stack, id);
            if signatures[id] == s {
                return (Channels::NONE, None);
            }
            let changed = vectorized(Recomposite {
                stack,
                id,
                spans,
                tile,
            });
            (changed, Some(s))
        });
        let mut written = Vec::new();
        for (id, (changed, s)) in ids.into_iter().zip(results) {
            if let Some(s) = s {
                self.signatures[id] = s;
            }
            if !changed.is_empty() {
                written.push(id);
            }
        }
        written
    }

    /// Puts a recomposited tile in place if it differs; whether it did.
    fn replace(maps: &mut MaterialMaps, id: usize, tile: Tile) -> bool {
        let old = maps.tile(id);
        let changed = Channels {
            kd: old.kd != tile.kd,
            ks: old.ks != tile.ks,
            n: old.n != tile.n,
        };
        if changed.is_empty() {
            return false;
        }
        // Only the planes that changed are marked: the upload stays per channel.
        maps.replace_tile_in(id, std::sync::Arc::new(tile), changed);
        true
    }

    /// Composites the `stale` tiles (with their new signatures) and writes those that changed.
    fn write(
        &mut self,
        stack: &LayerStack,
        maps: &mut MaterialMaps,
        stale: Vec<(usize, u64)>,
    ) -> Vec<usize> {
        let tiles: Vec<(usize, u64, Tile)> = stale
            .into_par_iter()
            .map(|(id, s)| {
                let tile = vectorized(CompositeTile(stack, id));
                (id, s, tile)
            })
            .collect();
        let mut written = Vec::new();
        for (id, s, tile) in tiles {
            self.signatures[id] = s;
            if Self::replace(maps, id, tile) {
                written.push(id);
            }
        }
        written
    }
}

/// Texels `spans` of tile `id` of the maps (`tile`) recomposited from `stack`, writing only
/// the channels that changed; which did.
struct Recomposite<'a> {
    stack: &'a LayerStack,
    id: usize,
    spans: &'a TileSpans,
    tile: &'a mut std::sync::Arc<Tile>,
}

impl Kernel for Recomposite<'_> {
    type Output = Channels;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> Channels {
        let texels = composite_spans(self.stack, self.id, self.spans);
        let runs = runs(self.spans);
        let changed = Channels {
            kd: differs(&self.tile.kd, &runs, &texels.kd),
            ks: differs(&self.tile.ks, &runs, &texels.ks),
            n: differs(&self.tile.n, &runs, &texels.n),
        };
        if !changed.is_empty() {
            let tile = std::sync::Arc::make_mut(self.tile);
            if changed.kd {
                write_runs(&mut tile.kd, &runs, &texels.kd);
            }
            if changed.ks {
                write_runs(&mut tile.ks, &runs, &texels.ks);
            }
            if changed.n {
                write_runs(&mut tile.n, &runs, &texels.n);
            }
        }
        changed
    }
}

/// Whether the texels of `runs` of `plane` differ from `new` (row by row).
#[inline(always)]
fn differs<T: Copy + PartialEq>(
    plane: &Plane<T>,
    runs: &[(usize, usize, usize)],
    new: &[T],
) -> bool {
    match plane {
        Plane::Uniform(u) => new.iter().any(|v| v != u),
        Plane::Data(d) => runs
            .iter()
            .any(|&(start, at, len)| d[start..start + len] != new[at..at + len]),
    }
}

/// Writes `new` (row by row) into the texels of `runs` of `plane`, and compacts it.
#[inline(always)]
fn write_runs<T: Copy + PartialEq>(
    plane: &mut Plane<T>,
    runs: &[(usize, usize, usize)],
    new: &[T],
) {
    let data = plane.data_mut();
    for &(start, at, len) in runs {
        data[start..start + len].copy_from_slice(&new[at..at + len]);
    }
    plane.compact();
}
