//! Clone and smudge on the mesh, in object space: a clone texel takes what the composite
//! held (before the stroke) at the surface point nearest its own baked point moved by the
//! stroke's offset; a smudge texel moves towards what the composite holds now one dab-step
//! (object space) behind it. Each dab's centre, moved so, is put back on the surface first,
//! and its texels read at their displacement from there (see [`SourceGrid`]). The source is
//! found in object space, so both run across UV seams: the nearest baked texel names the
//! triangle, the point is projected onto that triangle, and its UV is read bilinearly from
//! the composite.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::copy_dab::{CloneSource, mask_now, value_at};
use crate::layers::SharedMaskTile;
use crate::layers::edit::{self, LayerEdit, Planes, PrePlanes, TileTargets};
use crate::maps::MaterialMaps;
use crate::paint::{Coverage, Footprint};
use crate::surface::Surface;
use crate::tile::{TILE_SIZE, Tile, TileSpans};

/// Most cells a grid keeps (4 bytes each): a larger box takes larger cells.
const MAX_CELLS: usize = 1 << 22;

/// The surface texels near a dab's source, in a grid of cubes, for nearest-texel queries.
///
/// The dab's centre moved by the offset is put back on the surface (its nearest surface
/// point, the anchor): each texel of the dab then reads the surface at its own displacement
/// from the dab's centre, turned as the surface turns from there to the anchor (the shortest
/// turn from the dab's normal to the anchor's), so the patch lies on the surface where the
/// source is, whichever way it faces, and every query starts within a few texels of it. A
/// texel whose source falls on the triangle the texel before it found (projected inside it,
/// within a texel of its plane) takes it from there; only the others ask the cells, made on
/// the first such query: the surface texels near the anchor sorted by cube (each cube's run
/// found by its index, no search).
pub(super) struct SourceGrid<'a> {
    surface: &'a Surface,
    /// The dab's centre, and where its source lies on the surface.
    center: Vec3,
    anchor: Vec3,
    /// The turn from the dab's normal to the anchor's.
    turn: glam::Quat,
    /// The farthest a source may lie from the surface (a dab's rim on a differently curved
    /// part of the mesh, beyond it, is not written).
    reach: f32,
    /// The dab's radius (object units).
    radius: f32,
    /// The anchor's triangle: where the first texel's search starts.
    anchor_triangle: Option<u32>,
    /// The cells, made when a texel's source first leaves the triangle of the texel before
    /// it (most of a dab's texels find their source on that triangle).
    cells: std::sync::OnceLock<Cells>,
}

/// The surface texels near a dab's source, sorted into cubes.
struct Cells {
    cell: f32,
    reach: f32,
    /// The box of cells: its first cell and its size in cells.
    low: [i32; 3],
    dims: [i32; 3],
    /// Where each cell's texels start in `points` and `texels` (one more entry at the end).
    starts: Vec<u32>,
    points: Vec<Vec3>,
    texels: Vec<u32>,
}

impl<'a> SourceGrid<'a> {
    /// The grid for a dab at `center` (facing `normal`, zero: unknown) of `radius` (object
    /// units), its source `offset` away; `None` when no surface lies near the source.
    pub(super) fn new(
        surface: &'a Surface,
        (center, normal): (Vec3, Vec3),
        radius: f32,
        offset: Vec3,
    ) -> Option<Self> {
        let upt = surface.units_per_texel.max(f32::MIN_POSITIVE);
        let reach = 6.0 * upt;
        let source = center + offset;
        let near = surface.nearest_texel_from(source, 4.0 * upt)?;
        // On the surface itself: the nearest texel's triangle's nearest point (a texel's
        // centre would shift the whole patch by up to half a texel).
        let (anchor, anchor_normal) = surface_point(surface, source, near);
        let turn = if normal.length_squared() > 0.0 && anchor_normal.length_squared() > 0.0 {
            glam::Quat::from_rotation_arc(normal.normalize(), anchor_normal)
        } else {
            glam::Quat::IDENTITY
        };
        Some(Self {
            surface,
            center,
            anchor,
            turn,
            reach,
            radius,
            anchor_triangle: surface.bake.triangle(near),
            cells: std::sync::OnceLock::new(),
        })
    }

