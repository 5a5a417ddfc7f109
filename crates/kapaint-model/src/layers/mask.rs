//! A layer's mask: painted, or made by a generator with paint over it; what it holds at a
//! texel, and laying its generator on what the document's surface and bakes are.

use std::sync::Arc;

use super::{Layer, LayerContent, SharedMaskTile, Stamped};
use crate::tile::Plane;

/// A layer's grayscale mask: painted, or made by a generator with paint over it.
#[derive(Clone, Debug, PartialEq)]
pub struct Mask {
    /// One plane a tile: the mask itself, or, over a generator, the paint that adds to it
    /// (above [`NEUTRAL`](crate::generator::tiles::NEUTRAL)) or removes from it (below).
    pub tiles: Vec<SharedMaskTile>,
    /// Whether it applies.
    pub enabled: bool,
    /// Whether it applies inverted (black shows the layer).
    pub inverted: bool,
    /// The generator it is made by, laid on the document's map (parameters, not pixels).
    pub generator: Option<Arc<crate::generator::tiles::Generated>>,
}

impl Mask {
    /// A white mask (shows the whole layer) of `tile_count` tiles; uniform, so free.
    pub fn white(tile_count: usize) -> Self {
        let white = Arc::new(Stamped::new(Plane::Uniform(u16::MAX)));
        Self {
            tiles: vec![white; tile_count],
            enabled: true,
            inverted: false,
            generator: None,
        }
    }

    /// A mask made by `generated`, nothing painted over it yet.
    pub fn generated(tile_count: usize, generated: crate::generator::tiles::Generated) -> Self {
        Self {
            tiles: vec![neutral_tile(); tile_count],
            enabled: true,
            inverted: false,
            generator: Some(Arc::new(generated)),
        }
    }

    /// Heap bytes of its planes and computed generator tiles (uniform planes cost nothing;
    /// shared planes count once each).
    pub fn heap_bytes(&self) -> usize {
        self.tiles
            .iter()
            .map(|t| t.get().heap_bytes())
            .sum::<usize>()
            + self.generator.as_ref().map_or(0, |g| g.heap_bytes())
    }

    /// The generator's parameters, if a generator makes it.
    pub fn generator(&self) -> Option<&crate::generator::Generator> {
        self.generator.as_ref().map(|g| g.generator())
    }

    /// The value of texel `i` of tile `id` as the mask holds it (before inversion).
    pub fn value(&self, id: usize, i: usize) -> u16 {
        let paint = self.tiles[id].get().get(i);
        match &self.generator {
            Some(g) => crate::generator::tiles::with_paint(g.tile(id).get(i), paint),
            None => paint,
        }
    }

    /// [`Self::value`] without computing a generator's whole tile for it (what thumbnails
    /// read).
    pub fn sample(&self, id: usize, i: usize) -> u16 {
        let paint = self.tiles[id].get().get(i);
        match &self.generator {
            Some(g) => crate::generator::tiles::with_paint(g.sample(id, i), paint),
            None => paint,
        }
    }

    /// The value every texel of tile `id` holds, if they all hold one (before inversion).
    pub fn uniform(&self, id: usize) -> Option<u16> {
        let paint = self.tiles[id].get().uniform()?;
        match &self.generator {
            Some(g) => g
                .tile(id)
                .uniform()
                .map(|v| crate::generator::tiles::with_paint(v, paint)),
            None => Some(paint),
        }
    }

    /// Tile `id`'s values as the mask holds them (before inversion).
    pub fn plane(&self, id: usize) -> std::borrow::Cow<'_, Plane<u16>> {
        use std::borrow::Cow;
        let paint = self.tiles[id].get();
        let Some(g) = &self.generator else {
            return Cow::Borrowed(paint);
        };
        let made = g.tile(id);
        match (made, paint.uniform()) {
            (_, Some(crate::generator::tiles::NEUTRAL)) => Cow::Borrowed(made),
            (Plane::Uniform(v), Some(p)) => {
                Cow::Owned(Plane::Uniform(crate::generator::tiles::with_paint(*v, p)))
            }
            _ => {
                let mut out = Plane::Uniform(0);
                for (i, o) in out.data_mut().iter_mut().enumerate() {
                    *o = crate::generator::tiles::with_paint(made.get(i), paint.get(i));
                }
                Cow::Owned(out)
            }
        }
    }

    /// What tile `id`'s values depend on: the paint tile's stamp and the generator's.
    pub fn stamps(&self, id: usize) -> (u64, u64) {
        (
            self.tiles[id].stamp(),
            self.generator.as_ref().map_or(0, |g| g.stamp()),
        )
    }
}

/// A tile of paint over a generator that neither adds nor removes (uniform, so free).
pub fn neutral_tile() -> SharedMaskTile {
    Arc::new(Stamped::new(Plane::Uniform(
        crate::generator::tiles::NEUTRAL,
    )))
}

/// Lays every generator mask and projection fill in `layers` (at any depth) on `source` where it was laid on
/// other inputs (a new stamp: recomposited), or gives it `source`'s surface where it was laid
/// on the same mesh before the surface was attached (the same stamp); whether any changed. A
/// `source` without a surface keeps the mesh each generator was laid on.
pub fn lay_generators(layers: &mut [Layer], source: &crate::generator::tiles::Source) -> bool {
    let mut changed = false;
    for layer in layers {
        if let Some(mask) = &mut layer.mask
            && let Some(g) = &mask.generator
        {
            // No surface attached (yet, or for a while) does not change the mesh a
            // generator was laid on.
            let source = match (&source.surface, g.source().mesh) {
                (None, Some(mesh)) => &crate::generator::tiles::Source {
                    mesh: Some(mesh),
                    ..source.clone()
                },
                _ => source,
            };
            // A generator laid before its mesh was attached is laid again on the mesh: its
            // values (and the composite made from them) are computed there, never taken from
            // a file.
            let meets_surface = g.source().surface.is_none() && source.surface.is_some();
            if !g.source().same(source) || meets_surface {
                let made = crate::generator::tiles::Generated::new(
                    g.generator().clone(),
                    source.clone(),
                    g.is_coarse(),
                );
                mask.generator = Some(Arc::new(made));
                changed = true;
            }
        }
        match &mut layer.content {
            LayerContent::Group(children) => changed |= lay_generators(children, source),
            LayerContent::Projected(p) => {
                if let Some(again) = super::projected::relaid(p, source) {
                    *p = Arc::new(again);
                    changed = true;
                }
            }
            LayerContent::Paint(_) | LayerContent::Fill(_) => {}
        }
    }
    changed
}
