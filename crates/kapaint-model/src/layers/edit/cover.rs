//! Brush and eraser dabs on a paint layer or mask: the stroke's coverage raised, then the
//! texels it rose at written, a row at a time (the loops run through
//! [`vectorized`](kapaint_base::simd::vectorized)).
#![expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]

use rayon::prelude::*;

use super::{LayerEdit, Planes, Pre, PrePlanes, Slot, slots};
use crate::layers::{LayerStroke, LayerValue, PaintTile};
use crate::paint::n_bits_from_blend_in;
use crate::texel::{decode_unorm, encode_unorm};
use crate::tile::{Plane, TILE_SIZE, TileSpans};

/// Writes dabs into tiles `ids` (sorted, unique) in parallel, each with the stroke's coverage
/// so far (`covers`, one value a texel of the tile): [`Raise::raise`] raises a tile's
/// coverage and returns the texels where it rose, and each of those becomes its
/// pre-operation value at that coverage, a row at a time. Returns, per tile, those texels.
pub fn edit_cover(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    edit: &LayerEdit,
    ids: &[usize],
    covers: Vec<&mut [f32]>,
    raise: &impl Raise,
) -> Vec<TileSpans> {
    slots(planes, pre, ids)
        .into_par_iter()
        .zip(covers)
        .zip(ids)
        .map(|((slot, cover), &id)| {
            kapaint_base::simd::vectorized(CoverTile {
                slot,
                edit,
                id,
                cover,
                raise,
            })
        })
        .collect()
}

/// What a dab does to the stroke's coverage, for [`edit_cover`].
pub trait Raise: Sync {
    /// Raises the coverage `cover` of tile `id`; returns the texels where it rose. Mark it
    /// `#[inline(always)]`: it runs inside [`vectorized`](kapaint_base::simd::vectorized).
    fn raise(&self, id: usize, cover: &mut [f32]) -> TileSpans;
}

/// One tile of [`edit_cover`]: its coverage raised, then the texels it rose at written.
struct CoverTile<'a, 'b, R> {
    slot: Slot<'a>,
    edit: &'b LayerEdit,
    id: usize,
    cover: &'b mut [f32],
    raise: &'b R,
}

impl<R: Raise> kapaint_base::simd::Kernel for CoverTile<'_, '_, R> {
    type Output = TileSpans;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> TileSpans {
        let Self {
            mut slot,
            edit,
            id,
            cover,
            raise,
        } = self;
        let spans = raise.raise(id, cover);
        if !spans.is_empty() {
            slot.write_cover(edit, &spans, cover, None);
            slot.compact();
        }
        spans
    }
}

/// The coverage of a transparent texel after a brush at `cover`, at texels `spans` of a
/// channel's coverage plane (the value is the target's: see [`Slot::write_cover`]).
#[inline(always)]
pub(super) fn cover_alpha(alpha: &mut Plane<u16>, spans: &TileSpans, cover: &[f32]) {
    let mut row = [0_u16; TILE_SIZE];
    for (y, x0, x1) in spans.rows() {
        let (start, end) = (y * TILE_SIZE + x0, y * TILE_SIZE + x1);
        let cov = &cover[start..end];
        for (p, &a) in row.iter_mut().zip(cov) {
            *p = encode_unorm(a.min(1.0));
        }
        write_row(alpha, start, &row[..end - start], cov, all_reached(cov));
    }
}

