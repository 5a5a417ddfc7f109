//! Cutting big fans for the unwrapper: a point that is a corner of many triangles (a disc
//! capped by one fan, a polygon whose only inner diagonals meet at one corner) makes the
//! unwrapper's overlap test compare every pair of those triangles, in many cells of its grid:
//! 5,000 triangles around one point took 6.5 s, 20,000 more than 2 minutes. Seams cut such a
//! fan into wedges of at most [`MAX_FAN`] triangles, each charted on its own.

use std::collections::HashMap;

use glam::DVec3;

use crate::Mesh;
use crate::frame::UnitFrame;

/// The most triangles around one point that one chart keeps together.
pub const MAX_FAN: usize = 256;

/// Seam flags for the unwrapper (per triangle, the edge from corner `k` to `k + 1`) that cut
/// every fan of more than [`MAX_FAN`] triangles around one position into wedges of at most
/// that many, in order around the point; `None` when no point has so many.
pub(crate) fn fan_seams(mesh: &Mesh, frame: &UnitFrame) -> Option<Vec<[bool; 3]>> {
    // Points by position, as the unwrapper welds them (-0 and 0 alike).
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let weld: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let key = p.to_array().map(|c| (c + 0.0).to_bits());
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    let mut degree = vec![0_usize; ids.len()];
    for &v in mesh.triangles.iter().flatten() {
        degree[weld[v as usize] as usize] += 1;
    }
    if degree.iter().all(|&d| d <= MAX_FAN) {
        return None;
    }
    // Each hub's triangles, with the corner that is the hub.
    let mut around: HashMap<u32, Vec<(u32, usize)>> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for (corner, &v) in tri.iter().enumerate() {
            let w = weld[v as usize];
            if degree[w as usize] > MAX_FAN {
                around.entry(w).or_default().push((t as u32, corner));
            }
        }
    }
    let local = |v: u32| {
        frame
            .local_from_object(mesh.positions[v as usize])
            .as_dvec3()
    };
    let mut seams = vec![[false; 3]; mesh.triangles.len()];
    let mut hubs: Vec<_> = around.into_iter().collect();
    hubs.sort_unstable_by_key(|(w, _)| *w);
    for (_, fan) in hubs {
        let hub = local(mesh.triangles[fan[0].0 as usize][fan[0].1]);
        let corners = |t: u32| mesh.triangles[t as usize].map(local);
        // The fan's mean plane: its triangles' area-weighted normal.
        let normal = fan
            .iter()
            .map(|&(t, _)| {
                let [a, b, c] = corners(t);
                (b - a).cross(c - a)
            })
            .sum::<DVec3>()
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        // Triangles in order of the angle of their centroid about the hub.
        let mut order: Vec<(f64, u32, usize)> = fan
            .iter()
            .map(|&(t, corner)| {
                let d = corners(t).iter().sum::<DVec3>() / 3.0 - hub;
                (d.dot(v).atan2(d.dot(u)), t, corner)
            })
            .collect();
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // The spokes (edges from the hub) each triangle has, with its wedge: a spoke whose
        // triangles lie in two wedges is a seam.
        let mut spokes: HashMap<u32, Vec<(u32, usize, usize)>> = HashMap::new();
        for (rank, &(_, t, corner)) in order.iter().enumerate() {
            let tri = mesh.triangles[t as usize];
            let wedge = rank / MAX_FAN;
            // Edge `corner` runs to the next corner, edge `corner + 2` from the previous one.
            for (edge, other) in [
                (corner, (corner + 1) % 3),
                ((corner + 2) % 3, (corner + 2) % 3),
            ] {
                spokes
                    .entry(weld[tri[other] as usize])
                    .or_default()
                    .push((t, edge, wedge));
            }
        }
        for sides in spokes.values() {
            if sides.iter().any(|s| s.2 != sides[0].2) {
                for &(t, edge, _) in sides {
                    seams[t as usize][edge] = true;
                }
            }
        }
    }
    Some(seams)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A disc of `n` triangles around its centre.
    fn pizza(n: u32) -> Mesh {
        let positions: Vec<Vec3> = std::iter::once(Vec3::ZERO)
            .chain((0..n).map(|i| {
                let a = std::f32::consts::TAU * i as f32 / n as f32;
                Vec3::new(a.cos(), a.sin(), 0.0)
            }))
            .collect();
        Mesh {
            name: "pizza".into(),
            normals: vec![Vec3::Z; positions.len()],
            positions,
            uvs: None,
            triangles: (0..n).map(|i| [0, i + 1, (i + 1) % n + 1]).collect(),
            had_normals: true,
            labels: crate::Labels::default(),
        }
    }

    #[test]
    fn a_big_fan_is_cut_into_wedges_and_a_small_one_is_not() {
        let small = pizza(MAX_FAN as u32);
        assert!(fan_seams(&small, &UnitFrame::of(&small.positions)).is_none());
        let n = 10 * MAX_FAN as u32 + 7;
        let big = pizza(n);
        let seams = fan_seams(&big, &UnitFrame::of(&big.positions)).expect("cut");
        // 11 wedges: 11 spokes cut, each on both of its sides; no rim edge.
        let cut: usize = seams.iter().flatten().filter(|&&s| s).count();
        assert_eq!(cut, 22);
        assert!(seams.iter().all(|s| !s[1]), "rim edges stay");
    }
}
