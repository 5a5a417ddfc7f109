//! Rasterising a mesh into texture space: what surface point each texel paints.
//!
//! Texel `(x, y)` covers the UV square `[x/W, (x+1)/W] x [1 - (y+1)/H, 1 - y/H]` (rows grow
//! downwards, `v` upwards). Rasterisation is conservative: a texel is covered when any
//! triangle touches its square, so a seam never leaves an unpainted dot. When several
//! triangles touch a texel, the one containing the texel centre wins, else the nearest. The
//! attributes are those of the triangle's point nearest to the texel centre. Then `padding`
//! rings of empty texels around every island copy their neighbour, so filtering and mips
//! don't bleed the background into the edges.
//!
//! A texel keeps 8 bytes: its triangle (with a padding flag) and two barycentric weights as
//! unorm16; its position, normal and island come from the triangle when asked. An 8192^2 bake
//! is 0.5 GB where storing them per texel took 2.2 GB (33 bytes a texel).

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::Mesh;

/// Rows per parallel band.
const BAND_ROWS: usize = 32;

/// Coverage of a texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Coverage {
    /// No triangle touches the texel.
    Empty = 0,
    /// A triangle touches the texel.
    Surface = 1,
    /// Padding copied from a neighbour.
    Padding = 2,
}

/// Per-texel surface data of a mesh at a map resolution (row-major).
#[derive(Clone, Debug)]
pub struct UvBake {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Per texel: the triangle it paints, [`PADDING`] set on padding texels; [`EMPTY`] where
    /// no triangle is.
    cells: Vec<u32>,
    /// Per texel: the barycentric weights of the triangle's second and third corners,
    /// unorm16 (the first's is what they leave of 1).
    weights: Vec<[u16; 2]>,
    /// The mesh's corners, normals and triangles, and each triangle's UV island.
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    islands: Vec<u32>,
    /// Texel-triangle pairs the bake tested: its work, which overlapping UVs must not
    /// multiply (each covered texel is settled once).
    pub touch_tests: u64,
}

/// A texel no triangle paints.
const EMPTY: u32 = u32::MAX;
/// The flag of a padding texel (a copy of its neighbour).
const PADDING: u32 = 1 << 31;

impl UvBake {
    /// Texels in all.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Triangles of the mesh it was made from.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Whether the bake has no texels.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Heap bytes of the per-texel data (8 a texel).
    pub fn texel_bytes(&self) -> usize {
        std::mem::size_of_val(&self.cells[..]) + std::mem::size_of_val(&self.weights[..])
    }

    /// Coverage of texel `i`.
    #[inline]
    pub fn coverage(&self, i: usize) -> Coverage {
        match self.cells[i] {
            EMPTY => Coverage::Empty,
            c if c & PADDING != 0 => Coverage::Padding,
            _ => Coverage::Surface,
        }
    }

    /// The triangle texel `i` paints (padding: its neighbour's), if any.
    #[inline]
    pub fn triangle(&self, i: usize) -> Option<u32> {
        let c = self.cells[i];
        (c != EMPTY).then_some(c & !PADDING)
    }

    /// The UV island of texel `i`, if any.
    pub fn island(&self, i: usize) -> Option<u32> {
        self.triangle(i).map(|t| self.islands[t as usize])
    }

    /// The barycentric weights of texel `i`'s point on its triangle.
    #[inline]
    pub fn barycentric(&self, i: usize) -> Vec3 {
        let [b, c] = self.weights[i].map(|w| f32::from(w) / 65535.0);
        Vec3::new((1.0 - b - c).max(0.0), b, c)
    }

