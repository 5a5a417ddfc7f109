//! Rays through the BVH, compiled for the CPU's widest vectors: an AO query's rays (one
//! origin, a set of directions) one after another through one traversal, which ends at the
//! first triangle met; and the same walk for the nearest triangle (thickness, the surface
//! points of the bakes from a high mesh), which shortens the ray at each triangle met.
//!
//! The answer is obvhs's (`CwBvh::ray_traverse_miss`, `ray_traverse`) with its
//! Möller–Trumbore test, ray for ray: the same box arithmetic (the ray moved into each node's
//! quantised grid, slabs clipped to `[1e-4, far]`) and the same triangle arithmetic (its edges
//! and normal made once instead of per test), so the bits agree (the tests compare every ray's
//! answer and every nearest distance). Where triangles are met at the same distance (a shared
//! edge), the nearest is the first in the mesh, not the first the walk meets. What differs is
//! how it runs:
//! the eight children of a node are tested as one eight-lane loop, the whole walk is inlined
//! into a kernel that [`kapaint_base::simd::vectorized`] compiles for AVX2 where the CPU has
//! it, and a triangle's sums are read, not made. The order the children are visited in
//! changes only the speed: nearest first by the ray's octant, as the wide BVH's slots are laid
//! out for.

use glam::{Vec3, Vec3A};
use kapaint_base::simd;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;

/// The nearest a box may be entered along a ray (local units), as obvhs's traversal clips.
const BOX_NEAR: f32 = 1e-4;

/// A triangle as the occlusion test reads it: a corner and the two edges the Möller–Trumbore
/// test makes from it (`v0 - v1`, `v2 - v0`), packed (36 bytes: the walk waits on memory more
/// than on arithmetic, so the normal is made per test).
#[derive(Clone, Copy, Debug)]
pub(super) struct Facet {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Facet {
    pub(super) fn new(t: &Triangle) -> Self {
        let e1 = t.v0 - t.v1;
        let e2 = t.v2 - t.v0;
        Self {
            v0: t.v0.into(),
            e1: e1.into(),
            e2: e2.into(),
        }
    }

    /// The distance at which `ray` meets the triangle, where it lies in `[tmin, tmax)`.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub(super) fn distance(&self, ray: &Ray) -> Option<f32> {
        let (e1, e2) = (Vec3A::from(self.e1), Vec3A::from(self.e2));
        let n = e1.cross(e2);
        let c = Vec3A::from(self.v0) - ray.origin;
        let r = ray.direction.cross(c);
        let inv_det = 1.0 / n.dot(ray.direction);
        let u = r.dot(e2) * inv_det;
        let v = r.dot(e1) * inv_det;
        let w = 1.0 - u - v;
        // Any barycentric's sign bit set (a -0 too) is outside.
        let signs = u.to_bits() | v.to_bits() | w.to_bits();
        if inv_det == 0.0 || signs & 0x8000_0000 != 0 {
            return None;
        }
        let t = n.dot(c) * inv_det;
        (t >= ray.tmin && t < ray.tmax).then_some(t)
    }
}

/// A ray from `origin` along unit `dir` to `far` (local units), its inverse direction made as
/// obvhs's `Ray::new` makes it (a component within `f32::EPSILON` of zero inverted as that
/// epsilon). A direction's negative zero is made positive: the BVH's traversal takes a
/// component's sign from its bits and misses every triangle for a ray with a `-0.0` component
/// (a ray straight down, `-Y`, met nothing).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
pub(super) fn ray(origin: Vec3, dir: Vec3, far: f32) -> Ray {
    let direction = Vec3A::from(dir + Vec3::ZERO);
    let inverse = |x: f32| {
        if x.abs() <= f32::EPSILON {
            x.signum() / f32::EPSILON
        } else {
            1.0 / x
        }
    };
    Ray {
        origin: origin.into(),
        direction,
        inv_direction: Vec3A::new(
            inverse(direction.x),
            inverse(direction.y),
            inverse(direction.z),
        ),
        tmin: 0.0,
        tmax: far,
    }
}

