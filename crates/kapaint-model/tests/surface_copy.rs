//! Issue 56, items 4 and 5 on the mesh: a clone stroke on the surface copies, in object space,
//! what lay about its dabs' centres moved by the offset from its first point to the source
//! (each dab's patch laid on the surface there, turned as the surface turns), across the UV
//! seam (the sphere's, at +X); a smudge drags along the surface across the seam too; bad
//! input refused with the document unchanged.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::Vec3;
use kapaint_model::brush::{BrushSettings, SurfacePoint, SurfacePos};
use kapaint_model::surface::Surface;
use kapaint_model::texel::{Texel, linear_to_srgb};
use kapaint_model::{
    Document, DocumentSettings, MaterialMaps, MaterialValue, SettingsCommand, StrokeCommand,
    StrokeTool,
};

const SIDE: u32 = 512;

/// What the source holds at a surface point: `k_d` changing smoothly over the sphere.
fn pattern(p: Vec3) -> Vec3 {
    Vec3::splat(0.5) + 0.4 * p
}

/// The sphere with `pattern` painted over every texel of its surface.
fn painted_sphere() -> Document {
    let surface = Surface::new(kapaint_mesh::uv_sphere(64, 32), SIDE, SIDE).expect("bake");
    let base = MaterialValue::new(Vec3::splat(0.2), Vec3::splat(0.04), 10.0);
    let mut maps = MaterialMaps::new(SIDE, SIDE, base).expect("maps");
    for y in 0..SIDE {
        for x in 0..SIDE {
            let t = (y * SIDE + x) as usize;
            if surface.bake.triangle(t).is_some() {
                let v = MaterialValue::new(pattern(surface.bake.position(t)), base.ks, base.n);
                let (id, i) = maps.locate(x, y);
                maps.tile_mut(id).set_texel(i, Texel::encode(v));
            }
        }
    }
    let settings = DocumentSettings {
        base,
        ..DocumentSettings::default()
    };
    Document::from_parts(maps, settings)
        .with_surface(Some(Arc::new(surface)))
        .expect("surface")
}

fn equator(phi: f32) -> Vec3 {
    Vec3::new(phi.cos(), 0.0, -phi.sin())
}

fn points(from: f32, to: f32, steps: usize) -> Vec<SurfacePoint> {
    (0..=steps)
        .map(|k| {
            let p = equator(from + (to - from) * k as f32 / steps as f32);
            SurfacePoint {
                pos: SurfacePos {
                    point: p,
                    normal: p,
                },
                pressure: 1.0,
            }
        })
        .collect()
}

fn srgb8(v: f32) -> f32 {
    (linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round()
}

#[test]
fn a_clone_stroke_on_the_mesh_copies_its_source_across_the_uv_seam() {
    let mut doc = painted_sphere();
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 10.0,
        hardness: 1.0,
        opacity: 1.0,
        pressure_size: false,
        ..BrushSettings::default()
    }))
    .expect("brush");
    // The source a quarter of a unit above the stroke's first point, on the surface.
    let first = equator(-0.3);
    let source = (first + Vec3::Y * 0.25).normalize();
    doc.apply(SettingsCommand::SetSurfaceCloneSource(source))
        .expect("source");
    let offset = source - first;
    // Across the seam at longitude 0 (+X): the map's left and right edges.
    doc.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Clone,
        points: points(-0.3, 0.3, 60),
    })
    .expect("cloned");
    assert_eq!(doc.surface_clone_source(), Some((source, Some(offset))));
    let s = Arc::clone(doc.surface().expect("surface"));
    let radius = 10.0 * s.units_per_texel;
    let (mut checked, mut left, mut right, mut worst) = (0, 0, 0, 0.0_f32);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let t = (y * SIDE + x) as usize;
            if s.bake.triangle(t).is_none()
                || s.bake.coverage(t) != kapaint_mesh::bake::Coverage::Surface
            {
                continue;
            }
            let p = s.bake.position(t);
            // Under the hard core: within half the radius of the stroke's arc, away from its
            // ends.
            let phi = (-p.z).atan2(p.x);
            if p.y.abs() > 0.5 * radius || !(-0.25..=0.25).contains(&phi) {
                continue;
            }
            // The first dab to reach the texel (at coverage 1 it is the one that writes it):
            // its centre c, its source's point a on the surface; the patch turned from c's
            // normal to a's, which on the sphere is the turn taking c to a.
            let reach = (radius * radius - p.y * p.y).max(0.0).sqrt();
            let c = equator((phi - reach).max(-0.3));
            let a = (c + offset).normalize();
            let want = pattern(glam::Quat::from_rotation_arc(c, a) * p);
            let got = doc.maps().value(x, y).kd;
            for c in 0..3 {
                worst = worst.max((srgb8(got[c]) - srgb8(want[c])).abs());
            }
            checked += 1;
            left += usize::from(x < 16);
            right += usize::from(x >= SIDE - 16);
        }
    }
    eprintln!(
        "mesh clone across the seam: {checked} texels under the core ({left} at the map's left edge, {right} at its right), worst {worst} levels (8-bit sRGB)"
    );
    assert!(
        checked > 300 && left > 10 && right > 10,
        "{checked} {left} {right}"
    );
    assert!(worst <= 1.0, "{worst} levels");
    assert_eq!(doc.history().undo_steps().count(), 1);
}

