//! Profiling aid: the dabs of the `tools_4096` benchmark (a 128 px-radius brush at 10 %
//! spacing along rows of a painted 4096^2 document, a stroke a row) for the brush, clone,
//! smudge and the brush through a tiled stencil, without criterion's set-up of the other
//! benchmarks: `perf record` this, or read the milliseconds a dab it prints (the tools
//! interleaved round by round, so their ratios hold on a noisy machine; the fastest stroke's
//! dabs are the least disturbed by the machine's other work).
//!
//! The same dabs on the mesh (`mesh-brush`, `mesh-clone`, `mesh-smudge`, or `mesh` for the
//! three): around the equator of the built-in sphere baked at 4096^2, 200 dabs a stroke.
//!
//! `decal` places the `place_decal_1024px_image` benchmark's decal (a 1024^2 image, 0.5 units
//! wide) on the same sphere and undoes it, `DABS` times.
//!
//! Usage: `cargo run --release --example tool_dab_profile
//! [brush|clone|smudge|stencil|all|mesh|mesh-brush|mesh-clone|mesh-smudge|decal] [DABS]`

use kapaint::model::StrokeCommand;
use kapaint::model::StrokeTool;
use kapaint::model::brush::StrokePoint;
use kapaint::report::typical::{
    mesh_tool_dab_document, mesh_tool_dab_point, tool_dab_document, tool_dab_path as path,
};

/// The benchmark's document for `tool`, and the tool its strokes use.
fn prepared(tool: &str) -> Result<(kapaint::model::Document, StrokeTool), String> {
    let stroke_tool = match tool.trim_start_matches("mesh-") {
        "clone" => StrokeTool::Clone,
        "smudge" => StrokeTool::Smudge,
        _ => StrokeTool::Brush,
    };
    let doc = if tool.starts_with("mesh-") {
        mesh_tool_dab_document()?
    } else {
        tool_dab_document(tool == "stencil")?
    };
    Ok((doc, stroke_tool))
}

/// Dab `k` of a stroke of `tool` on `doc`.
fn dab(doc: &mut kapaint::model::Document, tool: &str, k: u32) -> Result<(), String> {
    let command = if tool.starts_with("mesh-") {
        let units = doc.surface().map_or(1.0, |s| s.units_per_texel);
        StrokeCommand::SurfaceStrokeTo(mesh_tool_dab_point(k, units))
    } else {
        StrokeCommand::StrokeTo(StrokePoint {
            pos: path(k),
            pressure: 1.0,
        })
    };
    doc.apply(command).map_err(|e| e.to_string())?;
    Ok(())
}

/// `times` placements of the decal benchmark's decal on the mesh document, each undone.
fn decals(times: u32) -> Result<(), String> {
    use kapaint::model::{HistoryCommand, PaintCommand};
    let mut doc = mesh_tool_dab_document()?;
    let logo = image::DynamicImage::ImageRgba8(image::RgbaImage::from_fn(1024, 1024, |x, y| {
        let alpha = if (x / 64 + y / 64) % 3 == 0 { 0 } else { 255 };
        image::Rgba([(x / 4) as u8, (y / 4) as u8, 128, alpha])
    }));
    let image =
        kapaint::model::paint_image::PaintImage::decoded(std::path::Path::new("logo.png"), &logo)
            .map_err(|e| e.to_string())?;
    let mut fastest = f64::INFINITY;
    for _ in 0..times {
        let start = std::time::Instant::now();
        let place = PaintCommand::PlaceDecal {
            image: image.clone(),
            at: glam::Vec3::new(0.3, 0.4, 1.2),
            size: 0.5,
            rotation: 20.0,
            channels: kapaint::model::Channels::ALL,
            opacity: 1.0,
        };
        doc.apply(place).map_err(|e| e.to_string())?;
        fastest = fastest.min(start.elapsed().as_secs_f64());
        doc.apply(HistoryCommand::Undo).map_err(|e| e.to_string())?;
    }
    println!("decal: fastest placement {:.1} ms", fastest * 1e3);
    Ok(())
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "all".into());
    let dabs: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(3000);
    if which == "decal" {
        return decals(dabs);
    }
    let names: Vec<&str> = match which.as_str() {
        "all" => vec!["brush", "clone", "smudge", "stencil"],
        "mesh" => vec!["mesh-brush", "mesh-clone", "mesh-smudge"],
        one => vec![one],
    };
    let mut docs = names
        .iter()
        .map(|n| prepared(n))
        .collect::<Result<Vec<_>, _>>()?;
    // Seconds a dab, stroke by stroke, per tool.
    let mut strokes = vec![Vec::new(); names.len()];
    // Rounds of 250 dabs (one stroke), the tools taking turns.
    for round in 0..dabs.div_ceil(250) {
        for (((doc, tool), times), name) in docs.iter_mut().zip(&mut strokes).zip(&names) {
            let start = std::time::Instant::now();
            doc.apply(StrokeCommand::BeginStroke(*tool))
                .map_err(|e| e.to_string())?;
            for k in round * 250..(round + 1) * 250 {
                dab(doc, name, k)?;
            }
            doc.apply(StrokeCommand::EndStroke)
                .map_err(|e| e.to_string())?;
            times.push(start.elapsed().as_secs_f64() / 250.0);
        }
    }
    for (name, times) in names.iter().zip(strokes) {
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        let fastest = times.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "{name}: {:.3} ms a dab (fastest stroke {:.3} ms)",
            mean * 1e3,
            fastest * 1e3
        );
    }
    Ok(())
}
