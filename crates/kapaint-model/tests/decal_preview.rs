//! Issue 56, item 2, the editor's side of a decal: a placement under way (`PreviewDecal`) is
//! moved by the next preview in its own undo step, committed by `PlaceDecal` in that step,
//! dropped by `DropDecal` with its step; another command ends the placement.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::{DynamicImage, Rgba, RgbaImage};
use kapaint_model::paint_image::PaintImage;
use kapaint_model::surface::Surface;
use kapaint_model::texel::{Channels, MaterialValue};
use kapaint_model::{Decal, Document, DocumentSettings, HistoryCommand, PaintCommand};

const SIDE: u32 = 256;

fn sphere_document() -> Document {
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

/// A white 32 x 32 image, opaque in a disc.
fn disc() -> PaintImage {
    let img = RgbaImage::from_fn(32, 32, |x, y| {
        let d = Vec2::new(x as f32 - 15.5, y as f32 - 15.5).length();
        Rgba([255, 255, 255, if d < 12.0 { 255 } else { 0 }])
    });
    PaintImage::decoded(
        std::path::Path::new("disc.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image")
}

fn decal(at: Vec3) -> Decal {
    Decal {
        image: disc(),
        at,
        size: 0.4,
        rotation: 0.0,
        channels: Channels::ALL,
        opacity: 1.0,
    }
}

/// The texels `k_d` is painted in.
fn painted(doc: &Document) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for y in 0..SIDE {
        for x in 0..SIDE {
            if doc.maps().value(x, y).kd.x > 0.5 {
                out.push((x, y));
            }
        }
    }
    out
}

fn steps(doc: &Document) -> Vec<String> {
    doc.history()
        .undo_steps()
        .map(|s| s.label.clone())
        .collect()
}

#[test]
fn a_decal_dragged_is_one_step_and_lies_only_where_it_was_left() {
    let mut doc = sphere_document();
    let (a, b) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
    let alone = {
        let mut d = sphere_document();
        d.apply(decal(b).place()).expect("placed");
        painted(&d)
    };
    assert!(!alone.is_empty());
    doc.apply(PaintCommand::PreviewDecal(Box::new(decal(a))))
        .expect("preview");
    let first = painted(&doc);
    assert!(!first.is_empty() && first != alone);
    // Dragged to b, and its size set twice: one step, and only where it is now.
    for at in [Vec3::new(0.7, 0.0, 0.7), b] {
        doc.apply(PaintCommand::PreviewDecal(Box::new(decal(at))))
            .expect("moved");
    }
    assert_eq!(painted(&doc), alone, "the earlier previews are gone");
    assert_eq!(steps(&doc), ["Place decal"]);
    // Enter: committed in the same step.
    doc.apply(decal(b).place()).expect("committed");
    assert_eq!(painted(&doc), alone);
    assert_eq!(steps(&doc), ["Place decal"]);
    // Undo takes the whole placement out.
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(painted(&doc).is_empty());
}

#[test]
fn escape_drops_the_decal_and_its_step_but_not_one_committed() {
    let mut doc = sphere_document();
    let version = doc.version();
    doc.apply(PaintCommand::PreviewDecal(Box::new(decal(Vec3::Z))))
        .expect("preview");
    assert!(!painted(&doc).is_empty());
    doc.apply(PaintCommand::DropDecal).expect("dropped");
    assert!(painted(&doc).is_empty());
    assert!(steps(&doc).is_empty());
    assert_eq!(doc.version(), version, "nothing left to save");
    // Committed, then Escape: the decal stays (Escape drops only a placement under way).
    doc.apply(PaintCommand::PreviewDecal(Box::new(decal(Vec3::Z))))
        .expect("preview");
    doc.apply(decal(Vec3::Z).place()).expect("committed");
    doc.apply(PaintCommand::DropDecal).expect("nothing to drop");
    assert!(!painted(&doc).is_empty());
    assert_eq!(steps(&doc), ["Place decal"]);
}

#[test]
fn a_second_decal_after_a_commit_is_its_own_step_and_a_refused_move_keeps_the_preview() {
    let mut doc = sphere_document();
    doc.apply(decal(Vec3::Z).place()).expect("first");
    let first = painted(&doc);
    doc.apply(PaintCommand::PreviewDecal(Box::new(decal(Vec3::X))))
        .expect("second");
    assert_eq!(steps(&doc), ["Place decal", "Place decal"]);
    let both = painted(&doc);
    assert!(both.len() > first.len() && first.iter().all(|t| both.contains(t)));
    // A move it cannot make (a zero size): refused, the preview and its step as they were.
    let mut bad = decal(Vec3::NEG_X);
    bad.size = 0.0;
    assert!(
        doc.apply(PaintCommand::PreviewDecal(Box::new(bad)))
            .is_err()
    );
    assert_eq!(painted(&doc), both);
    assert_eq!(steps(&doc), ["Place decal", "Place decal"]);
    // The run survives the refusal: the next move still replaces the preview.
    doc.apply(PaintCommand::PreviewDecal(Box::new(decal(Vec3::NEG_X))))
        .expect("moved");
    assert_eq!(steps(&doc), ["Place decal", "Place decal"]);
    assert!(
        painted(&doc)
            .iter()
            .all(|t| !both.contains(t) || first.contains(t))
    );
}
