//! Bakes against shapes with known answers, and bad values.

use super::*;
use crate::bake::bake;

/// A floor (y = 0, z from 0 to 50) beside a wall (z = 0, height `h`), both 2000 long.
fn floor_and_wall(h: f32) -> Mesh {
    let l = 1000.0;
    let positions = vec![
        Vec3::new(-l, 0.0, 0.0),
        Vec3::new(l, 0.0, 0.0),
        Vec3::new(l, 0.0, 50.0),
        Vec3::new(-l, 0.0, 50.0),
        Vec3::new(-l, 0.0, 0.0),
        Vec3::new(l, 0.0, 0.0),
        Vec3::new(l, h, 0.0),
        Vec3::new(-l, h, 0.0),
    ];
    Mesh {
        name: "floor and wall".into(),
        normals: [[Vec3::Y; 4], [Vec3::Z; 4]].concat(),
        positions,
        uvs: None,
        triangles: vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]],
        had_normals: true,
        labels: crate::Labels::default(),
    }
}

#[test]
fn a_floor_beside_a_wall_sees_what_geometry_says() {
    let h = 1.0;
    let rays = RayMesh::new(&floor_and_wall(h));
    for d in [0.25_f32, 1.0, 4.0] {
        let want = 0.5 * (1.0 + d / (d * d + h * h).sqrt());
        // Averaged over a few turns, as neighbouring texels would be.
        let set = Directions::new(256);
        let got: f32 = (0..8)
            .map(|k| {
                rays.open_fraction(
                    Vec3::new(0.0, 0.0, d),
                    Vec3::Y,
                    &set,
                    f32::INFINITY,
                    turn_of(k),
                )
            })
            .sum::<f32>()
            / 8.0;
        assert!((got - want).abs() < 0.02, "d {d}: {got} vs {want}");
    }
}

#[test]
fn the_sphere_is_open_sky_everywhere_and_its_maps_are_what_a_sphere_is() {
    let sphere = crate::uv_sphere(64, 32);
    let uv = bake(&sphere, 128, 128, 2).expect("bakes");
    let ao_map = bake_map(
        &sphere,
        &uv,
        BakeMap::Ao,
        BakeOptions {
            rays: 256,
            max_distance: None,
        },
        None,
    )
    .expect("ao");
    assert_eq!(ao_map.mesh_hash, sphere.content_hash());
    let ao = ao_map.stats(&uv);
    assert!(ao.texels > 10_000);
    assert!(ao.min >= 0.99, "min AO {}", ao.min);
    assert_eq!(ao.rays_cast, ao.texels * 256);
    let k = bake_map(
        &sphere,
        &uv,
        BakeMap::Curvature,
        BakeOptions::default(),
        None,
    )
    .expect("curvature")
    .stats(&uv);
    assert!(k.min > 0.5, "a sphere is convex everywhere: {}", k.min);
    // Inward, the far side is 2 R cos(theta) away: a cosine-weighted mean of 4R/3 over
    // the diagonal 2 sqrt(3) R.
    let t = bake_map(
        &sphere,
        &uv,
        BakeMap::Thickness,
        BakeOptions {
            rays: 64,
            max_distance: None,
        },
        None,
    )
    .expect("thickness")
    .stats(&uv);
    let want = 2.0 / (3.0 * 3.0_f32.sqrt());
    assert!(
        (t.mean - want).abs() < 0.02,
        "thickness {} vs {want}",
        t.mean
    );
    let n = bake_map(&sphere, &uv, BakeMap::Normal, BakeOptions::default(), None).expect("normal");
    let p = bake_map(
        &sphere,
        &uv,
        BakeMap::Position,
        BakeOptions::default(),
        None,
    )
    .expect("position");
    for i in (0..uv.len()).filter(|&i| uv.coverage(i) == Coverage::Surface) {
        let normal = Vec3::new(n.value(i, 0), n.value(i, 1), n.value(i, 2)) * 2.0 - 1.0;
        let position = Vec3::new(p.value(i, 0), p.value(i, 1), p.value(i, 2)) * 2.0 - 1.0;
        // The unit sphere: the normal points where the point is.
        assert!(
            (normal - position).length() < 0.05,
            "{normal} vs {position}"
        );
    }
}

#[test]
fn a_flat_plane_is_open_and_flat() {
    let plane = crate::plane();
    let uv = bake(&plane, 64, 64, 2).expect("bakes");
    let ao = bake_map(
        &plane,
        &uv,
        BakeMap::Ao,
        BakeOptions {
            rays: 16,
            max_distance: None,
        },
        None,
    )
    .expect("ao")
    .stats(&uv);
    assert_eq!(ao.min, 1.0);
    let k = bake_map(
        &plane,
        &uv,
        BakeMap::Curvature,
        BakeOptions::default(),
        None,
    )
    .expect("curvature")
    .stats(&uv);
    assert!((k.min - 0.5).abs() < 1e-4 && (k.mean - 0.5).abs() < 1e-4);
}

#[test]
fn bad_values_and_cancel_are_errors() {
    let sphere = crate::uv_sphere(16, 8);
    let uv = bake(&sphere, 32, 32, 2).expect("bakes");
    for rays in [0, 65_537] {
        let e = bake_map(
            &sphere,
            &uv,
            BakeMap::Ao,
            BakeOptions {
                rays,
                max_distance: None,
            },
            None,
        )
        .expect_err("rays out of range");
        assert!(e.to_string().contains("outside 1 to 65536"), "{e}");
    }
    for d in [f32::NAN, 0.0, -1.0, f32::INFINITY] {
        assert!(
            bake_map(
                &sphere,
                &uv,
                BakeMap::Ao,
                BakeOptions {
                    rays: 4,
                    max_distance: Some(d)
                },
                None
            )
            .is_err()
        );
    }
    let progress = Progress::default();
    progress.cancel();
    let e = bake_map(
        &sphere,
        &uv,
        BakeMap::Ao,
        BakeOptions::default(),
        Some(&progress),
    )
    .expect_err("cancelled");
    assert_eq!(e, BakeError::Cancelled);
}

