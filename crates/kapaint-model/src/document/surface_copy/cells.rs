//! The surface texels near a dab's source in a grid of cubes, for nearest-texel queries.

use glam::Vec3;

use crate::surface::Surface;

/// Most cells a grid keeps (4 bytes each): a larger box takes larger cells.
const MAX_CELLS: usize = 1 << 22;

/// The surface texels near a dab's source, sorted into cubes.
pub(super) struct Cells {
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

impl Cells {
    /// The surface texels within `within` of `anchor`, in cubes of two texels (larger where
    /// the box would hold too many).
    pub(super) fn new(surface: &Surface, anchor: Vec3, within: f32, reach: f32) -> Self {
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
    pub(super) fn nearest(&self, q: Vec3) -> Option<usize> {
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
