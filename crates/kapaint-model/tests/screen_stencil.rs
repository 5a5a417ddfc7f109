//! Issue 56, item 3 in the viewport: a stencil on the screen of a view, read by strokes on the
//! mesh where each texel's surface point projects through that view; a stencil on the canvas
//! read by strokes on the mesh where each texel lies; bad views refused, the stencil kept.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use kapaint_model::brush::{BrushSettings, StrokePoint, SurfacePoint, SurfacePos};
use kapaint_model::paint::ScreenView;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::surface::Surface;
use kapaint_model::{
    Document, DocumentSettings, MaterialValue, SettingsCommand, StrokeCommand, StrokeTool,
};

const SIDE: u32 = 256;
const GREY: f32 = 0.5;

fn sphere() -> Document {
    let surface = Surface::new(kapaint_mesh::uv_sphere(64, 32), SIDE, SIDE).expect("bake");
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(GREY), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    let mut doc = Document::new(SIDE, SIDE, settings).expect("document");
    doc = doc.with_surface(Some(Arc::new(surface))).expect("surface");
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 40.0,
        hardness: 1.0,
        opacity: 1.0,
        pressure_size: false,
        front_faces_only: false,
        ..BrushSettings::default()
    }))
    .expect("brush");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.05, 0.05),
        Vec3::splat(0.04),
        10.0,
    )))
    .expect("primary");
    doc
}

/// A `w x h` image, black on its left half and white on its right.
fn half_white(w: u32, h: u32) -> PaintImage {
    let dir = std::env::temp_dir().join(format!("kapaint-screen-stencil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let mut img = image::GrayImage::new(w, h);
    for x in w / 2..w {
        for y in 0..h {
            img.put_pixel(x, y, image::Luma([255]));
        }
    }
    let path = dir.join(format!("half-{w}x{h}.png"));
    img.save(&path).expect("save");
    let mut image = PaintImage::named(&path);
    image.load(std::path::Path::new("/")).expect("load");
    image
}

fn front_view() -> ScreenView {
    ScreenView {
        eye: Vec3::new(0.0, 0.0, 4.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov: 35.0,
        size: Vec2::new(400.0, 300.0),
    }
}

fn set_stencil(
    image: &PaintImage,
    center: Vec2,
    size: f32,
    view: Option<ScreenView>,
) -> SettingsCommand {
    SettingsCommand::SetStencil {
        image: image.clone(),
        center,
        size,
        rotation: 0.0,
        opacity: 1.0,
        tiled: false,
        view,
    }
}

/// A stroke on the sphere's front, across the middle of the front view.
fn front_stroke(doc: &mut Document) {
    let points = (0..=20)
        .map(|k| {
            let p = Vec3::new(-0.3 + 0.03 * k as f32, 0.0, 1.0).normalize();
            SurfacePoint {
                pos: SurfacePos {
                    point: p,
                    normal: p,
                },
                pressure: 1.0,
            }
        })
        .collect();
    doc.apply(StrokeCommand::SurfaceStroke {
        tool: StrokeTool::Brush,
        points,
    })
    .expect("stroke");
}

/// Over the texels under the hard core of [`front_stroke`] (on the front, near the equator,
/// inside it), those `side` says should be painted (`Some(true)`) or held back
/// (`Some(false)`; `None`: too near the stencil's edge to say) and how many are not:
/// `(painted, held, wrong)`.
fn sides(doc: &Document, side: impl Fn(u32, Vec3) -> Option<bool>) -> (usize, usize, usize) {
    let s = doc.surface().expect("surface");
    let (mut painted, mut held, mut wrong) = (0, 0, 0);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let t = (y * SIDE + x) as usize;
            if s.bake.triangle(t).is_none() {
                continue;
            }
            let p = s.bake.position(t);
            if p.z < 0.5 || p.y.abs() > 0.05 || p.x.abs() > 0.2 {
                continue;
            }
            let red = doc.maps().value(x, y).kd.x;
            match side(x, p) {
                Some(true) => {
                    painted += 1;
                    wrong += usize::from(red < 0.85);
                }
                Some(false) => {
                    held += 1;
                    wrong += usize::from((red - GREY).abs() > 1e-3);
                }
                None => {}
            }
        }
    }
    (painted, held, wrong)
}

#[test]
fn a_stencil_on_the_screen_paints_where_the_surface_projects_through_its_light_part() {
    let mut doc = sphere();
    let image = half_white(400, 300);
    // The whole picture: its right half (x >= 200 px) lets the paint through.
    let view = front_view();
    doc.apply(set_stencil(
        &image,
        Vec2::new(200.0, 150.0),
        400.0,
        Some(view),
    ))
    .expect("stencil");
    front_stroke(&mut doc);
    let to_clip = view.to_clip();
    let (painted, held, wrong) = sides(&doc, |_, p| {
        let sx = view.to_screen(&to_clip, p).expect("in front").x;
        (!(199.0..=201.0).contains(&sx)).then_some(sx > 201.0)
    });
    eprintln!(
        "screen stencil: {painted} texels painted, {held} held back, {wrong} wrong (more than a pixel from the stencil's edge)"
    );
    assert!(painted > 50 && held > 50, "{painted} {held}");
    assert_eq!(wrong, 0);
    // The same stencil seen from behind (+X on the left of the screen) holds back the other half.
    let mut doc = sphere();
    let behind = ScreenView {
        eye: Vec3::new(0.0, 0.0, -4.0),
        ..front_view()
    };
    doc.apply(set_stencil(
        &image,
        Vec2::new(200.0, 150.0),
        400.0,
        Some(behind),
    ))
    .expect("stencil");
    front_stroke(&mut doc);
    let red_at = |doc: &Document, p: Vec3| {
        let s = doc.surface().expect("surface");
        let t = s.nearest_texel(p, 0.05).expect("near");
        let w = SIDE as usize;
        doc.maps().value((t % w) as u32, (t / w) as u32).kd.x
    };
    let (left, right) = (
        Vec3::new(-0.1, 0.0, 1.0).normalize(),
        Vec3::new(0.1, 0.0, 1.0).normalize(),
    );
    assert!(red_at(&doc, left) > 0.85 && (red_at(&doc, right) - GREY).abs() < 1e-3);
    // A canvas stroke ignores a stencil on the screen.
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![StrokePoint {
            pos: Vec2::new(10.0, 10.0),
            pressure: 1.0,
        }],
    })
    .expect("canvas stroke");
    assert!(doc.maps().value(10, 10).kd.x > 0.85);
}

