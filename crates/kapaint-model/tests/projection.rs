//! Issue 56, item 1: `ProjectImage` through planar, spherical, tri-planar and UV projections,
//! measured through the baked position map (a dot's centroid against the analytic mapping),
//! no painting through the mesh, and bad input refused with the document unchanged.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::{DynamicImage, Rgba, RgbaImage};
use kapaint_mesh::Mesh;
use kapaint_model::paint::projection::Projection;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::surface::Surface;
use kapaint_model::texel::{Channels, MaterialValue, Texel, linear_to_srgb};
use kapaint_model::{Document, DocumentSettings, HistoryCommand, PaintCommand};

const SIDE: u32 = 512;

fn document(mesh: Option<Mesh>) -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.0), Vec3::splat(0.0), 10.0),
        ..DocumentSettings::default()
    };
    let doc = Document::new(SIDE, SIDE, settings).expect("doc");
    match mesh {
        Some(m) => doc
            .with_surface(Some(Arc::new(Surface::new(m, SIDE, SIDE).expect("bake"))))
            .expect("surface"),
        None => doc,
    }
}

/// A transparent 64 x 64 image with a white disc of radius 5 at its centre.
fn dot() -> PaintImage {
    let img = RgbaImage::from_fn(64, 64, |x, y| {
        let d = Vec2::new(x as f32 + 0.5 - 32.0, y as f32 + 0.5 - 32.0).length();
        Rgba([255, 255, 255, if d < 5.0 { 255 } else { 0 }])
    });
    PaintImage::decoded(
        std::path::Path::new("dot.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image")
}

fn project(doc: &mut Document, image: &PaintImage, projection: Projection) -> Result<(), String> {
    doc.apply(PaintCommand::ProjectImage {
        image: image.clone(),
        projection,
        channels: Channels::ALL,
        opacity: 1.0,
    })
    .map_err(|e| e.to_string())
}

/// The centroid of `k_d`'s red over the map, in texels.
fn centroid(doc: &Document) -> Vec2 {
    let (mut sum, mut weight) = (Vec2::ZERO, 0.0);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let w = doc.maps().value(x, y).kd.x;
            sum += Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * w;
            weight += w;
        }
    }
    assert!(weight > 0.0, "nothing painted");
    sum / weight
}

/// The texel whose baked position is nearest `p`, and how far it lies from it.
fn texel_of(doc: &Document, p: Vec3) -> Vec2 {
    let s = doc.surface().expect("surface");
    let mut best = (f32::INFINITY, 0);
    for i in 0..(SIDE * SIDE) as usize {
        if s.bake.triangle(i).is_some() {
            let d = s.bake.position(i).distance_squared(p);
            if d < best.0 {
                best = (d, i);
            }
        }
    }
    let i = best.1 as u32;
    // Between texel centres: the position map's gradient places `p` within the texel.
    let base = Vec2::new((i % SIDE) as f32 + 0.5, (i / SIDE) as f32 + 0.5);
    let (pos, step_x, step_y) = (
        s.bake.position(best.1),
        s.bake.position(best.1 + 1) - s.bake.position(best.1),
        s.bake.position(best.1 + SIDE as usize) - s.bake.position(best.1),
    );
    let d = p - pos;
    base + Vec2::new(
        d.dot(step_x) / step_x.length_squared().max(1e-12),
        d.dot(step_y) / step_y.length_squared().max(1e-12),
    )
}

#[test]
fn a_planar_dot_lands_within_half_a_texel_of_its_point() {
    let mut doc = document(Some(kapaint_mesh::plane()));
    let origin = Vec3::new(0.2, 0.0, -0.3);
    project(
        &mut doc,
        &dot(),
        Projection::Planar {
            origin,
            normal: Vec3::Y,
            up: Vec3::NEG_Z,
            width: 0.5,
            height: 0.5,
        },
    )
    .expect("project");
    let got = centroid(&doc);
    let want = texel_of(&doc, origin);
    eprintln!("planar dot: centroid {got}, analytic {want}");
    assert!(got.distance(want) < 0.5, "{got} vs {want}");
    assert_eq!(doc.history().undo_steps().count(), 1);
}

