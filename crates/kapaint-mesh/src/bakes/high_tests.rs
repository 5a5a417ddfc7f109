//! Normals from a high mesh: measured against analytic normals, flat where the two meshes
//! agree, and bad input refused.

use glam::Vec3;

use super::high::{HighBake, HighMap, HighOptions, NormalSpace, bake_from_high};
use crate::Mesh;
use crate::bake::bake;

fn decode(n: &HighBake, i: usize) -> Vec3 {
    let c = |k: usize| f32::from(n.data[i * 3 + k]) / 65535.0 * 2.0 - 1.0;
    Vec3::new(c(0), c(1), c(2))
}

fn options(space: NormalSpace) -> HighOptions {
    HighOptions::new(HighMap::Normal(space))
}

/// A coarse sphere's texels take a fine sphere's normals: within a degree of the analytic
/// normal where each ray meets the unit sphere (the 99th percentile), none missed.
#[test]
fn object_normals_from_a_fine_sphere_are_the_analytic_normals() {
    let low = crate::uv_sphere(24, 12);
    let high = crate::uv_sphere(512, 256);
    let uv = bake(&low, 256, 256, 2).expect("bakes");
    let baked =
        bake_from_high(&low, &uv, &high, None, options(NormalSpace::Object), None).expect("bakes");
    assert!(baked.covered > 30_000, "{}", baked.covered);
    assert_eq!(baked.missed, 0, "every ray meets the fine sphere");
    let mut errors = Vec::new();
    for i in 0..(256 * 256) {
        if uv.triangle(i).is_none() {
            continue;
        }
        // Where the ray meets the unit sphere: origin o = p + n f, along -n.
        let (p, n) = (uv.position(i), uv.normal(i));
        let o = p + n * baked.front;
        let b = o.dot(-n);
        let t = -b - (b * b - (o.length_squared() - 1.0)).max(0.0).sqrt();
        let want = (o - n * t).normalize();
        let got = decode(&baked, i).normalize();
        errors.push(got.dot(want).clamp(-1.0, 1.0).acos().to_degrees());
    }
    errors.sort_by(f32::total_cmp);
    let p99 = errors[errors.len() * 99 / 100];
    eprintln!(
        "high-poly normals: {} texels, p99 {p99:.3} degrees, worst {:.3}",
        errors.len(),
        errors[errors.len() - 1]
    );
    assert!(p99 < 1.0, "{p99}");
}

/// The same mesh as low and high bakes flat in tangent space (0, 0, 1); a bumped high mesh
/// does not, and its bumps lean the way the surface does.
#[test]
fn tangent_normals_are_flat_on_the_mesh_itself_and_lean_on_bumps() {
    let low = crate::uv_sphere(48, 24);
    let uv = bake(&low, 128, 128, 2).expect("bakes");
    let flat =
        bake_from_high(&low, &uv, &low, None, options(NormalSpace::Tangent), None).expect("bakes");
    let mut worst = 0.0_f32;
    for i in 0..(128 * 128) {
        if uv.triangle(i).is_some() && uv.coverage(i) == crate::bake::Coverage::Surface {
            worst = worst.max(
                decode(&flat, i)
                    .normalize()
                    .angle_between(Vec3::Z)
                    .to_degrees(),
            );
        }
    }
    assert!(worst < 1.0, "flat within a degree: {worst}");
    // Bumps: the high sphere's radius waves with longitude, so its normals lean east-west.
    let mut bumpy = crate::uv_sphere(256, 128);
    for (p, n) in bumpy.positions.iter_mut().zip(bumpy.normals.iter_mut()) {
        let phi = p.z.atan2(p.x);
        let r = 1.0 + 0.01 * (12.0 * phi).sin();
        *p *= r;
        *n = Vec3::ZERO;
    }
    recompute_normals(&mut bumpy);
    let leaned = bake_from_high(&low, &uv, &bumpy, None, options(NormalSpace::Tangent), None)
        .expect("bakes");
    let tilted = (0..128 * 128)
        .filter(|&i| uv.triangle(i).is_some())
        .filter(|&i| decode(&leaned, i).normalize().angle_between(Vec3::Z) > 5f32.to_radians())
        .count();
    assert!(tilted > 1000, "{tilted} texels lean");
    assert_eq!(leaned.missed, 0);
}

