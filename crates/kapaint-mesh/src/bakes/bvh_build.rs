//! Building the rays' BVH with a bounded peak: obvhs's slow preset (spatial pre-splits, PLOC,
//! reinsertion, eight children a node), composed from its public steps so that each input is
//! freed once used, and PLOC run part by part on a large mesh.
//!
//! PLOC holds two node arrays and a Morton buffer beside the tree it writes (about 200 bytes a
//! primitive over the boxes). A mesh of more than [`PART`] primitives is first cut in halves
//! (at the median centroid along the longest axis of the centroids, twice or three times);
//! each part is built by PLOC and its nodes moved into the whole tree (written in order, never
//! all held twice), under a top made of the cuts. The reinsertion pass then reshapes the tree
//! as a whole, the top included.

use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::cwbvh::CwBvh;
use obvhs::ploc::PlocBuilder;
use obvhs::triangle::Triangle;

/// Most primitives PLOC builds at once: a mesh with more is cut into parts of about this many
/// (at most [`MAX_CUTS`] levels of halves).
const PART: usize = 256 * 1024;

/// Most levels of halves a mesh is cut into (eight parts).
const MAX_CUTS: u32 = 3;

/// The BVH of `triangles` (see the module's notes). The Morton codes are 64-bit (21 bits an
/// axis is ample for the millions of triangles a sculpt has, and the sort's memory halves).
pub(super) fn build_bvh(triangles: Vec<Triangle>) -> CwBvh {
    let params = obvhs::BvhBuildParams {
        sort_precision: obvhs::ploc::SortPrecision::U64,
        ..obvhs::BvhBuildParams::slow_build()
    };
    if triangles.is_empty() {
        return CwBvh::default();
    }
    let (mut largest, mut total) = (0.0_f32, 0.0_f32);
    let mut aabbs: Vec<Aabb> = triangles
        .iter()
        .map(|t| {
            let b = t.aabb();
            largest = largest.max(b.half_area());
            total += b.half_area();
            b
        })
        .collect();
    let mut indices: Vec<u32> = (0..triangles.len() as u32).collect();
    let average = total / triangles.len() as f32;
    obvhs::splits::split_aabbs_preset(&mut aabbs, &mut indices, &triangles, average, largest);
    drop(triangles);
    let cuts = cuts(aabbs.len());
    let mut bvh2 = build_in_parts(&params, aabbs, indices, cuts);
    bvh2.uses_spatial_splits = true;
    obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
        &mut bvh2,
        params.reinsertion_batch_ratio,
        None,
    );
    obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
        &bvh2,
        params.max_prims_per_leaf.clamp(1, 3),
        true,
        false,
    )
}

/// Levels of halves `count` primitives are cut into.
fn cuts(count: usize) -> u32 {
    let mut cuts = 0;
    while cuts < MAX_CUTS && count > PART << cuts {
        cuts += 1;
    }
    cuts
}

/// The binary tree of `aabbs` (whose `indices` name the primitives), built by PLOC, in
/// `2^cuts` parts (see the module's notes). The boxes are freed on return.
fn build_in_parts(
    params: &obvhs::BvhBuildParams,
    aabbs: Vec<Aabb>,
    indices: Vec<u32>,
    cuts: u32,
) -> Bvh2 {
    let count = aabbs.len();
    let mut ploc = PlocBuilder::new();
    if cuts == 0 {
        return ploc.build(
            params.ploc_search_distance,
            &aabbs,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        );
    }
    let (aabbs, in_order) = cut(aabbs, &indices, cuts);
    // PLOC's leaves name their primitive by its index (below the triangles' count: the
    // pre-splits add their pieces after the triangles, naming them), which the tree reads
    // through its primitive indices: the whole's are the input's, as one PLOC build keeps them.
    let mut whole = Bvh2 {
        nodes: Vec::with_capacity(2 * count - 1),
        primitive_indices: indices,
        ..Bvh2::default()
    };
    let mut parts = Parts {
        ploc,
        part: Bvh2::default(),
        params,
        aabbs: &aabbs,
        indices: &in_order,
        whole: &mut whole,
        depth: 0,
    };
    parts.whole.nodes.push(Bvh2Node::default());
    parts.place(0, 0..count, cuts);
    let depth = parts.depth;
    whole.max_depth = whole.max_depth.max(depth);
    whole.children_are_ordered_after_parents = true;
    whole
}

