//! Ray picking: which surface point of a mesh is under the cursor.
//!
//! A bounding volume hierarchy over the triangles, built by splitting at the median centroid
//! along the longest axis (`select_nth_unstable`, so the build is O(n log n)), flattened into
//! an array. A pick walks it near child first and tests triangles with Moller-Trumbore.
//!
//! The hierarchy holds the mesh in its [`UnitFrame`] (centred, scaled into `[-1, 1]` by a power
//! of two), so boxes, centroids and intersections see the same numbers at any scale; rays come
//! in and hits go out in object units.

use glam::{Vec2, Vec3};

use super::Mesh;
use crate::frame::UnitFrame;

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first triangle in `order`; inner: index of the right child (left is next).
    start: u32,
    /// Leaf: triangle count; inner: 0.
    count: u32,
}

/// A BVH over a mesh's triangles.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Where the boxes and `positions` are.
    frame: UnitFrame,
    /// The mesh's positions in `frame`.
    positions: Vec<Vec3>,
    /// The mesh's triangles.
    triangles: Vec<[u32; 3]>,
}

/// A ray hit on the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Triangle index.
    pub triangle: u32,
    /// Barycentric weights of the triangle's three vertices.
    pub barycentric: Vec3,
    /// Distance along the ray (in units of the ray direction's length).
    pub t: f32,
    /// Object-space position.
    pub position: Vec3,
    /// Interpolated unit normal.
    pub normal: Vec3,
    /// Interpolated UV, if the mesh has UVs.
    pub uv: Option<Vec2>,
}

/// The box around the triangles `tris` (indices into `triangles`, corners in `positions`).
fn bounds(positions: &[Vec3], triangles: &[[u32; 3]], tris: &[u32]) -> (Vec3, Vec3) {
    tris.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &t| {
            triangles[t as usize].iter().fold((lo, hi), |(lo, hi), &v| {
                (lo.min(positions[v as usize]), hi.max(positions[v as usize]))
            })
        },
    )
}

impl Bvh {
    /// Builds the hierarchy. A mesh that fails [`Mesh::validate`] is built all the same:
    /// triangles with a non-finite corner, or a corner that is not a vertex, are left out (no
    /// ray meets them).
    pub fn build(mesh: &Mesh) -> Self {
        let frame = UnitFrame::of(&mesh.positions);
        let positions = frame.local_positions(&mesh.positions);
        let corner = |v: u32| positions.get(v as usize).copied().filter(|p| p.is_finite());
        let mut order: Vec<u32> = (0..mesh.triangles.len() as u32)
            .filter(|&t| {
                mesh.triangles[t as usize]
                    .iter()
                    .all(|&v| corner(v).is_some())
            })
            .collect();
        let centroids: Vec<Vec3> = mesh
            .triangles
            .iter()
            .map(|t| {
                t.map(|v| corner(v).unwrap_or(Vec3::ZERO))
                    .iter()
                    .sum::<Vec3>()
                    / 3.0
            })
            .collect();
        let triangles = mesh.triangles.clone();
        let mut nodes = Vec::with_capacity(2 * order.len() / LEAF_SIZE + 1);
        // (node index, start, end) still to split.
        let mut stack = vec![(0usize, 0usize, order.len())];
        nodes.push(Node {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            start: 0,
            count: 0,
        });
        while let Some((index, start, end)) = stack.pop() {
            let (lo, hi) = bounds(&positions, &triangles, &order[start..end]);
            if end - start <= LEAF_SIZE {
                nodes[index] = Node {
                    lo,
                    hi,
                    start: start as u32,
                    count: (end - start) as u32,
                };
                continue;
            }
            let (clo, chi) = order[start..end].iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(a, b), &t| (a.min(centroids[t as usize]), b.max(centroids[t as usize])),
            );
            let extent = chi - clo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = usize::midpoint(start, end);
            order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
            let left = nodes.len();
            nodes.push(Node {
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                start: 0,
                count: 0,
            });
            let right = nodes.len();
            nodes.push(Node {
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                start: 0,
                count: 0,
            });
            nodes[index] = Node {
                lo,
                hi,
                start: right as u32,
                count: 0,
            };
            // Left children must follow their parent for the traversal's `index + 1`; we store
            // both explicitly instead: left = right - 1.
            stack.push((right, mid, end));
            stack.push((left, start, mid));
        }
        Self {
            nodes,
            order,
            frame,
            positions,
            triangles,
        }
    }

    /// The nearest hit of the ray `origin + t * dir`, `t > 0`, if any. `mesh` is the mesh the
    /// hierarchy was built from (it gives the hit's position, normal and UV).
    pub fn pick(&self, mesh: &Mesh, origin: Vec3, dir: Vec3) -> Option<Hit> {
        // In f64: a direction of 1e30 has no f32 length.
        let length = dir.as_dvec3().length();
        if self.order.is_empty()
            || mesh.triangles.len() != self.triangles.len()
            || !origin.is_finite()
            || !(length.is_finite() && length > 0.0)
        {
            return None;
        }
        // The same ray in the local frame, with a unit direction: a local distance is
        // `length / local_per_object` of the ray's `t`.
        let t_per_local = 1.0 / (length * self.frame.local_per_object());
        let dir = (dir.as_dvec3() / length).as_vec3();
        let origin = self.frame.local_from_object(origin);
        let inv = dir.recip();
        let mut best: Option<(f32, u32, f32, f32)> = None;
        let mut stack = [0u32; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = self.nodes[stack[depth] as usize];
            let limit = best.map_or(f32::INFINITY, |b| b.0);
            if slab(node.lo, node.hi, origin, inv).is_none_or(|near| near > limit) {
                continue;
            }
            if node.count > 0 {
                for &t in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let corners = self.triangles[t as usize].map(|v| self.positions[v as usize]);
                    if let Some((d, u, v)) = moller_trumbore(corners, origin, dir)
                        && best.is_none_or(|b| d < b.0)
                    {
                        best = Some((d, t, u, v));
                    }
                }
                continue;
            }
            let (left, right) = (node.start - 1, node.start);
            let near = |i: u32| {
                let n = self.nodes[i as usize];
                slab(n.lo, n.hi, origin, inv).unwrap_or(f32::INFINITY)
            };
            // Push the far child first so the near one is visited next.
            let (first, second) = if near(left) <= near(right) {
                (left, right)
            } else {
                (right, left)
            };
            if depth + 2 <= stack.len() {
                stack[depth] = second;
                stack[depth + 1] = first;
                depth += 2;
            }
        }
        let (t, tri, u, v) = best?;
        let t = (f64::from(t) * t_per_local) as f32;
        let [a, b, c] = mesh.triangles[tri as usize];
        let bary = Vec3::new(1.0 - u - v, u, v);
        let lerp3 = |p: [Vec3; 3]| p[0] * bary.x + p[1] * bary.y + p[2] * bary.z;
        let corners = |data: &[Vec3]| [data[a as usize], data[b as usize], data[c as usize]];
        Some(Hit {
            triangle: tri,
            barycentric: bary,
            t,
            position: lerp3(corners(&mesh.positions)),
            normal: lerp3(corners(&mesh.normals))
                .try_normalize()
                .unwrap_or(Vec3::Y),
            uv: mesh.uvs.as_ref().map(|uvs| {
                uvs[a as usize] * bary.x + uvs[b as usize] * bary.y + uvs[c as usize] * bary.z
            }),
        })
    }
}

