//! Object-space painting on meshes: the ball footprint against brute force, strokes across
//! the UV seams of the sphere and of the real spot mesh, mirroring, facing, and island and
//! part fills.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use kapaint_mesh as builtin;
use kapaint_mesh as mesh;
use kapaint_mesh::bake::Coverage as Baked;
use kapaint_model::brush::{BrushSettings, Resampler, StrokePoint, SurfacePoint, SurfacePos};
use kapaint_model::paint::Footprint;
use kapaint_model::surface::{BallFootprint, Surface};
use kapaint_model::texel::{MaterialValue, Texel};
use kapaint_model::tile::TILE_SIZE;
use kapaint_model::{Command, Document, DocumentSettings, FillRegion, StrokeTool};
use kapaint_model::{HistoryCommand, ImportCommand, PaintCommand, StrokeCommand};

fn sphere_surface(side: u32) -> Arc<Surface> {
    Arc::new(Surface::new(builtin::uv_sphere(64, 32), side, side).expect("bake"))
}

fn settings(brush: BrushSettings) -> DocumentSettings {
    DocumentSettings {
        brush,
        base: MaterialValue::new(Vec3::splat(0.2), Vec3::splat(0.1), 10.0),
        primary: MaterialValue::new(Vec3::new(0.9, 0.5, 0.1), Vec3::splat(0.6), 500.0),
        ..DocumentSettings::default()
    }
}

fn document(surface: &Arc<Surface>, brush: BrushSettings) -> Document {
    Document::new(surface.width(), surface.height(), settings(brush))
        .expect("doc")
        .with_surface(Some(Arc::clone(surface)))
        .expect("surface")
}

fn at(pos: Vec3) -> SurfacePoint {
    StrokePoint {
        pos: SurfacePos {
            point: pos,
            normal: Vec3::ZERO,
        },
        pressure: 1.0,
    }
}

/// Every texel's stored k_d, row-major.
fn kd_map(doc: &Document) -> Vec<[u16; 3]> {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| doc.maps().texel(x, y).kd)
        .collect()
}

#[test]
fn ball_footprint_visits_exactly_the_texels_within_the_ball() {
    let surface = sphere_surface(256);
    let maps = kapaint_model::MaterialMaps::new(256, 256, MaterialValue::default()).expect("maps");
    let brush = BrushSettings {
        hardness: 0.3,
        ..BrushSettings::default()
    };
    let mut state = 7_u32;
    let mut random = || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0
    };
    for case in 0..12 {
        let center = Vec3::new(random(), random(), random()).normalize();
        let radius = 0.05 + 0.3 * random().abs();
        let normal = if case % 2 == 0 { center } else { Vec3::ZERO };
        let fp = BallFootprint {
            surface: &surface,
            center,
            radius,
            normal,
            brush: &brush,
        };
        let mut got = vec![0.0_f32; 256 * 256];
        for id in fp.tiles(&maps) {
            let rect = maps.tile_rect(id);
            fp.visit_tile(id, rect, |i, w| {
                let x = rect.x0 as usize + i % TILE_SIZE;
                let y = rect.y0 as usize + i / TILE_SIZE;
                got[y * 256 + x] = w;
            });
        }
        let r2 = radius * radius;
        for (i, &w) in got.iter().enumerate() {
            let want = if surface.bake.coverage(i) == Baked::Empty {
                0.0
            } else {
                let d2 = surface.bake.position(i).distance_squared(center);
                let facing = if normal == Vec3::ZERO {
                    1.0
                } else {
                    (surface.bake.normal(i).dot(normal) * 4.0).clamp(0.0, 1.0)
                };
                if d2 < r2 {
                    brush.falloff_sq(d2, r2) * facing
                } else {
                    0.0
                }
            };
            assert_eq!(w, want, "case {case}, texel {i}");
        }
    }
}

