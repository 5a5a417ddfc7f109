//! Rays against the mesh: a BVH for occlusion and distance, and the direction set a bake
//! casts about each texel's normal.
//!
//! The BVH holds the mesh in its [`UnitFrame`] (centred, scaled into `[-1, 1]` by a power of
//! two), so its build and every ray see the same numbers at any scale; rays are given and
//! distances handed back in object units.

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::CwBvh;
use obvhs::triangle::Triangle;

use super::bvh_build::build_bvh;
use super::occlusion::{Facet, Occluders, ray};
use crate::Mesh;
use crate::frame::UnitFrame;

/// Triangle `k` of `mesh` with its corners in `frame` (the BVH's); none where a corner is
/// missing or not finite.
fn local_triangle(mesh: &Mesh, frame: &UnitFrame, k: u32) -> Option<Triangle> {
    let t = mesh.triangles.get(k as usize)?;
    let corner = |i: u32| {
        let p = frame.local_from_object(*mesh.positions.get(i as usize)?);
        p.is_finite().then(|| Vec3A::from(p))
    };
    Some(Triangle {
        v0: corner(t[0])?,
        v1: corner(t[1])?,
        v2: corner(t[2])?,
    })
}

/// A BVH of the mesh for occlusion and distance rays.
pub struct RayMesh {
    bvh: CwBvh,
    /// The triangles in the BVH's order (no lookup through its primitive indices per test), in
    /// local coordinates: their corners, for a GPU and for obvhs's own traversal (the tests'
    /// reference).
    triangles: Vec<Triangle>,
    /// The same triangles as the walk reads them.
    facets: Vec<Facet>,
    /// Per triangle (in the BVH's order), its index in the mesh.
    sources: Vec<u32>,
    /// Where the triangles are.
    frame: UnitFrame,
    /// The bounding box's diagonal (object units; saturated at `f32::MAX`).
    pub diagonal: f32,
}

impl RayMesh {
    /// Builds the BVH of `mesh`'s triangles. A mesh that fails [`Mesh::validate`] is built all
    /// the same: triangles with a non-finite corner are left out (no ray meets them), and
    /// lengths saturate where its box is too large to measure.
    pub fn new(mesh: &Mesh) -> Self {
        Self::of_triangles(mesh, &UnitFrame::of(&mesh.positions), None)
    }

    /// One BVH per group of `mesh`'s triangles, `group_of` naming each triangle's (none where
    /// it is `groups` or more), indices still the mesh's; `None` for a group without a
    /// triangle. All share the mesh's frame.
    pub fn split(mesh: &Mesh, group_of: &[u32], groups: usize) -> Vec<Option<Self>> {
        let frame = UnitFrame::of(&mesh.positions);
        // The triangles of each group, in one pass over the mesh.
        let mut members = vec![Vec::new(); groups];
        for (k, &g) in (0u32..).zip(group_of) {
            if let Some(m) = members.get_mut(g as usize) {
                m.push(k);
            }
        }
        members
            .into_iter()
            .map(|m| (!m.is_empty()).then(|| Self::of_triangles(mesh, &frame, Some(m))))
            .collect()
    }

    /// The BVH of the triangles `which` names (all of the mesh's: `None`), in `frame`. Only
    /// their positions are held beside the build (no copy of the mesh's positions, no list
    /// of the triangles kept where all are): a sculpt's build holds little else at its peak.
    fn of_triangles(mesh: &Mesh, frame: &UnitFrame, which: Option<Vec<u32>>) -> Self {
        let mut triangles =
            Vec::with_capacity(which.as_ref().map_or(mesh.triangles.len(), Vec::len));
        // The mesh's index of each triangle built, where it is not its place in `triangles`.
        let kept = if let Some(mut listed) = which {
            listed.retain(|&k| {
                local_triangle(mesh, frame, k)
                    .map(|t| triangles.push(t))
                    .is_some()
            });
            Some(listed)
        } else {
            let mut kept: Option<Vec<u32>> = None;
            for k in 0..mesh.triangles.len() as u32 {
                match local_triangle(mesh, frame, k) {
                    Some(t) => {
                        triangles.push(t);
                        if let Some(kept) = &mut kept {
                            kept.push(k);
                        }
                    }
                    // The first left out: those before it were all kept.
                    None if kept.is_none() => kept = Some((0..k).collect()),
                    None => {}
                }
            }
            kept
        };
        let bvh = build_bvh(triangles);
        // The triangles again, in the BVH's order (a triangle split by the build appears
        // once for each of its pieces).
        let (sources, triangles): (_, Vec<_>) = bvh
            .primitive_indices
            .iter()
            .filter_map(|&i| {
                let k = kept
                    .as_ref()
                    .map_or(Some(i), |kept| kept.get(i as usize).copied())?;
                Some((k, local_triangle(mesh, frame, k)?))
            })
            .unzip();
        let facets = triangles.iter().map(Facet::new).collect();
        Self {
            bvh,
            triangles,
            facets,
            sources,
            diagonal: frame.diagonal(),
            frame: *frame,
        }
    }