    /// The object-space corners of triangle `t` (neighbouring texels mostly share one: a loop
    /// over texels keeps them while the triangle stays the same).
    #[inline]
    pub fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangles[t as usize].map(|v| self.positions[v as usize])
    }

    /// The unit normals at the corners of triangle `t` (see [`UvBake::corners`]).
    #[inline]
    pub fn corner_normals(&self, t: u32) -> [Vec3; 3] {
        self.triangles[t as usize].map(|v| self.normals[v as usize])
    }

    /// Object-space position of texel `i` (zero where it is empty).
    #[inline]
    pub fn position(&self, i: usize) -> Vec3 {
        self.triangle(i).map_or(Vec3::ZERO, |t| {
            let w = self.barycentric(i);
            let [a, b, c] = self.triangles[t as usize].map(|v| self.positions[v as usize]);
            a * w.x + b * w.y + c * w.z
        })
    }

    /// Unit object-space normal of texel `i` (zero where it is empty).
    #[inline]
    pub fn normal(&self, i: usize) -> Vec3 {
        self.triangle(i).map_or(Vec3::ZERO, |t| {
            let w = self.barycentric(i);
            let [a, b, c] = self.triangles[t as usize].map(|v| self.normals[v as usize]);
            (a * w.x + b * w.y + c * w.z).try_normalize().unwrap_or(a)
        })
    }

    /// Every texel's coverage, row-major (for a whole-map pass; 1 byte a texel).
    pub fn coverage_grid(&self) -> Vec<Coverage> {
        (0..self.len()).map(|i| self.coverage(i)).collect()
    }
}

/// Per-triangle UV island indices (union of triangles sharing UV points).
pub fn triangle_islands(mesh: &Mesh) -> Vec<u32> {
    let Some(uvs) = &mesh.uvs else {
        return vec![u32::MAX; mesh.triangles.len()];
    };
    super::connected_triangles(mesh, |v| {
        let t = uvs[v as usize];
        [t.x.to_bits(), t.y.to_bits(), 0]
    })
}