/// `aabbs` and `indices` (copied) reordered so that `2^cuts` parts of (nearly) equal size lie one after
/// another, each half of the range before it cut at the median centroid along the longest
/// axis of its centroids.
fn cut(aabbs: Vec<Aabb>, indices: &[u32], cuts: u32) -> (Vec<Aabb>, Vec<u32>) {
    fn halve(order: &mut [u32], aabbs: &[Aabb], cuts: u32) {
        if cuts == 0 || order.len() < 2 {
            return;
        }
        let mut bounds = Aabb::empty();
        for &i in order.iter() {
            bounds.extend(aabbs[i as usize].center());
        }
        let axis = bounds.largest_axis();
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |&a, &b| {
            let (a, b) = (aabbs[a as usize], aabbs[b as usize]);
            a.center_axis(axis).total_cmp(&b.center_axis(axis))
        });
        let (low, high) = order.split_at_mut(mid);
        halve(low, aabbs, cuts - 1);
        halve(high, aabbs, cuts - 1);
    }
    let mut order: Vec<u32> = (0..aabbs.len() as u32).collect();
    halve(&mut order, &aabbs, cuts);
    let sorted: Vec<Aabb> = order.iter().map(|&i| aabbs[i as usize]).collect();
    drop(aabbs);
    let indices = order.iter().map(|&i| indices[i as usize]).collect();
    (sorted, indices)
}

/// The parts' build, writing into the whole tree.
struct Parts<'a> {
    ploc: PlocBuilder,
    /// The part being built (its allocations kept for the next).
    part: Bvh2,
    params: &'a obvhs::BvhBuildParams,
    aabbs: &'a [Aabb],
    indices: &'a [u32],
    whole: &'a mut Bvh2,
    /// The deepest part's depth plus the most cuts above it.
    depth: usize,
}

impl Parts<'_> {
    /// Builds the primitives `range` into node `slot` of the whole tree, `cuts` more levels of
    /// halves above its parts; returns the node's box.
    fn place(&mut self, slot: usize, range: std::ops::Range<usize>, cuts: u32) -> Aabb {
        if cuts == 0 || range.len() < 2 {
            return self.part(slot, range);
        }
        let first = self.whole.nodes.len();
        self.whole
            .nodes
            .extend([Bvh2Node::default(), Bvh2Node::default()]);
        let mid = range.start + range.len() / 2;
        let low = self.place(first, range.start..mid, cuts - 1);
        let high = self.place(first + 1, mid..range.end, cuts - 1);
        let aabb = low.union(&high);
        self.whole.nodes[slot] = Bvh2Node::new(aabb, 0, first as u32);
        aabb
    }

    /// PLOC over the primitives `range`, its root put in `slot` and its other nodes after
    /// the whole tree's (children still after parents); its leaves name their primitives as
    /// they did.
    fn part(&mut self, slot: usize, range: std::ops::Range<usize>) -> Aabb {
        let p = self.params;
        self.ploc.build_with_bvh(
            &mut self.part,
            p.ploc_search_distance,
            &self.aabbs[range.clone()],
            self.indices[range].to_vec(),
            p.sort_precision,
            p.search_depth_threshold,
        );
        let part = &self.part;
        // At most MAX_CUTS levels above it (a stack size: more is safe).
        self.depth = self.depth.max(part.max_depth + MAX_CUTS as usize);
        let whole = &mut *self.whole;
        // A part's node k > 0 lands at `base + k - 1`.
        let base = whole.nodes.len() as u32;
        whole.nodes[slot] = moved(part.nodes[0], base);
        whole
            .nodes
            .extend(part.nodes[1..].iter().map(|&node| moved(node, base)));
        *part.nodes[0].aabb()
    }
}

