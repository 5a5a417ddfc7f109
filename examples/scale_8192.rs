//! Measures the 8192^2 targets of the material model: resident memory with 50 strokes of
//! undo, project file size, save and load time.
//!
//! Usage: `cargo run --release --example scale_8192 [SIDE]`

use std::path::Path;
use std::time::Instant;

use kapaint::model::project;
use kapaint::report::typical::typical_document;

fn resident_bytes() -> u64 {
    kapaint::memory::process_bytes("VmRSS:").unwrap_or(0)
}

fn main() -> Result<(), String> {
    let side: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(8192);
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    let start = Instant::now();
    let doc = typical_document(side, texture.exists().then_some(texture.as_path()), 50)?;
    println!(
        "built {side}x{side} typical document in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    println!("undo steps: {}", doc.history().undo_steps().count());
    println!(
        "maps heap: {:.1} MiB",
        doc.maps().heap_bytes() as f64 / 1_048_576.0
    );
    println!(
        "history: {:.1} MiB",
        doc.history().bytes() as f64 / 1_048_576.0
    );
    println!("resident: {:.1} MiB", resident_bytes() as f64 / 1_048_576.0);
    let path = std::env::temp_dir().join("kapaint-scale.kapaint");
    for round in 0..3 {
        let t = Instant::now();
        project::save(&doc, &path).map_err(|e| e.to_string())?;
        let save_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let loaded = project::load(&path).map_err(|e| e.to_string())?;
        let load_s = t.elapsed().as_secs_f64();
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        println!(
            "round {round}: save {save_s:.2} s, load {load_s:.2} s, file {:.1} MiB",
            bytes as f64 / 1_048_576.0
        );
        drop(loaded);
    }
    let _ = std::fs::remove_file(&path);
    Ok(())
}
