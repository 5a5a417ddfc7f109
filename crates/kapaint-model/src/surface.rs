//! Painting on a mesh: the UV bake of the mesh at the map resolution, a spatial index over
//! its texels, and the object-space brush footprint ([`BallFootprint`]).
//!
//! A dab centred at a point on the surface weighs every texel by the 3D distance of the
//! texel's baked position, whatever UV island it lies in, so strokes cross UV seams without a
//! gap or a double band. The index is a two-level bounding-box hierarchy over the texel grid
//! (64 x 64 tiles, then 8 x 8 blocks): a dab visits the tiles and blocks whose boxes meet its
//! ball, so it costs what it touches.

use glam::Vec3;

use super::brush::BrushSettings;
use super::maps::TexelRect;
use super::maps::{MaterialMaps, TileId};
use super::paint::Footprint;
use super::tile::TILE_SIZE;
use kapaint_mesh::Mesh;
use kapaint_mesh::bake::{self, Coverage, UvBake};

/// Side of an index block in texels.
const BLOCK: usize = 8;

/// Blocks per tile side.
const BLOCKS_PER_TILE: usize = TILE_SIZE / BLOCK;

/// Texels of padding baked beyond island borders (for filtering, mips and export).
pub const BAKE_PADDING: u32 = 4;

/// An axis-aligned box; empty when `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    fn union(&mut self, other: &Self) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// Whether the box meets the ball (empty boxes never do).
    fn meets_ball(&self, center: Vec3, r2: f32) -> bool {
        self.distance_squared(center) <= r2
    }

    /// The squared distance from `p` to the box (infinite for an empty box).
    fn distance_squared(&self, p: Vec3) -> f32 {
        if self.min.cmple(self.max).all() {
            p.clamp(self.min, self.max).distance_squared(p)
        } else {
            f32::INFINITY
        }
    }
}

/// A mesh baked at a map resolution, ready for object-space painting.
#[derive(Debug)]
pub struct Surface {
    /// The mesh.
    pub mesh: Mesh,
    /// Its UV bake at the map resolution.
    pub bake: UvBake,
    /// [`Mesh::content_hash`] of the mesh (what generators and bakes know it by).
    pub mesh_hash: u64,
    /// Object units per texel (square root of the mesh's surface area over its UV area in
    /// texels): converts brush radius and spacing from texels to object units.
    pub units_per_texel: f32,
    tiles_x: usize,
    tile_boxes: Vec<Aabb>,
    /// Per tile, its `BLOCKS_PER_TILE^2` block boxes (row-major).
    block_boxes: Vec<[Aabb; BLOCKS_PER_TILE * BLOCKS_PER_TILE]>,
    /// Per triangle, the triangles across its edges, made on first use.
    neighbours: std::sync::OnceLock<Vec<[u32; 3]>>,
}

impl Surface {
    /// Bakes `mesh` at `width x height` and indexes the baked texels.
    ///
    /// # Errors
    /// When the mesh cannot be painted (no UVs, invalid) or the size is zero.
    pub fn new(mesh: Mesh, width: u32, height: u32) -> Result<Self, String> {
        use rayon::prelude::*;
        let bake = bake::bake(&mesh, width, height, BAKE_PADDING)?;
        let (w, h) = (width as usize, height as usize);
        let tiles_x = w.div_ceil(TILE_SIZE);
        let tiles_y = h.div_ceil(TILE_SIZE);
        let block_boxes: Vec<[Aabb; BLOCKS_PER_TILE * BLOCKS_PER_TILE]> = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map(|id| {
                let (tx, ty) = (id % tiles_x, id / tiles_x);
                let mut boxes = [Aabb::EMPTY; BLOCKS_PER_TILE * BLOCKS_PER_TILE];
                for y in ty * TILE_SIZE..((ty + 1) * TILE_SIZE).min(h) {
                    let row = y * w;
                    for x in tx * TILE_SIZE..((tx + 1) * TILE_SIZE).min(w) {
                        if bake.coverage(row + x) != Coverage::Empty {
                            let b = ((y % TILE_SIZE) / BLOCK) * BLOCKS_PER_TILE
                                + (x % TILE_SIZE) / BLOCK;
                            boxes[b].grow(bake.position(row + x));
                        }
                    }
                }
                boxes
            })
            .collect();
        let tile_boxes = block_boxes
            .iter()
            .map(|blocks| {
                let mut b = Aabb::EMPTY;
                for block in blocks {
                    b.union(block);
                }
                b
            })
            .collect();
        let units_per_texel = units_per_texel(&mesh, width, height);
        Ok(Self {
            mesh_hash: mesh.content_hash(),
            mesh,
            bake,
            units_per_texel,
            tiles_x,
            tile_boxes,
            block_boxes,
            neighbours: std::sync::OnceLock::new(),
        })
    }