/// A part's `node`, its children's indices moved to where the part's nodes land (node k > 0
/// at `base + k - 1`).
fn moved(mut node: Bvh2Node, base: u32) -> Bvh2Node {
    if node.prim_count == 0 {
        node.first_index = base + node.first_index - 1;
    }
    node
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use obvhs::ray::Ray;

    /// A bumpy grid of `n x n` quads (two triangles each) in the unit square.
    fn grid(n: usize) -> Vec<Triangle> {
        let at = |i: usize, j: usize| {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            Vec3A::new(x, y, 0.05 * (x * 40.0).sin() * (y * 33.0).cos())
        };
        let mut out = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                out.push(Triangle {
                    v0: a,
                    v1: b,
                    v2: d,
                });
                out.push(Triangle {
                    v0: a,
                    v1: d,
                    v2: c,
                });
            }
        }
        out
    }

    #[test]
    fn a_tree_built_in_parts_holds_every_primitive_once_under_boxes_that_contain_it() {
        let triangles = grid(40);
        let aabbs: Vec<Aabb> = triangles.iter().map(Triangle::aabb).collect();
        let count = aabbs.len();
        let params = obvhs::BvhBuildParams::slow_build();
        let whole = build_in_parts(&params, aabbs, (0..count as u32).collect(), 3);
        assert!(whole.children_are_ordered_after_parents);
        assert_eq!(
            whole.nodes.len(),
            2 * count - 1,
            "a binary tree's node count"
        );
        // Every primitive reached once, inside every box above it.
        let mut seen = vec![0u32; count];
        let mut stack = vec![(0usize, Vec::<Aabb>::new())];
        while let Some((k, above)) = stack.pop() {
            let node = whole.nodes[k];
            let mut path = above.clone();
            path.push(*node.aabb());
            if node.prim_count == 0 {
                let first = node.first_index as usize;
                assert!(first > k, "children after their parent");
                stack.push((first, path.clone()));
                stack.push((first + 1, path));
            } else {
                for p in 0..node.prim_count {
                    let t = whole.primitive_indices[(node.first_index + p) as usize];
                    seen[t as usize] += 1;
                    let b = triangles[t as usize].aabb();
                    for a in &path {
                        assert!(a.contains_point(b.min) && a.contains_point(b.max));
                    }
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "each primitive once");
    }

    #[test]
    fn rays_meet_the_same_triangles_through_a_tree_built_in_parts_as_through_one_built_whole() {
        // Big enough to be cut (more than PART primitives).
        let triangles = grid(380);
        assert!(triangles.len() > PART, "{}", triangles.len());
        let parted = build_bvh(triangles.clone());
        let mut spent = std::time::Duration::ZERO;
        let whole = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &triangles,
            obvhs::BvhBuildParams::slow_build(),
            &mut spent,
        );
        for k in 0..2_000u32 {
            let (x, y) = (
                (k % 47) as f32 / 47.0 + 0.01,
                (k / 47) as f32 / 43.0 + 0.005,
            );
            let ray = Ray::new_inf(Vec3A::new(x, y, 1.0), Vec3A::new(0.0, 0.0, -1.0));
            let hit = |bvh: &CwBvh| {
                let mut hit = obvhs::ray::RayHit::none();
                bvh.ray_traverse(ray, &mut hit, |ray, id| {
                    triangles[bvh.primitive_indices[id] as usize].intersect(ray)
                })
                .then_some(hit.t)
            };
            assert_eq!(hit(&parted), hit(&whole), "ray {k}");
        }
    }
}
