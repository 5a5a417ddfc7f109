//! 64 x 64 tiles, each channel plane either uniform (one value, no memory) or full.

use super::texel::Texel;

/// Tile side in texels.
pub const TILE_SIZE: usize = 64;

/// Texels per tile.
pub const TILE_TEXELS: usize = TILE_SIZE * TILE_SIZE;

/// Disjoint mutable references to the elements of `items` at `ids` (sorted ascending, no
/// duplicates), for parallel work on several tiles at once.
pub fn select_mut<'a, T>(items: &'a mut [T], ids: &[usize]) -> Vec<&'a mut T> {
    debug_assert!(
        ids.windows(2).all(|w| w[0] < w[1]),
        "ids must be sorted and unique"
    );
    let mut wanted = ids.iter().peekable();
    items
        .iter_mut()
        .enumerate()
        .filter_map(|(i, item)| {
            if wanted.peek() == Some(&&i) {
                wanted.next();
                Some(item)
            } else {
                None
            }
        })
        .collect()
}

/// Texels inside one tile as a run of columns per row: the part of a tile an edit wrote (a
/// disc's part of a tile is about a fifth smaller than its bounding rectangle).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileSpans {
    /// Per row, the columns `x0..x1` (none where `x0 >= x1`).
    rows: [(u8, u8); TILE_SIZE],
}

impl TileSpans {
    /// No texel.
    pub const EMPTY: Self = Self {
        rows: [(TILE_SIZE as u8, 0); TILE_SIZE],
    };

    /// The whole tile.
    pub const FULL: Self = Self {
        rows: [(0, TILE_SIZE as u8); TILE_SIZE],
    };

    /// Texel `i` (row-major in the tile) alone.
    pub fn texel(i: usize) -> Self {
        let mut spans = Self::EMPTY;
        spans.include(i);
        spans
    }

    /// Grows to hold texel `i` (row-major in the tile).
    #[inline]
    pub fn include(&mut self, i: usize) {
        let (x, row) = ((i % TILE_SIZE) as u8, &mut self.rows[i / TILE_SIZE]);
        *row = (row.0.min(x), row.1.max(x + 1));
    }

    /// Grows to hold texels `start..end` (row-major in the tile) of one row.
    #[inline]
    pub fn include_run(&mut self, start: usize, end: usize) {
        debug_assert!(start < end && (end - 1) / TILE_SIZE == start / TILE_SIZE);
        self.include(start);
        self.include(end - 1);
    }

    /// Whether it holds no texel.
    pub fn is_empty(&self) -> bool {
        self.rows.iter().all(|&(x0, x1)| x0 >= x1)
    }

    /// Its rows that hold texels: `(row, x0, x1)`, top down.
    pub fn rows(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.rows
            .iter()
            .enumerate()
            .filter(|(_, (x0, x1))| x0 < x1)
            .map(|(y, &(x0, x1))| (y, usize::from(x0), usize::from(x1)))
    }

    /// The texel indices (row-major in the tile) inside, row by row.
    pub fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        self.rows()
            .flat_map(|(y, x0, x1)| (x0..x1).map(move |x| y * TILE_SIZE + x))
    }

    /// How many texels it holds.
    pub fn count(&self) -> usize {
        self.rows().map(|(_, x0, x1)| x1 - x0).sum()
    }
}

/// One channel of a tile: a single value for every texel, or one value per texel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Plane<T: Copy> {
    /// Every texel holds this value.
    Uniform(T),
    /// Row-major values, `TILE_TEXELS` of them.
    Data(Box<[T]>),
}

impl<T: Copy + PartialEq> Plane<T> {
    /// The value at texel index `i` (row-major within the tile).
    #[inline]
    pub fn get(&self, i: usize) -> T {
        match self {
            Self::Uniform(v) => *v,
            Self::Data(d) => d[i],
        }
    }

    /// The per-texel values, materialising a uniform plane first.
    pub fn data_mut(&mut self) -> &mut [T] {
        if let Self::Uniform(v) = *self {
            *self = Self::Data(vec![v; TILE_TEXELS].into_boxed_slice());
        }
        match self {
            Self::Data(d) => d,
            Self::Uniform(_) => unreachable!("materialised above"),
        }
    }

    /// The uniform value, if the plane is uniform.
    pub fn uniform(&self) -> Option<T> {
        match self {
            Self::Uniform(v) => Some(*v),
            Self::Data(_) => None,
        }
    }

    /// Turns a full plane whose texels are all equal back into a uniform one.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub fn compact(&mut self) {
        // The last and middle texels first: a tile an edit reached in part usually differs
        // there, and a whole scan that finds a difference late is the costly case.
        if let Self::Data(d) = self
            && let (Some(&first), Some(&last)) = (d.first(), d.last())
            && last == first
            && d[d.len() / 2] == first
            && d.iter().all(|&v| v == first)
        {
            *self = Self::Uniform(first);
        }
    }

    /// Heap bytes held by the plane.
    pub fn heap_bytes(&self) -> usize {
        match self {
            Self::Uniform(_) => 0,
            Self::Data(d) => std::mem::size_of_val(&**d),
        }
    }

    /// Texels `start..start + out.len()` through `f` into `out`, in a plain loop.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub fn decode_into(&self, start: usize, out: &mut [f32], f: impl Fn(T) -> f32) {
        match self {
            Self::Uniform(v) => out.fill(f(*v)),
            Self::Data(d) => {
                let d = &d[start..start + out.len()];
                for (o, &v) in out.iter_mut().zip(d) {
                    *o = f(v);
                }
            }
        }
    }
}

