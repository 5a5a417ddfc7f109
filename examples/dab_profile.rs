//! Profiling aid: repeats 128 px dabs on a 4096^2 map (`perf record` this).

use glam::{Vec2, Vec3};
use kapaint::model::brush::BrushSettings;
use kapaint::model::history::History;
use kapaint::model::paint::{Coverage, DiscFootprint, PaintTarget, paint_dab};
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Channels, MaterialMaps};

fn main() -> Result<(), String> {
    let brush = BrushSettings {
        radius_px: 128.0,
        hardness: 0.5,
        flow: 0.5,
        ..BrushSettings::default()
    };
    let channels = match std::env::args().nth(1).as_deref() {
        Some("kd") => Channels {
            kd: true,
            ks: false,
            n: false,
        },
        Some("n") => Channels {
            kd: false,
            ks: false,
            n: true,
        },
        Some("none") => Channels {
            kd: false,
            ks: false,
            n: false,
        },
        _ => Channels::ALL,
    };
    let target = PaintTarget::new(
        MaterialValue::new(Vec3::new(1.0, 0.2, 0.1), Vec3::splat(0.6), 300.0),
        channels,
        brush.blend,
        false,
    );
    let mut maps =
        MaterialMaps::new(4096, 4096, MaterialValue::default()).map_err(|e| e.to_string())?;
    let mut history = History::default();
    history.begin("profile");
    let fp = DiscFootprint {
        center: Vec2::new(2000.5, 1500.5),
        radius: 128.0,
        brush: &brush,
    };
    let start = std::time::Instant::now();
    let rounds = 2000;
    for _ in 0..rounds {
        let mut coverage = Coverage::default();
        paint_dab(
            &mut maps,
            &mut history,
            &mut coverage,
            &target,
            1.0,
            0.5,
            &fp,
        );
    }
    println!(
        "{:.3} ms per dab",
        start.elapsed().as_secs_f64() * 1e3 / f64::from(rounds)
    );
    Ok(())
}