/// A stroke along a parallel of the sphere from longitude `from` to `to` (radians).
fn parallel_stroke(from: f32, to: f32) -> Command {
    let (y, r) = (0.3_f32, (1.0_f32 - 0.09).sqrt());
    let points = (0..=40)
        .map(|k| {
            let phi = from + (to - from) * k as f32 / 40.0;
            at(Vec3::new(r * phi.cos(), y, -r * phi.sin()))
        })
        .collect();
    StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Brush,
        points,
    }
    .into()
}

#[test]
fn a_stroke_across_the_sphere_seam_matches_the_same_stroke_away_from_it() {
    // The seam is at longitude 0 (u = 0 / 1). Turning the sphere half a turn maps u to
    // u + 1/2, texel x to x + w/2: the stroke across the seam must equal, texel for texel,
    // the same stroke across longitude pi, where the UVs are continuous.
    let side = 512;
    let surface = sphere_surface(side);
    let brush = BrushSettings {
        radius_px: 12.0,
        hardness: 0.4,
        flow: 0.5,
        ..BrushSettings::default()
    };
    let mut seam = document(&surface, brush.clone());
    seam.apply(parallel_stroke(-0.4, 0.4)).expect("stroke");
    let mut away = document(&surface, brush);
    let pi = std::f32::consts::PI;
    away.apply(parallel_stroke(pi - 0.4, pi + 0.4))
        .expect("stroke");
    let (a, b) = (kd_map(&seam), kd_map(&away));
    let base = Texel::encode(settings(BrushSettings::default()).base).kd;
    let w = side as usize;
    let (mut painted_left, mut painted_right, mut worst) = (0, 0, 0_i32);
    for y in 0..w {
        for x in 0..w {
            let i = y * w + x;
            let j = y * w + (x + w / 2) % w;
            if surface.bake.coverage(i) != Baked::Surface
                || surface.bake.coverage(j) != Baked::Surface
            {
                continue;
            }
            for c in 0..3 {
                worst = worst.max((i32::from(a[i][c]) - i32::from(b[j][c])).abs());
            }
            if a[i] != base {
                if x < 8 {
                    painted_left += 1;
                }
                if x >= w - 8 {
                    painted_right += 1;
                }
            }
        }
    }
    // Both sides of the seam are painted, and every texel equals the seamless stroke's to
    // one unorm16 step (float rounding of the baked positions).
    assert!(
        painted_left > 50 && painted_right > 50,
        "{painted_left} {painted_right}"
    );
    assert!(worst <= 1, "largest difference {worst} / 65535");
}

/// A position's bits, to find vertices at the same place.
type PositionKey = [u32; 3];

/// Edges shared (by position) by two triangles whose UVs differ there: UV seams.
fn seam_edges(mesh: &mesh::Mesh) -> Vec<(Vec3, Vec3)> {
    use std::collections::HashMap;
    let uvs = mesh.uvs.as_ref().expect("uvs");
    let key = |v: u32| mesh.positions[v as usize].to_array().map(f32::to_bits);
    let mut edges: HashMap<(PositionKey, PositionKey), Vec<(u32, u32)>> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (ka, kb) = (key(a), key(b));
            let (e, v) = if ka < kb {
                ((ka, kb), (a, b))
            } else {
                ((kb, ka), (b, a))
            };
            edges.entry(e).or_default().push(v);
        }
    }
    edges
        .values()
        .filter(|v| v.len() == 2)
        .filter(|v| {
            let (a, b) = (v[0], v[1]);
            uvs[a.0 as usize] != uvs[b.0 as usize] || uvs[a.1 as usize] != uvs[b.1 as usize]
        })
        .map(|v| {
            (
                mesh.positions[v[0].0 as usize],
                mesh.positions[v[0].1 as usize],
            )
        })
        .collect()
}