impl Plane<[u16; 3]> {
    /// Texels `start..` of an RGB plane, unorm16 decoded, a component into each of `r`, `g`,
    /// `b` (as many texels as `r` holds): the texels taken apart in one pass.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub fn decode_rgb_into(&self, start: usize, [r, g, b]: [&mut [f32]; 3]) {
        let decode = super::texel::decode_unorm;
        match self {
            Self::Uniform(v) => {
                r.fill(decode(v[0]));
                g.fill(decode(v[1]));
                b.fill(decode(v[2]));
            }
            Self::Data(d) => {
                let d = &d[start..start + r.len()];
                for (((v, r), g), b) in d.iter().zip(r).zip(g).zip(b) {
                    (*r, *g, *b) = (decode(v[0]), decode(v[1]), decode(v[2]));
                }
            }
        }
    }
}

/// One tile of every channel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tile {
    /// `k_d` (unorm16 RGB).
    pub kd: Plane<[u16; 3]>,
    /// `k_s` (unorm16 RGB).
    pub ks: Plane<[u16; 3]>,
    /// `n` (half-float bits).
    pub n: Plane<u16>,
}

impl Tile {
    /// A tile where every texel is `texel`.
    pub fn uniform(texel: Texel) -> Self {
        Self {
            kd: Plane::Uniform(texel.kd),
            ks: Plane::Uniform(texel.ks),
            n: Plane::Uniform(texel.n),
        }
    }

    /// The texel at index `i` (row-major within the tile).
    #[inline]
    pub fn texel(&self, i: usize) -> Texel {
        Texel {
            kd: self.kd.get(i),
            ks: self.ks.get(i),
            n: self.n.get(i),
        }
    }

    /// Writes texel `i`.
    #[inline]
    pub fn set_texel(&mut self, i: usize, t: Texel) {
        self.kd.data_mut()[i] = t.kd;
        self.ks.data_mut()[i] = t.ks;
        self.n.data_mut()[i] = t.n;
    }

    /// Heap bytes held by the tile's planes.
    pub fn heap_bytes(&self) -> usize {
        self.kd.heap_bytes() + self.ks.heap_bytes() + self.n.heap_bytes()
    }

    /// Compacts every plane (see [`Plane::compact`]).
    pub fn compact(&mut self) {
        self.kd.compact();
        self.ks.compact();
        self.n.compact();
    }
}

/// Texel indices inside tile `id` of a `width x height` map, with their map coordinates.
pub fn tile_texels(width: u32, height: u32, id: usize) -> impl Iterator<Item = (usize, u32, u32)> {
    let tiles_x = (width as usize).div_ceil(TILE_SIZE);
    let (x0, y0) = ((id % tiles_x) * TILE_SIZE, (id / tiles_x) * TILE_SIZE);
    let (x1, y1) = (
        (x0 + TILE_SIZE).min(width as usize),
        (y0 + TILE_SIZE).min(height as usize),
    );
    (y0..y1).flat_map(move |y| {
        (x0..x1).map(move |x| ((y - y0) * TILE_SIZE + (x - x0), x as u32, y as u32))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_spans_grow_a_run_per_row() {
        let mut spans = TileSpans::EMPTY;
        assert!(spans.is_empty());
        for i in [5 * TILE_SIZE + 9, 5 * TILE_SIZE + 30, 2 * TILE_SIZE + 30] {
            spans.include(i);
        }
        assert_eq!(spans.rows().collect::<Vec<_>>(), [(2, 30, 31), (5, 9, 31)]);
        assert_eq!(spans.count(), 1 + 22);
        let mut run = spans;
        run.include_run(7 * TILE_SIZE + 3, 7 * TILE_SIZE + 12);
        run.include_run(5 * TILE_SIZE + 40, 5 * TILE_SIZE + 41);
        assert_eq!(
            run.rows().collect::<Vec<_>>(),
            [(2, 30, 31), (5, 9, 41), (7, 3, 12)]
        );
        assert_eq!(spans.indices().next(), Some(2 * TILE_SIZE + 30));
        assert_eq!(TileSpans::texel(7).indices().collect::<Vec<_>>(), [7]);
        assert_eq!(TileSpans::FULL.count(), TILE_TEXELS);
        assert!(TileSpans::FULL.indices().eq(0..TILE_TEXELS));
    }

    #[test]
    fn uniform_planes_materialise_on_write_and_compact_back() {
        let mut tile = Tile::uniform(Texel {
            kd: [1, 2, 3],
            ks: [4, 5, 6],
            n: 7,
        });
        assert_eq!(tile.heap_bytes(), 0);
        assert_eq!(tile.texel(100).ks, [4, 5, 6]);
        tile.kd.data_mut()[5] = [9, 9, 9];
        assert_eq!(tile.kd.get(5), [9, 9, 9]);
        assert_eq!(tile.kd.get(6), [1, 2, 3]);
        assert_eq!(tile.heap_bytes(), TILE_TEXELS * 6);
        tile.kd.data_mut()[5] = [1, 2, 3];
        tile.compact();
        assert_eq!(tile.kd.uniform(), Some([1, 2, 3]));
        assert_eq!(tile.heap_bytes(), 0);
    }
}
