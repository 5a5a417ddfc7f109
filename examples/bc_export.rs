//! Block-compressed export, measured: the `ktx2` preset on the stroke-edge project (the spot
//! texture in `k_d`, two soft strokes of `n = 3000` and `n = 2`), then, side by side in the
//! same run, the block encoders alone on the packed RGBA8 level 0 on one thread: Intel's ISPC
//! kernels and `block_compression`'s port at each BC7 effort, with their PSNR.
//!
//! Usage: `cargo run --release --example bc_export [SIDE] [PRESET] [export-only]`
//! (`export-only` skips the encoders' comparison, e.g. to measure the export's peak memory
//! with `/usr/bin/time -v`).

use std::path::Path;
use std::time::Instant;

use kapaint::export::blocks::{self, Coder};
use kapaint::export::codec::{Bc7, Effort};
use kapaint::export::preset;
use kapaint::export::set;
use kapaint::report::typical::stroke_edge_document;

fn psnr(a: &[u8], b: &[u8], k: usize) -> f64 {
    let (sum, count) =
        a.chunks_exact(4)
            .zip(b.chunks_exact(4))
            .fold((0.0, 0.0), |(s, c), (x, y)| {
                let d = f64::from(x[k]) - f64::from(y[k]);
                (s + d * d, c + 1.0)
            });
    10.0 * (255.0_f64 * 255.0 / (sum / count).max(1e-12)).log10()
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let side: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(4096);
    let name = args.next().unwrap_or_else(|| "ktx2".into());
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    let doc = stroke_edge_document(side, texture.exists().then_some(texture.as_path()))?;
    let p = preset::find(&name).map_err(|e| e.to_string())?;
    let out = std::env::temp_dir().join(format!("kapaint-bc-{}", std::process::id()));
    let start = Instant::now();
    let manifest = set::export(&doc, &p, &out).map_err(|e| e.to_string())?;
    println!("{name} {side}^2: {:.2} s", start.elapsed().as_secs_f64());
    println!(
        "k_a error: max {:.3} %, mean {:.4} %",
        manifest.ka_error.max * 100.0,
        manifest.ka_error.mean * 100.0
    );
    for (l, e) in manifest.level_ka_error.iter().enumerate() {
        println!(
            "  level {l}: max {:.3} %, mean {:.4} %",
            e.max * 100.0,
            e.mean * 100.0
        );
    }
    for f in &manifest.files {
        println!(
            "  {} {:?} {} bytes psnr {:?}",
            f.path, f.layout, f.bytes, f.psnr
        );
    }
    if let Some(b) = &manifest.blocks {
        println!(
            "chosen: {:?} {:?} ({:?}): {}",
            b.layout, b.bc7_effort, b.encoder, b.reason
        );
        for t in &b.trials {
            println!(
                "  trial {:?} {:?}: max {:.3} % mean {:.4} % psnr {:?} {:.2} s",
                t.layout,
                t.bc7_effort,
                t.ka_error.max * 100.0,
                t.ka_error.mean * 100.0,
                t.min_psnr,
                t.seconds
            );
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    if args.next().as_deref() == Some("export-only") {
        return Ok(());
    }

    // The encoders alone, one thread, on the packed level 0 (k_d sRGB + n code in alpha).
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let mut rgba = Vec::with_capacity(w as usize * h as usize * 4);
    let n_lo = 2.0_f32.ln_1p();
    let n_hi = 3000.0_f32.ln_1p();
    for y in 0..h {
        for x in 0..w {
            let v = maps.texel(x, y).decode();
            for c in 0..3 {
                rgba.push(kapaint::model::texel::linear_to_srgb8(v.kd[c]));
            }
            rgba.push(
                ((v.n.ln_1p() - n_lo) / (n_hi - n_lo) * 255.0)
                    .round()
                    .clamp(0.0, 255.0) as u8,
            );
        }
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    println!("one thread, BC7 RGBA {w}x{h} level 0:");
    let bc7 = Bc7::new(true, false);
    for effort in [Effort::UltraFast, Effort::VeryFast] {
        for encoder in [Coder::Ispc, Coder::Portable] {
            let start = Instant::now();
            let blocks = one
                .install(|| blocks::encode(encoder, &bc7, effort, &rgba, (w, h), None))
                .map_err(|e| e.to_string())?;
            let secs = start.elapsed().as_secs_f64();
            let back = blocks::decode(&bc7, &blocks, (w, h)).map_err(|e| e.to_string())?;
            println!(
                "  {encoder:?} {effort:?}: {secs:.2} s, PSNR {:.1} / {:.1} / {:.1} / {:.1} dB",
                psnr(&rgba, &back, 0),
                psnr(&rgba, &back, 1),
                psnr(&rgba, &back, 2),
                psnr(&rgba, &back, 3)
            );
        }
    }
    Ok(())
}
