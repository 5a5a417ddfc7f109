//! Rasterising a mesh into texture space: what surface point each texel paints.
//!
//! Texel `(x, y)` covers the UV square `[x/W, (x+1)/W] x [1 - (y+1)/H, 1 - y/H]` (rows grow
//! downwards, `v` upwards). Rasterisation is conservative: a texel is covered when any
//! triangle touches its square, so a seam never leaves an unpainted dot. When several
//! triangles touch a texel, the one containing the texel centre wins, else the nearest. The
//! attributes are those of the triangle's point nearest to the texel centre. Then `padding`
//! rings of empty texels around every island copy their neighbour, so filtering and mips
//! don't bleed the background into the edges.

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
    /// Object-space position.
    pub position: Vec<Vec3>,
    /// Unit object-space normal.
    pub normal: Vec<Vec3>,
    /// Triangle index, `u32::MAX` where empty.
    pub triangle: Vec<u32>,
    /// UV island index, `u32::MAX` where empty.
    pub island: Vec<u32>,
    /// Coverage.
    pub coverage: Vec<Coverage>,
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
fn nearest_barycentric(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> (Vec3, f32) {
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

/// Bakes `mesh` (which must have UVs) at `width x height` with `padding` texels of dilation.
pub fn bake(mesh: &Mesh, width: u32, height: u32, padding: u32) -> Result<UvBake, String> {
    mesh.paintable()?;
    let uvs = mesh.uvs.as_ref().ok_or("no UVs")?;
    let (w, h) = (width as usize, height as usize);
    let islands = triangle_islands(mesh);
    // UV to texel coordinates (x right, y down).
    let to_texel = |t: Vec2| Vec2::new(t.x * width as f32, (1.0 - t.y) * height as f32);
    let bands = h.div_ceil(BAND_ROWS);
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| to_texel(uvs[v as usize]));
        let (lo, hi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        if !(lo.is_finite() && hi.is_finite()) || hi < 0.0 || lo > height as f32 {
            continue;
        }
        let first = (lo.floor().max(0.0) as usize / BAND_ROWS).min(bands - 1);
        let last = (hi.floor().max(0.0) as usize / BAND_ROWS).min(bands - 1);
        for band in &mut binned[first..=last] {
            band.push(i as u32);
        }
    }
    let mut out = UvBake {
        width,
        height,
        position: vec![Vec3::ZERO; w * h],
        normal: vec![Vec3::ZERO; w * h],
        triangle: vec![u32::MAX; w * h],
        island: vec![u32::MAX; w * h],
        coverage: vec![Coverage::Empty; w * h],
    };
    let band_len = w * BAND_ROWS;
    out.position
        .par_chunks_mut(band_len)
        .zip(out.normal.par_chunks_mut(band_len))
        .zip(out.triangle.par_chunks_mut(band_len))
        .zip(out.island.par_chunks_mut(band_len))
        .zip(out.coverage.par_chunks_mut(band_len))
        .enumerate()
        .for_each(|(band, ((((pos, nrm), tri), isl), cov))| {
            let y0 = band * BAND_ROWS;
            let rows = pos.len() / w;
            let mut best = vec![f32::INFINITY; pos.len()];
            for &ti in &binned[band] {
                let t = mesh.triangles[ti as usize];
                let [a, b, c] = t.map(|v| to_texel(uvs[v as usize]));
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                let xs = (lo.x.floor().max(0.0) as usize).min(w - 1);
                let xe = (hi.x.floor().max(0.0) as usize).min(w - 1);
                let ys = (lo.y.floor().max(y0 as f32) as usize).clamp(y0, y0 + rows - 1);
                let ye = (hi.y.floor().max(0.0) as usize).clamp(y0, y0 + rows - 1);
                for y in ys..=ye {
                    for x in xs..=xe {
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
                        let [pa, pb, pc] = t.map(|v| mesh.positions[v as usize]);
                        let [na, nb, nc] = t.map(|v| mesh.normals[v as usize]);
                        pos[k] = pa * bary.x + pb * bary.y + pc * bary.z;
                        nrm[k] = (na * bary.x + nb * bary.y + nc * bary.z)
                            .try_normalize()
                            .unwrap_or(na);
                        tri[k] = ti;
                        isl[k] = islands[ti as usize];
                        cov[k] = Coverage::Surface;
                    }
                }
            }
        });
    dilate(&mut out, padding);
    Ok(out)
}

/// Grows every island by `rings` texels (bake padding).
fn dilate(bake: &mut UvBake, rings: u32) {
    let mut filled: Vec<bool> = bake
        .coverage
        .iter()
        .map(|c| *c != Coverage::Empty)
        .collect();
    dilate_grid(&mut filled, bake.width, bake.height, rings, |k, src| {
        bake.position[k] = bake.position[src];
        bake.normal[k] = bake.normal[src];
        bake.triangle[k] = bake.triangle[src];
        bake.island[k] = bake.island[src];
        bake.coverage[k] = Coverage::Padding;
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
mod tests {
    use super::*;

    #[test]
    fn the_touch_test_is_exact_for_a_simple_triangle() {
        let (a, b, c) = (
            Vec2::new(0.0, 0.0),
            Vec2::new(4.0, 0.0),
            Vec2::new(0.0, 4.0),
        );
        assert!(touches(a, b, c, Vec2::new(0.5, 0.5), 0.5));
        // The square [2.5, 3.5] x [2.5, 3.5] lies beyond the hypotenuse x + y = 4.
        assert!(!touches(a, b, c, Vec2::new(3.0, 3.0), 0.5));
        // [1.5, 2.5]^2 touches it at the corner (1.5, 2.5)... 1.5 + 2.5 = 4: touching counts.
        assert!(touches(a, b, c, Vec2::new(2.0, 2.0), 0.5));
        assert!(!touches(a, b, c, Vec2::new(-1.0, 2.0), 0.4));
    }

    #[test]
    fn nearest_point_is_inside_or_on_an_edge() {
        let (a, b, c) = (Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0));
        let (bary, d2) = nearest_barycentric(Vec2::new(0.2, 0.2), a, b, c);
        assert_eq!(d2, 0.0);
        assert!((bary.x - 0.6).abs() < 1e-6);
        let (bary, d2) = nearest_barycentric(Vec2::new(1.0, 1.0), a, b, c);
        assert!((d2 - 0.5).abs() < 1e-6);
        assert!((bary.y - 0.5).abs() < 1e-6 && (bary.z - 0.5).abs() < 1e-6);
    }

    #[test]
    fn full_dilation_fills_every_cell_from_its_nearest_island() {
        // Two filled cells at the ends of a 7x1 row: each fills its own half.
        let mut filled = [true, false, false, false, false, false, true];
        let mut value = [1, 0, 0, 0, 0, 0, 2];
        dilate_grid(&mut filled, 7, 1, u32::MAX, |k, s| value[k] = value[s]);
        assert!(filled.iter().all(|f| *f));
        assert_eq!(value, [1, 1, 1, 1, 2, 2, 2]);
        // Nothing filled: nothing to grow from.
        let mut none = [false; 4];
        dilate_grid(&mut none, 2, 2, u32::MAX, |_, _| unreachable!());
        assert!(none.iter().all(|f| !*f));
    }
}