    /// Per triangle, the triangle across the edge opposite each corner (`u32::MAX`: none),
    /// meeting where the corners lie at the same point (across UV seams too); made on first
    /// use.
    pub fn neighbours(&self) -> &[[u32; 3]] {
        self.neighbours
            .get_or_init(|| triangle_neighbours(&self.mesh))
    }

    /// Width of the bake in texels.
    pub fn width(&self) -> u32 {
        self.bake.width
    }

    /// Height of the bake in texels.
    pub fn height(&self) -> u32 {
        self.bake.height
    }

    /// The unit normal of the surface near `point`: the normal of the baked texel closest to
    /// it within `radius`, if any.
    pub fn normal_near(&self, point: Vec3, radius: f32) -> Option<Vec3> {
        self.nearest(point, radius).map(|(_, n)| n)
    }

    /// The tiles whose baked texels may lie within `radius` of `point`.
    pub fn tiles_near(&self, point: Vec3, radius: f32) -> Vec<TileId> {
        let r2 = radius * radius;
        (0..self.tile_boxes.len())
            .filter(|&id| self.tile_boxes[id].meets_ball(point, r2))
            .collect()
    }

    /// The baked surface texel nearest `point` within `radius`: its position and normal.
    pub fn nearest(&self, point: Vec3, radius: f32) -> Option<(Vec3, Vec3)> {
        self.nearest_texel(point, radius)
            .map(|i| (self.bake.position(i), self.bake.normal(i)))
    }

    /// The index of the baked surface texel nearest `point`, however far: looked for within
    /// `start`, then four times as far, and so on until the ball holds the whole mesh (the
    /// index costs what it visits, so a point near the surface is found cheaply).
    pub fn nearest_texel_from(&self, point: Vec3, start: f32) -> Option<usize> {
        if !point.is_finite() {
            return None;
        }
        let (lo, hi) = self.mesh.bounds();
        let far = lo.distance(hi) + point.distance(0.5 * (lo + hi));
        let mut r = start.max(self.units_per_texel).max(f32::MIN_POSITIVE);
        loop {
            if let Some(i) = self.nearest_texel(point, r) {
                return Some(i);
            }
            if !(r.is_finite() && r < far) {
                return None;
            }
            r *= 4.0;
        }
    }

    /// The index of the baked surface texel nearest `point` within `radius`.
    ///
    /// Nearest first: the tiles, then each tile's blocks, in the order of their boxes'
    /// distances, until the next box lies farther than the nearest texel found, so a query
    /// reads the texels of a block or two however large `radius` is.
    pub fn nearest_texel(&self, point: Vec3, radius: f32) -> Option<usize> {
        let mut best = (radius * radius, None);
        if best.0.is_nan() {
            return None;
        }
        let mut tiles: Vec<(f32, usize)> = (self.tile_boxes.iter().enumerate())
            .map(|(id, b)| (b.distance_squared(point), id))
            .filter(|&(d2, _)| d2 <= best.0)
            .collect();
        while let Some(k) = (0..tiles.len()).min_by(|&a, &b| tiles[a].0.total_cmp(&tiles[b].0)) {
            let (d2, id) = tiles.swap_remove(k);
            if d2 > best.0 {
                break;
            }
            let mut blocks: [(f32, usize); BLOCKS_PER_TILE * BLOCKS_PER_TILE] =
                std::array::from_fn(|b| (self.block_boxes[id][b].distance_squared(point), b));
            blocks.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            for (d2, b) in blocks {
                if d2 > best.0 {
                    break;
                }
                self.visit_block(id, b, |i, p| {
                    let d2 = p.distance_squared(point);
                    if d2 < best.0 || (best.1.is_none() && d2 <= best.0) {
                        best = (d2, Some(i));
                    }
                });
            }
        }
        best.1
    }

    /// Calls `f` with the index and position of every baked surface texel (not padding) of
    /// block `b` of tile `id`.
    #[inline]
    fn visit_block(&self, id: usize, b: usize, mut f: impl FnMut(usize, Vec3)) {
        let w = self.bake.width as usize;
        let bx = (id % self.tiles_x) * TILE_SIZE + (b % BLOCKS_PER_TILE) * BLOCK;
        let by = (id / self.tiles_x) * TILE_SIZE + (b / BLOCKS_PER_TILE) * BLOCK;
        for y in by..(by + BLOCK).min(self.bake.height as usize) {
            for x in bx..(bx + BLOCK).min(w) {
                let i = y * w + x;
                if self.bake.coverage(i) == Coverage::Surface {
                    f(i, self.bake.position(i));
                }
            }
        }
    }

