//! Profiling aid: the dabs of the `tools_4096` benchmark (a 128 px-radius brush at 10 %
//! spacing along rows of a painted 4096^2 document, a stroke a row) for the brush, clone,
//! smudge and the brush through a tiled stencil, without criterion's set-up of the other
//! benchmarks: `perf record` this, or read the milliseconds a dab it prints (the tools
//! interleaved round by round, so their ratios hold on a noisy machine).
//!
//! Usage: `cargo run --release --example tool_dab_profile [brush|clone|smudge|stencil|all]
//! [DABS]`

use glam::{Vec2, Vec3};
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::texel::{MaterialValue, Texel};
use kapaint::model::{Document, DocumentSettings, MaterialMaps, StrokeTool};
use kapaint::model::{SettingsCommand, StrokeCommand};

const SIDE: u32 = 4096;

/// The benchmark's document: every texel a different material.
fn painted_document() -> Result<Document, String> {
    let mut maps =
        MaterialMaps::new(SIDE, SIDE, MaterialValue::default()).map_err(|e| e.to_string())?;
    let texels = kapaint::model::tile::TILE_TEXELS;
    for id in 0..maps.tile_count() {
        let tile = maps.tile_mut(id);
        for i in 0..texels {
            let h = (id * texels + i) as u32;
            let f =
                |k: u32| ((h.wrapping_mul(2_654_435_761).rotate_left(k)) % 1000) as f32 / 1000.0;
            tile.set_texel(
                i,
                Texel::encode(MaterialValue::new(
                    Vec3::new(f(1), f(5), f(9)),
                    Vec3::splat(f(13)),
                    f(17) * 2000.0,
                )),
            );
        }
    }
    Ok(Document::from_parts(maps, DocumentSettings::default()))
}

fn prepared(tool: &str) -> Result<(Document, StrokeTool), String> {
    let mut doc = painted_document()?;
    let run =
        |doc: &mut Document, c: kapaint::model::Command| doc.apply(c).map_err(|e| e.to_string());
    run(
        &mut doc,
        SettingsCommand::SetBrush(BrushSettings {
            radius_px: 128.0,
            hardness: 0.5,
            flow: 0.5,
            spacing_percent: 10.0,
            ..BrushSettings::default()
        })
        .into(),
    )?;
    run(
        &mut doc,
        SettingsCommand::SetCloneSource(path(0) + Vec2::new(160.0, 0.0)).into(),
    )?;
    let stroke_tool = match tool {
        "clone" => StrokeTool::Clone,
        "smudge" => StrokeTool::Smudge,
        _ => StrokeTool::Brush,
    };
    if tool == "stencil" {
        let checker =
            image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(256, 256, |x, y| {
                image::Luma([if (x / 32 + y / 32) % 2 == 0 { 255 } else { 40 }])
            }));
        let image = kapaint::model::paint_image::PaintImage::decoded(
            std::path::Path::new("checker.png"),
            &checker,
        )
        .map_err(|e| e.to_string())?;
        run(
            &mut doc,
            SettingsCommand::SetStencil {
                image,
                center: Vec2::splat(2048.0),
                size: 4096.0,
                rotation: 15.0,
                opacity: 1.0,
                tiled: true,
                view: None,
            }
            .into(),
        )?;
    }
    Ok((doc, stroke_tool))
}

/// The benchmark's path: 250 dabs a row, rows 320 texels apart.
fn path(k: u32) -> Vec2 {
    let (row, col) = ((k / 250) % 12, k % 250);
    Vec2::new(256.5 + 12.8 * col as f32, 256.5 + 320.0 * row as f32)
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "all".into());
    let dabs: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(3000);
    let names: Vec<&str> = if which == "all" {
        vec!["brush", "clone", "smudge", "stencil"]
    } else {
        vec![which.as_str()]
    };
    let mut docs = names
        .iter()
        .map(|n| prepared(n))
        .collect::<Result<Vec<_>, _>>()?;
    let mut totals = vec![0.0_f64; names.len()];
    // Rounds of 250 dabs (one stroke), the tools taking turns.
    for round in 0..dabs.div_ceil(250) {
        for ((doc, tool), total) in docs.iter_mut().zip(&mut totals) {
            let start = std::time::Instant::now();
            doc.apply(StrokeCommand::BeginStroke(*tool))
                .map_err(|e| e.to_string())?;
            for k in round * 250..(round + 1) * 250 {
                doc.apply(StrokeCommand::StrokeTo(StrokePoint {
                    pos: path(k),
                    pressure: 1.0,
                }))
                .map_err(|e| e.to_string())?;
            }
            doc.apply(StrokeCommand::EndStroke)
                .map_err(|e| e.to_string())?;
            *total += start.elapsed().as_secs_f64();
        }
    }
    let count = f64::from(dabs.div_ceil(250) * 250);
    for (name, total) in names.iter().zip(totals) {
        println!("{name}: {:.3} ms a dab", total / count * 1e3);
    }
    Ok(())
}
