//! Issue 56 on the canvas: clone (aligned, from the composite before the stroke), smudge
//! (what is under the brush dragged along, `n` in log space, the energy guard kept) and the
//! stencil (the brush, eraser and clone through an image), each one undo step, with bad input
//! refused and the document unchanged.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::{Vec2, Vec3};
use kapaint_model::brush::{BrushSettings, StrokePoint};
use kapaint_model::paint_image::PaintImage;
use kapaint_model::texel::{Texel, linear_to_srgb};
use kapaint_model::{
    Document, DocumentSettings, HistoryCommand, MaterialValue, SettingsCommand, StrokeCommand,
    StrokeTool,
};

#[path = "common/layer_doc.rs"]
#[expect(dead_code, reason = "its 192 x 128 document is not used here")]
mod layer_doc;
use layer_doc::{mask_gray, run, texels};

/// A 256 x 256 document over a grey base.
fn document() -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    Document::new(256, 256, settings).expect("document")
}

fn brush(doc: &mut Document, radius: f32, hardness: f32, opacity: f32) {
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: radius,
        hardness,
        opacity,
        pressure_size: false,
        ..BrushSettings::default()
    }))
    .expect("brush");
}

fn line(from: Vec2, to: Vec2, steps: usize) -> Vec<StrokePoint> {
    (0..=steps)
        .map(|k| StrokePoint {
            pos: from.lerp(to, k as f32 / steps as f32),
            pressure: 1.0,
        })
        .collect()
}

fn stroke(doc: &mut Document, tool: StrokeTool, points: Vec<StrokePoint>) {
    doc.apply(StrokeCommand::Stroke { tool, points })
        .expect("stroke");
}

fn paint(doc: &mut Document, value: MaterialValue, at: Vec2, radius: f32) {
    doc.apply(SettingsCommand::SetPrimary(value))
        .expect("primary");
    brush(doc, radius, 1.0, 1.0);
    stroke(doc, StrokeTool::Brush, line(at, at, 1));
}

/// A patch of texture: stripes of three materials across `(40..104, 40..104)`.
fn patterned() -> Document {
    let mut doc = document();
    let stripes = [
        MaterialValue::new(Vec3::new(0.8, 0.1, 0.1), Vec3::splat(0.1), 2000.0),
        MaterialValue::new(Vec3::new(0.1, 0.6, 0.2), Vec3::splat(0.3), 8.0),
        MaterialValue::new(Vec3::new(0.2, 0.2, 0.7), Vec3::splat(0.05), 120.0),
    ];
    for (k, v) in stripes.into_iter().enumerate() {
        doc.apply(SettingsCommand::SetPrimary(v)).expect("primary");
        brush(&mut doc, 6.0, 1.0, 1.0);
        let y = 48.0 + 16.0 * k as f32;
        stroke(
            &mut doc,
            StrokeTool::Brush,
            line(Vec2::new(40.0, y), Vec2::new(104.0, y + 8.0), 16),
        );
    }
    doc
}

fn srgb8(c: f32) -> i32 {
    (linear_to_srgb(c) * 255.0).round() as i32
}

/// The largest difference in 8-bit sRGB levels of `k_d` and `k_s`, and the largest ratio of
/// `n`, between texels `a` and `b`.
fn difference(a: Texel, b: Texel) -> (i32, f32) {
    let (a, b) = (a.decode(), b.decode());
    let mut levels = 0;
    for (x, y) in [(a.kd, b.kd), (a.ks, b.ks)] {
        for c in 0..3 {
            levels = levels.max((srgb8(x[c]) - srgb8(y[c])).abs());
        }
    }
    (levels, (a.n / b.n).max(b.n / a.n))
}

