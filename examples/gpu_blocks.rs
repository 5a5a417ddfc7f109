//! GPU against CPU block encoding, side by side in one run: BC7 (opaque, each effort given)
//! of the spot texture scaled to `SIDE`^2 (default 4096), on the GPU block encoder (any
//! adapter, software included) and on the CPU's best encoder, with their PSNR. The pipeline
//! build is timed apart.
//!
//! `cargo run --release --example gpu_blocks [SIDE] [EFFORT...]` (efforts: `ultra-fast`,
//! `very-fast`, `fast`, `basic`, `slow`; default `ultra-fast`).

use std::time::Instant;

use kapaint::export::blocks::{self, Coder};
use kapaint::export::codec::{Bc7, Effort};
use kapaint::export::ktx::{Space, psnr};

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let side: u32 = args
        .next()
        .map_or(Ok(4096), |s| s.parse())
        .map_err(|e| format!("SIDE: {e}"))?;
    let efforts: Vec<Effort> = args
        .map(|a| {
            Effort::ALL
                .into_iter()
                .find(|q| format!("{q:?}").to_lowercase() == a.replace('-', ""))
                .ok_or(format!("unknown effort {a}"))
        })
        .collect::<Result<_, _>>()?;
    let efforts = if efforts.is_empty() {
        vec![Effort::UltraFast]
    } else {
        efforts
    };
    let spot = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/testdata/spot/spot_texture.png"
    );
    let texels = image::open(spot)
        .map_err(|e| format!("{spot}: {e}"))?
        .resize_exact(side, side, image::imageops::FilterType::Triangle)
        .to_rgba8()
        .into_raw();
    let t = Instant::now();
    let gpu = kapaint::gpu::Gpu::headless().map_err(|e| e.to_string())?;
    let adapter = format!(
        "{} ({:?}, {:?})",
        gpu.info.name, gpu.info.device_type, gpu.info.backend
    );
    let encoder = kapaint::gpu::blocks::GpuBlockEncoder::new(gpu);
    println!(
        "{adapter}: pipelines built in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    let size = (side, side);
    let spaces = [Space::Srgb, Space::Srgb, Space::Srgb, Space::Linear];
    let bc7 = Bc7::new(false, true);
    for effort in efforts {
        for encoder in [Coder::Brought(&encoder), Coder::best_cpu()] {
            let t = Instant::now();
            let out = blocks::encode(encoder, &bc7, effort, &texels, size, None)
                .map_err(|e| e.to_string())?;
            let seconds = t.elapsed().as_secs_f64();
            let back = blocks::decode(&bc7, &out, size).map_err(|e| e.to_string())?;
            let db: Vec<String> = psnr(&texels, &back, &spaces)
                .iter()
                .map(|p| p.map_or("exact".into(), |p| format!("{p:.2}")))
                .collect();
            println!(
                "{side}^2 BC7 {effort:?} {encoder:?}: {seconds:.3} s, PSNR {} dB",
                db.join(" / ")
            );
        }
    }
    Ok(())
}