    /// The cells, made on first use.
    fn cells(&self) -> &Cells {
        self.cells.get_or_init(|| {
            Cells::new(
                self.surface,
                self.anchor,
                self.radius + 2.0 * self.reach,
                self.reach,
            )
        })
    }
}

impl Cells {
    /// The surface texels within `within` of `anchor`, in cubes of two texels (larger where
    /// the box would hold too many).
    fn new(surface: &Surface, anchor: Vec3, within: f32, reach: f32) -> Self {
        let upt = surface.units_per_texel.max(f32::MIN_POSITIVE);
        let mut found: Vec<(u32, Vec3)> = Vec::new();
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        surface.visit_near(anchor, within, |i, p| {
            found.push((i as u32, p));
            min = min.min(p);
            max = max.max(p);
        });
        if found.is_empty() {
            (min, max) = (anchor, anchor);
        }
        let mut cell = 2.0 * upt;
        let (low, dims, cells) = loop {
            let low = Self::cell_of(min, cell);
            let high = Self::cell_of(max, cell);
            let dims: [i32; 3] = std::array::from_fn(|a| high[a] - low[a] + 1);
            let cells = dims.iter().map(|&d| d as usize).product::<usize>();
            if cells <= MAX_CELLS {
                break (low, dims, cells);
            }
            cell *= 2.0;
        };
        let mut grid = Self {
            cell,
            reach: reach.max(cell),
            low,
            dims,
            starts: vec![0; cells + 1],
            points: vec![Vec3::ZERO; found.len()],
            texels: vec![0; found.len()],
        };
        // A counting sort by cell.
        let index: Vec<usize> = found
            .iter()
            .map(|&(_, p)| grid.index(Self::cell_of(p, cell)).unwrap_or(0))
            .collect();
        for &c in &index {
            grid.starts[c + 1] += 1;
        }
        for c in 0..cells {
            grid.starts[c + 1] += grid.starts[c];
        }
        let mut next = grid.starts.clone();
        for (&(i, p), &c) in found.iter().zip(&index) {
            let at = next[c] as usize;
            next[c] += 1;
            grid.points[at] = p;
            grid.texels[at] = i;
        }
        grid
    }

    /// The index of cell `c` in the box, if it is inside it.
    fn index(&self, c: [i32; 3]) -> Option<usize> {
        let l: [i32; 3] = std::array::from_fn(|a| c[a] - self.low[a]);
        (0..3)
            .all(|a| (0..self.dims[a]).contains(&l[a]))
            .then(|| ((l[2] * self.dims[1] + l[1]) * self.dims[0] + l[0]) as usize)
    }

    fn cell_of(p: Vec3, cell: f32) -> [i32; 3] {
        (p / cell).floor().as_ivec3().to_array()
    }

    /// The baked texel nearest `q`, if one lies within the reach.
    fn nearest(&self, q: Vec3) -> Option<usize> {
        let c = Self::cell_of(q, self.cell);
        let shells = (self.reach / self.cell).ceil() as i32 + 1;
        // At most (2 shells + 1)^3 cells a query: the reach bounds the work.
        if (0..3)
            .any(|a| c[a] < self.low[a] - shells || c[a] >= self.low[a] + self.dims[a] + shells)
        {
            return None;
        }
        let mut best: Option<(f32, usize)> = None;
        for k in 0..=shells {
            // A texel in shell k lies at least (k - 1) cells away: once the best is nearer,
            // no later shell holds a nearer one.
            if let Some((d2, _)) = best
                && ((k - 1) as f32 * self.cell).powi(2) > d2
            {
                break;
            }
            for dz in -k..=k {
                for dy in -k..=k {
                    for dx in -k..=k {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != k {
                            continue;
                        }
                        let Some(cell) = self.index([c[0] + dx, c[1] + dy, c[2] + dz]) else {
                            continue;
                        };
                        let run = self.starts[cell] as usize..self.starts[cell + 1] as usize;
                        for (&p, &i) in self.points[run.clone()].iter().zip(&self.texels[run]) {
                            let d2 = p.distance_squared(q);
                            if best.is_none_or(|(b, _)| d2 < b) {
                                best = Some((d2, i as usize));
                            }
                        }
                    }
                }
            }
        }
        best.filter(|&(d2, _)| d2 <= self.reach * self.reach)
            .map(|(_, i)| i)
    }
}

