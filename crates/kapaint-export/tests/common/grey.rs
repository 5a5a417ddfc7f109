//! A project whose k_a mean no 8-bit file meets: the ktx2 tests' storage floor (shared with
//! the top-level tests/ktx2_astc.rs, which runs the binary).

use kapaint_model::Document;

/// A mid-grey k_d (0.5 linear, 187.5 in 8-bit sRGB: stored in 8 bits, half a level off
/// everywhere) with one red stroke: a k_a mean of 0.3 levels that no 8-bit file meets and BC6H's
/// half floats do.
pub fn grey_project(side: u32) -> Document {
    use glam::{Vec2, Vec3};
    use kapaint_model::brush::StrokePoint;
    use kapaint_model::texel::MaterialValue;
    use kapaint_model::{DocumentSettings, SettingsCommand, StrokeCommand, StrokeTool};
    let mut doc = Document::new(
        side,
        side,
        DocumentSettings {
            base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.25), 32.0),
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.8, 0.1, 0.1),
        Vec3::splat(0.5),
        200.0,
    )))
    .expect("primary");
    let y = side as f32 / 2.0;
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: [0.4, 0.55]
            .map(|x| StrokePoint {
                pos: Vec2::new(x * side as f32, y),
                pressure: 1.0,
            })
            .to_vec(),
    })
    .expect("stroke");
    doc
}