#[test]
fn a_stroke_across_a_seam_of_spot_paints_both_sides_as_one() {
    // The reference is computed per texel from its baked 3D position alone, with no index
    // and no knowledge of islands: where the stroke crosses the seam, both islands must
    // hold exactly what a seamless surface would.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/testdata/spot/spot_triangulated.obj");
    let spot = mesh::load(&path).expect("spot");
    let seams = seam_edges(&spot);
    assert!(!seams.is_empty(), "spot has UV seams");
    let side = 1024;
    let surface = Arc::new(Surface::new(spot, side, side).expect("bake"));
    // The longest seam edge, crossed at its middle.
    let &(p, q) = seams
        .iter()
        .max_by(|a, b| a.0.distance(a.1).total_cmp(&b.0.distance(b.1)))
        .expect("seam");
    let mid = (p + q) / 2.0;
    let normal = surface.normal_near(mid, 0.05).expect("surface at the seam");
    let across = (q - p).cross(normal).normalize();
    let brush = BrushSettings {
        radius_px: 10.0,
        hardness: 0.5,
        flow: 0.4,
        front_faces_only: false,
        ..BrushSettings::default()
    };
    let radius = brush.radius_px * surface.units_per_texel;
    let reach = 3.0 * radius;
    let input: Vec<SurfacePoint> = (0..=10)
        .map(|k| at(mid + across * (reach * (k as f32 / 5.0 - 1.0))))
        .collect();
    let mut doc = document(&surface, brush.clone());
    doc.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Brush,
        points: input.clone(),
    })
    .expect("stroke");

    // The dab centres, as the stroke places them.
    let mut resampler = Resampler::<SurfacePos>::new(brush.spacing_px() * surface.units_per_texel);
    let mut dabs = Vec::new();
    for p in &input {
        resampler.push(*p, &mut dabs).expect("within the dab limit");
    }
    let s = doc.settings();
    // On one layer over the base, a texel is the base blended towards the primary at the
    // stroke's coverage, with the brush's mode.
    let (mode, primary) = (s.brush.blend, s.primary.sanitized());
    let base = Texel::encode(s.base).decode();
    let r2 = radius * radius;
    let mut islands = std::collections::BTreeSet::new();
    let (w, got) = (side as usize, kd_map(&doc));
    for (i, &kd) in got.iter().enumerate() {
        let mut coverage = 0.0_f32;
        if surface.bake.coverage(i) != Baked::Empty {
            for dab in &dabs {
                let d2 = surface.bake.position(i).distance_squared(dab.pos.point);
                let wgt = if d2 < r2 {
                    brush.falloff_sq(d2, r2)
                } else {
                    0.0
                };
                let next = coverage + (1.0 - coverage) * (wgt * brush.flow).min(1.0);
                coverage = coverage.max(next);
            }
        }
        let blended = Vec3::from_array(std::array::from_fn(|c| {
            mode.apply(base.kd[c], primary.kd[c], coverage)
        }));
        let want = Texel::encode(MaterialValue {
            kd: blended,
            ..base
        })
        .kd;
        for c in 0..3 {
            let diff = (i32::from(kd[c]) - i32::from(want[c])).abs();
            assert!(
                diff <= 1,
                "texel ({}, {}): {kd:?} vs {want:?}",
                i % w,
                i / w
            );
        }
        if coverage > 0.5 && surface.bake.coverage(i) == Baked::Surface {
            islands.insert(surface.bake.island(i));
        }
    }
    assert!(
        islands.len() >= 2,
        "the stroke reaches both islands: {islands:?}"
    );
}