/// The larger of `a` and `b`, `b` where either is NaN (as the slab test's vector max).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The smaller of `a` and `b`, `b` where either is NaN.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Which of `node`'s eight child boxes `ray` crosses within `[1e-4, tmax]`, a bit a slot
/// (empty slots included: the caller masks them).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn child_hits(node: &CwBvhNode, ray: &Ray) -> u32 {
    // The ray in the node's grid: a quantised plane `q` is crossed at `q * scale + shift`.
    let scale = node.compute_extent() * ray.inv_direction;
    let shift = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // Per axis, the plane entered first and the one left.
    let axis = |negative: bool, min: &[u8; 8], max: &[u8; 8]| {
        if negative { (*max, *min) } else { (*min, *max) }
    };
    let (in_x, out_x) = axis(ray.direction.x < 0.0, &node.child_min_x, &node.child_max_x);
    let (in_y, out_y) = axis(ray.direction.y < 0.0, &node.child_min_y, &node.child_max_y);
    let (in_z, out_z) = axis(ray.direction.z < 0.0, &node.child_min_z, &node.child_max_z);
    // A byte a slot (one in a child crossed), gathered into bits after the loop: the loop stays
    // eight lanes wide, with no reduction across them.
    let mut crossed = [0u8; 8];
    for (i, crossed) in crossed.iter_mut().enumerate() {
        let enter_x = f32::from(in_x[i]) * scale.x + shift.x;
        let enter_y = f32::from(in_y[i]) * scale.y + shift.y;
        let enter_z = f32::from(in_z[i]) * scale.z + shift.z;
        let leave_x = f32::from(out_x[i]) * scale.x + shift.x;
        let leave_y = f32::from(out_y[i]) * scale.y + shift.y;
        let leave_z = f32::from(out_z[i]) * scale.z + shift.z;
        let enter = max(max(enter_x, max(enter_y, enter_z)), BOX_NEAR);
        let leave = min(min(leave_x, min(leave_y, leave_z)), ray.tmax);
        *crossed = u8::from(enter <= leave);
    }
    // Byte `i`'s low bit lands on bit `56 + i` of the product and nothing else reaches those
    // bits (the other products sum to less than `2^56`).
    (u64::from_le_bytes(crossed).wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32
}

/// `mask`'s bits moved from slot `s` to slot `s ^ flip` (`flip` below 8).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn permuted(mut mask: u32, flip: u32) -> u32 {
    if flip & 1 != 0 {
        mask = ((mask & 0x55) << 1) | ((mask >> 1) & 0x55);
    }
    if flip & 2 != 0 {
        mask = ((mask & 0x33) << 2) | ((mask >> 2) & 0x33);
    }
    if flip & 4 != 0 {
        mask = ((mask & 0x0f) << 4) | ((mask >> 4) & 0x0f);
    }
    mask
}

/// The slots of a node whose meta bytes are `meta` and internal-child mask `inner` that hold
/// triangles: a leaf's byte counts them in its top three bits (an empty slot's byte is 0).
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
)]
fn leaf_slots(meta: u64, inner: u32) -> u32 {
    // A byte's top three bits folded onto its lowest, then gathered as `child_hits` gathers.
    let counts = (meta >> 5) & 0x0707_0707_0707_0707;
    let any = (counts | counts >> 1 | counts >> 2) & 0x0101_0101_0101_0101;
    (any.wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32 & !inner
}

/// The BVH's nodes and its triangles (in the order the leaves name them) as the walk reads
/// them.
#[derive(Clone, Copy)]
pub(super) struct Occluders<'a> {
    pub nodes: &'a [CwBvhNode],
    pub facets: &'a [Facet],
    /// Per facet, the mesh's index of its triangle (the pieces the build split a triangle
    /// into share it).
    pub sources: &'a [u32],
}

