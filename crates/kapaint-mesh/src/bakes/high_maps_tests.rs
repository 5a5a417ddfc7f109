//! The other maps from a high mesh (AO, thickness, curvature, position, ID), samples, cages and
//! the skew view: measured against the mesh's own bakes, analytic answers and bad input.

use glam::Vec3;

use super::high::{HighBake, HighMap, HighOptions, NormalSpace, bake_from_high};
use super::{BakeMap, BakeOptions, bake_map};
use crate::Mesh;
use crate::bake::{Coverage, UvBake, bake};

/// Sample `c` of texel `i` in `[0, 1]`.
fn value(b: &HighBake, i: usize, c: usize) -> f32 {
    f32::from(b.data[i * b.map.channels() + c]) / 65535.0
}

/// The surface texels of `uv`.
fn surface(uv: &UvBake) -> Vec<usize> {
    (0..uv.len())
        .filter(|&i| uv.coverage(i) == Coverage::Surface)
        .collect()
}

/// Baked from itself, a torus's AO, thickness, curvature, position and object normal are its
/// own bakes of those maps: the same numbers where no rays are cast, the same means within
/// the rays' noise where they are.
#[test]
fn maps_from_the_mesh_itself_are_its_own_bakes() {
    let torus = crate::torus(1.0, 0.4, 48, 24);
    let uv = bake(&torus, 128, 128, 2).expect("bakes");
    let texels = surface(&uv);
    for (high, own, tolerance) in [
        (HighMap::Curvature, BakeMap::Curvature, 2e-3),
        (HighMap::Position, BakeMap::Position, 1e-3),
        (HighMap::Normal(NormalSpace::Object), BakeMap::Normal, 2e-3),
        (HighMap::Ao, BakeMap::Ao, 0.01),
        (HighMap::Thickness, BakeMap::Thickness, 0.01),
    ] {
        let options = HighOptions {
            rays: 64,
            ..HighOptions::new(high)
        };
        let from_high = bake_from_high(&torus, &uv, &torus, None, options, None).expect("bakes");
        assert_eq!(from_high.missed, 0, "{high:?}");
        let rays = BakeOptions {
            rays: 64,
            max_distance: None,
        };
        let itself = bake_map(&torus, &uv, own, rays, None).expect("bakes");
        for c in 0..own.channels() {
            let mean = |f: &dyn Fn(usize) -> f32| {
                texels.iter().map(|&i| f(i)).sum::<f32>() / texels.len() as f32
            };
            let (a, b) = (
                mean(&|i| value(&from_high, i, c)),
                mean(&|i| itself.value(i, c)),
            );
            assert!((a - b).abs() < tolerance, "{high:?} {c}: {a} vs {b}");
            if !high.casts_rays() {
                let worst = texels
                    .iter()
                    .map(|&i| (value(&from_high, i, c) - itself.value(i, c)).abs())
                    .fold(0.0, f32::max);
                assert!(
                    worst < tolerance * 5.0,
                    "{high:?} {c}: texel off by {worst}"
                );
            }
        }
    }
}

/// A plane baked from itself and a box standing on it: the plane's own AO is open sky
/// everywhere, from the high mesh the texels beside the box are shadowed by it; the ID map
/// holds two parts, a colour each, and the box's top counts as the box.
#[test]
fn ao_and_ids_from_a_high_mesh_see_what_the_low_one_has_not() {
    let plane = crate::plane();
    let mut cube = crate::cube();
    for p in &mut cube.positions {
        *p = *p * 0.2 + Vec3::new(0.3, 0.1, 0.3);
    }
    cube.uvs = None;
    let mut flat = plane.clone();
    flat.uvs = None;
    let high = Mesh::merged(vec![flat, cube]).expect("merges");
    let uv = bake(&plane, 64, 64, 2).expect("bakes");
    let texels = surface(&uv);
    let options = |map| HighOptions {
        front: Some(0.3),
        rays: 64,
        ..HighOptions::new(map)
    };
    let ao = bake_from_high(&plane, &uv, &high, None, options(HighMap::Ao), None).expect("bakes");
    let own = bake_from_high(&plane, &uv, &plane, None, options(HighMap::Ao), None).expect("bakes");
    let least = |b: &HighBake| texels.iter().map(|&i| value(b, i, 0)).fold(1.0, f32::min);
    assert!(
        least(&own) > 0.999,
        "the plane alone is open: {}",
        least(&own)
    );
    assert!(least(&ao) < 0.75, "beside the box: {}", least(&ao));
    let ids = bake_from_high(
        &plane,
        &uv,
        &high,
        None,
        options(HighMap::Id(super::IdSource::Piece)),
        None,
    )
    .expect("bakes");
    let mut colours: Vec<[u16; 3]> = texels
        .iter()
        .map(|&i| [0, 1, 2].map(|c| ids.data[i * 3 + c]))
        .collect();
    colours.sort_unstable();
    colours.dedup();
    assert_eq!(colours.len(), 2, "{colours:?}");
    // Texel (40, 40) lies under the box (x and z 0.1..0.5: texels 35..48 each way).
    let under_box = 40 * 64 + 40;
    let edge = 20 * 64 + 10;
    assert_ne!(
        [0, 1, 2].map(|c| ids.data[under_box * 3 + c]),
        [0, 1, 2].map(|c| ids.data[edge * 3 + c])
    );
}

