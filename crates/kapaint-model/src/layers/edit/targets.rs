//! Per-texel targets laid out a component at a time: seven planes (`k_d` RGB, `k_s` RGB,
//! `n` in blend space; a mask's gray in the first), so that the kernels that fill and read
//! them run over plain slices of one component.

use crate::tile::TILE_TEXELS;

/// Seven planes of `N` components each (see the module's notes).
pub struct Components<const N: usize>(Box<[[f32; N]; 7]>);

/// Per-texel targets of a tile, for [`edit_varying`](super::edit_varying).
pub type TileTargets = Components<TILE_TEXELS>;

impl<const N: usize> Default for Components<N> {
    fn default() -> Self {
        Self(Box::new([[0.0; N]; 7]))
    }
}

impl<const N: usize> Components<N> {
    /// Texel `i`'s seven components.
    #[inline]
    pub fn get(&self, i: usize) -> [f32; 7] {
        self.0.each_ref().map(|p| p[i])
    }

    /// Sets texel `i`'s seven components.
    #[inline]
    pub fn set(&mut self, i: usize, v: [f32; 7]) {
        for (p, v) in self.0.iter_mut().zip(v) {
            p[i] = v;
        }
    }

    /// Component `c` of every texel.
    #[inline]
    pub fn plane(&self, c: usize) -> &[f32; N] {
        &self.0[c]
    }

    /// Component `c` of every texel, to write.
    #[inline]
    pub fn plane_mut(&mut self, c: usize) -> &mut [f32; N] {
        &mut self.0[c]
    }

    /// Texels `start..end` of every component.
    #[inline]
    pub fn run_mut(&mut self, start: usize, end: usize) -> [&mut [f32]; 7] {
        self.0.each_mut().map(|p| &mut p[start..end])
    }
}

/// Writes `v` at index `k` of each of a run's component slices.
#[inline]
pub fn set_run(run: &mut [&mut [f32]; 7], k: usize, v: [f32; 7]) {
    for (p, v) in run.iter_mut().zip(v) {
        p[k] = v;
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::super::{
        EditValue, LayerEdit, LayerStroke, Planes, PrePlanes, edit_each, edit_each_in_place,
    };
    use super::*;
    use crate::brush::BlendMode;
    use crate::layers::{PaintTile, SharedPaintTile, Stamped};
    use crate::texel::{MaterialValue, Texel};
    use crate::tile::{TILE_SIZE, TileSpans};

    /// A paint tile whose every texel and coverage differs.
    fn varied_tile() -> SharedPaintTile {
        let mut t = PaintTile::filled(MaterialValue::default(), [true; 3]);
        for i in 0..TILE_TEXELS {
            let f = |k: usize| ((i * 7919 + k * 104_729) % 997) as f32 / 997.0;
            let v = MaterialValue::new(
                glam::Vec3::new(f(1), f(2), f(3)),
                glam::Vec3::splat(f(4) * 0.5),
                f(5) * 1000.0,
            );
            t.value.set_texel(i, Texel::encode(v));
            for (ch, a) in t.alpha.iter_mut().enumerate() {
                a.data_mut()[i] = (f(6 + ch) * 65535.0) as u16;
            }
        }
        Arc::new(Stamped::new(t))
    }

    /// A smudge-like operation: a disc of coverage with a target per texel.
    fn prepare(id: usize, cover: &mut [f32], targets: &mut TileTargets) -> TileSpans {
        let mut spans = TileSpans::EMPTY;
        for (i, c) in cover.iter_mut().enumerate() {
            let (x, y) = ((i % TILE_SIZE) as f32 - 30.0, (i / TILE_SIZE) as f32 - 34.0);
            let a = (1.0 - (x * x + y * y) / 900.0).max(0.0);
            if a > 0.0 {
                *c = a;
                let t = (i + id) as f32 / TILE_TEXELS as f32;
                targets.set(i, [t, 1.0 - t, 0.5 * t, 0.2, t * t, 0.1, t]);
                spans.include(i);
            }
        }
        spans
    }

    /// Reading a tile's pre-operation texels in place writes what reading them from a copy
    /// made before the operation writes, for the brush's modes and the eraser, the energy
    /// guard included.
    #[test]
    fn a_write_in_place_equals_a_write_from_a_copy() {
        let strokes = [
            LayerStroke::Brush(BlendMode::Normal),
            LayerStroke::Brush(BlendMode::Multiply),
            LayerStroke::Erase,
        ];
        for stroke in strokes {
            for energy_guard in [false, true] {
                let value = EditValue::of(MaterialValue::default());
                let edit = LayerEdit {
                    from: value,
                    to: value,
                    channels: [true, true, true],
                    stroke,
                    gray: [1.0, 1.0],
                    energy_guard,
                };
                let before = vec![Some(varied_tile())];
                let mut copied = before.clone();
                let _ = edit_each(
                    (Planes::Paint(&mut copied), PrePlanes::Paint(&before)),
                    &edit,
                    &[0],
                    &prepare,
                );
                let mut in_place = before.clone();
                let _ = edit_each_in_place(&mut in_place, &edit, &[0], &prepare);
                let (a, b) = (copied[0].as_ref(), in_place[0].as_ref());
                let (a, b) = (a.map(|t| t.get()), b.map(|t| t.get()));
                assert!(a == b, "{stroke:?}, guard {energy_guard}");
                assert!(a != before[0].as_ref().map(|t| t.get()), "{stroke:?} wrote");
            }
        }
    }
}