impl Occluders<'_> {
    /// Whether `ray` meets a triangle; `stack` is scratch.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub(super) fn occluded(&self, ray: &Ray, stack: &mut Vec<u32>) -> bool {
        self.walk::<true>(*ray, stack).is_some()
    }

    /// The nearest triangle `ray` meets: the distance to it and its index in the mesh;
    /// `stack` is scratch.
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    pub(super) fn nearest(&self, ray: &Ray, stack: &mut Vec<u32>) -> Option<(f32, u32)> {
        self.walk::<false>(*ray, stack)
    }

    /// The walk: with `ANY`, the first triangle met ends it; without, each one met shortens
    /// the ray to just past it (boxes beyond are not entered) and the nearest is the answer
    /// (with its index in the mesh), among as near ones the first in the mesh: the
    /// geometry's answer, not the order the walk happened to meet them in (but for a box
    /// whose entry, worked out in floats, rounds past a tie).
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn walk<const ANY: bool>(&self, mut ray: Ray, stack: &mut Vec<u32>) -> Option<(f32, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        // A slot's order for this ray: the higher `slot ^ flip`, the nearer (the slots are
        // laid out by the direction their child lies in from the node's centre).
        let flip = u32::from(ray.direction.x >= 0.0) << 2
            | u32::from(ray.direction.y >= 0.0) << 1
            | u32::from(ray.direction.z >= 0.0);
        stack.clear();
        let mut met = None;
        // The node walked next: the nearest child crossed, else the top of the stack.
        let mut next = Some(0);
        while let Some(index) = next.take().or_else(|| stack.pop()) {
            let Some(node) = self.nodes.get(index as usize) else {
                continue;
            };
            let meta = u64::from_le_bytes(node.child_meta);
            let inner = u32::from(node.imask);
            let hits = child_hits(node, &ray);
            let mut leaves = hits & leaf_slots(meta, inner);
            while leaves != 0 {
                let slot = leaves.trailing_zeros();
                leaves &= leaves - 1;
                let byte = (meta >> (8 * slot)) as u32 & 0xff;
                let first = node.primitive_base_idx + (byte & 0x1f);
                let count = (byte >> 5).count_ones();
                for k in first..first + count {
                    let Some(t) = self.facets.get(k as usize).and_then(|f| f.distance(&ray)) else {
                        continue;
                    };
                    let source = self.sources.get(k as usize).copied().unwrap_or(u32::MAX);
                    if ANY {
                        return Some((t, source));
                    }
                    // The nearest so far; at the same distance (an edge or a corner
                    // triangles share, a doubled face), the one first in the mesh, whichever
                    // the walk meets first (the pieces of one triangle are one).
                    if met.is_none_or(|(near, s)| t < near || (t == near && source < s)) {
                        met = Some((t, source));
                    }
                    // The ray ends just past it: after it, only as near triangles are met.
                    ray.tmax = t.next_up();
                }
            }
            // The nearest child crossed is walked next, the others pushed far first.
            let mut order = permuted(hits & inner, flip);
            if order == 0 {
                continue;
            }
            let nearest = order.ilog2();
            order &= !(1 << nearest);
            let child = |rank: u32| {
                let slot = rank ^ flip;
                node.child_base_idx + (inner & ((1 << slot) - 1)).count_ones()
            };
            while order != 0 {
                let rank = order.trailing_zeros();
                order &= order - 1;
                stack.push(child(rank));
            }
            next = Some(child(nearest));
        }
        met
    }

    /// How many of the directions `t d.x + b d.y + n d.z` (`d` each of `set`, `[t, b, n]` the
    /// `frame`) from `origin` meet nothing before `far` (local units), the walk compiled for
    /// the CPU's widest vectors.
    pub(super) fn open_count(
        &self,
        origin: Vec3,
        frame: [Vec3; 3],
        set: &[Vec3],
        far: f32,
    ) -> usize {
        simd::vectorized(OpenCount(self.query(origin, frame, set, far)))
    }

    /// The sum over the directions `t d.x + b d.y + n d.z` (`d` each of `set`, `[t, b, n]`
    /// the `frame`) from `origin` of the distance to the nearest triangle over `far` (1 where
    /// none is met before `far`; local units), the walk compiled for the CPU's widest vectors.
    pub(super) fn depth_sum(&self, origin: Vec3, frame: [Vec3; 3], set: &[Vec3], far: f32) -> f32 {
        simd::vectorized(DepthSum(self.query(origin, frame, set, far)))
    }

    /// The rays of `set` turned into `frame` from `origin` to `far`, against this BVH.
    fn query<'a>(&self, origin: Vec3, frame: [Vec3; 3], set: &'a [Vec3], far: f32) -> SetQuery<'a>
    where
        Self: 'a,
    {
        SetQuery {
            occluders: *self,
            origin,
            frame,
            set,
            far,
        }
    }

    /// [`Occluders::nearest`] compiled for the CPU's widest vectors, for one ray.
    pub(super) fn nearest_one(&self, ray: &Ray) -> Option<(f32, u32)> {
        simd::vectorized(NearestOne {
            occluders: *self,
            ray,
        })
    }
}

/// A set of directions turned into a frame, cast from one origin against one BVH: an AO or a
/// thickness query.
#[derive(Clone, Copy)]
struct SetQuery<'a> {
    occluders: Occluders<'a>,
    origin: Vec3,
    frame: [Vec3; 3],
    set: &'a [Vec3],
    far: f32,
}

impl SetQuery<'_> {
    /// The query's rays, direction by direction (`t d.x + b d.y + n d.z`).
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn rays(self) -> impl Iterator<Item = Ray> {
        let [t, b, n] = self.frame;
        self.set
            .iter()
            .map(move |d| ray(self.origin, t * d.x + b * d.y + n * d.z, self.far))
    }
}

/// [`Occluders::open_count`] as a kernel.
struct OpenCount<'a>(SetQuery<'a>);

impl simd::Kernel for OpenCount<'_> {
    type Output = usize;

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn with_simd<S: simd::Simd>(self, _: S) -> usize {
        let q = self.0;
        let mut stack = Vec::with_capacity(64);
        q.rays()
            .filter(|r| !q.occluders.occluded(r, &mut stack))
            .count()
    }
}

/// [`Occluders::depth_sum`] as a kernel.
struct DepthSum<'a>(SetQuery<'a>);

impl simd::Kernel for DepthSum<'_> {
    type Output = f32;

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn with_simd<S: simd::Simd>(self, _: S) -> f32 {
        let q = self.0;
        let mut stack = Vec::with_capacity(64);
        q.rays()
            .map(|r| {
                q.occluders
                    .nearest(&r, &mut stack)
                    .map_or(1.0, |(t, _)| t / q.far)
            })
            .sum()
    }
}

/// [`Occluders::nearest_one`] as a kernel.
struct NearestOne<'a> {
    occluders: Occluders<'a>,
    ray: &'a Ray,
}

impl simd::Kernel for NearestOne<'_> {
    type Output = Option<(f32, u32)>;

    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn with_simd<S: simd::Simd>(self, _: S) -> Option<(f32, u32)> {
        self.occluders
            .nearest(self.ray, &mut Vec::with_capacity(64))
    }
}
