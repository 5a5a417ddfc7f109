//! A stencil's weights as a stroke's dabs read them. A texel's weight depends only on where
//! it lies (and, for a stencil on the screen, on the view), not on the dab, and a texel lies
//! under a dozen or more dabs of a stroke: so the weights are worked out once a tile, at the
//! first dab that reads the tile, and kept for the stroke ([`StencilWeights`]).

use std::sync::{Arc, OnceLock};

use glam::Vec2;

use crate::maps::MaterialMaps;
use crate::paint::Stencil;
use crate::surface::Surface;
use crate::tile::TILE_SIZE;

/// A stencil as a dab reads it: on the canvas (each texel's weight where the texel lies), or
/// on the screen of a view (where the texel's surface point projects through it).
#[derive(Clone, Copy)]
pub(in crate::document) enum StencilOn<'a> {
    /// In texel space.
    Texels(&'a Stencil),
    /// On the screen: the stencil, the baked surface, the view's matrix to clip space.
    Screen(&'a Stencil, &'a Surface, glam::Mat4),
}

impl StencilOn<'_> {
    /// The weights of the row of texels from `(x, y)` (texel indices) on.
    fn row(&self, (x, y): (usize, usize), out: &mut [f32]) {
        match *self {
            Self::Texels(stencil) => {
                stencil.weights(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), out);
            }
            Self::Screen(stencil, surface, to_clip) => {
                let Some(view) = &stencil.view else {
                    out.fill(1.0);
                    return;
                };
                let row = y * surface.bake.width as usize + x;
                for (k, o) in out.iter_mut().enumerate() {
                    let i = row + k;
                    *o = match surface.bake.triangle(i) {
                        Some(_) => view
                            .to_screen(&to_clip, surface.bake.position(i))
                            .map_or(0.0, |p| stencil.weight(p)),
                        None => 0.0,
                    };
                }
            }
        }
    }
}

/// A stroke's stencil weights, per tile (`TILE_SIZE` x `TILE_SIZE`, row-major), each worked
/// out at the first dab that reads it, for the stencil (and surface) they were worked out for.
#[derive(Default)]
pub(in crate::document) struct StencilWeights {
    /// The stencil and the surface's address the tiles hold the weights of (an address is
    /// enough: the stroke's state before it holds the surface, so no other takes its place
    /// while the stroke lasts).
    key: Option<(Arc<Stencil>, usize)>,
    tiles: Vec<OnceLock<Box<[f32]>>>,
}

impl StencilWeights {
    /// Ready for `stencil` (on `surface`, where it lies on the screen) over `tiles` tiles:
    /// emptied where it held another stencil's weights.
    pub(in crate::document) fn prepare(
        &mut self,
        stencil: &Arc<Stencil>,
        surface: Option<&Surface>,
        tiles: usize,
    ) {
        let at = surface.map_or(0, |s| std::ptr::from_ref(s) as usize);
        let same = self
            .key
            .as_ref()
            .is_some_and(|(s, a)| Arc::ptr_eq(s, stencil) && *a == at);
        if !same || self.tiles.len() != tiles {
            self.key = Some((Arc::clone(stencil), at));
            self.tiles = (0..tiles).map(|_| OnceLock::new()).collect();
        }
    }
}

/// A stencil as a dab reads it, through its stroke's weights.
#[derive(Clone, Copy)]
pub(in crate::document) struct StencilRead<'a> {
    on: StencilOn<'a>,
    kept: &'a StencilWeights,
}

impl<'a> StencilRead<'a> {
    /// `on`, its weights kept in `kept` (prepared for it).
    pub(in crate::document) fn new(on: StencilOn<'a>, kept: &'a StencilWeights) -> Self {
        Self { on, kept }
    }

    /// The weights of tile `id`'s texels from `start` (its index in the tile, row-major at
    /// `TILE_SIZE` a row) along the row, into `out`.
    #[inline]
    pub(in crate::document) fn weights(
        &self,
        maps: &MaterialMaps,
        id: usize,
        start: usize,
        out: &mut [f32],
    ) {
        if let Some(tile) = self.kept.tiles.get(id) {
            let tile = tile.get_or_init(|| self.tile(maps, id));
            out.copy_from_slice(&tile[start..start + out.len()]);
        } else {
            // Not prepared for these maps: worked out for this run alone.
            let rect = maps.tile_rect(id);
            let (y, x) = (start / TILE_SIZE, start % TILE_SIZE);
            self.on
                .row((rect.x0 as usize + x, rect.y0 as usize + y), out);
        }
    }

    /// Every weight of tile `id`.
    fn tile(&self, maps: &MaterialMaps, id: usize) -> Box<[f32]> {
        let rect = maps.tile_rect(id);
        let mut out = vec![0.0; TILE_SIZE * TILE_SIZE];
        let width = (rect.x1 - rect.x0) as usize;
        for (y, row) in (rect.y0..rect.y1).zip(out.chunks_exact_mut(TILE_SIZE)) {
            self.on
                .row((rect.x0 as usize, y as usize), &mut row[..width]);
        }
        out.into()
    }
}