    /// The frame the BVH is built in.
    pub fn frame(&self) -> &UnitFrame {
        &self.frame
    }

    /// Whether a ray from `origin` along unit `dir` meets the mesh before `far` (object
    /// units).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, far: f32) -> bool {
        self.occluded_local(
            self.frame.local_from_object(origin),
            dir,
            self.frame.local_length(far),
        )
    }

    /// The distance along a ray from `origin` along unit `dir` to the mesh, if it meets it
    /// before `far` (object units).
    pub fn distance(&self, origin: Vec3, dir: Vec3, far: f32) -> Option<f32> {
        self.distance_local(
            self.frame.local_from_object(origin),
            dir,
            self.frame.local_length(far),
        )
        .map(|t| self.frame.object_length(t))
    }

    /// The cosine-weighted fraction of the `set`'s directions around unit `normal` from
    /// `point` that meet nothing before `far` (object units); the set is turned by `turn`
    /// about the normal.
    pub fn open_fraction(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        self.open_fraction_local(
            self.frame.local_from_object(point),
            normal,
            set,
            self.frame.local_length(far),
            turn,
        )
    }

    /// The mean of `min(distance, far) / far` over the `set`'s directions around unit
    /// `normal` from `point`, turned by `turn` (object units).
    pub fn mean_distance(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        self.mean_distance_local(
            self.frame.local_from_object(point),
            normal,
            set,
            self.frame.local_length(far),
            turn,
        )
    }

    /// The nearest triangle a ray from `origin` along unit `dir` meets before `far` (object
    /// units): the distance to it (object units) and its index in the mesh (of triangles met
    /// as near, the first in the mesh).
    pub fn nearest(&self, origin: Vec3, dir: Vec3, far: f32) -> Option<(f32, u32)> {
        let ray = ray(
            self.frame.local_from_object(origin),
            dir,
            self.frame.local_length(far),
        );
        let (t, source) = self.occluders().nearest_one(&ray)?;
        Some((self.frame.object_length(t), source))
    }

    /// [`RayMesh::occluded`] in local units.
    pub(super) fn occluded_local(&self, origin: Vec3, dir: Vec3, far: f32) -> bool {
        self.occluders()
            .occluded(&ray(origin, dir, far), &mut Vec::new())
    }

    /// [`RayMesh::occluded_local`] through obvhs's own traversal and triangle test: the
    /// reference the occlusion walk answers as, ray for ray.
    #[cfg(test)]
    pub(super) fn obvhs_occluded(&self, origin: Vec3, dir: Vec3, far: f32) -> bool {
        !self
            .bvh
            .ray_traverse_miss(ray(origin, dir, far), |ray, id| {
                self.triangles[id].intersect(ray)
            })
    }

    /// The BVH as the occlusion walk reads it.
    pub(super) fn occluders(&self) -> Occluders<'_> {
        Occluders {
            nodes: &self.bvh.nodes,
            facets: &self.facets,
            sources: &self.sources,
        }
    }

    /// [`RayMesh::distance`] in local units.
    pub(super) fn distance_local(&self, origin: Vec3, dir: Vec3, far: f32) -> Option<f32> {
        Some(self.occluders().nearest_one(&ray(origin, dir, far))?.0)
    }

    /// [`RayMesh::distance_local`] through obvhs's own traversal and triangle test: the
    /// reference the closest-hit walk answers as, ray for ray.
    #[cfg(test)]
    pub(super) fn obvhs_distance(&self, origin: Vec3, dir: Vec3, far: f32) -> Option<f32> {
        let mut hit = obvhs::ray::RayHit::none();
        self.bvh
            .ray_traverse(ray(origin, dir, far), &mut hit, |ray, id| {
                self.triangles[id].intersect(ray)
            })
            .then_some(hit.t)
    }

    /// [`RayMesh::open_fraction`] from a point and to a distance in local units.
    pub(super) fn open_fraction_local(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        let origin = point + normal * self.offset();
        let (t, b) = Directions::turned_frame(normal, turn);
        let open = self
            .occluders()
            .open_count(origin, [t, b, normal], set.as_slice(), far);
        open as f32 / set.len() as f32
    }

    /// [`RayMesh::mean_distance`] from a point and to a distance in local units.
    pub(super) fn mean_distance_local(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        let origin = point + normal * self.offset();
        let (t, b) = Directions::turned_frame(normal, turn);
        let sum = self
            .occluders()
            .depth_sum(origin, [t, b, normal], set.as_slice(), far);
        sum / set.len() as f32
    }

    /// How far a ray starts off the surface (local units): clear of the triangle it leaves,
    /// close enough to see a neighbour.
    pub(super) fn offset(&self) -> f32 {
        self.frame.local_diagonal() * 1e-5
    }

    /// The rays [`RayMesh::open_fraction`] (and, about the opposite normal,
    /// [`RayMesh::mean_distance`]) casts from `point` about unit `normal`, turned by `turn`,
    /// as a query: their origin (local units, off the surface) and the frame the set is turned
    /// into. `group` is the BVH it is for.
    pub fn query(&self, point: Vec3, normal: Vec3, turn: f32, group: u32) -> RayQuery {
        let (t, b) = Directions::turned_frame(normal, turn);
        RayQuery {
            origin: self.frame.local_from_object(point) + normal * self.offset(),
            t,
            b,
            n: normal,
            group,
        }
    }

    /// The BVH as a GPU reads it: per node 20 words (its origin's three floats' bits; the
    /// three exponents and the internal-child mask, a byte each; the first child node; the
    /// first triangle; the children's meta bytes, 8; their quantised boxes, min x, max x, min
    /// y, max y, min z, max z, 8 bytes each), and per triangle (in the order the leaves name
    /// them) its three corners, 9 floats, in the BVH's frame.
    pub fn gpu_layout(&self) -> (Vec<u32>, Vec<f32>) {
        let word = |b: [u8; 4]| u32::from_le_bytes(b);
        let pair = |b: [u8; 8]| {
            [
                word([b[0], b[1], b[2], b[3]]),
                word([b[4], b[5], b[6], b[7]]),
            ]
        };
        let nodes = self
            .bvh
            .nodes
            .iter()
            .flat_map(|n| {
                let mut w = vec![
                    n.p.x.to_bits(),
                    n.p.y.to_bits(),
                    n.p.z.to_bits(),
                    word([n.e[0], n.e[1], n.e[2], n.imask]),
                    n.child_base_idx,
                    n.primitive_base_idx,
                ];
                for bytes in [
                    n.child_meta,
                    n.child_min_x,
                    n.child_max_x,
                    n.child_min_y,
                    n.child_max_y,
                    n.child_min_z,
                    n.child_max_z,
                ] {
                    w.extend(pair(bytes));
                }
                w
            })
            .collect();
        let triangles = self
            .triangles
            .iter()
            .flat_map(|t| [t.v0, t.v1, t.v2].into_iter().flat_map(|v| v.to_array()))
            .collect();
        (nodes, triangles)
    }
}

