//! Triangulating a polygon face: OBJ files may hold faces of any number of corners.
//!
//! Triangles and quads are split as `tobj` splits them (a quad along its first diagonal), so
//! the meshes that have always loaded load the same. A larger polygon is projected onto its
//! plane (Newell's normal) and triangulated by the `spade` crate's constrained Delaunay
//! triangulation of its corners with its edges as constraints (bulk-loaded, O(n log n)); the
//! triangles inside it by the even-odd rule are kept, so a concave polygon, or one whose
//! outline returns along a bridge to cut a hole, is covered exactly once, and none is a needle
//! from one corner across the whole face (a fan of 100,000 corners is 100,000 needles
//! through one vertex, which the unwrapper's overlap test meets all at once). A polygon that
//! crosses itself, or that has no plane, keeps the fan.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation as _};

/// Triangles of the polygon whose corners are `corners` (in order), as indices into
/// `corners`, wound as the polygon is.
pub(crate) fn triangulate(corners: &[Vec3]) -> Vec<[u32; 3]> {
    match corners.len() {
        0..3 => Vec::new(),
        3 => vec![[0, 1, 2]],
        4 => vec![[0, 1, 2], [0, 2, 3]],
        n => constrained(corners).unwrap_or_else(|| fan(n)),
    }
}

/// The fan from the first corner.
fn fan(n: usize) -> Vec<[u32; 3]> {
    (1..n as u32 - 1).map(|i| [0, i, i + 1]).collect()
}