impl SourceGrid<'_> {
    /// Where on the map (texel units) the source of texel `t` (its index in the map) lies;
    /// none for a texel off the mesh or a source off the surface. `hint`: the triangle the
    /// source of the texel before lay on (none at a row's start), updated.
    fn source_of(&self, t: usize, hint: &mut Option<u32>) -> Option<Vec2> {
        let bake = &self.surface.bake;
        bake.triangle(t)?;
        self.source_texel(bake.position(t), hint)
    }

    /// Where on the map (texel units) the source of a texel whose point is `p` lies.
    fn source_texel(&self, p: Vec3, hint: &mut Option<u32>) -> Option<Vec2> {
        let q = self.anchor + self.turn * (p - self.center);
        let bake = &self.surface.bake;
        // The triangle before, where `q` projects inside it and near enough that no other
        // sheet of the surface can be nearer: the texels of a row are a texel apart, so this
        // is most of them. Else the nearest baked texel names the triangle.
        let near = self.surface.units_per_texel.powi(2);
        let on_hint = self.walk(q, hint.or(self.anchor_triangle), near);
        let (t, w) = if let Some(found) = on_hint {
            found
        } else {
            let i = self.cells().nearest(q)?;
            let t = bake.triangle(i)?;
            (t, closest_on_triangle(q, bake.corners(t)))
        };
        *hint = Some(t);
        let uvs = self.surface.mesh.uvs.as_ref()?;
        let [a, b, c] = self.surface.mesh.triangles[t as usize].map(|v| uvs[v as usize]);
        let uv = a * w.x + b * w.y + c * w.z;
        Some(Vec2::new(
            uv.x * bake.width as f32,
            (1.0 - uv.y) * bake.height as f32,
        ))
    }
}

impl SourceGrid<'_> {
    /// The triangle `q` projects inside, within `sqrt(near2)` of its plane, found by walking
    /// from `start` across the edge `q` lies beyond, eight triangles at most.
    fn walk(&self, q: Vec3, start: Option<u32>, near2: f32) -> Option<(u32, Vec3)> {
        let bake = &self.surface.bake;
        let mut t = start?;
        for _ in 0..8 {
            match locate(q, bake.corners(t), near2) {
                Locate::Inside(w) => return Some((t, w)),
                Locate::Beyond(k) => {
                    t = *self.surface.neighbours().get(t as usize)?.get(k)?;
                    if t == u32::MAX {
                        return None;
                    }
                }
                Locate::Away => return None,
            }
        }
        None
    }
}

/// Where a point lies for a triangle.
enum Locate {
    /// Its projection falls inside, these barycentric weights, and it is near the plane.
    Inside(Vec3),
    /// Its projection falls beyond the edge opposite this corner.
    Beyond(usize),
    /// The triangle has no area, or the point is off its plane.
    Away,
}

/// Where `p` lies for triangle `[a, b, c]`: inside it (its projection inside, `p` within
/// `sqrt(near2)` of its plane), or beyond the edge opposite the corner of the most negative
/// weight.
#[inline]
fn locate(p: Vec3, [a, b, c]: [Vec3; 3], near2: f32) -> Locate {
    let (e0, e1, d) = (b - a, c - a, p - a);
    let n = e0.cross(e1);
    let n2 = n.length_squared();
    if n2 <= f32::MIN_POSITIVE {
        return Locate::Away;
    }
    // Barycentrics of the projection, by the areas of the sub-triangles.
    let v = d.cross(e1).dot(n) / n2;
    let w = e0.cross(d).dot(n) / n2;
    let weights = [1.0 - v - w, v, w];
    if weights.iter().all(|&x| x >= 0.0) {
        let height = d.dot(n);
        return if height * height <= near2 * n2 {
            Locate::Inside(Vec3::from_array(weights))
        } else {
            Locate::Away
        };
    }
    let k = (0..3)
        .min_by(|&i, &j| weights[i].total_cmp(&weights[j]))
        .unwrap_or(0);
    Locate::Beyond(k)
}

