//! A generator laid on a map: its mask value per tile, computed the first time a tile is read
//! (by the compositor, a thumbnail, the mask view) and kept until the generator, the mesh, the
//! bakes or the map size change. Where a texel is on the surface comes from the document's UV
//! bake of its mesh; a document without a mesh paints the builtin sphere, whose UV layout
//! gives it analytically.
//!
//! A coarse result (one value per 4 x 4 texels) is what the editor shows while a parameter is
//! dragged: a sixteenth of the work, replaced by the full result when the drag ends.

use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3};
use kapaint_mesh::bake::Coverage;
use kapaint_mesh::bakes::Baked;

use super::{Evaluator, Generator, Grid, Texel};
use crate::surface::Surface;
use crate::tile::{Plane, TILE_SIZE, TILE_TEXELS};

/// The next stamp of a laid generator (0 stands for none).
fn next_stamp() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Texels a side of one coarse sample.
pub const COARSE: usize = 4;

/// What a generator reads besides its parameters.
#[derive(Clone, Debug)]
pub struct Source {
    /// The [content hash](kapaint_mesh::Mesh::content_hash) of the mesh it is laid on
    /// (`None`: no mesh, the analytic sphere).
    pub mesh: Option<u64>,
    /// That mesh's UV bake at the map size, once attached (texels read as no surface until
    /// then).
    pub surface: Option<Arc<Surface>>,
    /// The document's bakes (only those at the map size are read).
    pub bakes: Vec<Arc<Baked>>,
    /// Map width in texels.
    pub width: u32,
    /// Map height in texels.
    pub height: u32,
}

impl Source {
    /// `surface` and those of `bakes` made at `width x height`.
    pub fn new(
        surface: Option<Arc<Surface>>,
        bakes: &[Arc<Baked>],
        width: u32,
        height: u32,
    ) -> Self {
        Self {
            mesh: surface.as_ref().map(|s| s.mesh_hash),
            surface,
            bakes: bakes
                .iter()
                .filter(|b| (b.width, b.height) == (width, height))
                .cloned()
                .collect(),
            width,
            height,
        }
    }

    /// The inputs of a project just read, before its mesh is attached: the mesh it names
    /// (by hash), its bakes and size.
    pub fn expecting(mesh: Option<u64>, bakes: &[Arc<Baked>], width: u32, height: u32) -> Self {
        Self {
            mesh,
            ..Self::new(None, bakes, width, height)
        }
    }

    /// Whether `other` is the same inputs: the same mesh (by hash), size and bakes (by
    /// identity).
    pub fn same(&self, other: &Self) -> bool {
        self.mesh == other.mesh
            && (self.width, self.height) == (other.width, other.height)
            && self.bakes.len() == other.bakes.len()
            && self
                .bakes
                .iter()
                .zip(&other.bakes)
                .all(|(a, b)| Arc::ptr_eq(a, b))
    }
}

/// A generator laid on a map, its tiles computed when first read.
pub struct Generated {
    stamp: u64,
    generator: Generator,
    /// The generator as evaluated: its relative levels made absolute on the source's bakes.
    evaluated: Generator,
    coarse: bool,
    source: Source,
    bounds: (Vec3, Vec3),
    tiles: Vec<OnceLock<Plane<u16>>>,
}

impl std::fmt::Debug for Generated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Generated")
            .field("generator", &self.generator)
            .field("coarse", &self.coarse)
            .finish_non_exhaustive()
    }
}

impl PartialEq for Generated {
    /// The same parameters at the same resolution (the inputs are the document's own).
    fn eq(&self, other: &Self) -> bool {
        self.generator == other.generator && self.coarse == other.coarse
    }
}

