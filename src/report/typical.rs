//! A typical project for scale measurements: real image content, a gradient and brush
//! strokes, as an artist's document would hold after a session.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::model::brush::{BrushSettings, StrokePoint};
use crate::model::paint::GradientShape;
use crate::model::{
    Channel, Channels, Command, Document, DocumentSettings, MaterialValue, StrokeTool, import,
};

/// Builds a `side x side` document: `texture` (if given and readable) imported into `k_d`, a
/// radial gradient over `n`, then `strokes` brush strokes of 64 px radius with varied
/// materials, each one undo step.
pub fn typical_document(
    side: u32,
    texture: Option<&Path>,
    strokes: usize,
) -> Result<Document, String> {
    let mut doc =
        Document::new(side, side, DocumentSettings::default()).map_err(|e| e.to_string())?;
    if let Some(path) = texture {
        import::import_file(&mut doc, Channel::Kd, path).map_err(|e| e.to_string())?;
    }
    let s = side as f32;
    let apply = |doc: &mut Document, c: Command| doc.apply(c).map_err(|e| e.to_string());
    apply(
        &mut doc,
        Command::SetChannels(Channels {
            kd: false,
            ks: false,
            n: true,
        }),
    )?;
    apply(
        &mut doc,
        Command::SetPrimary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 2000.0)),
    )?;
    apply(
        &mut doc,
        Command::SetSecondary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 8.0)),
    )?;
    apply(
        &mut doc,
        Command::Gradient {
            shape: GradientShape::Radial,
            start: Vec2::splat(s / 2.0),
            end: Vec2::new(s, s / 2.0),
        },
    )?;
    apply(&mut doc, Command::SetChannels(Channels::ALL))?;
    apply(
        &mut doc,
        Command::SetBrush(BrushSettings {
            radius_px: 64.0,
            hardness: 0.6,
            ..BrushSettings::default()
        }),
    )?;
    let mut state = 0x0123_4567_89AB_CDEF_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..strokes {
        let value = MaterialValue::new(
            Vec3::new(next(), next(), next()),
            Vec3::splat(next()),
            1.0 + 500.0 * next(),
        );
        apply(&mut doc, Command::SetPrimary(value))?;
        let mut pos = Vec2::new(next() * s, next() * s);
        let mut points = Vec::new();
        for _ in 0..12 {
            points.push(StrokePoint {
                pos,
                pressure: 0.5 + 0.5 * next(),
            });
            pos += Vec2::new(next() - 0.5, next() - 0.5) * 160.0;
        }
        apply(
            &mut doc,
            Command::Stroke {
                tool: StrokeTool::Brush,
                points,
            },
        )?;
    }
    Ok(doc)
}