    /// Calls `f` with the index and position of every baked surface texel (not padding)
    /// within `radius` of `point`.
    pub fn visit_near(&self, point: Vec3, radius: f32, mut f: impl FnMut(usize, Vec3)) {
        let r2 = radius * radius;
        for (id, tile) in self.tile_boxes.iter().enumerate() {
            if !tile.meets_ball(point, r2) {
                continue;
            }
            for (b, block) in self.block_boxes[id].iter().enumerate() {
                if block.meets_ball(point, r2) {
                    self.visit_block(id, b, |i, p| {
                        if p.distance_squared(point) <= r2 {
                            f(i, p);
                        }
                    });
                }
            }
        }
    }

    /// A mask of the texels (covered or padding) of the UV island under texel `(x, y)`, or
    /// `None` where no island is.
    pub fn island_mask(&self, x: u32, y: u32) -> Option<Vec<bool>> {
        let i = self.index(x, y)?;
        let island = self.bake.island(i)?;
        Some(
            (0..self.bake.len())
                .map(|k| self.bake.island(k) == Some(island))
                .collect(),
        )
    }

    /// A mask of the texels of the mesh part (connected piece of surface, through shared
    /// positions) under texel `(x, y)`, or `None` where the mesh is not.
    pub fn part_mask(&self, x: u32, y: u32) -> Option<Vec<bool>> {
        let i = self.index(x, y)?;
        let triangle = self.bake.triangle(i)?;
        let parts = self.mesh.parts();
        let part = parts[triangle as usize];
        Some(
            (0..self.bake.len())
                .map(|k| {
                    self.bake
                        .triangle(k)
                        .is_some_and(|t| parts[t as usize] == part)
                })
                .collect(),
        )
    }

    fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.bake.width && y < self.bake.height)
            .then(|| y as usize * self.bake.width as usize + x as usize)
    }
}

/// Object units per texel: `sqrt(surface area / UV area in texels)`, 1 for degenerate UVs.
fn units_per_texel(mesh: &Mesh, width: u32, height: u32) -> f32 {
    let Some(uvs) = &mesh.uvs else {
        return 1.0;
    };
    let texel = glam::DVec2::new(f64::from(width), f64::from(height));
    let (mut area, mut uv_area) = (0.0_f64, 0.0_f64);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
        area += (b - a).cross(c - a).length() / 2.0;
        let [p, q, r] = t.map(|v| uvs[v as usize].as_dvec2() * texel);
        uv_area += (q - p).perp_dot(r - p).abs() / 2.0;
    }
    let ratio = (area / uv_area).sqrt();
    if ratio.is_finite() && ratio > 0.0 {
        ratio as f32
    } else {
        1.0
    }
}

/// Per triangle of `mesh`, the triangle across the edge opposite each corner (`u32::MAX`:
/// none); corners at the same point are the same, so seams split in UV are crossed.
fn triangle_neighbours(mesh: &Mesh) -> Vec<[u32; 3]> {
    let mut welded: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    let ids: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = welded.len() as u32;
            // -0 and +0 are one point (adding zero turns -0 into +0).
            *welded
                .entry(p.to_array().map(|c| (c + 0.0).to_bits()))
                .or_insert(next)
        })
        .collect();
    let mut open: std::collections::HashMap<(u32, u32), (u32, usize)> =
        std::collections::HashMap::with_capacity(mesh.triangles.len() * 3 / 2);
    let mut out = vec![[u32::MAX; 3]; mesh.triangles.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let a = ids
                .get(tri[(k + 1) % 3] as usize)
                .copied()
                .unwrap_or(u32::MAX);
            let b = ids
                .get(tri[(k + 2) % 3] as usize)
                .copied()
                .unwrap_or(u32::MAX);
            match open.remove(&(a.min(b), a.max(b))) {
                Some((other, edge)) => {
                    out[t][k] = other;
                    out[other as usize][edge] = t as u32;
                }
                None => {
                    open.insert((a.min(b), a.max(b)), (t as u32, k));
                }
            }
        }
    }
    out
}

