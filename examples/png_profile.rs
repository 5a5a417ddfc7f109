//! The `compact` export and its PNG encoding, profiled: the whole export timed, then every
//! PNG of the set decoded and encoded again at each compression and filter setting of the
//! `png` crate (through `image`), timed and sized, all in one run. kapaint writes
//! `Fast` (`fdeflate`'s ultra-fast compressor) with the `Adaptive` filter.
//!
//! Usage: `cargo run --release --example png_profile [SIDE]`

use std::path::Path;
use std::time::Instant;

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use kapaint::export::preset;
use kapaint::export::set;
use kapaint::report::typical::typical_document;

fn main() -> Result<(), String> {
    let side: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4096);
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    let doc = typical_document(side, texture.exists().then_some(texture.as_path()), 50)?;
    let p = preset::find("compact").map_err(|e| e.to_string())?;
    let out = std::env::temp_dir().join(format!("kapaint-png-{}", std::process::id()));
    let mut best = f64::MAX;
    let mut manifest = None;
    for _ in 0..3 {
        let _ = std::fs::remove_dir_all(&out);
        let start = Instant::now();
        manifest = Some(set::export(&doc, &p, &out).map_err(|e| e.to_string())?);
        best = best.min(start.elapsed().as_secs_f64());
    }
    println!("compact {side}^2: {best:.2} s (best of 3)");
    let manifest = manifest.ok_or("no export")?;
    let settings = [
        ("Fast", CompressionType::Fast, FilterType::Adaptive),
        ("Fast", CompressionType::Fast, FilterType::Sub),
        ("Fast", CompressionType::Fast, FilterType::Up),
        ("Fast", CompressionType::Fast, FilterType::Paeth),
        ("Fast", CompressionType::Fast, FilterType::NoFilter),
        ("Level(1)", CompressionType::Level(1), FilterType::Adaptive),
        ("Default", CompressionType::Default, FilterType::Adaptive),
    ];
    println!("file, compression, filter: seconds (one thread), bytes");
    for file in &manifest.files {
        let image = image::open(out.join(&file.path)).map_err(|e| e.to_string())?;
        let (w, h) = (image.width(), image.height());
        let color = image.color().into();
        for (name, compression, filter) in settings {
            let mut bytes = Vec::new();
            let start = Instant::now();
            PngEncoder::new_with_quality(&mut bytes, compression, filter)
                .write_image(image.as_bytes(), w, h, color)
                .map_err(|e| e.to_string())?;
            println!(
                "  {} {name} {filter:?}: {:.3} s, {} bytes",
                file.path,
                start.elapsed().as_secs_f64(),
                bytes.len()
            );
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    Ok(())
}
