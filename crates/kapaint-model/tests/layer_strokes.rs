//! Brushes on layers: every mode paints on an empty layer, and a brush on tiles new to a layer
//! (coverage only) composites exactly as on transparent tiles it already had.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::Vec3;

#[path = "common/layer_doc.rs"]
mod layer_doc;
use layer_doc::{document, mask_gray, run, texels};

/// Every brush mode paints on an empty layer (source-over with the mode's blend, as Krita
/// paints): multiply used to change only texels the layer already covered, so on an empty
/// layer it did nothing at all.
#[test]
fn a_multiply_brush_on_an_empty_layer_paints_the_target() {
    let mut doc = document();
    let base = texels(&doc);
    run(
        &mut doc,
        r"(commands: [
            SetPrimary((kd: (0.9, 0.1, 0.1), ks: (0.2, 0.2, 0.2), n: 300.0)),
            SetBrush((radius_px: 12.0, hardness: 1.0, flow: 1.0, opacity: 1.0, blend: Multiply)),
            Stroke(tool: Brush, points: [(pos: (40.0, 60.0), pressure: 1.0), (pos: (140.0, 60.0), pressure: 1.0)]),
        ])",
    );
    assert_ne!(texels(&doc), base, "the stroke changed nothing");
    let t = doc.maps().texel(90, 60).decode();
    assert!(
        (t.kd - Vec3::new(0.9, 0.1, 0.1)).abs().max_element() < 1e-4,
        "{t:?}"
    );
    assert!((t.n - 300.0).abs() < 0.5, "{t:?}");
}

/// A brush on tiles the layer did not have writes coverage only (the tile holds the target as
/// one value per channel); on tiles it has, fully transparent, every texel goes through the
/// general stroke. The composites are bit-identical.
#[test]
fn a_brush_on_new_tiles_composites_as_on_transparent_ones() {
    let script = r"(commands: [
        SetPrimary((kd: (0.7, 0.3, 0.2), ks: (0.1, 0.4, 0.3), n: 42.0)),
        SetBrush((radius_px: 19.0, hardness: 0.4, flow: 0.35, opacity: 0.8)),
        Stroke(tool: Brush, points: [(pos: (10.0, 20.0), pressure: 0.7), (pos: (170.0, 100.0), pressure: 1.0), (pos: (30.0, 110.0), pressure: 0.4)]),
    ])";
    let mut fresh = document();
    run(&mut fresh, script);
    // The same layer, its tiles present but transparent: painted over, then erased.
    let mut erased = document();
    run(
        &mut erased,
        r"(commands: [
            Fill(All),
            SetBrush((radius_px: 400.0, hardness: 1.0, flow: 1.0, opacity: 1.0)),
            Stroke(tool: Eraser, points: [(pos: (96.0, 64.0), pressure: 1.0)]),
        ])",
    );
    assert_eq!(
        texels(&erased),
        texels(&document()),
        "the layer is transparent"
    );
    run(&mut erased, script);
    assert_eq!(texels(&fresh), texels(&erased));
}

/// The brush's energy guard (`k_d + k_s <= 1` per colour channel) holds on a layer as it did
/// on the flat maps: it used to be ignored there.
#[test]
fn the_energy_guard_holds_on_a_layer() {
    let mut doc = document();
    run(
        &mut doc,
        r"(commands: [
            SetPrimary((kd: (0.9, 0.6, 0.2), ks: (0.5, 0.5, 0.5), n: 80.0)),
            SetBrush((radius_px: 14.0, hardness: 1.0, flow: 1.0, opacity: 1.0, energy_guard: true)),
            Stroke(tool: Brush, points: [(pos: (40.0, 60.0), pressure: 1.0), (pos: (140.0, 60.0), pressure: 1.0)]),
            SetBrush((radius_px: 14.0, hardness: 0.3, flow: 0.5, opacity: 1.0, energy_guard: true, blend: Add)),
            Stroke(tool: Brush, points: [(pos: (60.0, 66.0), pressure: 1.0), (pos: (120.0, 66.0), pressure: 1.0)]),
        ])",
    );
    for x in (30..150).step_by(3) {
        for y in 48..74 {
            let t = doc.maps().texel(x, y).decode();
            let sum = t.kd + t.ks;
            assert!(
                sum.max_element() <= 1.0 + 2.0 / 65535.0,
                "({x}, {y}): {t:?}"
            );
        }
    }
    // Both channels painted: both scale down together, as on the flat maps.
    let t = doc.maps().texel(90, 50).decode();
    assert!((t.kd.x - 0.9 / 1.4).abs() < 1e-3, "{t:?}");
    assert!((t.ks.x - 0.5 / 1.4).abs() < 1e-3, "{t:?}");
    // A fill on a new layer keeps it too (it no longer takes the one-value-a-tile shortcut).
    run(
        &mut doc,
        r#"(commands: [AddLayer(kind: Paint, name: "fill"), Fill(All)])"#,
    );
    let t = doc.maps().texel(5, 120).decode();
    assert!((t.kd.x - 0.9 / 1.4).abs() < 1e-3, "{t:?}");
}

/// A mask takes the value of the brush's colour (as Krita and Substance paint masks): black
/// hides, mid grey half shows, white reveals; the eraser hides. It used to paint white with any
/// colour.
#[test]
fn a_mask_is_painted_with_the_value_of_the_primary_colour() {
    use kapaint_model::layers::LayerContent;
    let mut doc = document();
    run(
        &mut doc,
        r"(commands: [
            AddMask, SelectMask,
            SetBrush((radius_px: 10.0, hardness: 1.0, flow: 1.0, opacity: 1.0)),
            SetPrimary((kd: (0.0, 0.0, 0.0), ks: (0.5, 0.5, 0.5), n: 10.0)),
            Stroke(tool: Brush, points: [(pos: (20.0, 30.0), pressure: 1.0), (pos: (60.0, 30.0), pressure: 1.0)]),
            SetPrimary((kd: (0.2140, 0.2140, 0.2140), ks: (0.5, 0.5, 0.5), n: 10.0)),
            Stroke(tool: Brush, points: [(pos: (20.0, 90.0), pressure: 1.0), (pos: (60.0, 90.0), pressure: 1.0)]),
            SetPrimary((kd: (1.0, 0.2, 0.2), ks: (0.5, 0.5, 0.5), n: 10.0)),
            Stroke(tool: Eraser, points: [(pos: (120.0, 30.0), pressure: 1.0), (pos: (160.0, 30.0), pressure: 1.0)]),
        ])",
    );
    let layer = doc.stack().layer(&doc.selection().path).expect("layer");
    assert!(matches!(layer.content, LayerContent::Paint(_)));
    assert!(
        mask_gray(&doc, 40, 30) < 0.01,
        "black hides: {}",
        mask_gray(&doc, 40, 30)
    );
    let grey = mask_gray(&doc, 40, 90);
    assert!(
        (grey - 0.5).abs() < 0.01,
        "mid grey (sRGB 0.5) half shows: {grey}"
    );
    assert!(mask_gray(&doc, 140, 30) < 0.01, "the eraser hides");
    assert!(mask_gray(&doc, 100, 100) > 0.99, "untouched stays white");
}
