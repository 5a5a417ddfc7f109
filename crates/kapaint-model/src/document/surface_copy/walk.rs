//! Finding where on the map each texel of a dab reads, texel after texel: its point on the
//! surface moved to the source (see [`SourceGrid`]), then the triangle of the surface under
//! that point, found by walking across the mesh's edges from the triangle of the texel
//! before (neighbouring texels' sources lie a texel apart), and its UV there.

use glam::{Vec2, Vec3};

use super::SourceGrid;
use crate::surface::Surface;

/// Most triangles a walk from the texel before crosses (a texel's step crosses one or two).
const SHORT_WALK: usize = 8;

/// Most triangles a walk from the first source of the run before, or from the anchor,
/// crosses: a row of a tile, or a dab's radius, on a mesh of large triangles; on a finer mesh
/// a longer way is found through the grid's cells instead.
const LONG_WALK: usize = 64;

/// A triangle of the surface, ready for many points: where a point projects on it and how
/// far off its plane it lies are three dot products, and its map position one more blend.
#[derive(Clone, Copy, Debug)]
struct SourceTriangle {
    t: u32,
    /// Its first corner.
    a: Vec3,
    /// A point's second and third barycentric weights are its offset from `a` dotted with
    /// these.
    to_v: Vec3,
    to_w: Vec3,
    /// The unit normal.
    normal: Vec3,
    /// The first corner's map position (texel units), and the other two's minus it.
    at_a: Vec2,
    at_v: Vec2,
    at_w: Vec2,
}

/// Where a point lies for a triangle.
enum Locate {
    /// Its projection falls inside, these barycentric weights, and it is near the plane.
    Inside(Vec3),
    /// Its projection falls beyond the edge opposite this corner.
    Beyond(usize),
    /// The point is off the triangle's plane.
    Away,
}

impl SourceTriangle {
    /// Triangle `t` of `surface`; `None` when it has no area or the mesh no UVs.
    fn new(surface: &Surface, t: u32) -> Option<Self> {
        let [a, b, c] = surface.bake.corners(t);
        let (e0, e1) = (b - a, c - a);
        let n = e0.cross(e1);
        let n2 = n.length_squared();
        if n2 <= f32::MIN_POSITIVE {
            return None;
        }
        let [ta, tb, tc] = texel_corners(surface, t)?;
        Some(Self {
            t,
            a,
            to_v: e1.cross(n) / n2,
            to_w: n.cross(e0) / n2,
            normal: n / n2.sqrt(),
            at_a: ta,
            at_v: tb - ta,
            at_w: tc - ta,
        })
    }

    /// Where `p` lies: inside (its projection inside, `p` within `near` of the plane), or
    /// beyond the edge opposite the corner of the most negative weight.
    #[inline]
    fn locate(&self, p: Vec3, near: f32) -> Locate {
        let d = p - self.a;
        let (v, w) = (d.dot(self.to_v), d.dot(self.to_w));
        let u = 1.0 - v - w;
        if u >= 0.0 && v >= 0.0 && w >= 0.0 {
            if d.dot(self.normal).abs() <= near {
                Locate::Inside(Vec3::new(u, v, w))
            } else {
                Locate::Away
            }
        } else if u <= v && u <= w {
            Locate::Beyond(0)
        } else if v <= w {
            Locate::Beyond(1)
        } else {
            Locate::Beyond(2)
        }
    }

    /// The map position (texel units) of the point of barycentric weights `w`.
    #[inline]
    fn texel_at(&self, w: Vec3) -> Vec2 {
        self.at_a + self.at_v * w.y + self.at_w * w.z
    }
}

/// The map positions (texel units, rows growing downward) of triangle `t`'s corners.
fn texel_corners(surface: &Surface, t: u32) -> Option<[Vec2; 3]> {
    let uvs = surface.mesh.uvs.as_ref()?;
    let size = Vec2::new(surface.bake.width as f32, surface.bake.height as f32);
    let corners = surface.mesh.triangles.get(t as usize)?;
    Some(corners.map(|v| {
        let uv = uvs[v as usize];
        Vec2::new(uv.x, 1.0 - uv.y) * size
    }))
}

/// The sources of one tile's texels, found run after run (a run: texels of one row, left to
/// right): each texel's search starts on the triangle where the texel before found its
/// source, a run's first texel's on the triangle where the run before's first one did.
pub(in crate::document) struct Walker<'g, 'a> {
    grid: &'g SourceGrid<'a>,
    /// The texel's triangle, its corners moved to where the source lies.
    dest: Option<(u32, [Vec3; 3])>,
    /// The triangle the texel before's source lay on.
    src: Option<SourceTriangle>,
    /// The triangle of the run before's first source.
    run_seed: Option<SourceTriangle>,
    /// No source found yet in this run.
    run_start: bool,
}

impl<'g, 'a> Walker<'g, 'a> {
    pub(in crate::document) fn new(grid: &'g SourceGrid<'a>) -> Self {
        Self {
            grid,
            dest: None,
            src: None,
            run_seed: None,
            run_start: true,
        }
    }

    /// A new run of texels begins.
    #[inline]
    pub(in crate::document) fn start_run(&mut self) {
        self.src = self.run_seed;
        self.run_start = true;
    }

