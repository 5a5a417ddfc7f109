//! The occlusion and nearest-triangle walk checked against obvhs's own traversal.

use glam::Vec3;

use crate::Mesh;
use crate::bakes::{Directions, RayMesh};

/// A number in `[0, 1)` from a hash of `i`.
fn unit(i: u32) -> f32 {
    super::rays::turn_of(i as usize)
}

/// A point in `[-1, 1]^3` from three hashes.
fn point(i: u32) -> Vec3 {
    Vec3::new(unit(3 * i), unit(3 * i + 1), unit(3 * i + 2)) * 2.0 - 1.0
}

/// `count` small triangles scattered through a cube, some on its axes' planes (rays along
/// and across them, edges at zero), with tilts of every kind.
fn soup(count: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for k in 0..count {
        let c = point(k);
        let c = if k % 7 == 0 { c.with_y(0.0) } else { c };
        let size = 0.05 + 0.3 * unit(10_000 + k);
        let first = positions.len() as u32;
        positions.push(c);
        positions.push(c + point(20_000 + k) * size);
        positions.push(c + point(40_000 + k) * size);
        triangles.push([first, first + 1, first + 2]);
    }
    Mesh {
        name: "soup".into(),
        normals: vec![Vec3::Z; positions.len()],
        positions,
        uvs: None,
        triangles,
        had_normals: false,
        labels: crate::Labels::default(),
    }
}

#[test]
fn every_ray_is_met_or_missed_as_obvhs_traversal_says() {
    let mesh = RayMesh::new(&soup(12_000));
    let (mut met, mut rays) = (0, 0);
    for i in 0..20_000u32 {
        let (origin, dir, far) = soup_ray(i);
        let ours = mesh.occluded_local(origin, dir, far);
        assert_eq!(
            ours,
            mesh.obvhs_occluded(origin, dir, far),
            "ray {i} from {origin} along {dir} to {far}"
        );
        met += usize::from(ours);
        rays += 1;
    }
    // Both answers are common, so the comparison can fail either way.
    assert!(
        met > rays / 10 && met < rays * 9 / 10,
        "{met} of {rays} met"
    );
}

/// A ray of the soup's tests: from inside or around the cube, some along the axes
/// (negative zeros among them), reaching short, far or without end.
fn soup_ray(i: u32) -> (Vec3, Vec3, f32) {
    let origin = point(60_000 + i) * 1.2;
    let mut dir = (point(90_000 + i)).normalize_or(Vec3::Z);
    if i.is_multiple_of(11) {
        dir = [Vec3::X, Vec3::NEG_Y, Vec3::Z, Vec3::new(-0.0, -1.0, 0.0)][(i / 11 % 4) as usize];
    }
    let far = [0.05, 0.5, 4.0, f32::INFINITY][(i % 4) as usize];
    (origin, dir, far)
}

#[test]
fn every_ray_meets_its_nearest_triangle_at_the_distance_obvhs_traversal_finds() {
    let mesh = RayMesh::new(&soup(12_000));
    let (mut met, mut rays) = (0, 0);
    for i in 0..20_000u32 {
        let (origin, dir, far) = soup_ray(i);
        let ours = mesh.distance_local(origin, dir, far);
        assert_eq!(
            ours.map(f32::to_bits),
            mesh.obvhs_distance(origin, dir, far).map(f32::to_bits),
            "ray {i} from {origin} along {dir} to {far}"
        );
        met += usize::from(ours.is_some());
        rays += 1;
    }
    assert!(
        met > rays / 10 && met < rays * 9 / 10,
        "{met} of {rays} met"
    );
}

#[test]
fn among_triangles_met_as_near_the_first_in_the_mesh_is_the_nearest() {
    // Every triangle twice over (a doubled face, as real meshes have): each hit is a tie.
    let mut doubled = soup(3_000);
    let again = doubled.triangles.clone();
    doubled.triangles.extend(again);
    let mesh = RayMesh::new(&doubled);
    let walk = mesh.occluders();
    let (mut ties, mut met) = (0, 0);
    for i in 0..5_000u32 {
        let (origin, dir, far) = soup_ray(i);
        let r = super::occlusion::ray(origin, dir, far);
        // Every facet tested: the nearest distance, the first triangle of the mesh at it.
        let mut every: Option<(f32, u32)> = None;
        let mut at_nearest = 0;
        for (f, &source) in walk.facets.iter().zip(walk.sources) {
            let Some(t) = f.distance(&r) else { continue };
            match every {
                Some((near, _)) if t > near => {}
                Some((near, first)) if t == near => {
                    at_nearest += 1;
                    every = Some((near, first.min(source)));
                }
                _ => {
                    every = Some((t, source));
                    at_nearest = 1;
                }
            }
        }
        let ours = walk.nearest_one(&r);
        assert_eq!(
            ours.map(|(t, k)| (t.to_bits(), k)),
            every.map(|(t, k)| (t.to_bits(), k)),
            "ray {i}"
        );
        met += usize::from(every.is_some());
        ties += usize::from(at_nearest > 1);
    }
    assert!(
        met > 500 && ties * 10 > met * 9,
        "{ties} ties of {met} hits"
    );
}

#[test]
fn a_thickness_query_sums_the_nearest_distances_of_its_set() {
    let mesh = RayMesh::new(&soup(2_000));
    let set = Directions::new(64);
    let mut short = 0;
    for i in 0..300u32 {
        let origin = point(120_000 + i);
        let normal = point(150_000 + i).normalize_or(Vec3::Z);
        let turn = unit(180_000 + i);
        let ours = mesh.mean_distance_local(origin, normal, &set, 0.8, turn);
        let (t, b) = Directions::turned_frame(normal, turn);
        let start = origin + normal * mesh.offset();
        let sum: f32 = set
            .as_slice()
            .iter()
            .map(|d| {
                let dir = t * d.x + b * d.y + normal * d.z;
                mesh.obvhs_distance(start, dir, 0.8)
                    .map_or(1.0, |t| t / 0.8)
            })
            .sum();
        assert_eq!(
            ours.to_bits(),
            (sum / set.len() as f32).to_bits(),
            "query {i}"
        );
        short += usize::from(ours < 1.0);
    }
    assert!(short > 30, "{short} of 300 queries met something");
}

#[test]
fn a_query_counts_the_open_directions_of_its_set_turned_about_its_normal() {
    let mesh = RayMesh::new(&soup(2_000));
    let set = Directions::new(64);
    for i in 0..300u32 {
        let origin = point(120_000 + i);
        let normal = point(150_000 + i).normalize_or(Vec3::Z);
        let (t, b) = Directions::turned_frame(normal, unit(180_000 + i));
        let open = mesh
            .occluders()
            .open_count(origin, [t, b, normal], set.as_slice(), 0.8);
        let expected = set
            .as_slice()
            .iter()
            .filter(|d| !mesh.obvhs_occluded(origin, t * d.x + b * d.y + normal * d.z, 0.8))
            .count();
        assert_eq!(open, expected, "query {i}");
    }
}