#[test]
fn spacing_on_the_surface_does_not_depend_on_input_sampling() {
    let surface = sphere_surface(256);
    let brush = BrushSettings {
        radius_px: 8.0,
        flow: 0.3,
        ..BrushSettings::default()
    };
    // Points along a curve on the sphere (an arc of its equator, winding up and down).
    let line = |n: usize| {
        (0..=n)
            .map(|k| {
                let t = k as f32 / n as f32;
                let (lon, lat) = (0.64 + 0.5 * t, 0.15 * (6.0 * t).sin());
                at(Vec3::new(
                    lon.sin() * lat.cos(),
                    lat.sin(),
                    lon.cos() * lat.cos(),
                ))
            })
            .collect::<Vec<_>>()
    };
    let paint = |points| {
        let mut doc = document(&surface, brush.clone());
        doc.apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Brush,
            points,
        })
        .expect("stroke");
        kd_map(&doc)
    };
    let (coarse, fine) = (paint(line(60)), paint(line(600)));
    let worst = coarse
        .iter()
        .zip(&fine)
        .flat_map(|(a, b)| (0..3).map(|c| (i32::from(a[c]) - i32::from(b[c])).abs()))
        .max();
    // The dabs drift by what the coarse chords cut off the curve's length (measured:
    // 114 / 65535, 0.2 %, as on the UV canvas).
    assert!(worst.is_some_and(|d| d <= 160), "{worst:?}");
}

#[test]
fn object_space_mirror_paints_the_reflected_dab() {
    let surface = sphere_surface(256);
    let p = Vec3::new(0.6, 0.3, 0.5).normalize();
    let mirrored = Vec3::new(-p.x, p.y, p.z);
    let brush = BrushSettings {
        radius_px: 10.0,
        mirror_x: true,
        ..BrushSettings::default()
    };
    let mut one = document(&surface, brush.clone());
    one.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Brush,
        points: vec![at(p)],
    })
    .expect("stroke");
    let mut two = document(
        &surface,
        BrushSettings {
            mirror_x: false,
            ..brush
        },
    );
    two.apply(StrokeCommand::BeginStroke(StrokeTool::Brush))
        .expect("begin");
    // Two separate dabs in one stroke: the same as one mirrored dab.
    two.apply(StrokeCommand::SurfaceStrokeTo(at(p)))
        .expect("dab");
    two.apply(StrokeCommand::EndStroke).expect("end");
    two.apply(StrokeCommand::BeginStroke(StrokeTool::Brush))
        .expect("begin");
    two.apply(StrokeCommand::SurfaceStrokeTo(at(mirrored)))
        .expect("dab");
    two.apply(StrokeCommand::EndStroke).expect("end");
    assert_eq!(kd_map(&one), kd_map(&two));
    assert_ne!(
        kd_map(&one),
        kd_map(&document(&surface, BrushSettings::default()))
    );
}

#[test]
fn front_faces_only_keeps_a_big_brush_on_the_near_side() {
    let surface = sphere_surface(128);
    for front in [true, false] {
        let mut doc = document(
            &surface,
            BrushSettings {
                radius_px: 4096.0,
                hardness: 1.0,
                front_faces_only: front,
                ..BrushSettings::default()
            },
        );
        doc.apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Brush,
            points: vec![at(Vec3::Y)],
        })
        .expect("stroke");
        let painted = |pos: Vec3| {
            let (i, _) = (0..surface.bake.len())
                .map(|i| (i, surface.bake.position(i)))
                .filter(|(i, _)| surface.bake.coverage(*i) == Baked::Surface)
                .min_by(|a, b| a.1.distance(pos).total_cmp(&b.1.distance(pos)))
                .expect("texel");
            let (x, y) = ((i % 128) as u32, (i / 128) as u32);
            doc.maps().value(x, y).kd.x > 0.5
        };
        assert!(painted(Vec3::new(0.0, 0.9, 0.4)));
        assert_eq!(
            painted(Vec3::new(0.0, -0.9, 0.4)),
            !front,
            "front only: {front}"
        );
    }
}