/// `mesh` with its positions moved by `offset` and scaled by `scale`.
fn scaled(mesh: &Mesh, offset: Vec3, scale: f32) -> Mesh {
    let mut out = mesh.clone();
    for p in &mut out.positions {
        *p = (*p + offset) * scale;
    }
    out
}

/// The largest and the mean difference between two bakes' samples (unorm16 steps).
fn difference(a: &Baked, b: &Baked) -> (u16, f64) {
    let diffs = a.data.iter().zip(&b.data).map(|(&x, &y)| x.abs_diff(y));
    let max = diffs.clone().max().unwrap_or(0);
    let mean = diffs.map(f64::from).sum::<f64>() / a.data.len().max(1) as f64;
    (max, mean)
}

#[test]
fn bakes_are_the_same_at_every_scale() {
    // A torus (occluded inside its ring, curved both ways) away from the origin.
    let torus = crate::torus(1.0, 0.35, 48, 24);
    let offset = Vec3::new(3.0, -1.0, 0.5);
    let bake_at = |scale: f32, map: BakeMap| {
        let mesh = scaled(&torus, offset, scale);
        let uv = bake(&mesh, 96, 96, 2).expect("bakes");
        let options = BakeOptions {
            rays: 32,
            // Object units, scaled with the mesh.
            max_distance: (map == BakeMap::Ao).then_some(1.5 * scale),
        };
        bake_map(&mesh, &uv, map, options, None).expect("a bake")
    };
    for map in [
        BakeMap::Ao,
        BakeMap::Thickness,
        BakeMap::Curvature,
        BakeMap::Position,
    ] {
        let unit = bake_at(1.0, map);
        let stats = unit.stats(&bake(&torus, 96, 96, 2).expect("bakes"));
        assert!(stats.min < stats.mean, "{map:?} has something to compare");
        // A power of two scales exactly: the same bits.
        for scale in [2.0_f32.powi(-70), 2.0_f32.powi(100)] {
            assert!(bake_at(scale, map).data == unit.data, "{map:?} at {scale}");
        }
        // Any other scale rounds the positions once: a sample may move by a step, and a ray
        // that grazes an edge may turn (one ray of 32); almost every sample is the same.
        for scale in [1e-20_f32, 3.0, 1e30] {
            let (max, mean) = difference(&bake_at(scale, map), &unit);
            assert!(
                u32::from(max) <= 65535 / 32 && mean < 0.05,
                "{map:?} at {scale}: largest difference {max}, mean {mean}"
            );
        }
    }
}

#[test]
fn a_mesh_too_large_to_measure_is_refused_not_baked() {
    // The box from -1e38 to 1e38 on every axis: its diagonal is more than f32 holds.
    let huge = scaled(&crate::uv_sphere(16, 8), Vec3::ZERO, 1e38);
    let e = huge.validate().expect_err("refused");
    assert!(e.contains("too large to measure"), "{e}");
    let uv = bake(&huge, 32, 32, 2).expect("the UV bake needs no positions");
    for map in [BakeMap::Ao, BakeMap::Thickness, BakeMap::Curvature] {
        let e = bake_map(&huge, &uv, map, BakeOptions::default(), None).expect_err("refused");
        assert!(
            e.to_string().contains("too large to measure"),
            "{map:?}: {e}"
        );
    }
    // Long on one axis only, it is measured and baked.
    let mut long = crate::uv_sphere(16, 8);
    long.positions.iter_mut().for_each(|p| p.x *= 1e38);
    assert!(long.validate().is_ok());
    let uv = bake(&long, 32, 32, 2).expect("bakes");
    let ao = bake_map(&long, &uv, BakeMap::Ao, BakeOptions::default(), None).expect("ao");
    assert!(
        ao.stats(&uv).min >= 0.99,
        "a convex shape is open: {:?}",
        ao.stats(&uv)
    );
}

#[test]
fn a_triangle_with_a_nan_corner_is_left_out_and_the_others_keep_their_names() {
    // Three triangles in a row along x at y = 0, the middle one with a NaN corner.
    let quad = |x: f32| {
        [
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 0.0, 0.0),
            Vec3::new(x, 0.0, 1.0),
        ]
    };
    let mut positions = [quad(0.0), quad(2.0), quad(4.0)].concat();
    positions[4].x = f32::NAN;
    let mesh = Mesh {
        name: "row".into(),
        normals: vec![Vec3::Y; 9],
        positions,
        uvs: None,
        triangles: vec![[0, 2, 1], [3, 5, 4], [6, 8, 7]],
        had_normals: true,
        labels: crate::Labels::default(),
    };
    let down = Vec3::NEG_Y;
    for rays in [
        RayMesh::new(&mesh),
        RayMesh::split(&mesh, &[0, 0, 0], 1).remove(0).unwrap(),
    ] {
        let hit = |x: f32| rays.nearest(Vec3::new(x, 1.0, 0.2), down, 10.0);
        assert_eq!(hit(0.2).map(|(_, t)| t), Some(0));
        assert_eq!(hit(2.2), None, "the NaN triangle is met by no ray");
        let (d, t) = hit(4.2).expect("the last triangle is met");
        assert_eq!(t, 2, "named as in the mesh, after the one left out");
        assert!((d - 1.0).abs() < 1e-5, "{d}");
    }
}
