//! What the layer engine's tools share: where a dab lands ([`Footprint`]), a stroke's
//! per-texel [`Coverage`], the flood fill's region, the gradient shapes, the energy guard, and
//! the tables between stored `n` bits and the perceptual blend space.
//!
//! A stroke keeps a coverage value per texel, the alpha it has reached so far. Each dab raises
//! coverage towards the brush opacity by its flow; the layer's texel is then the blend of its
//! value before the stroke with the target at that coverage. Overlapping dabs (or mirrored
//! copies of one) therefore never exceed the opacity, and a stroke's result does not depend
//! on dab order.

mod fill;
mod footprint;
mod gradient;
pub mod mapper;
pub mod projection;
mod stencil;
#[cfg(test)]
mod tests;

pub use fill::flood_region;
pub use footprint::{DiscFootprint, Footprint};
pub use gradient::GradientShape;
pub use stencil::{ScreenView, Stencil};

use std::sync::OnceLock;

use super::maps::TileId;
use super::texel::{decode_n, n_from_blend, n_to_blend};
use super::tile::TILE_TEXELS;

/// Lookup tables between stored `n` bits and the perceptual blend space.
struct NTables {
    to_blend: Vec<f32>,
    from_blend: Box<NBitsTable>,
}

/// Resolution of the blend-space to bits table: finer than a half float's step everywhere.
const FROM_BLEND_STEPS: usize = 1 << 18;

fn n_tables() -> &'static NTables {
    static TABLES: OnceLock<NTables> = OnceLock::new();
    TABLES.get_or_init(|| NTables {
        to_blend: (0..=u16::MAX).map(|b| n_to_blend(decode_n(b))).collect(),
        from_blend: (0..=FROM_BLEND_STEPS)
            .map(|i| super::texel::encode_n(n_from_blend(i as f32 / FROM_BLEND_STEPS as f32)))
            .collect::<Box<[u16]>>()
            .try_into()
            .unwrap_or_else(|_| unreachable!("FROM_BLEND_STEPS + 1 entries")),
    })
}

#[inline]
pub(crate) fn n_bits_to_blend(bits: u16) -> f32 {
    n_tables().to_blend[bits as usize]
}

/// The table [`n_bits_to_blend`] reads: every half-float bit pattern's blend-space value, for
/// loops that look up many.
pub(crate) fn n_blend_table() -> &'static [f32] {
    &n_tables().to_blend
}

#[inline]
pub(crate) fn n_bits_from_blend(u: f32) -> u16 {
    n_bits_from_blend_in(n_bits_table(), u)
}

/// The blend-space to half-float bits table: [`FROM_BLEND_STEPS`] steps over `[0, 1]`.
pub(crate) type NBitsTable = [u16; FROM_BLEND_STEPS + 1];

/// The table [`n_bits_from_blend`] reads, for loops that encode many
/// ([`n_bits_from_blend_in`]).
pub(crate) fn n_bits_table() -> &'static NBitsTable {
    &n_tables().from_blend
}

/// [`n_bits_from_blend`] through `table` ([`n_bits_table`]): no bounds check.
#[inline]
pub(crate) fn n_bits_from_blend_in(table: &NBitsTable, u: f32) -> u16 {
    let i = super::texel::trunc_small(super::texel::unit(u) * FROM_BLEND_STEPS as f32 + 0.5);
    table[(i as usize).min(FROM_BLEND_STEPS)]
}

/// Keeps `k_d + k_s <= 1` per colour channel: the channel being painted gives way to the
/// other; when both are painted, both scale down together.
pub(crate) fn guard_energy(
    kd: &mut [f32; 3],
    ks: &mut [f32; 3],
    painting_kd: bool,
    painting_ks: bool,
) {
    for c in 0..3 {
        let sum = kd[c] + ks[c];
        if sum <= 1.0 {
            continue;
        }
        match (painting_kd, painting_ks) {
            (true, false) => kd[c] = 1.0 - ks[c],
            (false, true) => ks[c] = 1.0 - kd[c],
            _ => {
                kd[c] /= sum;
                ks[c] /= sum;
            }
        }
    }
}

/// Per-texel stroke coverage for the tiles a stroke touched, indexed by tile.
#[derive(Default, Debug)]
pub struct Coverage {
    tiles: Vec<Option<Box<[f32]>>>,
}

impl Coverage {
    /// Resets every texel to zero, keeping the allocations (a new stroke on the same tiles).
    pub fn clear(&mut self) {
        for tile in self.tiles.iter_mut().flatten() {
            tile.fill(0.0);
        }
    }

    /// Coverage slices for several tiles (sorted, unique ids), created at zero on first use.
    pub(crate) fn tiles_mut(&mut self, tile_count: usize, ids: &[TileId]) -> Vec<&mut [f32]> {
        if self.tiles.len() < tile_count {
            self.tiles.resize_with(tile_count, || None);
        }
        for &id in ids {
            self.tiles[id].get_or_insert_with(|| vec![0.0; TILE_TEXELS].into_boxed_slice());
        }
        super::tile::select_mut(&mut self.tiles, ids)
            .into_iter()
            .filter_map(|slot| slot.as_deref_mut())
            .collect()
    }
}
