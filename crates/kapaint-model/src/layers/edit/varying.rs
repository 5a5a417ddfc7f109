//! Writes whose every texel has its own target and coverage (clone, smudge, projections):
//! a tile's preparation sets them, then the texels it returns are written, both in one
//! vectorised kernel.

use rayon::prelude::*;

use super::{LayerEdit, Planes, Pre, PrePlanes, Slot, TileTargets, slots};
use crate::layers::SharedPaintTile;
use crate::tile::{TILE_SIZE, TileSpans, select_mut};

/// What sets a tile's coverage and targets for [`edit_varying`] and [`edit_each`]
/// (`prepare(id, cover, targets)`, see there); a closure is one.
pub trait Prepare: Sync {
    /// Sets tile `id`'s coverage and targets; returns the texels to write. Mark it
    /// `#[inline(always)]`: it runs inside [`vectorized`](kapaint_base::simd::vectorized) (a
    /// closure's body stays compiled for the baseline).
    fn prepare(&self, id: usize, cover: &mut [f32], targets: &mut TileTargets) -> TileSpans;
}

impl<F: Fn(usize, &mut [f32], &mut TileTargets) -> TileSpans + Sync> Prepare for F {
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn prepare(&self, id: usize, cover: &mut [f32], targets: &mut TileTargets) -> TileSpans {
        self(id, cover, targets)
    }
}

/// Writes tiles `ids` (sorted, unique) in parallel, each texel from its pre-operation value
/// towards its own target at its own coverage, a row at a time as [`edit_cover`](super::edit_cover) does:
/// `prepare(id, cover, targets)` sets a tile's coverage (texels left at zero are not written)
/// and the targets where it is positive, and returns the texels to write. Returns, per tile,
/// those texels.
pub fn edit_varying(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    edit: &LayerEdit,
    ids: &[usize],
    covers: Vec<&mut [f32]>,
    prepare: &impl Prepare,
) -> Vec<TileSpans> {
    slots(planes, pre, ids)
        .into_par_iter()
        .zip(covers)
        .zip(ids)
        .map(|((mut slot, cover), &id)| write_varying(&mut slot, edit, id, cover, prepare))
        .collect()
}

/// [`edit_varying`] for an operation whose coverage is its own (a projection, a smudge dab)
/// over tiles `ids`: each tile's coverage starts at zero in a worker's own buffer. Returns,
/// per tile, the texels written.
pub fn edit_each(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    edit: &LayerEdit,
    ids: &[usize],
    prepare: &impl Prepare,
) -> Vec<TileSpans> {
    write_each(slots(planes, pre, ids), edit, ids, prepare)
}

/// [`edit_each`] on a paint layer's tiles `ids` read in place: a texel's pre-operation value
/// is what it holds until it is written, once, so no copy of a tile is held (a smudge dab,
/// whose source is the composite, not the layer).
pub fn edit_each_in_place(
    tiles: &mut [Option<SharedPaintTile>],
    edit: &LayerEdit,
    ids: &[usize],
    prepare: &impl Prepare,
) -> Vec<TileSpans> {
    let slots = select_mut(tiles, ids)
        .into_iter()
        .map(|t| Slot::Paint(t, Pre::InPlace, false))
        .collect();
    write_each(slots, edit, ids, prepare)
}

/// Writes `slots` (tiles `ids`) through [`write_varying`] with a worker's coverage buffer.
fn write_each(
    slots: Vec<Slot<'_>>,
    edit: &LayerEdit,
    ids: &[usize],
    prepare: &impl Prepare,
) -> Vec<TileSpans> {
    slots
        .into_par_iter()
        .zip(ids)
        .map(|(mut slot, &id)| {
            COVER.with_borrow_mut(|cover| {
                cover.clear();
                cover.resize(TILE_SIZE * TILE_SIZE, 0.0);
                write_varying(&mut slot, edit, id, cover, prepare)
            })
        })
        .collect()
}

/// One tile of [`edit_varying`] and [`edit_each`]: `prepare` fills its coverage and targets
/// (in a worker's own buffer of targets), then the texels it returns are written.
fn write_varying<P: Prepare>(
    slot: &mut Slot<'_>,
    edit: &LayerEdit,
    id: usize,
    cover: &mut [f32],
    prepare: &P,
) -> TileSpans {
    TARGETS.with_borrow_mut(|targets| {
        kapaint_base::simd::vectorized(VaryingWrite {
            slot,
            edit,
            id,
            cover,
            targets,
            prepare,
        })
    })
}

/// [`edit_varying`]'s tile, its preparation and write compiled for the CPU's widest vectors.
struct VaryingWrite<'s, 'a, P> {
    slot: &'s mut Slot<'a>,
    edit: &'s LayerEdit,
    id: usize,
    cover: &'s mut [f32],
    targets: &'s mut TileTargets,
    prepare: &'s P,
}

impl<P: Prepare> kapaint_base::simd::Kernel for VaryingWrite<'_, '_, P> {
    type Output = TileSpans;

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn with_simd<S: pulp::Simd>(self, _: S) -> TileSpans {
        let spans = self.prepare.prepare(self.id, self.cover, self.targets);
        if !spans.is_empty() {
            self.slot
                .write_cover(self.edit, &spans, self.cover, Some(self.targets));
            self.slot.compact();
        }
        spans
    }
}

thread_local! {
    /// A worker's tile of targets for [`edit_varying`], kept from dab to dab (only the
    /// texels `prepare` returns are read, and it sets each of them).
    static TARGETS: std::cell::RefCell<TileTargets> = std::cell::RefCell::new(TileTargets::default());
    /// A worker's tile of coverage for [`edit_each`].
    static COVER: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
}