#[test]
fn a_mesh_clone_without_a_source_on_the_mesh_or_from_off_it_is_refused() {
    let mut doc = painted_sphere();
    let version = doc.version();
    let e = doc
        .apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Clone,
            points: points(0.0, 0.2, 4),
        })
        .expect_err("no source");
    assert!(e.to_string().contains("source"), "{e}");
    // A canvas source is not a mesh source.
    doc.apply(SettingsCommand::SetCloneSource(glam::Vec2::new(10.0, 10.0)))
        .expect("canvas source");
    let e = doc
        .apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Clone,
            points: points(0.0, 0.2, 4),
        })
        .expect_err("no mesh source");
    assert!(e.to_string().contains("SetSurfaceCloneSource"), "{e}");
    for bad in [Vec3::splat(3.0), Vec3::new(f32::NAN, 0.0, 0.0)] {
        let e = doc
            .apply(SettingsCommand::SetSurfaceCloneSource(bad))
            .expect_err("off the mesh");
        assert!(e.to_string().contains("not on the mesh"), "{e}");
    }
    assert!(doc.surface_clone_source().is_none());
    assert_eq!(doc.version(), version);
    assert_eq!(doc.history().undo_steps().count(), 0);
}

#[test]
fn a_smudge_on_the_mesh_carries_the_picked_colour_across_the_uv_seam() {
    let surface = Surface::new(kapaint_mesh::uv_sphere(64, 32), SIDE, SIDE).expect("bake");
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    let mut doc = Document::new(SIDE, SIDE, settings)
        .expect("doc")
        .with_surface(Some(Arc::new(surface)))
        .expect("surface");
    let brush = |doc: &mut Document, hardness: f32| {
        doc.apply(SettingsCommand::SetBrush(BrushSettings {
            radius_px: 16.0,
            hardness,
            opacity: 1.0,
            pressure_size: false,
            ..BrushSettings::default()
        }))
        .expect("brush");
    };
    let red = MaterialValue::new(Vec3::new(0.9, 0.05, 0.05), Vec3::splat(0.04), 10.0);
    doc.apply(SettingsCommand::SetPrimary(red)).expect("red");
    brush(&mut doc, 1.0);
    doc.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Brush,
        points: points(-0.32, -0.28, 4),
    })
    .expect("red spot");
    brush(&mut doc, 0.7);
    let texel = |phi: f32| {
        let u = (phi / std::f32::consts::TAU).rem_euclid(1.0);
        ((u * SIDE as f32) as u32).min(SIDE - 1)
    };
    assert!(
        doc.maps().value(texel(0.01), SIDE / 2).kd.x < 0.6,
        "grey past the seam before"
    );
    // From the spot across the seam at longitude 0.
    let (from, to) = (-0.3_f32, 0.3_f32);
    doc.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Smudge,
        points: points(from, to, 120),
    })
    .expect("smudged");
    // Along the equator (texel row SIDE / 2; u the longitude over 2 pi), how far the texels
    // stay nearer the red than the grey base.
    let steps = 600;
    let carried = (0..steps)
        .map(|k| from + (to - from) * k as f32 / steps as f32)
        .take_while(|&phi| doc.maps().value(texel(phi), SIDE / 2).kd.x > 0.7)
        .count();
    let fraction = carried as f32 / steps as f32;
    eprintln!(
        "smudge on the mesh at opacity 1 carried the red {:.0} % of the stroke (across the seam)",
        100.0 * fraction
    );
    assert!(fraction >= 0.8, "{fraction}");
    assert!(
        doc.maps().value(texel(0.01), SIDE / 2).kd.x > 0.7,
        "past the seam"
    );
    assert_eq!(doc.history().undo_steps().count(), 2);
}

