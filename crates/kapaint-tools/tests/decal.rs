//! Issue 56, item 2: the Decal tool without a window. A click places the decal (laid as a
//! preview), a drag moves it over the surface, the options scale and turn it, Enter commits
//! it and Escape takes it back, one undo step a placement; on the canvas a click places it
//! where the map lies on the mesh.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::{DynamicImage, Rgba, RgbaImage};
use kapaint_model::brush::SurfacePos;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::surface::Surface;
use kapaint_model::texel::MaterialValue;
use kapaint_model::{Command, Document, DocumentSettings, PaintCommand};
use kapaint_tools::{
    DecalOption, DecalTool, OptionChange, OptionWidget, Place, ToolEvent, ToolKind, Tools,
};

const SIDE: u32 = 256;

fn document() -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 10.0),
        ..DocumentSettings::default()
    };
    let surface = Surface::new(kapaint_mesh::uv_sphere(64, 32), SIDE, SIDE).expect("bake");
    Document::new(SIDE, SIDE, settings)
        .expect("doc")
        .with_surface(Some(Arc::new(surface)))
        .expect("surface")
}

fn logo() -> PaintImage {
    let img = RgbaImage::from_fn(32, 16, |x, _| {
        Rgba([255, 255, 255, if (4..28).contains(&x) { 255 } else { 0 }])
    });
    PaintImage::decoded(
        std::path::Path::new("logo.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image")
}

fn on_surface(point: Vec3) -> Place {
    Place::Surface {
        pos: SurfacePos {
            point,
            normal: point.normalize(),
        },
        texel: None,
    }
}

/// Runs events through the tools and applies every command; returns the commands.
fn run(tools: &mut Tools, doc: &mut Document, events: &[ToolEvent]) -> Vec<Command> {
    let mut all = Vec::new();
    for &event in events {
        for command in tools.handle(event, doc) {
            doc.apply(command.clone())
                .expect("a tool's command applies");
            all.push(command);
        }
    }
    all
}

fn painted(doc: &Document) -> usize {
    let mut n = 0;
    for y in 0..SIDE {
        for x in 0..SIDE {
            n += usize::from(doc.maps().value(x, y).kd.x > 0.5);
        }
    }
    n
}

fn labels(doc: &Document) -> Vec<String> {
    doc.history()
        .undo_steps()
        .map(|s| s.label.clone())
        .collect()
}

fn decal_tools(doc: &Document) -> Tools {
    let mut tools = Tools::default();
    tools.select(ToolKind::DECAL, doc);
    assert!(
        tools
            .set_option(OptionChange::Image(logo()), doc)
            .is_empty(),
        "nothing is placed yet"
    );
    tools
}

#[test]
fn click_drag_and_enter_place_one_decal_in_one_step() {
    let mut doc = document();
    let mut tools = decal_tools(&doc);
    let press = ToolEvent::Press {
        at: on_surface(Vec3::Z),
        pressure: 1.0,
    };
    let out = run(&mut tools, &mut doc, &[press]);
    assert!(matches!(
        out.as_slice(),
        [Command::Paint(PaintCommand::PreviewDecal(_))]
    ));
    assert!(tools.busy());
    let at_z = painted(&doc);
    assert!(at_z > 0);
    // Dragged over the surface: moved, still one step.
    let drags: Vec<ToolEvent> = [0.2_f32, 0.5, 0.8, 1.0]
        .iter()
        .map(|&t| ToolEvent::Drag {
            at: on_surface(Vec3::Z.lerp(Vec3::X, t).normalize()),
            pressure: 1.0,
        })
        .collect();
    let out = run(&mut tools, &mut doc, &drags);
    assert_eq!(out.len(), 4);
    run(&mut tools, &mut doc, &[ToolEvent::Release]);
    assert_eq!(labels(&doc), ["Place decal"]);
    let placing = tools
        .get_mut::<DecalTool>()
        .and_then(|t| t.placing())
        .expect("still being placed");
    assert!(placing.distance(Vec3::X) < 1e-5);
    // The size field doubles it: laid again, larger, same step.
    let size = tools
        .get_mut::<DecalTool>()
        .and_then(|t| t.size)
        .expect("size");
    let out = tools.set_option(OptionChange::Decal(DecalOption::Size(2.0 * size)), &doc);
    for c in out {
        doc.apply(c).expect("resized");
    }
    let larger = painted(&doc);
    assert!(larger > 3 * at_z, "{larger} vs {at_z}");
    // Enter commits it, in the same step.
    let out = run(&mut tools, &mut doc, &[ToolEvent::Commit]);
    assert!(matches!(
        out.as_slice(),
        [Command::Paint(PaintCommand::PlaceDecal { .. })]
    ));
    assert!(!tools.busy());
    assert_eq!(labels(&doc), ["Place decal"]);
    assert_eq!(painted(&doc), larger);
}

#[test]
fn escape_takes_the_decal_back_and_nothing_is_placed_without_an_image() {
    let mut doc = document();
    let mut tools = Tools::default();
    tools.select(ToolKind::DECAL, &doc);
    let press = ToolEvent::Press {
        at: on_surface(Vec3::Z),
        pressure: 1.0,
    };
    assert!(run(&mut tools, &mut doc, &[press]).is_empty(), "no image");
    let options = tools.options(&doc);
    assert!(
        matches!(options[0].widget, OptionWidget::Image { path: None }),
        "the panel offers an image to choose"
    );
    tools.set_option(OptionChange::Image(logo()), &doc);
    let version = doc.version();
    run(&mut tools, &mut doc, &[press, ToolEvent::Release]);
    assert!(painted(&doc) > 0);
    let out = run(&mut tools, &mut doc, &[ToolEvent::Escape]);
    assert_eq!(out, [Command::Paint(PaintCommand::DropDecal)]);
    assert_eq!(painted(&doc), 0);
    assert!(labels(&doc).is_empty());
    assert_eq!(doc.version(), version);
    // Another tool chosen while one is placed keeps it.
    run(&mut tools, &mut doc, &[press, ToolEvent::Release]);
    for c in tools.select(ToolKind::BRUSH, &doc) {
        doc.apply(c).expect("kept");
    }
    assert!(painted(&doc) > 0);
    assert_eq!(labels(&doc), ["Place decal"]);
}

#[test]
fn a_click_on_the_canvas_places_the_decal_where_that_texel_lies_on_the_mesh() {
    let mut doc = document();
    let mut tools = decal_tools(&doc);
    let texel = Vec2::new(100.5, 128.5);
    let want = {
        let s = doc.surface().expect("surface");
        s.bake.position(128 * SIDE as usize + 100)
    };
    let press = ToolEvent::Press {
        at: Place::Canvas(texel),
        pressure: 1.0,
    };
    run(&mut tools, &mut doc, &[press, ToolEvent::Release]);
    let at = tools
        .get_mut::<DecalTool>()
        .and_then(|t| t.placing())
        .expect("placed");
    assert!(at.distance(want) < 1e-6, "{at} vs {want}");
    // The texel itself took the decal.
    assert!(doc.maps().value(100, 128).kd.x > 0.5);
}

#[test]
fn the_handles_scale_and_turn_the_decal_and_its_outline_follows() {
    let mut doc = document();
    let mut tools = decal_tools(&doc);
    let press = |p: Vec3| ToolEvent::Press {
        at: on_surface(p),
        pressure: 1.0,
    };
    let drag = |p: Vec3| ToolEvent::Drag {
        at: on_surface(p),
        pressure: 1.0,
    };
    assert!(tools.overlay().is_none(), "no outline before a decal");
    run(&mut tools, &mut doc, &[press(Vec3::Z), ToolEvent::Release]);
    let outline = |tools: &Tools| match tools.overlay() {
        Some(kapaint_tools::Overlay::Decal { corners, handles }) => (corners, handles),
        other => panic!("no decal outline: {other:?}"),
    };
    let (corners, [scale, turn]) = outline(&tools);
    let width = corners[0].distance(corners[1]);
    let size = |tools: &mut Tools| {
        tools
            .get_mut::<DecalTool>()
            .and_then(|t| t.size)
            .expect("size")
    };
    assert!((width - size(&mut tools)).abs() < 1e-4, "{width}");
    // The scale handle dragged out along the diagonal by half again: 1.5 times as wide, the
    // same step, still at the same point.
    let centre = (corners[0] + corners[2]) * 0.5;
    let farther = centre + (scale - centre) * 1.5;
    run(
        &mut tools,
        &mut doc,
        &[press(scale), drag(farther), ToolEvent::Release],
    );
    let grown = size(&mut tools);
    assert!((grown / width - 1.5).abs() < 0.02, "{grown} from {width}");
    assert_eq!(labels(&doc), ["Place decal"]);
    let placing = tools
        .get_mut::<DecalTool>()
        .and_then(|t| t.placing())
        .expect("placed");
    assert!(placing.distance(Vec3::Z) < 1e-5, "not moved: {placing}");
    let (corners, [_, turn_after]) = outline(&tools);
    assert!((corners[0].distance(corners[1]) - grown).abs() < 1e-4);
    assert!(
        turn_after.distance(centre) > turn.distance(centre),
        "the outline follows"
    );
    // The turn handle dragged a quarter turn to the right (seen from outside, +Z): turned
    // clockwise, -90 degrees.
    let (corners, [_, turn]) = outline(&tools);
    let centre = (corners[0] + corners[2]) * 0.5;
    let right = (corners[1] - corners[0]).normalize();
    let to_right = centre + right * turn.distance(centre);
    run(
        &mut tools,
        &mut doc,
        &[press(turn), drag(to_right), ToolEvent::Release],
    );
    let rotation = tools
        .get_mut::<DecalTool>()
        .map(|t| t.rotation)
        .expect("rotation");
    assert!((rotation + 90.0).abs() < 2.0, "{rotation}");
    let (turned, _) = outline(&tools);
    let top = (turned[0] + turned[1]) * 0.5 - centre;
    assert!(
        top.normalize().dot(right) > 0.95,
        "its top now faces right: {top}"
    );
    // A press on the decal away from its handles moves it; Escape takes it all back.
    run(
        &mut tools,
        &mut doc,
        &[press(Vec3::new(0.05, -0.05, 1.0).normalize())],
    );
    let placing = tools
        .get_mut::<DecalTool>()
        .and_then(|t| t.placing())
        .expect("placed");
    assert!(placing.distance(Vec3::Z) > 0.01);
    run(
        &mut tools,
        &mut doc,
        &[ToolEvent::Release, ToolEvent::Escape],
    );
    assert!(labels(&doc).is_empty());
    assert!(tools.overlay().is_none());
}
