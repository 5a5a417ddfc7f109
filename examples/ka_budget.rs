//! The export budget in what the eye sees, measured: the typical project (the spot texture in
//! `k_d`, a log gradient of `n`, 50 strokes) and the stroke-edge project (two soft strokes of
//! `n = 3000` and `n = 2`) exported with `ktx2-raw` and the block-compressed presets, each
//! set's `k_a` error in levels of 8-bit sRGB (max, p99.9, mean) per mip level, the relative
//! error, the block search's choice and the export's time, in one run.
//!
//! Usage: `cargo run --release --example ka_budget [SIDE] [PRESET...]` (default 4096, and
//! `ktx2-raw ktx2`).

use std::path::Path;
use std::time::Instant;

use kapaint::export::{preset, set};
use kapaint::report::typical::{stroke_edge_document, typical_document};

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let side: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(4096);
    let mut presets: Vec<String> = args.collect();
    if presets.is_empty() {
        presets = vec!["ktx2-raw".into(), "ktx2".into()];
    }
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    let texture = texture.exists().then_some(texture.as_path());
    let projects = [
        ("typical", typical_document(side, texture, 50)?),
        ("stroke-edge", stroke_edge_document(side, texture)?),
    ];
    for (project, doc) in &projects {
        for name in &presets {
            let p = preset::find(name).map_err(|e| e.to_string())?;
            let out = std::env::temp_dir().join(format!(
                "kapaint-ka-budget-{}-{project}-{name}",
                std::process::id()
            ));
            let start = Instant::now();
            let m = set::export(doc, &p, &out).map_err(|e| e.to_string())?;
            let seconds = start.elapsed().as_secs_f64();
            let _ = std::fs::remove_dir_all(&out);
            let srgb = m.ka_error_srgb.unwrap_or_default();
            println!(
                "{project} {side}^2, {name}: {seconds:.2} s; sRGB levels max {:.2}, p99.9 {:.2}, mean {:.3}; relative max {:.2} %, mean {:.3} %",
                srgb.max,
                srgb.p999,
                srgb.mean,
                m.ka_error.max * 100.0,
                m.ka_error.mean * 100.0
            );
            let levels: Vec<String> = m
                .level_ka_error_srgb
                .iter()
                .map(|e| format!("{:.2}/{:.3}", e.p999, e.mean))
                .collect();
            if !levels.is_empty() {
                println!("  p99.9/mean per mip level: {}", levels.join(" "));
            }
            if let Some(b) = &m.blocks {
                println!("  {}", b.summary());
                for t in &b.trials {
                    let e = t.ka_error_srgb.unwrap_or_default();
                    println!(
                        "    {:?} at {:?}: p99.9 {:.2}, mean {:.3}, max {:.2} levels; {:.2} s",
                        t.layout, t.bc7_effort, e.p999, e.mean, e.max, t.seconds
                    );
                }
            }
        }
    }
    Ok(())
}