#[test]
fn the_nearest_surface_texel_is_found_from_near_or_far_and_never_from_nowhere() {
    let s = Surface::new(kapaint_mesh::uv_sphere(32, 16), 128, 128).expect("bake");
    // The texel nearest a point is the one whose baked point is nearest, however far the
    // point lies and whatever radius the search starts from.
    for (point, start) in [
        (Vec3::new(0.2, 0.9, 0.1), 0.01),
        (Vec3::new(30.0, -5.0, 2.0), 0.01),
        (Vec3::new(-0.1, 0.05, 0.0), 100.0),
        (Vec3::new(0.6, -0.7, -0.4), 0.2),
        (Vec3::new(1.0, 0.0, 0.0), 0.001),
        (Vec3::new(0.0, -1.5, 0.0), 0.5),
    ] {
        let found = s.nearest_texel_from(point, start).expect("a texel");
        let want = (0..128 * 128)
            .filter(|&i| s.bake.coverage(i) == kapaint_mesh::bake::Coverage::Surface)
            .map(|i| s.bake.position(i).distance(point))
            .fold(f32::INFINITY, f32::min);
        let got = s.bake.position(found).distance(point);
        assert!((got - want).abs() < 1e-5, "{point}: {got} vs {want}");
    }
    assert_eq!(
        s.nearest_texel_from(Vec3::new(f32::NAN, 0.0, 0.0), 1.0),
        None
    );
    assert_eq!(s.nearest_texel_from(Vec3::splat(f32::INFINITY), 1.0), None);
}

#[test]
fn every_triangle_of_the_sphere_meets_three_others_across_its_uv_seam_too() {
    for (segments, rings) in [(16, 8), (128, 64)] {
        sphere_is_closed(segments, rings);
    }
}

/// Every edge of `uv_sphere(segments, rings)` meets another triangle, across the UV seam and
/// around the poles too: the seam's two columns are at the same points, bit for bit, and each
/// pole's ring at the pole (they were not: the seam's last column at `TAU`, whose sine is not
/// zero in f32, so no walk across the mesh crossed the seam).
fn sphere_is_closed(segments: u32, rings: u32) {
    let surface = Surface::new(kapaint_mesh::uv_sphere(segments, rings), 64, 64).expect("bake");
    let near = surface.neighbours();
    assert_eq!(near.len(), surface.mesh.triangles.len());
    let mut across_seam = 0;
    for (t, sides) in near.iter().enumerate() {
        for (k, &o) in sides.iter().enumerate() {
            // Degenerate pole triangles aside, every edge is shared, and both sides agree.
            if o == u32::MAX {
                continue;
            }
            assert!(
                near[o as usize].contains(&(t as u32)),
                "{t} -> {o} is not mutual"
            );
            let tri = surface.mesh.triangles[t];
            let other = surface.mesh.triangles[o as usize];
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            // Met by position; across the seam the vertex indices differ.
            across_seam += usize::from(!other.contains(&a) || !other.contains(&b));
        }
    }
    let open = near.iter().flatten().filter(|&&o| o == u32::MAX).count();
    eprintln!("{open} open edges, {across_seam} meetings across the seam");
    // Each row of quads meets itself across the seam once, from both sides.
    assert!(across_seam as u32 >= 2 * rings, "the seam is crossed");
    assert_eq!(open, 0, "open edges");
}