impl Generated {
    /// `generator` over `source`'s map, nothing computed yet; `coarse` computes one value per
    /// [`COARSE`]² texels.
    pub fn new(generator: Generator, source: Source, coarse: bool) -> Self {
        let tiles_x = (source.width as usize).div_ceil(TILE_SIZE);
        let tiles_y = (source.height as usize).div_ceil(TILE_SIZE);
        let source = Self::fitted(source);
        let bounds = source
            .surface
            .as_ref()
            .map_or((Vec3::splat(-1.0), Vec3::splat(1.0)), |s| s.mesh.bounds());
        debug_assert!(
            source
                .surface
                .as_ref()
                .is_none_or(|s| Some(s.mesh_hash) == source.mesh),
            "a source's surface is of its mesh"
        );
        Self {
            stamp: next_stamp(),
            evaluated: generator.resolved(&source.bakes),
            generator,
            coarse,
            source,
            bounds,
            tiles: (0..tiles_x * tiles_y).map(|_| OnceLock::new()).collect(),
        }
    }

    /// `source` with only the bakes of its size.
    fn fitted(source: Source) -> Source {
        Source {
            mesh: source.mesh,
            ..Source::new(source.surface, &source.bakes, source.width, source.height)
        }
    }

    /// A number no other laid generator has: what the compositor compares.
    pub fn stamp(&self) -> u64 {
        self.stamp
    }

    /// The parameters.
    pub fn generator(&self) -> &Generator {
        &self.generator
    }

    /// Whether this is the coarse result shown while dragging.
    pub fn is_coarse(&self) -> bool {
        self.coarse
    }

    /// What it reads.
    pub fn source(&self) -> &Source {
        &self.source
    }

    /// The mask values of tile `id` (computed now if no one read them before).
    pub fn tile(&self, id: usize) -> &Plane<u16> {
        self.tiles[id].get_or_init(|| self.evaluate(id))
    }

    /// The value at texel `i` of tile `id`: from the tile if it was computed, else computed
    /// alone (a thumbnail reads a few texels of every tile: it need not compute them all).
    pub fn sample(&self, id: usize, i: usize) -> u16 {
        if let Some(tile) = self.tiles[id].get() {
            return tile.get(i);
        }
        let tiles_x = (self.source.width as usize).div_ceil(TILE_SIZE);
        let (x, y) = (
            (id % tiles_x) * TILE_SIZE + i % TILE_SIZE,
            (id / tiles_x) * TILE_SIZE + i / TILE_SIZE,
        );
        let grid = Grid {
            side: 1,
            texels: self.texels((x, y), 1, 1),
        };
        let mut v = [0.0];
        Evaluator::new(&self.evaluated, &self.source.bakes).grid_values(&grid, false, &mut v);
        unorm(v[0])
    }

    /// Heap bytes of the tiles computed so far.
    pub fn heap_bytes(&self) -> usize {
        self.tiles
            .iter()
            .filter_map(OnceLock::get)
            .map(Plane::heap_bytes)
            .sum()
    }