/// A clone dab on the mesh raising the stroke's coverage by `raise`: each texel it rose at
/// takes its source's value (see the module's notes); a texel whose source lies off the
/// surface is not written. Returns, per tile of `ids`, the texels written.
pub(super) fn surface_clone_dab(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    target: &LayerEdit,
    coverage: &mut Coverage,
    (maps, ids): (&MaterialMaps, &[usize]),
    (source, grid): (&CloneSource, &SourceGrid<'_>),
    raise: &impl edit::Raise,
) -> Vec<TileSpans> {
    let covers = coverage.tiles_mut(maps.tile_count(), ids);
    let mask = match pre {
        PrePlanes::Mask(m) => Some(m),
        PrePlanes::Paint(_) => None,
    };
    let blend = crate::paint::n_blend_table();
    let w = maps.width() as usize;
    let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rose = raise.raise(id, cover);
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        // The triangle the texel before's source lay on, kept from row to row.
        let mut hint = None;
        for (y, x0, x1) in rose.rows() {
            let row = (rect.y0 as usize + y) * w + rect.x0 as usize;
            for x in x0..x1 {
                let k = y * TILE_SIZE + x;
                match grid.source_of(row + x, &mut hint) {
                    Some(at) => targets.set(k, bilinear(&source.tiles, mask, maps, at, blend)),
                    // Its source lies off the surface as this dab lays it: not written (a later
                    // dab of the stroke may reach it from elsewhere).
                    None => cover[k] = 0.0,
                }
            }
            written.include_run(y * TILE_SIZE + x0, y * TILE_SIZE + x1);
        }
        written
    };
    edit::edit_varying((planes, pre), target, ids, covers, &prepare)
}

/// A smudge dab on the mesh through `fp` at `strength`: each texel moves towards the
/// composite (or the mask) as it is now at its point moved by the grid's offset (back along
/// the step). Returns, per tile of `ids`, the texels written.
pub(super) fn surface_smudge_dab(
    planes: Planes<'_>,
    target: &LayerEdit,
    (maps, ids): (&MaterialMaps, &[usize]),
    (fp, strength): (&impl Footprint, f32),
    grid: &SourceGrid<'_>,
) -> Vec<TileSpans> {
    match planes {
        // The source is the composite: the layer's own tiles are read in place.
        Planes::Paint(tiles) => {
            let prepare = surface_smudge_tile((maps, None), (fp, strength), grid);
            edit::edit_each_in_place(tiles, target, ids, &prepare)
        }
        Planes::Mask(tiles) => mask_now(tiles, |planes, now| {
            let prepare = surface_smudge_tile((maps, Some(now)), (fp, strength), grid);
            edit::edit_each(planes, target, ids, &prepare)
        }),
    }
}

/// [`surface_smudge_dab`]'s tile for [`edit::edit_each`], reading the composite (or `mask`).
fn surface_smudge_tile<'a>(
    (maps, mask): (&'a MaterialMaps, Option<&'a [SharedMaskTile]>),
    (fp, strength): (&'a impl Footprint, f32),
    grid: &'a SourceGrid<'_>,
) -> impl Fn(usize, &mut [f32], &mut TileTargets) -> TileSpans + Sync + 'a {
    let blend = crate::paint::n_blend_table();
    let w = maps.width() as usize;
    let tiles = maps.tiles();
    move |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        let mut hint = None;
        fp.visit_runs(id, rect, |start, dab| {
            for (k, &wgt) in dab.iter().enumerate() {
                let i = start + k;
                let a = (wgt * strength).min(1.0);
                let t = (rect.y0 as usize + i / TILE_SIZE) * w + rect.x0 as usize + i % TILE_SIZE;
                if let Some(at) = (a > 0.0).then(|| grid.source_of(t, &mut hint)).flatten() {
                    cover[i] = a;
                    targets.set(i, bilinear(tiles, mask, maps, at, blend));
                    written.include(i);
                }
            }
        });
        written
    }
}