/// The even-odd inside of the constrained Delaunay triangulation of the polygon's projection
/// onto its plane; `None` when the polygon has no plane or crosses itself.
fn constrained(corners: &[Vec3]) -> Option<Vec<[u32; 3]>> {
    let points: Vec<DVec3> = corners.iter().map(|p| p.as_dvec3()).collect();
    if !points.iter().all(|p| p.is_finite()) {
        return None;
    }
    // Newell's normal about the centroid (exact in direction for a planar polygon, the best
    // plane's normal for a bent one).
    let centroid = points.iter().sum::<DVec3>() / points.len() as f64;
    let normal = points
        .iter()
        .zip(points.iter().cycle().skip(1))
        .map(|(&a, &b)| (a - centroid).cross(b - centroid))
        .sum::<DVec3>()
        .try_normalize()?;
    // Right-handed about the normal, so counter-clockwise in the plane is the polygon's
    // winding.
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let planar: Vec<[f64; 2]> = points
        .iter()
        .map(|&p| [(p - centroid).dot(u), (p - centroid).dot(v)])
        .collect();
    // Into [-1, 1], with values spade would refuse as too small (below 2^-142) set to zero.
    let extent = planar
        .iter()
        .flatten()
        .fold(0.0_f64, |m, &x| m.max(x.abs()));
    if !(extent.is_finite() && extent > 0.0) {
        return None;
    }
    let flush = |x: f64| {
        let x = x / extent;
        if x.abs() < 1e-30 { 0.0 } else { x }
    };
    // One point a position (spade keeps one of each), with each corner's point.
    let mut ids: HashMap<[u64; 2], usize> = HashMap::with_capacity(corners.len());
    let mut unique: Vec<Point2<f64>> = Vec::with_capacity(corners.len());
    let mut first_corner = Vec::with_capacity(corners.len());
    let point_of: Vec<usize> = planar
        .iter()
        .enumerate()
        .map(|(corner, &[x, y])| {
            let (x, y) = (flush(x), flush(y));
            let key = [(x + 0.0).to_bits(), (y + 0.0).to_bits()];
            *ids.entry(key).or_insert_with(|| {
                unique.push(Point2::new(x, y));
                first_corner.push(corner as u32);
                unique.len() - 1
            })
        })
        .collect();
    if unique.len() < 3 {
        return None;
    }
    // The outline's edges, each as often as it is walked: an edge walked twice (a bridge
    // there and back) bounds nothing.
    let mut walked: HashMap<[usize; 2], u32> = HashMap::new();
    for (k, &a) in point_of.iter().enumerate() {
        let b = point_of[(k + 1) % point_of.len()];
        if a != b {
            *walked.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let mut edges: Vec<[usize; 2]> = walked
        .into_iter()
        .filter(|&(_, times)| times % 2 == 1)
        .map(|(edge, _)| edge)
        .collect();
    edges.sort_unstable();
    let mut crossed = false;
    let cdt =
        ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(unique, edges, |_| {
            crossed = true;
        })
        .ok()?;
    if crossed {
        return None;
    }
    let inside = even_odd_inside(&cdt);
    let triangles: Vec<[u32; 3]> = cdt
        .inner_faces()
        .filter(|f| inside[f.fix().index()])
        .map(|f| f.vertices().map(|v| first_corner[v.fix().index()]))
        .collect();
    (!triangles.is_empty()).then_some(triangles)
}

/// Per face index of the triangulation: whether the face is inside the constraints by the
/// even-odd rule (reached from outside across an odd number of them).
fn even_odd_inside(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<bool> {
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut seen = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for hull in cdt.convex_hull() {
        for edge in [hull, hull.rev()] {
            if let Some(face) = edge.face().as_inner() {
                let i = face.fix().index();
                if !seen[i] {
                    seen[i] = true;
                    inside[i] = edge.is_constraint_edge();
                    stack.push(face);
                }
            }
        }
    }
    while let Some(face) = stack.pop() {
        let here = inside[face.fix().index()];
        for edge in face.adjacent_edges() {
            if let Some(next) = edge.rev().face().as_inner() {
                let i = next.fix().index();
                if !seen[i] {
                    seen[i] = true;
                    inside[i] = here ^ edge.is_constraint_edge();
                    stack.push(next);
                }
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twice the signed area of the triangles in the plane z = 0.
    fn area2(corners: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| corners[i as usize].as_dvec3());
                (b - a).cross(c - a).z
            })
            .sum()
    }

    /// Twice the signed area of the polygon (shoelace).
    fn polygon_area2(corners: &[Vec3]) -> f64 {
        corners
            .iter()
            .zip(corners.iter().cycle().skip(1))
            .map(|(a, b)| f64::from(a.x) * f64::from(b.y) - f64::from(b.x) * f64::from(a.y))
            .sum()
    }

    /// A star of `n` corners, alternately at radius 1 and `inner`.
    fn star(n: usize, inner: f32) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let a = std::f32::consts::TAU * i as f32 / n as f32;
                let r = if i % 2 == 0 { 1.0 } else { inner };
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect()
    }

    #[test]
    fn a_concave_polygon_is_covered_once_with_its_winding() {
        for corners in [star(10, 0.4), star(1000, 0.9), star(20_000, 0.5)] {
            let triangles = triangulate(&corners);
            assert_eq!(triangles.len(), corners.len() - 2);
            // Every triangle winds as the polygon does, and together they are its area: none
            // overlaps, none is outside.
            assert!(triangles.iter().all(|t| area2(&corners, &[*t]) > 0.0));
            let (got, want) = (area2(&corners, &triangles), polygon_area2(&corners));
            assert!((got / want - 1.0).abs() < 1e-9, "{got} against {want}");
            // Clockwise, the same with the triangles turned.
            let reversed: Vec<Vec3> = corners.iter().rev().copied().collect();
            let back = triangulate(&reversed);
            assert!(back.iter().all(|t| area2(&reversed, &[*t]) < 0.0));
        }
    }

    #[test]
    fn a_tilted_polygon_keeps_its_corners_and_small_faces_split_as_before() {
        let turn = glam::Quat::from_rotation_x(1.0) * glam::Quat::from_rotation_y(0.5);
        let corners: Vec<Vec3> = star(12, 0.5)
            .into_iter()
            .map(|p| turn * p + Vec3::splat(100.0))
            .collect();
        let triangles = triangulate(&corners);
        assert_eq!(triangles.len(), 10);
        let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
        used.sort_unstable();
        used.dedup();
        assert_eq!(used, (0..12).collect::<Vec<_>>());
        let quad = [Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::Y];
        assert_eq!(triangulate(&quad), vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(triangulate(&quad[..3]), vec![[0, 1, 2]]);
        assert!(triangulate(&quad[..2]).is_empty());
    }

    #[test]
    fn a_hole_cut_by_a_bridge_is_left_out_and_a_crossing_outline_keeps_the_fan() {
        // A square with a square hole, the outline walking in along a bridge and back.
        let outer = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)];
        let hole = [(1.0, 1.0), (1.0, 3.0), (3.0, 3.0), (3.0, 1.0)];
        let corners: Vec<Vec3> = outer
            .iter()
            .chain(&outer[..1])
            .chain(&hole)
            .chain(&hole[..1])
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        let triangles = triangulate(&corners);
        assert!((area2(&corners, &triangles) - 2.0 * 12.0).abs() < 1e-9);
        assert!(triangles.iter().all(|t| area2(&corners, &[*t]) > 0.0));
        // A bow tie crosses itself: the fan, as before.
        let bow = [
            Vec3::ZERO,
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        assert_eq!(triangulate(&bow), fan(5));
        // All on a line: no plane.
        let line: Vec<Vec3> = (0..6).map(|i| Vec3::X * i as f32).collect();
        assert_eq!(triangulate(&line), fan(6));
    }
}