    /// Where the texels of a `side x side` grid of samples `step` apart from `(x0, y0)` are
    /// on the surface (each at the centre of its `step x step` block), `None` where no
    /// triangle is or past the map's edge.
    fn texels(&self, (x0, y0): (usize, usize), step: usize, side: usize) -> Vec<Option<Texel>> {
        let (w, h) = (self.source.width as usize, self.source.height as usize);
        let (lo, hi) = self.bounds;
        let scale = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE)).recip();
        if self.source.mesh.is_some() && self.source.surface.is_none() {
            // The mesh is not attached yet: no texel is known to be on it.
            return vec![None; side * side];
        }
        let at = |k: usize| {
            let (x, y) = (x0 + k * step, y0 + k * step);
            ((x + step / 2).min(w - 1), (y + step / 2).min(h - 1))
        };
        let uv = |x: usize, y: usize| {
            Vec2::new(
                (x as f32 + 0.5) / w as f32,
                1.0 - (y as f32 + 0.5) / h as f32,
            )
        };
        let inside = |kx: usize, ky: usize| x0 + kx * step < w && y0 + ky * step < h;
        if let Some(s) = &self.source.surface {
            return (0..side * side)
                .map(|k| {
                    let (kx, ky) = (k % side, k / side);
                    if !inside(kx, ky) {
                        return None;
                    }
                    let (x, y) = (at(kx).0, at(ky).1);
                    let index = y * w + x;
                    if s.bake.coverage(index) == Coverage::Empty {
                        return None;
                    }
                    Some(Texel {
                        uv: uv(x, y),
                        position: (s.bake.position(index) - lo) * scale,
                        normal: s.bake.normal(index),
                        index,
                    })
                })
                .collect();
        }
        // The builtin sphere: u runs around +Y from +X, v from the north pole down;
        // the angles' sines and cosines once per row and column.
        let rows: Vec<(f32, f32)> = (0..side)
            .map(|k| (std::f32::consts::PI * (1.0 - uv(0, at(k).1).y)).sin_cos())
            .collect();
        let cols: Vec<(f32, f32)> = (0..side)
            .map(|k| (std::f32::consts::TAU * uv(at(k).0, 0).x).sin_cos())
            .collect();
        (0..side * side)
            .map(|k| {
                let (kx, ky) = (k % side, k / side);
                if !inside(kx, ky) {
                    return None;
                }
                let ((st, ct), (sp, cp)) = (rows[ky], cols[kx]);
                let p = Vec3::new(st * cp, ct, -st * sp);
                let (x, y) = (at(kx).0, at(ky).1);
                Some(Texel {
                    uv: uv(x, y),
                    position: (p - lo) * scale,
                    normal: p,
                    index: y * w + x,
                })
            })
            .collect()
    }

    /// Computes tile `id`: uniform where every texel came out the same (a tile no triangle
    /// reaches is uniform 0, and costs nothing).
    fn evaluate(&self, id: usize) -> Plane<u16> {
        self.evaluate_with(id, !self.coarse)
    }

    /// Tile `id` with every texel computed, none interpolated (what the tests compare with).
    #[cfg(test)]
    pub(crate) fn tile_exact(&self, id: usize) -> Plane<u16> {
        self.evaluate_with(id, false)
    }

    /// Tile `id`, noise interpolated where smooth if `interpolate`.
    fn evaluate_with(&self, id: usize, interpolate: bool) -> Plane<u16> {
        let tiles_x = (self.source.width as usize).div_ceil(TILE_SIZE);
        let (x0, y0) = ((id % tiles_x) * TILE_SIZE, (id / tiles_x) * TILE_SIZE);
        let step = if self.coarse { COARSE } else { 1 };
        let side = TILE_SIZE / step;
        let texels = self.texels((x0, y0), step, side);
        if texels.iter().all(Option::is_none) {
            return Plane::Uniform(0);
        }
        let grid = Grid { side, texels };
        let mut values = vec![0.0; side * side];
        Evaluator::new(&self.evaluated, &self.source.bakes).grid_values(
            &grid,
            interpolate,
            &mut values,
        );
        let mut data = vec![0_u16; TILE_TEXELS];
        for (k, v) in values.into_iter().enumerate() {
            let (bx, by) = ((k % side) * step, (k / side) * step);
            let v = unorm(v);
            for row in data[by * TILE_SIZE..].chunks_mut(TILE_SIZE).take(step) {
                row[bx..bx + step].fill(v);
            }
        }
        let mut plane = Plane::Data(data.into_boxed_slice());
        plane.compact();
        plane
    }
}

/// `v` in `[0, 1]` as unorm16.
fn unorm(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// The paint over a generator that neither adds nor removes.
pub const NEUTRAL: u16 = 32768;

/// A generator's value `g` with the paint `p` over it: above [`NEUTRAL`] adds (white paint
/// makes it 1), below removes (black paint makes it 0).
#[inline]
pub fn with_paint(g: u16, p: u16) -> u16 {
    let (g, p) = (i64::from(g), i64::from(p));
    let n = i64::from(NEUTRAL);
    let v = if p >= n {
        g + (p - n) * 65535 / (65535 - n)
    } else {
        g - (n - p) * 65535 / n
    };
    u16::try_from(v.clamp(0, 65535)).unwrap_or(u16::MAX)
}