/// An object-space dab: a ball around a point on the surface, with the brush's hardness
/// falloff on 3D distance, optionally only where the surface faces the brush.
pub struct BallFootprint<'a> {
    /// The baked, indexed mesh.
    pub surface: &'a Surface,
    /// Centre in object space.
    pub center: Vec3,
    /// Radius in object units.
    pub radius: f32,
    /// The direction the brush faces (the surface normal at the centre); texels whose normal
    /// points away from it are skipped, with a soft edge. Zero: no facing test.
    pub normal: Vec3,
    /// Falloff.
    pub brush: &'a BrushSettings,
}

impl BallFootprint<'_> {
    /// The weight of a texel at squared distance `d2` whose normal is `blend` made unit
    /// (`fallback` where it has no length).
    #[inline]
    fn weight(&self, d2: f32, r2: f32, (blend, fallback): (Vec3, Vec3)) -> f32 {
        let w = self.brush.falloff_sq(d2, r2);
        if self.normal == Vec3::ZERO || w == 0.0 {
            return w;
        }
        // Full weight where the normals are within ~75 degrees (the unit normal's dot at
        // least 1/4, told without a square root: most texels), fading to zero at 90.
        let (dot, len2) = (blend.dot(self.normal), blend.length_squared());
        if dot > 0.0 && len2.is_normal() && 16.0 * dot * dot >= len2 {
            return w;
        }
        let n = blend.try_normalize().unwrap_or(fallback);
        w * (n.dot(self.normal) * 4.0).clamp(0.0, 1.0)
    }
}

impl Footprint for BallFootprint<'_> {
    fn tiles(&self, maps: &MaterialMaps) -> Vec<TileId> {
        let s = self.surface;
        if maps.width() != s.width() || maps.height() != s.height() {
            return Vec::new();
        }
        if !(self.center.is_finite() && self.radius.is_finite() && self.radius > 0.0) {
            return Vec::new();
        }
        let r2 = self.radius * self.radius;
        s.tile_boxes
            .iter()
            .enumerate()
            .filter(|(_, b)| b.meets_ball(self.center, r2))
            .map(|(id, _)| id)
            .collect()
    }

    fn visit_runs(&self, id: TileId, rect: TexelRect, mut f: impl FnMut(usize, &[f32])) {
        let s = self.surface;
        let TexelRect { x0, y0, x1, y1 } = rect;
        let r2 = self.radius * self.radius;
        let w = s.bake.width as usize;
        let blocks = &s.block_boxes[id];
        let mut weights = [0.0_f32; TILE_SIZE];
        for by in 0..BLOCKS_PER_TILE {
            let hit: [bool; BLOCKS_PER_TILE] = std::array::from_fn(|bx| {
                blocks[by * BLOCKS_PER_TILE + bx].meets_ball(self.center, r2)
            });
            let rows =
                (y0 as usize + by * BLOCK)..(y0 as usize + (by + 1) * BLOCK).min(y1 as usize);
            // Maximal spans of neighbouring blocks that meet the ball.
            let mut bx = 0;
            while bx < BLOCKS_PER_TILE {
                if !hit[bx] {
                    bx += 1;
                    continue;
                }
                let first = bx;
                while bx < BLOCKS_PER_TILE && hit[bx] {
                    bx += 1;
                }
                let xs = x0 as usize + first * BLOCK;
                let xe = (x0 as usize + bx * BLOCK).min(x1 as usize);
                if xe <= xs {
                    continue;
                }
                // The triangle of the texel before: its corners are loaded once a run of
                // texels on it.
                let mut corners: (u32, [Vec3; 3], [Vec3; 3]) =
                    (u32::MAX, [Vec3::ZERO; 3], [Vec3::ZERO; 3]);
                for y in rows.clone() {
                    let row = y * w;
                    let run = &mut weights[..xe - xs];
                    for (k, wt) in run.iter_mut().enumerate() {
                        let i = row + xs + k;
                        let Some(t) = s.bake.triangle(i) else {
                            *wt = 0.0;
                            continue;
                        };
                        if t != corners.0 {
                            corners = (t, s.bake.corners(t), s.bake.corner_normals(t));
                        }
                        let b = s.bake.barycentric(i);
                        let [pa, pb, pc] = corners.1;
                        let d2 = (pa * b.x + pb * b.y + pc * b.z).distance_squared(self.center);
                        *wt = if d2 < r2 {
                            // As the bake's normal: the corners' blend, made unit.
                            let [na, nb, nc] = corners.2;
                            self.weight(d2, r2, (na * b.x + nb * b.y + nc * b.z, na))
                        } else {
                            0.0
                        };
                    }
                    f(
                        (y - y0 as usize) * TILE_SIZE + (xs - x0 as usize),
                        &weights[..xe - xs],
                    );
                }
            }
        }
    }
}