/// The point of the surface nearest `q`, and its normal, on the triangle of the baked texel
/// `near` (the texel nearest `q`).
fn surface_point(surface: &Surface, q: Vec3, near: usize) -> (Vec3, Vec3) {
    let bake = &surface.bake;
    let Some(t) = bake.triangle(near) else {
        return (bake.position(near), bake.normal(near));
    };
    let corners = bake.corners(t);
    let w = closest_on_triangle(q, corners);
    let [a, b, c] = bake.corner_normals(t);
    let normal = (a * w.x + b * w.y + c * w.z).normalize_or_zero();
    (
        corners[0] * w.x + corners[1] * w.y + corners[2] * w.z,
        normal,
    )
}

/// The barycentric weights of the point of triangle `[a, b, c]` nearest `p`.
fn closest_on_triangle(p: Vec3, [a, b, c]: [Vec3; 3]) -> Vec3 {
    let (e0, e1, d) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (d.dot(e0), d.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    if denom.abs() > f32::MIN_POSITIVE {
        let v = (d11 * d20 - d01 * d21) / denom;
        let w = (d00 * d21 - d01 * d20) / denom;
        if v >= 0.0 && w >= 0.0 && v + w <= 1.0 {
            return Vec3::new(1.0 - v - w, v, w);
        }
    }
    // Outside (or degenerate): the nearest point of the three edges.
    let edge = |p0: Vec3, p1: Vec3| {
        let e = p1 - p0;
        let len2 = e.length_squared();
        let t = if len2 > 0.0 {
            ((p - p0).dot(e) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t, (p0 + e * t).distance_squared(p))
    };
    let (tab, dab) = edge(a, b);
    let (tbc, dbc) = edge(b, c);
    let (tca, dca) = edge(c, a);
    if dab <= dbc && dab <= dca {
        Vec3::new(1.0 - tab, tab, 0.0)
    } else if dbc <= dca {
        Vec3::new(0.0, 1.0 - tbc, tbc)
    } else {
        Vec3::new(tca, 0.0, 1.0 - tca)
    }
}

/// The composite (or the mask's gray) at texel-unit point `at`, bilinear between texel
/// centres and clamped to the map.
pub(super) fn bilinear(
    tiles: &[Arc<Tile>],
    mask: Option<&[crate::layers::SharedMaskTile]>,
    maps: &MaterialMaps,
    at: Vec2,
    blend: &[f32],
) -> [f32; 7] {
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    let p = at - 0.5;
    let (x0, y0) = (p.x.floor(), p.y.floor());
    let (fx, fy) = (p.x - x0, p.y - y0);
    let mut out = [0.0_f32; 7];
    for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
        for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
            let weight = wx * wy;
            if weight <= 0.0 {
                continue;
            }
            let x = (x0 as i64 + dx).clamp(0, w - 1) as u32;
            let y = (y0 as i64 + dy).clamp(0, h - 1) as u32;
            let v = value_at(tiles, mask, maps, (x, y), blend);
            for (o, v) in out.iter_mut().zip(v) {
                *o += v * weight;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_point_of_a_triangle_is_inside_or_on_its_edges() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let w = closest_on_triangle(Vec3::new(0.25, 0.25, 3.0), t);
        assert!((w - Vec3::new(0.5, 0.25, 0.25)).length() < 1e-6, "{w}");
        let w = closest_on_triangle(Vec3::new(2.0, -1.0, 0.0), t);
        assert!((w - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6, "{w}");
        let w = closest_on_triangle(Vec3::new(0.5, -1.0, 0.0), t);
        assert!((w - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6, "{w}");
    }
}
