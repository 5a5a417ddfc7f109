//! Measures the memory and file targets of the layer stack (issue 18): a 4096^2 document of 16
//! paint layers, each painted by strokes over about 10 % of the map and given a mask with a
//! painted stroke, built through the document's commands (so undo holds every step). Prints
//! the model's own accounting (layer tiles, undo, composite), the process's resident and peak
//! memory, what one more empty layer costs, and the save and open times of the project.
//!
//! Usage: `cargo run --release --example layer_memory [SIDE] [LAYERS]`; run it under
//! `/usr/bin/time -v` for the peak as the kernel saw it.

use std::time::Instant;

use glam::{Vec2, Vec3};
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Command, Document, DocumentSettings, LayerKind, StrokeTool, project};
use kapaint::model::{LayerCommand, MaskCommand, SettingsCommand, StrokeCommand};

/// A `/proc/self/status` field in bytes (`VmRSS`, `VmHWM`; 0 where unknown).
fn status_bytes(field: &str) -> u64 {
    kapaint::memory::process_bytes(field).unwrap_or(0)
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / 1_048_576.0)
}

fn run(doc: &mut Document, command: Command) -> Result<(), String> {
    doc.apply(command).map_err(|e| e.to_string())
}

/// A horizontal stroke of `radius` at row `y` from `x0` to `x1`.
fn stroke(doc: &mut Document, y: f32, (x0, x1): (f32, f32)) -> Result<(), String> {
    let points = (0..=16)
        .map(|k| StrokePoint {
            pos: Vec2::new(x0 + (x1 - x0) * k as f32 / 16.0, y),
            pressure: 1.0,
        })
        .collect();
    run(
        doc,
        StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points,
        }
        .into(),
    )
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let side: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(4096);
    let layers: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(16);
    let s = side as f32;
    let start = Instant::now();
    let mut doc =
        Document::new(side, side, DocumentSettings::default()).map_err(|e| e.to_string())?;
    // Two strokes of radius side/25 across 2/3 of the map cover about 10 % of it.
    let radius = s / 25.0;
    run(
        &mut doc,
        SettingsCommand::SetBrush(BrushSettings {
            radius_px: radius,
            hardness: 0.8,
            flow: 1.0,
            ..BrushSettings::default()
        })
        .into(),
    )?;
    for l in 0..layers {
        if l > 0 {
            run(
                &mut doc,
                LayerCommand::AddLayer {
                    kind: LayerKind::Paint,
                    name: format!("Layer {}", l + 1),
                }
                .into(),
            )?;
        }
        let t = l as f32 / layers as f32;
        run(
            &mut doc,
            SettingsCommand::SetPrimary(MaterialValue::new(
                Vec3::new(t, 0.5, 1.0 - t),
                Vec3::splat(0.2),
                (1.0 + 12.0 * t).exp2(),
            ))
            .into(),
        )?;
        let y = s * (0.1 + 0.8 * t);
        stroke(&mut doc, y, (s * 0.1, s * 0.77))?;
        stroke(&mut doc, (y + s * 0.45) % s, (s * 0.2, s * 0.87))?;
        // A mask, black where one shorter stroke crosses the paint.
        run(&mut doc, MaskCommand::AddMask.into())?;
        run(&mut doc, MaskCommand::SelectMask.into())?;
        run(
            &mut doc,
            SettingsCommand::SetPrimary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 1.0)).into(),
        )?;
        stroke(&mut doc, y, (s * 0.3, s * 0.5))?;
        run(&mut doc, MaskCommand::SelectContent.into())?;
    }
    println!(
        "built {side}x{side}, {layers} layers in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let stack = doc.stack().heap_bytes() as u64;
    let undo = doc.history().bytes() as u64;
    let maps = doc.maps().heap_bytes() as u64;
    println!("layer tiles and masks: {}", mib(stack));
    println!("undo (held only by history): {}", mib(undo));
    println!("composite maps: {}", mib(maps));
    println!("model total: {}", mib(stack + undo + maps));
    println!("resident now: {}", mib(status_bytes("VmRSS:")));
    println!("resident peak: {}", mib(status_bytes("VmHWM:")));
    run(
        &mut doc,
        LayerCommand::AddLayer {
            kind: LayerKind::Paint,
            name: "Empty".into(),
        }
        .into(),
    )?;
    let empty = doc.stack().heap_bytes() as u64 - stack;
    println!(
        "an empty layer: {empty} bytes of tiles, {} bytes of table",
        doc.stack().tile_count()
            * std::mem::size_of::<Option<kapaint::model::layers::SharedPaintTile>>()
    );
    run(&mut doc, LayerCommand::DeleteLayer.into())?;
    let path = std::env::temp_dir().join(format!("kapaint-layers-{}.kapaint", std::process::id()));
    for round in 0..2 {
        let t = Instant::now();
        project::save(&doc, &path).map_err(|e| e.to_string())?;
        let save = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let loaded = project::load(&path).map_err(|e| e.to_string())?;
        let open = t.elapsed().as_secs_f64();
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        println!(
            "round {round}: save {save:.2} s, open {open:.2} s, {} on disk, same composite: {}",
            mib(bytes),
            loaded.maps().tile_count() == doc.maps().tile_count()
                && (0..doc.maps().tile_count())
                    .all(|id| **loaded.maps().tile(id) == **doc.maps().tile(id))
        );
    }
    let _ = std::fs::remove_file(&path);
    println!("resident peak at the end: {}", mib(status_bytes("VmHWM:")));
    Ok(())
}
