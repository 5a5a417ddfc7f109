//! Profiling aid: repeats the dab of the `layers_4096` benchmark (a 128 px-radius brush, back
//! and forth by its spacing through the document, then `k_a` derived on the tiles it
//! changed) on a 4096^2 document: on layer 8 of the 16-layer benchmark stack, or with
//! `single` on a one-layer document. `perf record` this.
//!
//! With `moving`, the dabs go along a stroke instead (32 px apart, row after row across the
//! map), so every dab reaches texels the stroke has not covered yet, and a new stroke starts
//! where the path does (as in the benchmark); `over` does the same on
//! the layer filled first (every tile of it painted); `repaint` paints the path's first pass
//! untimed, then times new strokes over it (as the benchmark does once the path wraps).
//!
//! Usage: `cargo run --release --example dab_profile [layers|single] [ROUNDS]
//! [moving|over|repaint]`

use glam::{Vec2, Vec3};
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Command, Document, DocumentSettings, StrokeTool};
use kapaint::model::{LayerCommand, PaintCommand, SettingsCommand, StrokeCommand};
use kapaint::reflectance::{AmbientApprox, ShadingModel};

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let single = args.next().as_deref() == Some("single");
    let rounds: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let how = args.next();
    let moving = matches!(how.as_deref(), Some("moving" | "over" | "repaint"));
    let settings = DocumentSettings {
        brush: BrushSettings {
            radius_px: 128.0,
            hardness: 0.5,
            flow: 0.5,
            ..BrushSettings::default()
        },
        primary: MaterialValue::new(Vec3::new(0.8, 0.3, 0.1), Vec3::splat(0.3), 60.0),
        ..DocumentSettings::default()
    };
    let (mut doc, layer) = if single {
        (Document::new(4096, 4096, settings), 0)
    } else {
        let stack = kapaint::report::typical::layered_stack(4096, 16);
        (Document::from_stack(stack, settings), 8)
    };
    let doc = doc.as_mut().map_err(|e| e.to_string())?;
    let run = |doc: &mut Document, c: Command| doc.apply(c).map_err(|e| e.to_string());
    run(doc, LayerCommand::SelectPath(vec![layer]).into())?;
    if how.as_deref() == Some("over") {
        let primary = doc.settings().primary;
        run(
            doc,
            SettingsCommand::SetPrimary(kapaint::report::typical::under_paint()).into(),
        )?;
        run(
            doc,
            PaintCommand::Fill(kapaint::model::FillRegion::All).into(),
        )?;
        run(doc, SettingsCommand::SetPrimary(primary).into())?;
    }
    let points = kapaint::report::typical::STROKE_PATH_POINTS;
    let repaint = how.as_deref() == Some("repaint");
    if repaint {
        // The first pass of the path, untimed: the timed dabs paint over its strokes.
        run(doc, StrokeCommand::BeginStroke(StrokeTool::Brush).into())?;
        for k in 0..points {
            let pos = kapaint::report::typical::stroke_path(k);
            run(
                doc,
                StrokeCommand::StrokeTo(StrokePoint { pos, pressure: 1.0 }).into(),
            )?;
        }
        run(doc, StrokeCommand::EndStroke.into())?;
    }
    run(doc, StrokeCommand::BeginStroke(StrokeTool::Brush).into())?;
    let mut version = doc.maps().version();
    let start = std::time::Instant::now();
    let mut derived = 0;
    let mut ka = Vec::new();
    for k in 0..rounds {
        if moving && k > 0 && k % points == 0 {
            run(doc, StrokeCommand::EndStroke.into())?;
            run(doc, StrokeCommand::BeginStroke(StrokeTool::Brush).into())?;
        }
        let pos = if moving {
            kapaint::report::typical::stroke_path(k)
        } else {
            Vec2::new(2000.5 + if k % 2 == 0 { 0.0 } else { 32.0 }, 1500.5)
        };
        run(
            doc,
            StrokeCommand::StrokeTo(StrokePoint { pos, pressure: 1.0 }).into(),
        )?;
        let dirty = doc.maps().tiles_changed_since(version);
        version = doc.maps().version();
        doc.maps()
            .derive_ka_tiles_into(ShadingModel::Phong, AmbientApprox::Fast, &dirty, &mut ka);
        derived += dirty.len();
    }
    let per = start.elapsed().as_secs_f64() / f64::from(rounds);
    println!("{:.3} ms a dab ({derived} tiles derived)", per * 1e3);
    Ok(())
}
