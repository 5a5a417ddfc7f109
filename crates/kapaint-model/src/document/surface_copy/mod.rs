//! Clone and smudge on the mesh, in object space: a clone texel takes what the composite
//! held (before the stroke) at the surface point nearest its own baked point moved by the
//! stroke's offset; a smudge texel moves towards what the composite holds now one dab-step
//! (object space) behind it. Each dab's centre, moved so, is put back on the surface first,
//! and its texels read at their displacement from there (see [`SourceGrid`]). The source is
//! found in object space, so both run across UV seams: the triangle under the moved point is
//! followed across the mesh from texel to texel (`walk`; where that finds nothing, the
//! nearest baked texel names it), the point is projected onto that triangle, and its UV is
//! read bilinearly from the composite (`sample`).

mod cells;
mod sample;
mod walk;

use glam::Vec3;

use super::copy_dab::{CloneSource, mask_now};
use crate::layers::SharedMaskTile;
use crate::layers::edit::{self, LayerEdit, Planes, PrePlanes, TileTargets};
use crate::maps::MaterialMaps;
use crate::paint::{Coverage, Footprint};
use crate::surface::Surface;
use crate::tile::{TILE_SIZE, TileSpans};
use cells::Cells;
use sample::Sampler;
use walk::{Walker, closest_on_triangle};

/// Where a dab's texels read on the surface, and the surface texels near there in a grid of
/// cubes, for nearest-texel queries.
///
/// The dab's centre moved by the offset is put back on the surface (its nearest surface
/// point, the anchor): each texel of the dab then reads the surface at its own displacement
/// from the dab's centre, turned as the surface turns from there to the anchor (the shortest
/// turn from the dab's normal to the anchor's), so the patch lies on the surface where the
/// source is, whichever way it faces, and every query starts within a few texels of it. A
/// texel whose source falls on the triangle the texel before it found (projected inside it,
/// within the reach of its plane) takes it from there, the others walk across the mesh's edges
/// from there ([`Walker`]); only where no walk arrives are the cells asked, made on the first
/// such query: the surface texels near the anchor sorted by cube (each cube's run found by
/// its index, no search).
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
    let sampler = Sampler::new(&source.tiles, mask, maps);
    let w = maps.width() as usize;
    let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rose = raise.raise(id, cover);
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        let mut walker = Walker::new(grid);
        for (y, x0, x1) in rose.rows() {
            let row = (rect.y0 as usize + y) * w + rect.x0 as usize;
            walker.start_run();
            for x in x0..x1 {
                let k = y * TILE_SIZE + x;
                match walker.source(row + x) {
                    Some(at) => targets.set(k, sampler.sample(at)),
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
    let sampler = Sampler::new(maps.tiles(), mask, maps);
    let w = maps.width() as usize;
    move |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
        let rect = maps.tile_rect(id);
        let mut written = TileSpans::EMPTY;
        let mut walker = Walker::new(grid);
        fp.visit_runs(id, rect, |start, dab| {
            walker.start_run();
            let row = (rect.y0 as usize + start / TILE_SIZE) * w + rect.x0 as usize;
            let x0 = start % TILE_SIZE;
            for (k, &wgt) in dab.iter().enumerate() {
                let i = start + k;
                let a = (wgt * strength).min(1.0);
                if let Some(at) = (a > 0.0).then(|| walker.source(row + x0 + k)).flatten() {
                    cover[i] = a;
                    targets.set(i, sampler.sample(at));
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