#[test]
fn the_image_keeps_its_orientation_and_its_alpha_is_the_coverage() {
    // Red on the left half, blue on the right, the top row green, half transparent below.
    let img = RgbaImage::from_fn(64, 64, |x, y| match (x < 32, y < 8) {
        (_, true) => Rgba([0, 255, 0, 255]),
        (true, false) => Rgba([255, 0, 0, if y >= 56 { 128 } else { 255 }]),
        (false, false) => Rgba([0, 0, 255, 255]),
    });
    let image = PaintImage::decoded(
        std::path::Path::new("sides.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image");
    let mut doc = document(Some(kapaint_mesh::plane()));
    project(
        &mut doc,
        &image,
        Projection::Planar {
            origin: Vec3::ZERO,
            normal: Vec3::Y,
            up: Vec3::NEG_Z,
            width: 1.0,
            height: 1.0,
        },
    )
    .expect("project");
    // The plane's texel (x, y) is at ((2x/512 - 1), 0, (2y/512 - 1)); the image spans the
    // middle half of the map.
    let at = |x: u32, y: u32| doc.maps().value(x, y).kd;
    assert!(at(200, 300).x > 0.9 && at(200, 300).z < 0.05, "left is red");
    assert!(
        at(312, 300).z > 0.9 && at(312, 300).x < 0.05,
        "right is blue"
    );
    assert!(at(256, 135).y > 0.9, "top is green");
    // Half coverage over a black base: a linear half of red.
    let half = at(200, 378).x;
    assert!((half - 128.0 / 255.0).abs() < 0.02, "{half}");
    // k_s is the luminance, n the gray through the import's mapping.
    let v = doc.maps().value(312, 300);
    let l = 0.0722;
    assert!((v.ks.x - l).abs() < 2e-3, "{v:?}");
    assert_eq!(
        at(100, 100),
        Vec3::ZERO,
        "outside the image nothing changes"
    );
}

/// Two planes facing +Y, the upper one at y = 0 over the map's left half, the lower at
/// y = -0.5 over its right half, both covering the same XZ square.
fn stacked_planes() -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for (k, y) in [0.0_f32, -0.5].into_iter().enumerate() {
        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            positions.push(Vec3::new(2.0 * a - 1.0, y, 2.0 * b - 1.0));
            uvs.push(Vec2::new(0.5 * (a + k as f32), 1.0 - b));
        }
    }
    Mesh {
        name: "stacked".into(),
        normals: vec![Vec3::Y; positions.len()],
        positions,
        uvs: Some(uvs),
        triangles: vec![[0, 2, 1], [1, 2, 3], [4, 6, 5], [5, 6, 7]],
        had_normals: true,
        labels: kapaint_mesh::Labels::default(),
    }
}

#[test]
fn a_planar_projection_paints_the_nearest_surface_only() {
    let mut doc = document(Some(stacked_planes()));
    let full = PaintImage::decoded(
        std::path::Path::new("white.png"),
        &DynamicImage::ImageRgba8(RgbaImage::from_pixel(8, 8, Rgba([255, 255, 255, 255]))),
    )
    .expect("image");
    project(
        &mut doc,
        &full,
        Projection::Planar {
            origin: Vec3::new(0.0, 1.0, 0.0),
            normal: Vec3::Y,
            up: Vec3::NEG_Z,
            width: 1.0,
            height: 1.0,
        },
    )
    .expect("project");
    // The upper plane (left half of the map) took it where the image lies; the lower plane
    // (right half) lies behind it.
    assert!(doc.maps().value(128, 256).kd.x > 0.99);
    assert_eq!(doc.maps().value(384, 256).kd, Vec3::ZERO);
    // From below, nothing faces the image: refused, nothing changed, no undo step.
    let before: Vec<Texel> = (0..SIDE).map(|x| doc.maps().texel(x, 256)).collect();
    let e = project(
        &mut doc,
        &full,
        Projection::Planar {
            origin: Vec3::new(0.0, -2.0, 0.0),
            normal: Vec3::NEG_Y,
            up: Vec3::Z,
            width: 1.0,
            height: 1.0,
        },
    )
    .expect_err("faces nothing");
    assert!(e.contains("reaches no texel"), "{e}");
    let after: Vec<Texel> = (0..SIDE).map(|x| doc.maps().texel(x, 256)).collect();
    assert!(before == after);
    assert_eq!(doc.history().undo_steps().count(), 1);
}

#[test]
fn a_spherical_dot_lands_within_half_a_texel_of_its_point_on_the_sphere() {
    let mut doc = document(Some(kapaint_mesh::uv_sphere(64, 32)));
    // The dot at the image's centre lands on the equator (v = 0.5) at the front's longitude:
    // the longitude of a texel beside the map's middle (away from the sphere's UV seam, so
    // the dot lies in one island).
    let front = doc
        .surface()
        .expect("surface")
        .bake
        .position((SIDE / 2 * SIDE + SIDE / 2 + 7) as usize)
        * Vec3::new(1.0, 0.0, 1.0);
    let front = front.normalize();
    project(
        &mut doc,
        &dot(),
        Projection::Spherical {
            origin: Vec3::ZERO,
            up: Vec3::Y,
            front,
        },
    )
    .expect("project");
    let got = centroid(&doc);
    let want = texel_of(&doc, front);
    eprintln!("spherical dot: centroid {got}, analytic {want}");
    assert!(got.distance(want) < 0.5, "{got} vs {want}");
}

