//! Ray picking: which surface point of a mesh is under the cursor.
//!
//! A bounding volume hierarchy over the triangles, built by splitting at the median centroid
//! along the longest axis (`select_nth_unstable`, so the build is O(n log n)), flattened into
//! an array. A pick walks it near child first and tests triangles with Moller-Trumbore.

use glam::{Vec2, Vec3};

use super::Mesh;

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

fn bounds(mesh: &Mesh, tris: &[u32]) -> (Vec3, Vec3) {
    tris.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &t| {
            mesh.triangles[t as usize]
                .iter()
                .fold((lo, hi), |(lo, hi), &v| {
                    (
                        lo.min(mesh.positions[v as usize]),
                        hi.max(mesh.positions[v as usize]),
                    )
                })
        },
    )
}

impl Bvh {
    /// Builds the hierarchy.
    pub fn build(mesh: &Mesh) -> Self {
        let centroids: Vec<Vec3> = mesh
            .triangles
            .iter()
            .map(|t| t.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / 3.0)
            .collect();
        let mut order: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * mesh.triangles.len() / LEAF_SIZE + 1);
        // (node index, start, end) still to split.
        let mut stack = vec![(0usize, 0usize, order.len())];
        nodes.push(Node {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            start: 0,
            count: 0,
        });
        while let Some((index, start, end)) = stack.pop() {
            let (lo, hi) = bounds(mesh, &order[start..end]);
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
        Self { nodes, order }
    }

    /// The nearest hit of the ray `origin + t * dir`, `t > 0`, if any.
    pub fn pick(&self, mesh: &Mesh, origin: Vec3, dir: Vec3) -> Option<Hit> {
        if self.nodes.is_empty()
            || mesh.triangles.is_empty()
            || !origin.is_finite()
            || !dir.is_finite()
            || dir == Vec3::ZERO
        {
            return None;
        }
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
                    if let Some((d, u, v)) = intersect(mesh, t, origin, dir)
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

/// Moller-Trumbore: `(t, u, v)` of the ray's hit on triangle `tri`, two-sided.
pub fn intersect(mesh: &Mesh, tri: u32, origin: Vec3, dir: Vec3) -> Option<(f32, f32, f32)> {
    let [a, b, c] = mesh.triangles[tri as usize].map(|v| mesh.positions[v as usize]);
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