/// A cosine-weighted Hammersley set of directions about `+z`, made once per bake; each texel
/// turns it about its own normal.
pub struct Directions(Vec<Vec3>);

impl Directions {
    /// `n` directions.
    pub fn new(n: u32) -> Self {
        Self(
            (0..n)
                .map(|k| {
                    let u = (k as f32 + 0.5) / n as f32;
                    let v = k.reverse_bits() as f32 / 4_294_967_296.0;
                    let r = u.sqrt();
                    let phi = std::f32::consts::TAU * v;
                    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt())
                })
                .collect(),
        )
    }

    /// How many.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The tangents `(t, b)` the set's `x` and `y` turn into about unit `normal`, turned by
    /// `turn`: a direction `d` of the set is `t d.x + b d.y + normal d.z`.
    pub(super) fn turned_frame(normal: Vec3, turn: f32) -> (Vec3, Vec3) {
        let (t, b) = normal.any_orthonormal_pair();
        let (sin, cos) = (std::f32::consts::TAU * turn).sin_cos();
        (t * cos + b * sin, b * cos - t * sin)
    }

    /// The directions about `+z`.
    pub fn as_slice(&self) -> &[Vec3] {
        &self.0
    }
}

/// One sample's AO or thickness rays: from `origin` (the BVH's frame, off the surface), each
/// direction `d` of the set as `t d.x + b d.y + n d.z`, against BVH `group`
/// ([`RayQuery::NONE`]: none, so nothing is met).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayQuery {
    /// Where the rays start (local units).
    pub origin: Vec3,
    /// The set's `x` turned.
    pub t: Vec3,
    /// The set's `y` turned.
    pub b: Vec3,
    /// The set's `z`: the normal the rays open about.
    pub n: Vec3,
    /// Which BVH.
    pub group: u32,
}

