//! A projection fill: a fill layer that holds an image through a projection instead of one
//! material. What the layer keeps is the projection's parameters and the image; its tiles are
//! laid on the document's map through [`Mapper::lay_tile`] (the same texels `ProjectImage`
//! paints), each the first time it is read, and laid again whenever the mesh, its bake or the
//! map size change, so the layer follows the mesh it lies on.

use std::sync::{Arc, OnceLock};

use super::{PaintTile, SharedPaintTile, Stamped};
use crate::generator::tiles::Source;
use crate::paint::mapper::Mapper;
use crate::paint::projection::Projection;
use crate::paint_image::PaintImage;
use crate::texel::{Channels, Texel, encode_rgb, encode_unorm};
use crate::tile::{Plane, TILE_TEXELS, Tile};

/// What a projection fill holds: the image, how it is laid, the channels it fills.
#[derive(Clone, Debug, PartialEq)]
pub struct ProjectionFill {
    /// The image (loaded).
    pub image: PaintImage,
    /// How it is laid on the surface.
    pub projection: Projection,
    /// The channels it fills (the others show what lies below).
    pub channels: Channels,
}

/// A projection fill laid on a map: its tiles made when first read.
pub struct Projected {
    fill: ProjectionFill,
    source: Source,
    /// The mapper, made with the first tile (a planar one's depth map costs a pass over the
    /// mesh); `None` where the projection cannot be laid on the source (no mesh yet).
    mapper: OnceLock<Option<Mapper>>,
    tiles: Vec<OnceLock<Option<SharedPaintTile>>>,
}

impl std::fmt::Debug for Projected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Projected")
            .field("fill", &self.fill)
            .finish_non_exhaustive()
    }
}

impl PartialEq for Projected {
    /// The same parameters (the inputs are the document's own).
    fn eq(&self, other: &Self) -> bool {
        self.fill == other.fill
    }
}

impl Projected {
    /// `fill` laid on `source`'s map, nothing computed yet.
    pub fn new(fill: ProjectionFill, source: Source) -> Self {
        let count = tile_count(&source);
        Self {
            fill,
            source,
            mapper: OnceLock::new(),
            tiles: (0..count).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The parameters.
    pub fn fill(&self) -> &ProjectionFill {
        &self.fill
    }

    /// What it is laid on.
    pub fn source(&self) -> &Source {
        &self.source
    }

    /// Tile `id` as a paint layer's tile would hold it (`None`: the image reaches nothing
    /// there), laid now if no one read it before.
    pub fn tile(&self, id: usize) -> Option<&SharedPaintTile> {
        self.tiles
            .get(id)?
            .get_or_init(|| self.lay(id).map(|t| Arc::new(Stamped::new(t))))
            .as_ref()
    }

    /// Tiles in the map it is laid on.
    pub fn tile_count(&self) -> usize {
        self.tiles.len()
    }

    /// Heap bytes of the tiles laid so far.
    pub fn heap_bytes(&self) -> usize {
        self.tiles
            .iter()
            .filter_map(|t| t.get()?.as_ref())
            .map(|t| t.get().heap_bytes())
            .sum()
    }

    fn mapper(&self) -> Option<&Mapper> {
        self.mapper
            .get_or_init(|| {
                let pixels = Arc::clone(self.fill.image.pixels().ok()?);
                let surface = self.source.surface.clone();
                let size = (self.source.width, self.source.height);
                Mapper::new(&self.fill.projection, surface, pixels, size, None).ok()
            })
            .as_ref()
    }

    /// Lays tile `id`: the image's material where it reaches, at its alpha, in the enabled
    /// channels.
    fn lay(&self, id: usize) -> Option<PaintTile> {
        let mapper = self.mapper()?;
        let mut cover = vec![0.0_f32; TILE_TEXELS];
        let mut targets = super::edit::TileTargets::default();
        if mapper
            .lay_tile(id, (1.0, false), &mut cover, &mut targets)
            .is_empty()
        {
            return None;
        }
        let texel = |t: &[f32; 7]| Texel {
            kd: encode_rgb(glam::Vec3::new(t[0], t[1], t[2])),
            ks: encode_rgb(glam::Vec3::new(t[3], t[4], t[5])),
            n: crate::paint::n_bits_from_blend(t[6]),
        };
        let texels: Vec<Texel> = (0..TILE_TEXELS).map(|i| texel(&targets.get(i))).collect();
        let mut value = Tile::uniform(texel(&[0.0; 7]));
        value.kd = Plane::Data(texels.iter().map(|t| t.kd).collect());
        value.ks = Plane::Data(texels.iter().map(|t| t.ks).collect());
        value.n = Plane::Data(texels.iter().map(|t| t.n).collect());
        value.kd.compact();
        value.ks.compact();
        value.n.compact();
        let c = self.fill.channels;
        let alpha = [c.kd, c.ks, c.n].map(|on| {
            let mut plane = if on {
                Plane::Data(cover.iter().map(|&a| encode_unorm(a)).collect())
            } else {
                Plane::Uniform(0)
            };
            plane.compact();
            plane
        });
        Some(PaintTile { value, alpha })
    }
}

fn tile_count(source: &Source) -> usize {
    let side = crate::tile::TILE_SIZE;
    (source.width as usize).div_ceil(side) * (source.height as usize).div_ceil(side)
}

/// Lays `fill` again where what it reads changed: laid on another mesh, size or bakes, or on
/// the same mesh before its surface was attached; `None` where it stays as laid.
pub fn relaid(laid: &Projected, source: &Source) -> Option<Projected> {
    // No surface attached (yet, or for a while) does not change the mesh it was laid on.
    let source = match (&source.surface, laid.source.mesh) {
        (None, Some(mesh)) => &Source {
            mesh: Some(mesh),
            ..source.clone()
        },
        _ => source,
    };
    let meets_surface = laid.source.surface.is_none() && source.surface.is_some();
    (!laid.source.same(source) || meets_surface)
        .then(|| Projected::new(laid.fill.clone(), source.clone()))
}