#[test]
fn fills_by_island_and_by_part() {
    let surface = Arc::new(Surface::new(builtin::cube(), 128, 128).expect("bake"));
    let (x, y) = (0..128 * 128)
        .find(|&i| surface.bake.coverage(i) == Baked::Surface)
        .map(|i| ((i % 128) as u32, (i / 128) as u32))
        .expect("a covered texel");
    let island = surface.bake.island((y * 128 + x) as usize);
    let mut doc = document(&surface, BrushSettings::default());
    doc.apply(PaintCommand::Fill(FillRegion::Island { x, y }))
        .expect("fill island");
    let kd = kd_map(&doc);
    let painted = Texel::encode(doc.settings().primary).kd;
    for (i, v) in kd.iter().enumerate() {
        let inside = surface.bake.island(i) == island;
        assert_eq!(*v == painted, inside, "texel {i}");
    }
    doc.apply(PaintCommand::Fill(FillRegion::Part { x, y }))
        .expect("fill part");
    let kd = kd_map(&doc);
    for (i, v) in kd.iter().enumerate() {
        let on_mesh = surface.bake.triangle(i).is_some();
        assert_eq!(*v == painted, on_mesh, "texel {i}");
    }
    doc.apply(HistoryCommand::Undo).expect("undo");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(kd_map(&doc).iter().all(|v| *v != painted));
}

#[test]
fn mesh_commands_without_a_mesh_are_clear_errors() {
    let mut doc = Document::new(64, 64, DocumentSettings::default()).expect("doc");
    let err = doc
        .apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Brush,
            points: vec![at(Vec3::Y)],
        })
        .expect_err("no surface");
    assert!(err.to_string().contains("needs a mesh"), "{err}");
    let err = doc
        .apply(PaintCommand::Fill(FillRegion::Island { x: 1, y: 1 }))
        .expect_err("no surface");
    assert!(err.to_string().contains("needs a mesh"), "{err}");
    let other = sphere_surface(32);
    assert!(doc.with_surface(Some(other)).is_err(), "size mismatch");
}

#[test]
fn a_resize_is_one_undo_step_that_brings_back_the_maps_and_their_surface() {
    use kapaint_model::resize::{ResizedMaps, resized_stack};
    let surface = sphere_surface(128);
    let mut doc = document(&surface, BrushSettings::default());
    let on_sphere = |doc: &mut Document| {
        let pos = SurfacePos {
            point: Vec3::new(0.0, 0.0, 1.0),
            normal: Vec3::Z,
        };
        doc.apply(StrokeCommand::SurfaceStroke {
            tool: StrokeTool::Brush,
            points: vec![SurfacePoint { pos, pressure: 1.0 }],
        })
        .expect("stroke");
    };
    on_sphere(&mut doc);
    let before: Vec<Texel> = texels(&doc);
    let version = doc.version();
    let small = resized_stack(doc.stack(), 64, 64).expect("resized");
    let baked = Arc::new(Surface::new(surface.mesh.clone(), 64, 64).expect("bake"));
    doc.apply(ImportCommand::Resize(ResizedMaps(Arc::new((
        small,
        Some(baked),
    )))))
    .expect("resize");
    assert_eq!(
        (doc.maps().width(), doc.surface().map(|s| s.width())),
        (64, Some(64))
    );
    assert_ne!(doc.version(), version, "a resize is a change");
    let after = texels(&doc);
    // Painting on the mesh at the new size works (the surface follows the maps).
    on_sphere(&mut doc);
    // Two steps back: the stroke, then the resize; the maps and the surface return exactly.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), after);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), before);
    assert!(Arc::ptr_eq(doc.surface().expect("surface"), &surface));
    assert_eq!(
        doc.version(),
        version,
        "undone to the state it had: the version it had"
    );
    // Redo brings the resized maps back, bit-exactly.
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert_eq!(texels(&doc), after);
    assert_eq!(doc.surface().map(|s| s.width()), Some(64));
    // A baked surface of another size is refused, and nothing changes.
    let wrong = Arc::new(Surface::new(surface.mesh.clone(), 32, 32).expect("bake"));
    let big = resized_stack(doc.stack(), 128, 128).expect("resized");
    assert!(
        doc.apply(ImportCommand::Resize(ResizedMaps(Arc::new((
            big,
            Some(wrong)
        )))))
        .is_err()
    );
    assert_eq!(texels(&doc), after);
}

fn texels(doc: &Document) -> Vec<Texel> {
    let mut out = Vec::new();
    doc.maps().for_each_texel(|_, _, t| out.push(t));
    out
}