/// Barycentrics of the point of triangle `(a, b, c)` nearest to `p`, and its squared distance.
pub(crate) fn nearest_barycentric(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> (Vec3, f32) {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let d00 = v0.dot(v0);
    let d01 = v0.dot(v1);
    let d11 = v1.dot(v1);
    let d20 = v2.dot(v0);
    let d21 = v2.dot(v1);
    let denom = d00 * d11 - d01 * d01;
    if denom.abs() > f32::MIN_POSITIVE {
        let v = (d11 * d20 - d01 * d21) / denom;
        let w = (d00 * d21 - d01 * d20) / denom;
        let u = 1.0 - v - w;
        if u >= 0.0 && v >= 0.0 && w >= 0.0 {
            return (Vec3::new(u, v, w), 0.0);
        }
    }
    // Outside (or degenerate): the nearest point on the three edges.
    let edge = |p0: Vec2, p1: Vec2| {
        let d = p1 - p0;
        let t = if d.length_squared() > 0.0 {
            ((p - p0).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t, (p0 + d * t).distance_squared(p))
    };
    let (tab, dab) = edge(a, b);
    let (tbc, dbc) = edge(b, c);
    let (tca, dca) = edge(c, a);
    if dab <= dbc && dab <= dca {
        (Vec3::new(1.0 - tab, tab, 0.0), dab)
    } else if dbc <= dca {
        (Vec3::new(0.0, 1.0 - tbc, tbc), dbc)
    } else {
        (Vec3::new(tca, 0.0, 1.0 - tca), dca)
    }
}

/// Whether triangle `(a, b, c)` (texel units) touches the axis-aligned square of half-size
/// `h` around `center`: the separating-axis test on the square's axes and the three edges.
fn touches(a: Vec2, b: Vec2, c: Vec2, center: Vec2, h: f32) -> bool {
    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
    if hi.x < center.x - h || lo.x > center.x + h || hi.y < center.y - h || lo.y > center.y + h {
        return false;
    }
    for (p, q, r) in [(a, b, c), (b, c, a), (c, a, b)] {
        let e = q - p;
        let n = Vec2::new(-e.y, e.x);
        let side = n.dot(r - p);
        if side == 0.0 {
            continue; // degenerate edge: the box test above decides
        }
        // Distance of the square's farthest corner towards the triangle's side.
        let reach = h * (n.x.abs() + n.y.abs());
        let s = n.dot(center - p) * side.signum();
        if s < -reach {
            return false;
        }
    }
    true
}

/// Most texel rows all triangles together may span: a bound on the bake's work that no real
/// UV layout comes near (a mesh filling an 8192^2 map ten times over spans about 10^7), but
/// that a hostile file of millions of large overlapping triangles would pass.
pub const MAX_BAKE_ROWS: u64 = 1 << 30;

/// How far beyond a triangle's exact extent in a row texels are still tested (texels), so
/// that rounding never drops a texel the touch test would take.
const SPAN_MARGIN: f32 = 0.01;

/// The x extent of triangle `(a, b, c)` within the horizontal slab `y0 <= y <= y1`: the
/// extent of the polygon the slab cuts out of it (its corners inside the slab and its edges'
/// crossings of the slab's lines), or `None` when the slab misses it.
fn slab_span(a: Vec2, b: Vec2, c: Vec2, y0: f32, y1: f32) -> Option<(f32, f32)> {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for p in [a, b, c] {
        if p.y >= y0 && p.y <= y1 {
            lo = lo.min(p.x);
            hi = hi.max(p.x);
        }
    }
    for (p, q) in [(a, b), (b, c), (c, a)] {
        for line in [y0, y1] {
            if (p.y - line) * (q.y - line) < 0.0 {
                let x = p.x + (q.x - p.x) * ((line - p.y) / (q.y - p.y));
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Which texels of a band can still change: a texel whose centre lies inside a triangle is
/// final (no later triangle can beat distance 0), so overlapping UVs cost only the texels
/// still open. Bits are set for open texels, one row of words per texel row, with a summary
/// bit per word that has any.
struct OpenTexels {
    words_per_row: usize,
    summaries_per_row: usize,
    bits: Vec<u64>,
    summary: Vec<u64>,
}

impl OpenTexels {
    fn new(width: usize, rows: usize) -> Self {
        let words_per_row = width.div_ceil(64);
        let summaries_per_row = words_per_row.div_ceil(64);
        let mut bits = vec![u64::MAX; words_per_row * rows];
        let mut summary = vec![0_u64; summaries_per_row * rows];
        for r in 0..rows {
            if !width.is_multiple_of(64) {
                bits[r * words_per_row + words_per_row - 1] = (1_u64 << (width % 64)) - 1;
            }
            for w in 0..words_per_row {
                summary[r * summaries_per_row + w / 64] |= 1 << (w % 64);
            }
        }
        Self {
            words_per_row,
            summaries_per_row,
            bits,
            summary,
        }
    }

    /// The open texels of row `r` in `x0..=x1`, in order.
    fn open_in(&self, r: usize, x0: usize, x1: usize, out: &mut Vec<usize>) {
        out.clear();
        let (w0, w1) = (x0 / 64, x1 / 64);
        let mut w = w0;
        while w <= w1 {
            let s = self.summary[r * self.summaries_per_row + w / 64] >> (w % 64);
            if s == 0 {
                w = (w / 64 + 1) * 64; // no open word in the rest of this summary word
                continue;
            }
            w += s.trailing_zeros() as usize;
            if w > w1 {
                break;
            }
            let mut word = self.bits[r * self.words_per_row + w];
            if w == w0 {
                word &= u64::MAX << (x0 % 64);
            }
            if w == w1 && x1 % 64 != 63 {
                word &= (1_u64 << (x1 % 64 + 1)) - 1;
            }
            while word != 0 {
                out.push(w * 64 + word.trailing_zeros() as usize);
                word &= word - 1;
            }
            w += 1;
        }
    }

    /// Marks texel `x` of row `r` final.
    fn close(&mut self, r: usize, x: usize) {
        let w = x / 64;
        let word = &mut self.bits[r * self.words_per_row + w];
        *word &= !(1_u64 << (x % 64));
        if *word == 0 {
            self.summary[r * self.summaries_per_row + w / 64] &= !(1_u64 << (w % 64));
        }
    }
}

/// Bakes `mesh` (which must have UVs) at `width x height` with `padding` texels of dilation.
///
/// # Errors
/// A mesh without UVs, or one whose triangles together span more than [`MAX_BAKE_ROWS`]
/// texel rows.
pub fn bake(mesh: &Mesh, width: u32, height: u32, padding: u32) -> Result<UvBake, String> {
    mesh.paintable()?;
    if mesh.triangles.len() >= PADDING as usize {
        return Err(format!(
            "{} triangles are more than a bake indexes",
            mesh.triangles.len()
        ));
    }
    let uvs = mesh.uvs.as_ref().ok_or("no UVs")?;
    let (w, h) = (width as usize, height as usize);
    let islands = triangle_islands(mesh);
    // UV to texel coordinates (x right, y down).
    let to_texel = |t: Vec2| Vec2::new(t.x * width as f32, (1.0 - t.y) * height as f32);
    let bands = h.div_ceil(BAND_ROWS);
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    let mut rows_spanned: u64 = 0;
    for (i, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| to_texel(uvs[v as usize]));
        let (lo, hi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        if !(lo.is_finite() && hi.is_finite()) || hi < 0.0 || lo > height as f32 {
            continue;
        }
        let (top, bottom) = (
            (lo.floor().max(0.0) as usize).min(h - 1),
            (hi.floor().max(0.0) as usize).min(h - 1),
        );
        rows_spanned += (bottom - top + 1) as u64;
        if rows_spanned > MAX_BAKE_ROWS {
            return Err(format!(
                "the UV layout is too costly to bake at {width}x{height}: its triangles span more than {MAX_BAKE_ROWS} texel rows in all (millions of large overlapping UV triangles?)"
            ));
        }
        for band in &mut binned[top / BAND_ROWS..=bottom / BAND_ROWS] {
            band.push(i as u32);
        }
    }
    let mut out = UvBake {
        width,
        height,
        cells: vec![EMPTY; w * h],
        weights: vec![[0; 2]; w * h],
        positions: mesh.positions.clone(),
        normals: mesh.normals.clone(),
        triangles: mesh.triangles.clone(),
        islands,
        touch_tests: 0,
    };
    let band_len = w * BAND_ROWS;
    out.touch_tests = out
        .cells
        .par_chunks_mut(band_len)
        .zip(out.weights.par_chunks_mut(band_len))
        .enumerate()
        .map(|(band, (cells, weights))| {
            rasterize_band(
                mesh,
                uvs,
                (width, height),
                &binned[band],
                band * BAND_ROWS,
                (cells, weights),
            )
        })
        .sum();
    dilate(&mut out, padding);
    Ok(out)
}

/// Rasterises `triangles` (indices into the mesh) into the band of rows starting at `y0`;
/// returns the texel tests made.
fn rasterize_band(
    mesh: &Mesh,
    uvs: &[Vec2],
    (width, height): (u32, u32),
    triangles: &[u32],
    y0: usize,
    (cells, weights): (&mut [u32], &mut [[u16; 2]]),
) -> u64 {
    let w = width as usize;
    let to_texel = |t: Vec2| Vec2::new(t.x * width as f32, (1.0 - t.y) * height as f32);
    let rows = cells.len() / w;
    let mut best = vec![f32::INFINITY; cells.len()];
    let mut open = OpenTexels::new(w, rows);
    let mut candidates = Vec::new();
    let mut tests = 0_u64;
    for &ti in triangles {
        let t = mesh.triangles[ti as usize];
        let [a, b, c] = t.map(|v| to_texel(uvs[v as usize]));
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        let xs = (lo.x.floor().max(0.0) as usize).min(w - 1);
        let xe = (hi.x.floor().max(0.0) as usize).min(w - 1);
        let ys = (lo.y.floor().max(y0 as f32) as usize).clamp(y0, y0 + rows - 1);
        let ye = (hi.y.floor().max(0.0) as usize).clamp(y0, y0 + rows - 1);
        for y in ys..=ye {
            let Some((left, right)) = slab_span(a, b, c, y as f32, y as f32 + 1.0) else {
                continue;
            };
            // Texel x touches [left, right] when x + 1 >= left and x <= right.
            let x0 = ((left - SPAN_MARGIN).ceil() - 1.0).max(xs as f32) as usize;
            let x1 = ((right + SPAN_MARGIN).floor().min(xe as f32)).max(0.0) as usize;
            if x0 > x1 {
                continue;
            }
            open.open_in(y - y0, x0, x1, &mut candidates);
            tests += candidates.len() as u64;
            for &x in &candidates {
                let center = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                if !touches(a, b, c, center, 0.5) {
                    continue;
                }
                let (bary, d2) = nearest_barycentric(center, a, b, c);
                let k = (y - y0) * w + x;
                if d2 >= best[k] {
                    continue;
                }
                best[k] = d2;
                if d2 == 0.0 {
                    open.close(y - y0, x);
                }
                cells[k] = ti;
                weights[k] = [bary.y, bary.z].map(|b| (b.clamp(0.0, 1.0) * 65535.0).round() as u16);
            }
        }
    }
    tests
}

/// Grows every island by `rings` texels (bake padding).
fn dilate(bake: &mut UvBake, rings: u32) {
    let mut filled: Vec<bool> = bake.cells.iter().map(|&c| c != EMPTY).collect();
    dilate_grid(&mut filled, bake.width, bake.height, rings, |k, src| {
        bake.cells[k] = bake.cells[src] | PADDING;
        bake.weights[k] = bake.weights[src];
    });
}

/// Grows the filled cells of a row-major `width x height` grid by up to `rings` cells: each
/// empty cell next to a filled one (8 neighbours, taken in a fixed order) gets
/// `copy(cell, source)` and becomes filled. Sources are chosen against the state before each
/// ring. Works on the frontier only, so the cost is the islands' perimeter times `rings`, not
/// the whole grid per ring; `u32::MAX` rings fills every cell reachable from a filled one.
pub fn dilate_grid(
    filled: &mut [bool],
    width: u32,
    height: u32,
    rings: u32,
    mut copy: impl FnMut(usize, usize),
) {
    const NEIGHBOURS: [(i64, i64); 8] = [
        (-1, 0),
        (1, 0),
        (0, -1),
        (0, 1),
        (-1, -1),
        (1, -1),
        (-1, 1),
        (1, 1),
    ];
    let (w, h) = (i64::from(width), i64::from(height));
    let neighbours = move |k: usize| {
        let (x, y) = (k as i64 % w, k as i64 / w);
        NEIGHBOURS.iter().filter_map(move |&(dx, dy)| {
            let (nx, ny) = (x + dx, y + dy);
            (nx >= 0 && ny >= 0 && nx < w && ny < h).then(|| (ny * w + nx) as usize)
        })
    };
    // Empty cells touching a filled one, found in parallel.
    let mut frontier: Vec<usize> = {
        let filled = &*filled;
        (0..filled.len())
            .into_par_iter()
            .filter(|&k| !filled[k] && neighbours(k).any(|n| filled[n]))
            .collect()
    };
    for _ in 0..rings {
        if frontier.is_empty() {
            break;
        }
        let fills: Vec<(usize, usize)> = frontier
            .iter()
            .filter_map(|&k| neighbours(k).find(|&n| filled[n]).map(|s| (k, s)))
            .collect();
        for &(k, src) in &fills {
            copy(k, src);
        }
        for &(k, _) in &fills {
            filled[k] = true;
        }
        let mut next: Vec<usize> = fills
            .iter()
            .flat_map(|&(k, _)| neighbours(k))
            .filter(|&n| !filled[n])
            .collect();
        next.sort_unstable();
        next.dedup();
        frontier = next;
    }
}

#[cfg(test)]
mod tests;
