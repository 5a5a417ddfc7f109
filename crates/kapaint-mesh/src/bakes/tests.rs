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
        assert!(e.contains("outside 1 to 65536"), "{e}");
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
    assert_eq!(e, "cancelled");
}