/// A step in the high mesh across the middle of a texel column: one sample a texel takes the
/// side its centre is on, sixteen take the mean of both sides.
#[test]
fn sixteen_samples_average_a_texel_and_one_takes_its_centre() {
    let plane = crate::plane();
    let quad = |x0: f32, x1: f32, y: f32| Mesh {
        name: "step".into(),
        positions: vec![
            Vec3::new(x0, y, -1.0),
            Vec3::new(x1, y, -1.0),
            Vec3::new(x0, y, 1.0),
            Vec3::new(x1, y, 1.0),
        ],
        normals: vec![Vec3::Y; 4],
        uvs: None,
        triangles: vec![[0, 2, 1], [1, 2, 3]],
        had_normals: true,
        labels: crate::Labels::default(),
    };
    // Texel column 32 of 64 spans x 0 to 0.03125; the step at 0.014 leaves two of its four
    // sample columns low and its centre (0.0156) high.
    let step = Mesh::merged(vec![quad(-1.0, 0.014, 0.0), quad(0.014, 1.0, 0.01)]).expect("merges");
    let uv = bake(&plane, 64, 64, 2).expect("bakes");
    let height = |samples| {
        let options = HighOptions {
            front: Some(0.05),
            rear: Some(0.05),
            samples,
            ..HighOptions::new(HighMap::Height)
        };
        let b = bake_from_high(&plane, &uv, &step, None, options, None).expect("bakes");
        assert_eq!(b.missed, 0);
        (value(&b, 20 * 64 + 32, 0), value(&b, 20 * 64 + 10, 0))
    };
    let (one, low) = height(1);
    assert!(
        (one - 0.6).abs() < 1e-3 && (low - 0.5).abs() < 1e-3,
        "{one} {low}"
    );
    let (sixteen, low) = height(16);
    assert!(
        (sixteen - 0.55).abs() < 1e-3 && (low - 0.5).abs() < 1e-3,
        "{sixteen} {low}"
    );
    let e = bake_from_high(
        &plane,
        &uv,
        &step,
        None,
        HighOptions {
            samples: 3,
            ..HighOptions::new(HighMap::Height)
        },
        None,
    )
    .expect_err("3 samples");
    assert!(e.to_string().contains("1, 4 or 16"), "{e}");
}

/// Rays from a cage, the coarse sphere pushed out by 5 %, go towards the centre: each meets the
/// fine sphere where the radius through its texel does, so the normal there is that radius
/// (within a degree at the 99th percentile). A cage of another topology, or with a NaN, is
/// refused.
#[test]
fn rays_from_a_cage_meet_the_high_mesh_along_the_cage_directions() {
    let low = crate::uv_sphere(24, 12);
    let high = crate::uv_sphere(512, 256);
    let cage = Mesh {
        positions: low.positions.iter().map(|p| *p * 1.05).collect(),
        ..low.clone()
    };
    let uv = bake(&low, 256, 256, 2).expect("bakes");
    let options = HighOptions {
        samples: 4,
        ..HighOptions::new(HighMap::Normal(NormalSpace::Object))
    };
    let b = bake_from_high(&low, &uv, &high, Some(&cage), options, None).expect("bakes");
    assert_eq!(b.missed, 0);
    assert!(b.cage);
    let mut errors: Vec<f32> = surface(&uv)
        .into_iter()
        .map(|i| {
            let n = Vec3::new(value(&b, i, 0), value(&b, i, 1), value(&b, i, 2)) * 2.0 - 1.0;
            n.normalize()
                .angle_between(uv.position(i).normalize())
                .to_degrees()
        })
        .collect();
    errors.sort_by(f32::total_cmp);
    let p99 = errors[errors.len() * 99 / 100];
    assert!(p99 < 1.0, "p99 {p99} degrees");
    let other = crate::uv_sphere(25, 12);
    let e = bake_from_high(&low, &uv, &high, Some(&other), options, None).expect_err("topology");
    assert!(e.to_string().contains("topology"), "{e}");
    let mut nan = cage.clone();
    nan.positions[5] = Vec3::NAN;
    let e = bake_from_high(&low, &uv, &high, Some(&nan), options, None).expect_err("nan");
    assert!(e.to_string().contains("cage"), "{e}");
}

/// The skew view: zero on the cube (its normals are its faces'), above zero on a coarse
/// sphere whose averaged normals lean off its facets, most at the facets' corners.
#[test]
fn the_skew_view_shows_where_averaged_normals_tilt_the_rays() {
    let skew_of = |mesh: &Mesh| {
        let uv = bake(mesh, 128, 128, 2).expect("bakes");
        let options = HighOptions::new(HighMap::Height);
        let b = bake_from_high(mesh, &uv, mesh, None, options, None).expect("bakes");
        let texels = surface(&uv);
        texels.iter().map(|&i| b.skew[i]).max().unwrap_or(0)
    };
    assert_eq!(skew_of(&crate::cube()), 0);
    let sphere = f32::from(skew_of(&crate::uv_sphere(12, 6))) / 255.0 * 90.0;
    // Facets 30 degrees across: the normals at their corners lean a good part of that.
    assert!(sphere > 5.0 && sphere < 30.0, "{sphere} degrees");
}

/// One BVH for several maps bakes what a bake that builds its own does.
#[test]
fn a_bvh_built_once_bakes_what_each_bake_builds() {
    let low = crate::uv_sphere(24, 12);
    let high = crate::torus(1.0, 0.4, 64, 32);
    let uv = bake(&low, 64, 64, 2).expect("bakes");
    let rays = super::HighRays::whole(super::RayMesh::new(&high));
    for map in [HighMap::Curvature, HighMap::Ao] {
        let options = HighOptions {
            rays: 8,
            front: Some(0.5),
            rear: Some(0.5),
            ..HighOptions::new(map)
        };
        let own = bake_from_high(&low, &uv, &high, None, options, None).expect("bakes");
        let shared = super::bake_from_high_with(&low, &uv, (&high, &rays), None, options, None)
            .expect("bakes");
        assert_eq!(own.data, shared.data, "{map:?}");
        assert_eq!(own.misses, shared.misses);
    }
}