/// Channel `ch` of a paint tile's texels `spans` after a brush of `target` (its components)
/// whose mode gives `value` ([`LayerStroke::value`]) at coverage `cover`, from the
/// pre-operation texels (a tile before, none: transparent, or the tile's own), a row at a
/// time: the coverage and the pre-stroke value's weight once per texel, then each component
/// in a plain loop over the row ([`LayerStroke::apply`], term for term).
#[inline(always)]
pub(super) fn cover_channel(
    (tile, pre, ch, target, spans, cover): (
        &mut PaintTile,
        Pre<&PaintTile>,
        usize,
        Targets<'_>,
        &TileSpans,
        &[f32],
    ),
    value: impl Fn((f32, f32), f32, f32) -> f32,
) {
    let table = crate::paint::n_blend_table();
    let n_bits = crate::paint::n_bits_table();
    let mut pre_alpha = [0.0_f32; TILE_SIZE];
    // Per component: the pre-operation values of a run, and the uniform targets of any.
    let mut pre_value = [[0.0_f32; TILE_SIZE]; 3];
    let mut uniform = [[0.0_f32; TILE_SIZE]; 3];
    let components = match &target {
        Targets::Uniform(u) => {
            for (t, &u) in uniform.iter_mut().zip(u.iter()) {
                t.fill(u);
            }
            u.len()
        }
        Targets::Varying(_, range) => range.len(),
    };
    let (mut a, mut w) = ([0.0_f32; TILE_SIZE], [0.0_f32; TILE_SIZE]);
    let mut alpha = [0_u16; TILE_SIZE];
    let mut out = [[0_u16; TILE_SIZE]; 3];
    for (y, x0, x1) in spans.rows() {
        let (start, width) = (y * TILE_SIZE + x0, x1 - x0);
        let cov = &cover[start..start + width];
        // Every buffer at the run's width, so that the loops below run without bounds checks.
        let (a, w, alpha, pre_alpha) = (
            &mut a[..width],
            &mut w[..width],
            &mut alpha[..width],
            &mut pre_alpha[..width],
        );
        // The run's texels before the operation (in place: read before the run is written).
        let pre = match pre {
            Pre::Before(p) => p,
            Pre::InPlace => Some(&*tile),
        };
        if let Some(p) = pre {
            p.alpha[ch].decode_into(start, pre_alpha, decode_unorm);
        }
        for j in 0..width {
            let aj = cov[j].clamp(0.0, 1.0);
            let (coverage, weight) = LayerStroke::cover(pre_alpha[j], aj);
            (a[j], w[j], alpha[j]) = (aj, weight, encode_unorm(coverage.min(1.0)));
        }
        // Every component's targets of the run (the varying ones where they lie), then its
        // pre-operation values (interleaved in the tile: taken apart in one pass).
        let t: [&[f32]; 3] = std::array::from_fn(|c| match &target {
            Targets::Uniform(_) => &uniform[c][..width],
            Targets::Varying(v, range) if c < range.len() => {
                &v.plane(range.start + c)[start..start + width]
            }
            Targets::Varying(..) => &[],
        });
        if let Some(p) = pre {
            match ch {
                0 | 1 => {
                    let plane = if ch == 0 { &p.value.kd } else { &p.value.ks };
                    plane.decode_rgb_into(start, pre_value.each_mut().map(|v| &mut v[..width]));
                }
                _ => p
                    .value
                    .n
                    .decode_into(start, &mut pre_value[0][..width], |bits| {
                        table[bits as usize]
                    }),
            }
        }
        for c in 0..components {
            let (t, pre_value) = (&t[c][..width], &pre_value[c][..width]);
            let encoded = &mut out[c][..width];
            if ch == 2 {
                for j in 0..width {
                    let v = value((w[j], a[j]), pre_value[j], t[j]);
                    encoded[j] = n_bits_from_blend_in(n_bits, v);
                }
            } else {
                for j in 0..width {
                    encoded[j] = encode_unorm(value((w[j], a[j]), pre_value[j], t[j]));
                }
            }
        }
        // Only texels the stroke reached change.
        let all = all_reached(cov);
        write_row(&mut tile.alpha[ch], start, alpha, cov, all);
        match ch {
            0 | 1 => {
                let [r, g, b] = &out;
                let mut rgb = [[0_u16; 3]; TILE_SIZE];
                for (j, p) in rgb[..width].iter_mut().enumerate() {
                    *p = [r[j], g[j], b[j]];
                }
                let plane = if ch == 0 {
                    &mut tile.value.kd
                } else {
                    &mut tile.value.ks
                };
                write_row(plane, start, &rgb[..width], cov, all);
            }
            _ => write_row(&mut tile.value.n, start, &out[0][..width], cov, all),
        }
    }
}