#[test]
fn clone_reproduces_its_source_under_the_hard_core_and_keeps_its_offset() {
    let mut doc = patterned();
    let source_of = |doc: &Document, x: u32, y: u32| doc.maps().texel(x, y);
    let original: Vec<Vec<Texel>> = (0..256)
        .map(|y| (0..256).map(|x| source_of(&doc, x, y)).collect())
        .collect();
    doc.apply(SettingsCommand::SetCloneSource(Vec2::new(72.0, 72.0)))
        .expect("source");
    brush(&mut doc, 20.0, 0.8, 1.0);
    let steps_before = doc.history().undo_steps().count();
    // The first point takes the source's texel: the offset is (-100, -90) texels.
    stroke(
        &mut doc,
        StrokeTool::Clone,
        line(Vec2::new(172.0, 162.0), Vec2::new(190.0, 170.0), 6),
    );
    assert_eq!(doc.history().undo_steps().count(), steps_before + 1);
    assert_eq!(
        doc.clone_source(),
        Some((Vec2::new(72.0, 72.0), Some(Vec2::new(-100.0, -90.0))))
    );
    // The hard core (radius 16), less the dab spacing (5 texels: the last dab may stop short
    // of the last point) and a texel.
    let core = 20.0 * 0.8 - 5.0 - 1.0;
    let mut checked = 0;
    let (mut worst, mut worst_n) = (0, 1.0_f32);
    for y in 140..200_u32 {
        for x in 150..220_u32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let along = |a: Vec2, b: Vec2| {
                let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                p.distance(a.lerp(b, t))
            };
            if along(Vec2::new(172.0, 162.0), Vec2::new(190.0, 170.0)) > core {
                continue;
            }
            let got = doc.maps().texel(x, y);
            let want = original[(y - 90) as usize][(x - 100) as usize];
            let (levels, n) = difference(got, want);
            worst = worst.max(levels);
            worst_n = worst_n.max(n);
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked}");
    assert!(worst <= 1 && worst_n < 1.01, "{worst} levels, n x{worst_n}");
    // Aligned: the next stroke keeps the offset.
    stroke(
        &mut doc,
        StrokeTool::Clone,
        line(Vec2::new(120.0, 200.0), Vec2::new(121.0, 200.0), 1),
    );
    let (levels, _) = difference(doc.maps().texel(120, 200), original[110][20]);
    assert!(levels <= 1, "{levels}");
    // A new source starts a new alignment.
    doc.apply(SettingsCommand::SetCloneSource(Vec2::new(60.0, 50.0)))
        .expect("source");
    assert_eq!(doc.clone_source(), Some((Vec2::new(60.0, 50.0), None)));
}

#[test]
fn clone_without_a_source_or_from_outside_the_map_is_refused_and_changes_nothing() {
    let mut doc = patterned();
    let before = texels(&doc);
    brush(&mut doc, 10.0, 1.0, 1.0);
    let e = doc
        .apply(StrokeCommand::Stroke {
            tool: StrokeTool::Clone,
            points: line(Vec2::new(10.0, 10.0), Vec2::new(20.0, 10.0), 4),
        })
        .expect_err("no source");
    assert!(e.to_string().contains("SetCloneSource"), "{e}");
    for bad in [
        Vec2::new(-1.0, 5.0),
        Vec2::new(256.0, 5.0),
        Vec2::new(3.0, f32::NAN),
    ] {
        let e = doc
            .apply(SettingsCommand::SetCloneSource(bad))
            .expect_err("outside");
        assert!(e.to_string().contains("outside"), "{e}");
    }
    assert_eq!(doc.clone_source(), None);
    assert!(texels(&doc) == before, "a refused command changed the maps");
}

#[test]
fn smudge_carries_the_picked_colour_along_most_of_the_stroke() {
    let mut doc = document();
    let red = MaterialValue::new(Vec3::new(0.9, 0.05, 0.05), Vec3::splat(0.04), 10.0);
    paint(&mut doc, red, Vec2::new(40.0, 128.0), 16.0);
    brush(&mut doc, 16.0, 0.7, 1.0);
    let length = 160.0;
    stroke(
        &mut doc,
        StrokeTool::Smudge,
        line(Vec2::new(40.0, 128.0), Vec2::new(40.0 + length, 128.0), 80),
    );
    // Along the stroke's line, how far the texels stay nearer the red than the grey base.
    let reddish = (40..(40 + length as u32))
        .take_while(|&x| doc.maps().value(x, 128).kd.x > 0.7)
        .count();
    eprintln!(
        "smudge at opacity 1 carried the red {reddish} of {length} texels ({:.0} %)",
        100.0 * reddish as f32 / length
    );
    assert!(reddish as f32 >= 0.8 * length, "{reddish}");
    // Beside the stroke the base is untouched.
    assert!(
        (doc.maps().value(120, 20).kd - Vec3::splat(0.5))
            .abs()
            .max_element()
            < 1e-4
    );
}