    /// Where on the map (texel units) the source of texel `i` (its index in the map) lies;
    /// none for a texel off the mesh or a source off the surface.
    ///
    /// On the triangle before when the moved point projects inside it within the grid's
    /// reach of its plane (most texels, here in line), else [`Self::find`]. The reach, not a
    /// texel: a patch moved across a coarse mesh meets facets tilted unlike its own, up to a
    /// texel or more off them (the sphere's 32 x 64-texel facets at 4096^2: 0.8 texel), and
    /// the same surface followed texel after texel is the source, where the nearest texel
    /// might jump to another sheet.
    #[inline]
    pub(in crate::document) fn source(&mut self, i: usize) -> Option<Vec2> {
        let q = self.moved_point(i)?;
        let here = self
            .src
            .and_then(|src| match src.locate(q, self.grid.reach) {
                Locate::Inside(w) => Some(src.texel_at(w)),
                Locate::Beyond(_) | Locate::Away => None,
            });
        let found = here.or_else(|| self.find(q));
        if found.is_some() && self.run_start {
            self.run_seed = self.src;
            self.run_start = false;
        }
        found
    }

    /// Texel `i`'s point moved to where its source lies (see [`SourceGrid`]).
    #[inline]
    fn moved_point(&mut self, i: usize) -> Option<Vec3> {
        let bake = &self.grid.surface.bake;
        let t = bake.triangle(i)?;
        let [a, b, c] = match self.dest {
            Some((dt, corners)) if dt == t => corners,
            _ => {
                let g = self.grid;
                let moved = bake.corners(t).map(|p| g.anchor + g.turn * (p - g.center));
                self.dest = Some((t, moved));
                moved
            }
        };
        let w = bake.barycentric(i);
        Some(a * w.x + b * w.y + c * w.z)
    }

    /// Where on the map the surface under `q` lies when it is not on the triangle before: a
    /// walk from there (from the anchor's triangle at a tile's start), else the triangle of
    /// the nearest baked texel.
    #[inline(never)]
    fn find(&mut self, q: Vec3) -> Option<Vec2> {
        let surface = self.grid.surface;
        let start = match self.src {
            Some(s) => Some((
                s,
                if self.run_start {
                    LONG_WALK
                } else {
                    SHORT_WALK
                },
            )),
            None => (self.grid.anchor_triangle)
                .and_then(|t| SourceTriangle::new(surface, t))
                .map(|s| (s, LONG_WALK)),
        };
        let walked = start.and_then(|(from, steps)| walk(surface, q, from, steps, self.grid.reach));
        if let Some((tri, w)) = walked {
            self.src = Some(tri);
            return Some(tri.texel_at(w));
        }
        let i = self.grid.cells().nearest(q)?;
        let t = surface.bake.triangle(i)?;
        let w = closest_on_triangle(q, surface.bake.corners(t));
        let [a, b, c] = texel_corners(surface, t)?;
        self.src = SourceTriangle::new(surface, t);
        Some(a * w.x + b * w.y + c * w.z)
    }
}

/// The triangle `q` projects inside, within `near` of its plane, found by walking from
/// `from` across the edge `q` lies beyond, `steps` triangles at most; with `q`'s barycentric
/// weights there.
fn walk(
    surface: &Surface,
    q: Vec3,
    mut tri: SourceTriangle,
    steps: usize,
    near: f32,
) -> Option<(SourceTriangle, Vec3)> {
    for _ in 0..steps {
        match tri.locate(q, near) {
            Locate::Inside(w) => return Some((tri, w)),
            Locate::Beyond(k) => {
                let next = *surface.neighbours().get(tri.t as usize)?.get(k)?;
                if next == u32::MAX {
                    return None;
                }
                tri = SourceTriangle::new(surface, next)?;
            }
            Locate::Away => return None,
        }
    }
    None
}

/// The barycentric weights of the point of triangle `[a, b, c]` nearest `p`.
pub(super) fn closest_on_triangle(p: Vec3, [a, b, c]: [Vec3; 3]) -> Vec3 {
    let (e0, e1, d) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (d.dot(e0), d.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    if denom.abs() > f32::MIN_POSITIVE {
        let v = (d11 * d20 - d01 * d21) / denom;
        let w = (d00 * d21 - d01 * d20) / denom;
        if v >= 0.0 && w >= 0.0 && v + w <= 1.0 {
            return Vec3::new(1.0 - v - w, v, w);
        }
    }
    // Outside (or degenerate): the nearest point of the three edges.
    let edge = |p0: Vec3, p1: Vec3| {
        let e = p1 - p0;
        let len2 = e.length_squared();
        let t = if len2 > 0.0 {
            ((p - p0).dot(e) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t, (p0 + e * t).distance_squared(p))
    };
    let (tab, dab) = edge(a, b);
    let (tbc, dbc) = edge(b, c);
    let (tca, dca) = edge(c, a);
    if dab <= dbc && dab <= dca {
        Vec3::new(1.0 - tab, tab, 0.0)
    } else if dbc <= dca {
        Vec3::new(0.0, 1.0 - tbc, tbc)
    } else {
        Vec3::new(tca, 0.0, 1.0 - tca)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_point_of_a_triangle_is_inside_or_on_its_edges() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let w = closest_on_triangle(Vec3::new(0.25, 0.25, 3.0), t);
        assert!((w - Vec3::new(0.5, 0.25, 0.25)).length() < 1e-6, "{w}");
        let w = closest_on_triangle(Vec3::new(2.0, -1.0, 0.0), t);
        assert!((w - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6, "{w}");
        let w = closest_on_triangle(Vec3::new(0.5, -1.0, 0.0), t);
        assert!((w - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6, "{w}");
    }
}