/// Entry distance of a ray into a box, if it hits it at `t >= 0`.
fn slab(lo: Vec3, hi: Vec3, origin: Vec3, inv: Vec3) -> Option<f32> {
    let t0 = (lo - origin) * inv;
    let t1 = (hi - origin) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element();
    (near <= far).then_some(near)
}

/// Moller-Trumbore in object space: `(t, u, v)` of the ray's hit on triangle `tri`,
/// two-sided. A reference to check [`Bvh::pick`] against on meshes of moderate scale (f32
/// products of coordinates overflow beyond about 1e19); the hierarchy tests the same way in the
/// mesh's unit frame.
pub fn intersect(mesh: &Mesh, tri: u32, origin: Vec3, dir: Vec3) -> Option<(f32, f32, f32)> {
    moller_trumbore(
        mesh.triangles[tri as usize].map(|v| mesh.positions[v as usize]),
        origin,
        dir,
    )
}

/// Moller-Trumbore: `(t, u, v)` of the ray's hit on the triangle `[a, b, c]`, two-sided.
fn moller_trumbore([a, b, c]: [Vec3; 3], origin: Vec3, dir: Vec3) -> Option<(f32, f32, f32)> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some((t, u, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_are_the_same_at_every_scale() {
        let torus = crate::torus(1.0, 0.35, 40, 20);
        let offset = Vec3::new(-2.0, 0.5, 1.0);
        // Rays from a ring around the torus towards points on and off it.
        let rays: Vec<(Vec3, Vec3)> = (0..400)
            .map(|i| {
                let a = i as f32 * 2.399;
                let origin = Vec3::new(3.0 * a.cos(), 1.0 + (i % 7) as f32 * 0.1, 3.0 * a.sin());
                let aim = Vec3::new(0.9 * (a * 1.7).sin(), 0.3 * (a * 0.3).cos(), 0.9 * a.cos());
                (origin + offset, aim - origin)
            })
            .collect();
        let picks = |scale: f32| {
            let mut mesh = torus.clone();
            mesh.positions
                .iter_mut()
                .for_each(|p| *p = (*p + offset) * scale);
            let bvh = Bvh::build(&mesh);
            rays.iter()
                .map(|&(o, d)| bvh.pick(&mesh, o * scale, d * scale))
                .collect::<Vec<_>>()
        };
        let unit = picks(1.0);
        assert!(unit.iter().flatten().count() > 100, "enough rays hit");
        for scale in [1e-20_f32, 1e30, 2.0_f32.powi(-100), 2.0_f32.powi(120)] {
            for (k, (a, b)) in unit.iter().zip(picks(scale)).enumerate() {
                let (Some(a), Some(b)) = (a, b) else {
                    assert!(
                        a.is_none() && b.is_none(),
                        "ray {k} at {scale}: {a:?} {b:?}"
                    );
                    continue;
                };
                assert_eq!(a.triangle, b.triangle, "ray {k} at {scale}");
                assert!((a.t - b.t).abs() <= 1e-5 * a.t, "ray {k} at {scale}");
                assert!((a.barycentric - b.barycentric).abs().max_element() < 1e-4);
                let back = b.position / scale - offset;
                assert!(
                    (a.position - offset - back).length() < 1e-4,
                    "ray {k} at {scale}"
                );
            }
        }
    }
}
