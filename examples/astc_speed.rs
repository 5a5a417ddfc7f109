//! kapaint's ASTC 4x4 encoding (ARM's astcenc, through the export's block encoder) timed at
//! each effort on the images the peer script also encodes: the typical project's `k_d` + `n`
//! image (level 0 as `ktx2-raw` stores it) and the spot texture. Writes each input as raw
//! RGBA8 (`NAME.rgba`, with `NAME.size`) and each encoding's blocks (`NAME_EFFORT.astc`) into
//! OUT, and prints one line per encoding: seconds and megatexels per second. Run it with
//! `RAYON_NUM_THREADS=1` for one core (`benches/peers/astc_side_by_side.sh` does).
//!
//! Usage: `cargo run --release --example astc_speed -- OUT [SIDE]` (default 2048).

use std::path::{Path, PathBuf};
use std::time::Instant;

use kapaint::export::blocks::{self, Coder};
use kapaint::export::codec::{Astc, AstcBlock, Effort, astc};
use kapaint::export::preset;
use kapaint::export::{ktx, set};
use kapaint::report::typical::typical_document;

/// The typical project's `k_d` + `n` image at `side`, as RGBA8.
fn typical_kd_n(side: u32, texture: Option<&Path>, out: &Path) -> Result<Vec<u8>, String> {
    let doc = typical_document(side, texture, 50)?;
    let dir = out.join("raw-set");
    let raw = preset::find("ktx2-raw").map_err(|e| e.to_string())?;
    set::export(&doc, &raw, &dir).map_err(|e| e.to_string())?;
    let bytes = std::fs::read(dir.join("kd_n.ktx2")).map_err(|e| e.to_string())?;
    let _ = std::fs::remove_dir_all(&dir);
    let decoded = ktx::decode(&bytes)?;
    Ok(decoded
        .rgba
        .iter()
        .map(|v| (v * 255.0).round() as u8)
        .collect())
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().ok_or("usage: astc_speed OUT [SIDE]")?);
    let side: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(2048);
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    let mut inputs = vec![("typical", (side, side), {
        typical_kd_n(side, texture.exists().then_some(texture.as_path()), &out)?
    })];
    if texture.exists() {
        let spot = image::open(&texture).map_err(|e| e.to_string())?.to_rgba8();
        inputs.push(("spot", spot.dimensions(), spot.into_raw()));
    }
    println!("threads: {}", rayon::current_num_threads());
    for (name, (w, h), rgba) in &inputs {
        std::fs::write(out.join(format!("{name}.rgba")), rgba).map_err(|e| e.to_string())?;
        std::fs::write(out.join(format!("{name}.size")), format!("{w} {h}"))
            .map_err(|e| e.to_string())?;
        let codec = Astc::new(AstcBlock::DEFAULT, 4, false);
        for effort in Effort::ALL {
            let preset = astc::preset_of(effort).0.replace(' ', "-");
            // Once to build the codec's contexts, then timed.
            blocks::encode(Coder::best_cpu(), &codec, effort, rgba, (*w, *h), None)
                .map_err(|e| e.to_string())?;
            let start = Instant::now();
            let encoded = blocks::encode(Coder::best_cpu(), &codec, effort, rgba, (*w, *h), None)
                .map_err(|e| e.to_string())?;
            let seconds = start.elapsed().as_secs_f64();
            std::fs::write(out.join(format!("{name}_{preset}.astc")), &encoded)
                .map_err(|e| e.to_string())?;
            println!(
                "kapaint astcenc {name} {w}x{h} {preset}: {seconds:.3} s, {:.2} Mtexel/s",
                f64::from(w * h) / seconds / 1e6
            );
        }
    }
    Ok(())
}