#[test]
fn smudge_blends_n_in_log_space_and_keeps_the_energy_guard() {
    let mut doc = document();
    let glossy = MaterialValue::new(Vec3::splat(0.1), Vec3::splat(0.9), 2000.0);
    paint(&mut doc, glossy, Vec2::new(60.0, 128.0), 20.0);
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 20.0,
        hardness: 1.0,
        opacity: 0.5,
        pressure_size: false,
        energy_guard: true,
        ..BrushSettings::default()
    }))
    .expect("brush");
    stroke(
        &mut doc,
        StrokeTool::Smudge,
        line(Vec2::new(60.0, 128.0), Vec2::new(140.0, 128.0), 40),
    );
    // Half-way between n = 2000 and the base's 10 in log space is about 141; a linear mean
    // would be about 1000. Somewhere along the smear the exponent passes through the
    // geometric range without the linear one's jump.
    let ns: Vec<f32> = (60..160).map(|x| doc.maps().value(x, 128).n).collect();
    assert!(
        ns.iter().any(|&n| (60.0..400.0).contains(&n)),
        "no exponent between: {ns:?}"
    );
    for x in 40..200 {
        for y in 100..156 {
            let v = doc.maps().value(x, y);
            assert!(
                (v.kd + v.ks).max_element() <= 1.0 + 2e-3,
                "({x}, {y}): {v:?}"
            );
        }
    }
}

/// A smudge on a mask drags the mask's own gray (as it is at each dab), not the composite's.
#[test]
fn smudge_on_a_mask_drags_its_gray() {
    let mut doc = document();
    run(
        &mut doc,
        r"(commands: [
            AddMask, SelectMask,
            SetBrush((radius_px: 16.0, hardness: 1.0, flow: 1.0, opacity: 1.0)),
            SetPrimary((kd: (0.0, 0.0, 0.0), ks: (0.5, 0.5, 0.5), n: 10.0)),
            Stroke(tool: Brush, points: [(pos: (40.0, 128.0), pressure: 1.0)]),
        ])",
    );
    assert!(mask_gray(&doc, 40, 128) < 0.01 && mask_gray(&doc, 100, 128) > 0.99);
    brush(&mut doc, 16.0, 0.7, 1.0);
    let length = 120.0;
    stroke(
        &mut doc,
        StrokeTool::Smudge,
        line(Vec2::new(40.0, 128.0), Vec2::new(40.0 + length, 128.0), 60),
    );
    let dark = (40..(40 + length as u32))
        .take_while(|&x| mask_gray(&doc, x, 128) < 0.3)
        .count();
    assert!(dark as f32 >= 0.6 * length, "the black went {dark} texels");
    assert!(
        mask_gray(&doc, 120, 20) > 0.99,
        "beside the stroke the mask is white"
    );
}

/// A 64 x 4 image, black on the left half and white on the right.
fn half_white(dir: &std::path::Path) -> std::path::PathBuf {
    let mut img = image::GrayImage::new(64, 4);
    for x in 32..64 {
        for y in 0..4 {
            img.put_pixel(x, y, image::Luma([255]));
        }
    }
    let path = dir.join("half.png");
    img.save(&path).expect("save");
    path
}

fn stencil(path: &std::path::Path, center: Vec2, size: f32, rotation: f32) -> SettingsCommand {
    let mut image = PaintImage::named(path);
    image.load(std::path::Path::new("/")).expect("load");
    SettingsCommand::SetStencil {
        image,
        center,
        size,
        rotation,
        opacity: 1.0,
        tiled: false,
        view: None,
    }
}

