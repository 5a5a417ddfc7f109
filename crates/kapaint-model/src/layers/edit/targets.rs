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