#[test]
fn a_triplanar_projection_shows_no_seam_across_uv_islands() {
    let mut doc = document(Some(kapaint_mesh::uv_sphere(64, 32)));
    let img = RgbaImage::from_fn(32, 32, |x, y| {
        Rgba([(x * 8) as u8, (y * 8) as u8, ((x + y) * 4) as u8, 255])
    });
    let image = PaintImage::decoded(
        std::path::Path::new("ramp.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image");
    project(
        &mut doc,
        &image,
        Projection::Triplanar {
            scale: 0.7,
            blend: 0.5,
        },
    )
    .expect("project");
    // The sphere's UV seam (column 0 beside column 511, the same meridian): the step across
    // it is no larger than the steps beside it, within one 8-bit level.
    let srgb8 = |c: f32| (linear_to_srgb(c) * 255.0).round() as i32;
    let level = |x: u32, y: u32| doc.maps().value(x, y).kd.to_array().map(srgb8);
    let step = |a: [i32; 3], b: [i32; 3]| (0..3).map(|c| (a[c] - b[c]).abs()).max().unwrap_or(0);
    let (mut rows, mut worst) = (0, i32::MIN);
    for y in SIDE / 8..SIDE * 7 / 8 {
        let (l1, l0, r0, r1) = (
            level(1, y),
            level(0, y),
            level(SIDE - 1, y),
            level(SIDE - 2, y),
        );
        let beside = step(l1, l0).max(step(r0, r1));
        worst = worst.max(step(l0, r0) - beside);
        rows += 1;
    }
    eprintln!(
        "tri-planar: {rows} rows across the sphere's UV seam, the step there exceeds the steps beside it by at most {worst} levels"
    );
    assert!(worst <= 1, "{worst}");
}

#[test]
fn a_uv_projection_tiles_and_turns_the_image_without_a_mesh() {
    let mut doc = document(None);
    // A 2 x 2 checker: white at the top-left.
    let img = RgbaImage::from_fn(2, 2, |x, y| {
        let v = if (x + y) % 2 == 0 { 255 } else { 0 };
        Rgba([v, v, v, 255])
    });
    let image = PaintImage::decoded(
        std::path::Path::new("checker.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image");
    project(
        &mut doc,
        &image,
        Projection::Uv {
            offset: Vec2::ZERO,
            scale: Vec2::splat(4.0),
            rotation: 0.0,
        },
    )
    .expect("project");
    // Four repeats: cells of 64 texels, white where (col + row) is even.
    for (x, y, white) in [
        (32, 32, true),
        (96, 32, false),
        (96, 96, true),
        (480, 32, false),
    ] {
        let v = doc.maps().value(x, y).kd.x;
        assert_eq!(v > 0.5, white, "({x}, {y}): {v}");
    }
    doc.apply(HistoryCommand::Undo).expect("undo");
    // A quarter turn about the map's centre moves a cell by one.
    project(
        &mut doc,
        &image,
        Projection::Uv {
            offset: Vec2::ZERO,
            scale: Vec2::new(4.0, 2.0),
            rotation: 90.0,
        },
    )
    .expect("project");
    let (a, b) = (doc.maps().value(32, 32).kd.x, doc.maps().value(32, 96).kd.x);
    assert!((a > 0.5) != (b > 0.5), "turned: {a} {b}");
}

#[test]
fn bad_projections_are_refused_and_change_nothing() {
    let mut doc = document(Some(kapaint_mesh::plane()));
    let planar = |normal: Vec3, up: Vec3, width: f32| Projection::Planar {
        origin: Vec3::ZERO,
        normal,
        up,
        width,
        height: 1.0,
    };
    for (projection, want) in [
        (planar(Vec3::Y, Vec3::Y, 1.0), "parallel"),
        (planar(Vec3::Y, Vec3::ZERO, 1.0), "parallel"),
        (planar(Vec3::ZERO, Vec3::Z, 1.0), "zero"),
        (planar(Vec3::Y, Vec3::Z, 0.0), "positive"),
        (planar(Vec3::Y, Vec3::Z, f32::NAN), "positive"),
        (
            Projection::Cylindrical {
                origin: Vec3::ZERO,
                axis: Vec3::Y,
                front: Vec3::Y,
                height: 1.0,
            },
            "parallel",
        ),
        (
            Projection::Triplanar {
                scale: 1.0,
                blend: 0.0,
            },
            "blend",
        ),
        (
            Projection::Uv {
                offset: Vec2::ZERO,
                scale: Vec2::new(1.0, -1.0),
                rotation: 0.0,
            },
            "scale",
        ),
    ] {
        let e = project(&mut doc, &dot(), projection).expect_err("refused");
        assert!(e.contains(want), "{projection:?}: {e}");
    }
    // Without a mesh, only the UV projection paints.
    let mut flat = document(None);
    let e = project(&mut flat, &dot(), planar(Vec3::Y, Vec3::Z, 1.0)).expect_err("no mesh");
    assert!(e.contains("mesh"), "{e}");
    assert_eq!(doc.history().undo_steps().count(), 0);
    assert_eq!(flat.history().undo_steps().count(), 0);
}

#[test]
fn a_decal_lands_at_the_surface_point_nearest_its_point_and_nowhere_else() {
    let mut doc = document(Some(kapaint_mesh::uv_sphere(64, 32)));
    // A point off the surface beside the map's middle texel's point, a third of a unit out.
    let s = doc.surface().expect("surface");
    let p = s.bake.position((SIDE / 2 * SIDE + SIDE / 2 + 7) as usize);
    let at = p * 1.3;
    doc.apply(PaintCommand::PlaceDecal {
        image: dot(),
        at,
        size: 0.5,
        rotation: 30.0,
        channels: Channels::ALL,
        opacity: 1.0,
    })
    .expect("decal");
    let got = centroid(&doc);
    let want = texel_of(&doc, p);
    eprintln!("decal dot: centroid {got}, analytic {want}");
    assert!(got.distance(want) < 1.0, "{got} vs {want}");
    // Bounded to the image: nothing beyond its half-diagonal from the point.
    let s = doc.surface().expect("surface");
    for i in (0..(SIDE * SIDE) as usize).step_by(97) {
        if s.bake.triangle(i).is_some() && s.bake.position(i).distance(p) > 0.36 {
            let (x, y) = (i as u32 % SIDE, i as u32 / SIDE);
            assert_eq!(doc.maps().value(x, y).kd, Vec3::ZERO, "({x}, {y})");
        }
    }
    assert_eq!(doc.history().undo_steps().count(), 1);
    // A zero size, a non-finite point, or no mesh: refused.
    for (size, at) in [(0.0, at), (0.5, Vec3::new(f32::NAN, 0.0, 0.0))] {
        let e = doc.apply(PaintCommand::PlaceDecal {
            image: dot(),
            at,
            size,
            rotation: 0.0,
            channels: Channels::ALL,
            opacity: 1.0,
        });
        assert!(e.is_err());
    }
    assert_eq!(doc.history().undo_steps().count(), 1);
}

/// An open cylinder about +Y, radius 1 and 2 tall, its UVs unrolled: u the angle from +X
/// towards -Z (the seam at +X), v the height.
fn cylinder(segments: u32) -> Mesh {
    let (mut positions, mut normals, mut uvs, mut triangles) = (vec![], vec![], vec![], vec![]);
    for i in 0..=segments {
        let u = i as f32 / segments as f32;
        let a = u * std::f32::consts::TAU;
        let n = Vec3::new(a.cos(), 0.0, -a.sin());
        for (j, y) in [-1.0_f32, 1.0].into_iter().enumerate() {
            positions.push(n + Vec3::Y * y);
            normals.push(n);
            uvs.push(Vec2::new(u, j as f32));
        }
    }
    for i in 0..segments {
        let (a, b) = (2 * i, 2 * i + 2);
        triangles.push([a, b, a + 1]);
        triangles.push([b, b + 1, a + 1]);
    }
    Mesh {
        name: "cylinder".into(),
        positions,
        normals,
        uvs: Some(uvs),
        triangles,
        had_normals: true,
        labels: kapaint_mesh::Labels::default(),
    }
}

#[test]
fn a_cylindrical_dot_lands_within_half_a_texel_of_its_point_on_a_cylinder() {
    let mut doc = document(Some(cylinder(256)));
    // The image's middle faces -X (u = 0.5 on the mesh too), at mid-height.
    project(
        &mut doc,
        &dot(),
        Projection::Cylindrical {
            origin: Vec3::ZERO,
            axis: Vec3::Y,
            front: Vec3::NEG_X,
            height: 2.0,
        },
    )
    .expect("project");
    let got = centroid(&doc);
    // The cylinder's own UVs: -X is u = 0.5, mid-height v = 0.5: texel (256, 256).
    let want = Vec2::splat(SIDE as f32 / 2.0);
    eprintln!("cylindrical dot: centroid {got}, analytic {want}");
    assert!(got.distance(want) < 0.5, "{got} vs {want}");
}