#[test]
fn the_brush_paints_only_through_the_stencils_light_part() {
    let dir = std::env::temp_dir().join(format!("kapaint-stencil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = half_white(&dir);
    let red = MaterialValue::new(Vec3::new(0.9, 0.05, 0.05), Vec3::splat(0.04), 10.0);
    for (rotation, painted, kept) in [
        (0.0, (150, 128), (100, 128)),
        // Turned half a turn, the white half lies on the left.
        (180.0, (100, 128), (150, 128)),
    ] {
        let mut doc = document();
        doc.apply(stencil(&path, Vec2::new(128.0, 128.0), 128.0, rotation))
            .expect("stencil");
        doc.apply(SettingsCommand::SetPrimary(red))
            .expect("primary");
        brush(&mut doc, 12.0, 1.0, 1.0);
        stroke(
            &mut doc,
            StrokeTool::Brush,
            line(Vec2::new(80.0, 128.0), Vec2::new(176.0, 128.0), 24),
        );
        let at = |doc: &Document, (x, y)| doc.maps().value(x, y).kd.x;
        let (p, k) = (at(&doc, painted), at(&doc, kept));
        assert!(p > 0.85, "rotation {rotation}: {p}");
        assert!((k - 0.5).abs() < 1e-3, "rotation {rotation}: {k}");
        // Cleared, the brush paints everywhere again.
        doc.apply(SettingsCommand::ClearStencil).expect("clear");
        stroke(
            &mut doc,
            StrokeTool::Brush,
            line(Vec2::new(80.0, 128.0), Vec2::new(176.0, 128.0), 24),
        );
        let k = at(&doc, kept);
        assert!(k > 0.85, "rotation {rotation}: {k}");
    }
    // Bad numbers are refused and no stencil is set.
    let mut doc = document();
    for (size, center) in [
        (0.0, Vec2::ZERO),
        (-3.0, Vec2::ZERO),
        (f32::INFINITY, Vec2::ZERO),
        (10.0, Vec2::new(f32::NAN, 0.0)),
    ] {
        assert!(doc.apply(stencil(&path, center, size, 0.0)).is_err());
    }
    assert!(doc.stencil().is_none());
    // An image the command names but nobody loaded is refused, naming it.
    let e = doc
        .apply(SettingsCommand::SetStencil {
            image: PaintImage::named("not-loaded.png"),
            center: Vec2::ZERO,
            size: 10.0,
            rotation: 0.0,
            opacity: 1.0,
            tiled: false,
            view: None,
        })
        .expect_err("not loaded");
    assert!(e.to_string().contains("not-loaded.png"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_script_names_the_new_tools_and_each_stroke_is_one_step() {
    let mut doc = patterned();
    let before = texels(&doc);
    run(
        &mut doc,
        r"(commands: [
            SetBrush((radius_px: 10, hardness: 1, pressure_size: false)),
            SetCloneSource((60, 60)),
            Stroke(tool: Clone, points: [(pos: (150, 150), pressure: 1), (pos: (170, 150), pressure: 1)]),
            Stroke(tool: Smudge, points: [(pos: (60, 60), pressure: 1), (pos: (90, 60), pressure: 1)]),
            ClearStencil,
        ])",
    );
    assert!(texels(&doc) != before);
    doc.apply(HistoryCommand::Undo).expect("undo");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(texels(&doc) == before, "two strokes, two steps");
}

/// A stroke keeps the stencil's weights where its dabs have read them; a stencil turned
/// inside the stroke is read afresh, not from what the stroke kept.
#[test]
fn a_stencil_turned_inside_a_stroke_paints_through_its_new_place() {
    let dir = std::env::temp_dir().join(format!("kapaint-turned-stencil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = half_white(&dir);
    let red = MaterialValue::new(Vec3::new(0.9, 0.05, 0.05), Vec3::splat(0.04), 10.0);
    let mut doc = document();
    doc.apply(stencil(&path, Vec2::new(128.0, 128.0), 128.0, 0.0))
        .expect("stencil");
    doc.apply(SettingsCommand::SetPrimary(red))
        .expect("primary");
    brush(&mut doc, 12.0, 1.0, 1.0);
    let along = |doc: &mut Document| {
        for p in line(Vec2::new(80.0, 128.0), Vec2::new(176.0, 128.0), 24) {
            doc.apply(StrokeCommand::StrokeTo(p)).expect("dab");
        }
    };
    doc.apply(StrokeCommand::BeginStroke(StrokeTool::Brush))
        .expect("begin");
    along(&mut doc);
    let at = |doc: &Document, (x, y)| doc.maps().value(x, y).kd.x;
    assert!(
        (at(&doc, (100, 128)) - 0.5).abs() < 1e-3,
        "held back on the left"
    );
    // Turned half a turn, its white half lies on the left: the same stroke paints there now.
    doc.apply(stencil(&path, Vec2::new(128.0, 128.0), 128.0, 180.0))
        .expect("turned");
    along(&mut doc);
    doc.apply(StrokeCommand::EndStroke).expect("end");
    assert!(at(&doc, (100, 128)) > 0.85, "{}", at(&doc, (100, 128)));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_grey_stencil_lets_its_share_of_the_paint_through_however_many_dabs_pass() {
    let dir = std::env::temp_dir().join(format!("kapaint-grey-stencil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("grey.png");
    image::GrayImage::from_pixel(8, 8, image::Luma([128]))
        .save(&path)
        .expect("save");
    let mut doc = document();
    doc.apply(stencil(&path, Vec2::new(128.0, 128.0), 200.0, 0.0))
        .expect("stencil");
    let red = MaterialValue::new(Vec3::new(0.9, 0.05, 0.05), Vec3::splat(0.04), 10.0);
    doc.apply(SettingsCommand::SetPrimary(red))
        .expect("primary");
    brush(&mut doc, 16.0, 1.0, 1.0);
    // Forty dabs pass over the middle: a multiplied footprint would build up to full red.
    stroke(
        &mut doc,
        StrokeTool::Brush,
        line(Vec2::new(100.0, 128.0), Vec2::new(156.0, 128.0), 40),
    );
    let want = 0.5 + (0.9 - 0.5) * 128.0 / 255.0;
    let got = doc.maps().value(128, 128).kd.x;
    assert!((got - want).abs() < 2e-3, "{got} vs {want}");
    let _ = std::fs::remove_dir_all(&dir);
}