/// A channel's targets: one value a component, or one a texel (seven components, of which
/// `range` are the channel's).
#[derive(Clone)]
pub(super) enum Targets<'a> {
    /// The same components everywhere.
    Uniform(&'a [f32]),
    /// Per texel of the tile.
    Varying(&'a super::TileTargets, std::ops::Range<usize>),
}

/// Whether a dab reached every texel of a row's run (as a disc does).
#[inline(always)]
fn all_reached(cov: &[f32]) -> bool {
    cov.iter().all(|&c| c > 0.0)
}

/// Writes `new` into `plane` from texel `start` where `cov` reached (`all`: everywhere, a
/// plain copy; else chosen texel by texel, without a branch). A uniform plane those values
/// leave as it is stays uniform: where a stroke has saturated, its dabs do not expand a tile
/// only for it to be compacted again.
#[inline(always)]
fn write_row<T: Copy + PartialEq>(
    plane: &mut Plane<T>,
    start: usize,
    new: &[T],
    cov: &[f32],
    all: bool,
) {
    if let Plane::Uniform(u) = plane
        && new.iter().zip(cov).all(|(v, &c)| v == u || c <= 0.0)
    {
        return;
    }
    let plane = &mut plane.data_mut()[start..start + new.len()];
    if all {
        plane.copy_from_slice(new);
    } else {
        for ((p, &new), &c) in plane.iter_mut().zip(new).zip(cov) {
            *p = if c > 0.0 { new } else { *p };
        }
    }
}

/// The eraser on channel `ch` of a paint tile's texels `spans` at coverage `cover`, from the
/// pre-operation texels: the coverage falls ([`LayerStroke::apply`]); values stay.
#[inline(always)]
pub(super) fn erase_channel(
    (tile, pre, ch, spans, cover): (&mut PaintTile, Pre<&PaintTile>, usize, &TileSpans, &[f32]),
) {
    let erased = |pre_alpha: u16, a: f32| {
        let before = LayerValue {
            value: 0.0,
            alpha: decode_unorm(pre_alpha),
        };
        encode_unorm(LayerStroke::Erase.apply(before, 0.0, a).alpha)
    };
    let pre = match pre {
        Pre::Before(Some(p)) => p,
        // Nothing to erase: the tile is as transparent as before the stroke.
        Pre::Before(None) => return,
        Pre::InPlace => {
            let plane = tile.alpha[ch].data_mut();
            for i in spans.indices() {
                let a = cover[i];
                plane[i] = if a > 0.0 {
                    erased(plane[i], a)
                } else {
                    plane[i]
                };
            }
            return;
        }
    };
    let plane = tile.alpha[ch].data_mut();
    for i in spans.indices() {
        let a = cover[i];
        plane[i] = if a > 0.0 {
            erased(pre.alpha[ch].get(i), a)
        } else {
            plane[i]
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_that_leaves_a_uniform_plane_as_it_is_does_not_expand_it() {
        let cov = [1.0, 0.0, 0.5];
        let mut plane = Plane::Uniform(7_u16);
        // Where the dab reached, the values are the plane's; where it did not, they are not read.
        write_row(&mut plane, 10, &[7, 9, 7], &cov, false);
        assert_eq!(plane, Plane::Uniform(7));
        write_row(&mut plane, 10, &[7, 9, 8], &cov, false);
        let Plane::Data(d) = &plane else {
            panic!("a new value expands the plane");
        };
        assert_eq!((d[9], d[10], d[11], d[12], d[13]), (7, 7, 7, 8, 7));
    }
}