fn recompute_normals(mesh: &mut Mesh) {
    let mut sums = vec![Vec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        let face = (b - a).cross(c - a);
        for v in t {
            sums[*v as usize] += face;
        }
    }
    mesh.normals = sums.into_iter().map(Vec3::normalize_or_zero).collect();
}

#[test]
fn bad_high_meshes_and_distances_are_refused() {
    let low = crate::uv_sphere(16, 8);
    let uv = bake(&low, 64, 64, 2).expect("bakes");
    let empty = Mesh {
        triangles: vec![],
        ..low.clone()
    };
    let mut nan = low.clone();
    nan.positions[3] = Vec3::NAN;
    for (high, want) in [(&empty, "no triangles"), (&nan, "non-finite")] {
        let e = bake_from_high(&low, &uv, high, None, options(NormalSpace::Object), None)
            .expect_err(want);
        assert!(e.to_string().contains(want), "{e}");
    }
    for d in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let e = bake_from_high(
            &low,
            &uv,
            &low,
            None,
            HighOptions {
                front: Some(d),
                ..options(NormalSpace::Object)
            },
            None,
        )
        .expect_err("bad distance");
        assert!(e.to_string().contains("not a positive number"), "{e}");
    }
    // Rays that stop short of a high mesh far away miss, and say so.
    let far = Mesh {
        positions: low.positions.iter().map(|p| *p * 3.0).collect(),
        ..low.clone()
    };
    let missed =
        bake_from_high(&low, &uv, &far, None, options(NormalSpace::Object), None).expect("bakes");
    assert_eq!(missed.missed, missed.covered);
}

/// Regression: a ray whose direction has a negative zero (straight down is `(-0, -1, -0)`)
/// met nothing in the BVH (its traversal reads the sign bit): every texel of spot's seam at
/// `x = 0`, whose normals have `x = -0` once negated, missed itself.
#[test]
fn a_ray_straight_down_meets_the_mesh_below_it() {
    let sphere = crate::uv_sphere(32, 16);
    let rays = super::RayMesh::new(&sphere);
    for dir in [
        -Vec3::Y,
        Vec3::new(-0.0, -1.0, -0.0),
        Vec3::new(0.0, -1.0, 0.0),
    ] {
        let hit = rays.nearest(Vec3::new(0.1, 3.0, 0.1), dir, 10.0);
        let (d, _) = hit.unwrap_or_else(|| panic!("{dir:?} met nothing"));
        assert!((d - 2.01).abs() < 0.02, "{d}");
        assert!(rays.occluded(Vec3::new(0.1, 3.0, 0.1), dir, 10.0));
        assert!(rays.distance(Vec3::new(0.1, 3.0, 0.1), dir, 10.0).is_some());
    }
}

/// Height: a sphere of radius 1.01 over the unit sphere stands 0.01 above it everywhere, read
/// through the distances (`(h + rear) / (front + rear)`); the sphere itself stands at 0.
#[test]
fn height_is_the_high_surface_over_the_low_one_by_the_distances() {
    let low = crate::uv_sphere(64, 32);
    let uv = bake(&low, 128, 128, 2).expect("bakes");
    let grown = Mesh {
        positions: low.positions.iter().map(|p| *p * 1.01).collect(),
        ..low.clone()
    };
    let height = |high: &Mesh| {
        let opts = HighOptions {
            front: Some(0.05),
            rear: Some(0.05),
            ..HighOptions::new(HighMap::Height)
        };
        let b = bake_from_high(&low, &uv, high, None, opts, None).expect("bakes");
        assert_eq!(b.missed, 0);
        let values: Vec<f32> = (0..128 * 128)
            .filter(|&i| uv.coverage(i) == crate::bake::Coverage::Surface)
            .map(|i| f32::from(b.data[i]) / 65535.0 * 0.1 - 0.05)
            .collect();
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        let worst = values.iter().map(|v| (v - mean).abs()).fold(0.0, f32::max);
        (mean, worst)
    };
    let (same, spread) = height(&low);
    assert!(same.abs() < 1e-4 && spread < 1e-4, "{same} {spread}");
    let (above, spread) = height(&grown);
    // The texels lie on the low facets, a little inside the unit sphere: 0.01 above it and
    // the facets' sag.
    assert!(
        (above - 0.0107).abs() < 0.002 && spread < 0.002,
        "{above} {spread}"
    );
}
