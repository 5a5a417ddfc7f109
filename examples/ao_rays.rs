//! Profiling aid and peer measure: kapaint's AO rays alone on a mesh, as
//! `benches/peers/ao_embree.py` times Embree's — surface points picked area-weighted, 64
//! cosine-weighted directions about each point's geometric normal from 1e-5 of the box's
//! diagonal off the surface, unbounded, one thread, the occlusion queries timed and nothing
//! else (the BVH is built before the clock starts). Prints rays per second (the fastest of
//! `ROUNDS` rounds over the same points) and the mean open fraction. With `coherent` the
//! points are walked in Morton order (near points one after another, as a bake walks its
//! texels); without it in the order they were drawn (each query far from the last).
//!
//! Usage: `cargo run --release --example ao_rays MESH.obj [POINTS] [ROUNDS] [coherent]`

use std::time::Instant;

use glam::Vec3;
use kapaint::mesh::bakes::{Directions, RayMesh};

/// A number in `[0, 1)` from a hash of `i` (splitmix64's finaliser).
fn unit(i: u64) -> f64 {
    let mut h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^= h >> 31;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` points on `mesh` picked by area, each with its triangle's unit normal.
fn surface_points(mesh: &kapaint::mesh::Mesh, count: usize) -> Vec<(Vec3, Vec3)> {
    let corners = |t: &[u32; 3]| t.map(|i| mesh.positions[i as usize]);
    let mut sums = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0f64;
    for t in &mesh.triangles {
        let [a, b, c] = corners(t);
        total += f64::from((b - a).cross(c - a).length());
        sums.push(total);
    }
    (0..count as u64)
        .filter_map(|k| {
            let at = unit(3 * k) * total;
            let i = sums.partition_point(|&s| s <= at).min(sums.len() - 1);
            let [a, b, c] = corners(&mesh.triangles[i]);
            let normal = (b - a).cross(c - a).try_normalize()?;
            let (r1, r2) = (unit(3 * k + 1) as f32, unit(3 * k + 2) as f32);
            let s = r1.sqrt();
            Some((a * (1.0 - s) + b * (s * (1.0 - r2)) + c * (s * r2), normal))
        })
        .collect()
}

/// `x`'s low 21 bits spread to every third bit.
fn spread(x: u64) -> u64 {
    (0..21).fold(0, |code, bit| code | ((x >> bit) & 1) << (3 * bit))
}

/// `points` ordered along a Morton curve through their bounding box.
fn morton_order(points: &mut [(Vec3, Vec3)]) {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), (p, _)| (lo.min(*p), hi.max(*p)),
    );
    let scale = ((1u64 << 21) - 1) as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    points.sort_by_cached_key(|(p, _)| {
        let q = ((*p - lo) * scale).as_uvec3();
        spread(u64::from(q.x)) << 2 | spread(u64::from(q.y)) << 1 | spread(u64::from(q.z))
    });
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: ao_rays MESH.obj [POINTS] [ROUNDS] [coherent]")?;
    let count: usize = args
        .get(1)
        .map_or(Ok(150_000), |a| a.parse())
        .map_err(|e| format!("{e}"))?;
    let rounds: usize = args
        .get(2)
        .map_or(Ok(3), |a| a.parse())
        .map_err(|e| format!("{e}"))?;
    let mesh = kapaint::mesh::load(std::path::Path::new(path)).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let rays = RayMesh::new(&mesh);
    eprintln!(
        "BVH of {} triangles: {:.2} s",
        mesh.triangles.len(),
        start.elapsed().as_secs_f64()
    );
    let mut points = surface_points(&mesh, count);
    let coherent = match args.get(3).map(String::as_str) {
        None => false,
        Some("coherent") => true,
        Some(other) => {
            return Err(format!(
                "the fourth argument is `coherent` or nothing, not `{other}`"
            ));
        }
    };
    if coherent {
        morton_order(&mut points);
    }
    let set = Directions::new(64);
    let mut best = f64::INFINITY;
    let mut open = 0.0;
    for _ in 0..rounds {
        let start = Instant::now();
        open = points
            .iter()
            .enumerate()
            .map(|(k, &(p, n))| {
                f64::from(rays.open_fraction(p, n, &set, f32::INFINITY, unit(k as u64 + 7) as f32))
            })
            .sum::<f64>();
        best = best.min(start.elapsed().as_secs_f64());
    }
    let cast = points.len() * set.len();
    println!(
        "kapaint: {cast} rays in {best:.2} s, {:.2} M rays/s (one thread{}), mean open fraction {:.4}",
        cast as f64 / best / 1e6,
        if coherent { ", Morton order" } else { "" },
        open / points.len() as f64
    );
    Ok(())
}
