//! Profiling aid: repeats a hard 128 px dab inside one 256x256 square of 4096^2 maps and
//! syncs the dirty tiles to the GPU each time (`perf record` this). Prints the mean sync
//! time, with and without waiting for the queue. `cargo run --release --example
//! upload_profile [ROUNDS]`.

use std::time::{Duration, Instant};

use glam::Vec2;
use kapaint::gpu::{Gpu, MapTextures};
use kapaint::model::StrokeCommand;
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::{Document, DocumentSettings, StrokeTool};

fn main() -> Result<(), String> {
    let gpu = Gpu::headless().map_err(|e| e.to_string())?;
    let brush = BrushSettings {
        radius_px: 128.0,
        hardness: 1.0,
        ..BrushSettings::default()
    };
    let mut doc = Document::new(
        4096,
        4096,
        DocumentSettings {
            brush,
            ..DocumentSettings::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let mut maps = MapTextures::new(&gpu, doc.maps()).map_err(|e| e.to_string())?;
    // Rounds from the first argument (default 2000).
    let rounds: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2000);
    let (mut cpu, mut whole) = (Duration::ZERO, Duration::ZERO);
    for k in 0..rounds {
        let x0 = f32::from((k % 15) as u16) * 256.0;
        doc.apply(StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points: vec![StrokePoint {
                pos: Vec2::new(x0 + 128.0, 128.0 + 256.0 * (k % 7) as f32),
                pressure: 1.0,
            }],
        })
        .map_err(|e| e.to_string())?;
        let start = Instant::now();
        maps.sync(&gpu, doc.maps()).map_err(|e| e.to_string())?;
        cpu += start.elapsed();
        gpu.wait();
        whole += start.elapsed();
    }
    let ms = |d: Duration| d.as_secs_f64() * 1e3 / f64::from(rounds);
    println!(
        "sync {:.3} ms (CPU side), {:.3} ms until the GPU has it",
        ms(cpu),
        ms(whole)
    );
    Ok(())
}