impl RayQuery {
    /// No BVH: every ray open.
    pub const NONE: u32 = u32::MAX;
}

/// What a batch of queries measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// The fraction of the directions that meet nothing before `far` (ambient occlusion).
    Open,
    /// The mean over the directions of `min(distance, far) / far` (thickness).
    Depth,
}

/// Queries to cast, with the direction set and how far the rays look (local units).
pub struct RayBatch<'a> {
    /// The queries.
    pub queries: &'a [RayQuery],
    /// The set about `+z`.
    pub directions: &'a [Vec3],
    /// How far a ray looks (local units; may be infinite).
    pub far: f32,
    /// What is measured.
    pub kind: RayKind,
}

/// What casts a bake's AO and thickness rays: every core ([`CpuCaster`], the reference), or
/// a GPU.
pub trait RayCaster: Sync {
    /// Per query, what `batch.kind` measures.
    ///
    /// # Errors
    /// What the device said.
    fn cast(&self, batch: &RayBatch<'_>) -> Result<Vec<f32>, String>;

    /// How many queries a batch should hold: few for the CPU (cancelled within moments),
    /// many for a GPU.
    fn batch_size(&self) -> usize;

    /// Where the rays ran, for reports ("the CPU", a GPU's name).
    fn name(&self) -> String;
}

/// Casts on every core against `groups` (a query's `group` names its BVH).
pub struct CpuCaster<'a>(pub &'a [Option<RayMesh>]);

impl RayCaster for CpuCaster<'_> {
    fn cast(&self, batch: &RayBatch<'_>) -> Result<Vec<f32>, String> {
        use rayon::prelude::*;
        let set = batch.directions;
        let count = set.len().max(1) as f32;
        Ok(batch
            .queries
            .par_iter()
            .with_min_len(16)
            .map(|q| {
                let Some(Some(mesh)) = self.0.get(q.group as usize) else {
                    return 1.0;
                };
                match batch.kind {
                    RayKind::Open => {
                        mesh.occluders()
                            .open_count(q.origin, [q.t, q.b, q.n], set, batch.far)
                            as f32
                            / count
                    }
                    RayKind::Depth => {
                        mesh.occluders()
                            .depth_sum(q.origin, [q.t, q.b, q.n], set, batch.far)
                            / count
                    }
                }
            })
            .collect())
    }

    fn batch_size(&self) -> usize {
        // About a second of rays on two cores at 64 a query: a cancel is seen within it.
        1 << 16
    }

    fn name(&self) -> String {
        "the CPU".into()
    }
}

/// A per-texel turn in `[0, 1)` from a hash of its index.
pub(super) fn turn_of(i: usize) -> f32 {
    let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    (h & 0x00FF_FFFF) as f32 / 16_777_216.0
}