#[test]
fn a_stencil_on_the_canvas_holds_back_a_mesh_stroke_where_its_texels_lie() {
    let mut doc = sphere();
    let image = half_white(256, 256);
    // Its edge down the middle of the stroke (texel column 192, the sphere's front): texels
    // right of it let the paint through.
    doc.apply(set_stencil(&image, Vec2::new(192.0, 128.0), 256.0, None))
        .expect("stencil");
    front_stroke(&mut doc);
    let (painted, held, wrong) = sides(&doc, |x, _| (!(191..=193).contains(&x)).then_some(x > 193));
    assert!(painted > 20 && held > 20, "{painted} {held}");
    assert_eq!(wrong, 0);
}

/// A script's commands, as `kapaint script` reads them.
#[derive(serde::Deserialize)]
struct Script {
    commands: Vec<kapaint_model::Command>,
}

#[test]
fn bad_views_are_refused_and_the_stencil_is_kept() {
    let mut doc = sphere();
    let image = half_white(64, 48);
    doc.apply(set_stencil(
        &image,
        Vec2::new(200.0, 150.0),
        400.0,
        Some(front_view()),
    ))
    .expect("stencil");
    let kept = doc.stencil().cloned();
    let v = front_view();
    for (bad, says) in [
        (ScreenView { target: v.eye, ..v }, "eye away"),
        (ScreenView { up: Vec3::Z, ..v }, "up direction"),
        (ScreenView { fov: 0.0, ..v }, "field of view"),
        (ScreenView { fov: 180.0, ..v }, "field of view"),
        (
            ScreenView {
                size: Vec2::new(0.0, 300.0),
                ..v
            },
            "1 x 1",
        ),
        (
            ScreenView {
                eye: Vec3::new(f32::NAN, 0.0, 4.0),
                ..v
            },
            "finite",
        ),
    ] {
        let e = doc
            .apply(set_stencil(
                &image,
                Vec2::new(200.0, 150.0),
                400.0,
                Some(bad),
            ))
            .expect_err("refused");
        assert!(e.to_string().contains(says), "{e}");
        assert_eq!(doc.stencil().cloned(), kept);
    }
    // A script writes the view without `Some(...)`; `up` is +Y by default.
    let script = r#"(commands: [SetStencil(image: "half-64x48.png", center: (200, 150), size: 400,
        view: (eye: (0, 0, 4), target: (0, 0, 0), fov: 35, size: (400, 300)))])"#;
    let script: Script = ron::from_str(script).expect("parsed");
    let kapaint_model::Command::Settings(SettingsCommand::SetStencil { view, .. }) =
        &script.commands[0]
    else {
        panic!("not a stencil: {:?}", script.commands[0]);
    };
    assert_eq!(*view, Some(front_view()));
}
