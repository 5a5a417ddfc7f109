//! Block encoding on the GPU (issue 21): `block_compression`'s compute shaders through
//! `kapaint::gpu::blocks`, on whatever adapter there is (lavapipe here and in CI). Its blocks
//! decode as close to the source as the CPU encoder's, strip by strip, for every kind; a
//! whole `ktx2` export on it records the GPU encoder and reads back; a device lost part-way
//! hands the rest to the CPU; and the command line leaves a software adapter alone unless
//! asked.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use kapaint::export::blocks::{self, BlockEncoder, Coder, Encoder};
use kapaint::export::codec::{Bc4, Bc5, Bc6h, Bc7, Codec, Effort};
use kapaint::export::ktx::{Space, psnr};
use kapaint::export::preset;
use kapaint::export::set;
use kapaint::gpu::blocks::GpuBlockEncoder;
use kapaint::report::typical::stroke_edge_document;
use kapaint::task::Progress;

fn spot() -> Option<PathBuf> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    path.exists().then_some(path)
}

/// Soft gradients with a few hard edges, `per` bytes per texel (alpha opaque).
fn pattern((w, h): (u32, u32), per: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(w as usize * h as usize * per);
    for y in 0..h as usize {
        for x in 0..w as usize {
            for k in 0..per {
                let edge = if (x / 9 + y / 7) % 3 == 0 { 60 } else { 0 };
                let v = (x + y * 2 + k * 20 + edge).min(255);
                out.push(if per == 4 && k == 3 { 255 } else { v as u8 });
            }
        }
    }
    out
}

/// The same texels as linear half floats (RGBA, alpha 1), BC6H's input.
fn halves(bytes: &[u8]) -> Vec<u8> {
    bytes
        .chunks_exact(4)
        .flat_map(|t| {
            let v = [t[0], t[1], t[2]].map(|b| 0.01 + f32::from(b) / 255.0);
            [v[0], v[1], v[2], 1.0]
        })
        .flat_map(|v| half::f16::from_f32(v).to_le_bytes())
        .collect()
}

fn quality(codec: &dyn Codec, src: &[u8], blocks: &[u8], size: (u32, u32)) -> Vec<Option<f64>> {
    let back = blocks::decode(codec, blocks, size).expect("decoded");
    if codec.texel_bytes() == 8 {
        // Compare as 8-bit values: the halves' relative error shows as dB like the rest.
        let bytes = |d: &[u8]| -> Vec<u8> {
            d.chunks_exact(2)
                .map(|h| (half::f16::from_le_bytes([h[0], h[1]]).to_f32() * 255.0).round() as u8)
                .collect()
        };
        let spaces = vec![Space::Linear; 4];
        return psnr(&bytes(src), &bytes(&back), &spaces);
    }
    psnr(src, &back, &vec![Space::Linear; codec.texel_bytes()])
}

#[test]
fn gpu_blocks_decode_as_close_as_the_cpu_encoders_and_a_ktx2_export_records_them() {
    let Some(gpu) = common::gpu() else { return };
    let adapter = format!("{} ({:?})", gpu.info.name, gpu.info.device_type);
    // Strips of 8 texel rows: 44 rows are five whole strips and a short one. Building the
    // pipelines takes a minute on lavapipe: one encoder serves the whole test.
    // The export is handed the encoder; nothing in it opens a device of its own.
    let encoder = GpuBlockEncoder::new(gpu).with_strip_rows(8);
    let encoder = &encoder;
    assert_eq!(Coder::best(Some(encoder)).name(), Encoder::Gpu);
    assert_eq!(Coder::best(None).name(), Encoder::best_cpu());
    let size = (64, 44);
    let codecs: [(Box<dyn Codec>, Effort); 5] = [
        (Box::new(Bc4), Effort::UltraFast),
        (Box::new(Bc5), Effort::UltraFast),
        (Box::new(Bc7::new(false, true)), Effort::UltraFast),
        (Box::new(Bc7::new(true, false)), Effort::VeryFast),
        (Box::new(Bc6h), Effort::UltraFast),
    ];
    for (codec, effort) in codecs {
        let (codec, kind) = (&*codec, format!("{codec:?} {effort:?}"));
        assert!(encoder.encodes(codec), "{kind}");
        let src = if codec.texel_bytes() == 8 {
            halves(&pattern(size, 4))
        } else {
            pattern(size, codec.texel_bytes())
        };
        let row = size.0 as usize * codec.texel_bytes();
        let mut strips = Vec::new();
        let mut gpu_blocks = vec![0; (size.0 * size.1) as usize / 16 * codec.block_bytes()];
        encoder
            .encode(
                (codec, effort),
                size,
                &mut |y, rows, out: &mut [u8]| {
                    out.copy_from_slice(&src[y as usize * row..(y + rows) as usize * row]);
                },
                &mut |rows| {
                    strips.push(rows);
                    true
                },
                &mut gpu_blocks,
            )
            .expect("GPU encode");
        assert_eq!(strips, [8, 8, 8, 8, 8, 4], "{kind}");
        // Through the exporter's entry point too (texels widened strip by strip).
        let brought = blocks::encode(Coder::Brought(encoder), codec, effort, &src, size, None);
        assert_eq!(brought.expect("blocks"), gpu_blocks, "{kind}");
        let cpu_blocks =
            blocks::encode(Coder::best_cpu(), codec, effort, &src, size, None).expect("blocks");
        let (on_gpu, on_cpu) = (
            quality(codec, &src, &gpu_blocks, size),
            quality(codec, &src, &cpu_blocks, size),
        );
        for (g, c) in on_gpu.iter().zip(&on_cpu) {
            let (g, c) = (g.unwrap_or(99.0), c.unwrap_or(99.0));
            // The shaders port the CPU kernels: the same quality, give or take rounding. A
            // strip written to the wrong rows or a wrong source format falls below 20 dB.
            assert!(
                g > 30.0 && g > c - 1.0,
                "{kind} on {adapter}: GPU {on_gpu:?} dB, CPU {on_cpu:?} dB"
            );
        }
    }

    // A whole export: the manifest names the GPU encoder, and the set reads back close.
    let out = std::env::temp_dir().join(format!("kapaint-gpu-set-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let doc = stroke_edge_document(64, spot().as_deref()).expect("project");
    let manifest = ktx2_export(&doc, &out, &Progress::default(), encoder).expect("export");
    let choice = manifest.blocks.as_ref().expect("a block-compressed set");
    assert_eq!(choice.encoder, Encoder::Gpu);
    assert!(
        choice.trials.iter().all(|t| t.ka_error.mean < 0.02),
        "{choice:?}"
    );
    for file in &manifest.files {
        for p in file.psnr.iter().flatten().flatten() {
            assert!(*p > 40.0, "{}: {p} dB", file.path);
        }
    }
    set::import(&out.join("material.json")).expect("the set reads back");

    // Last: it ends this process's GPU encoder.
    lost_part_way_through_an_export(encoder, &out);
    let _ = std::fs::remove_dir_all(out);
}

/// The `ktx2` preset exported into `out` with `encoder` handed in.
fn ktx2_export(
    doc: &kapaint::model::Document,
    out: &Path,
    progress: &Progress,
    encoder: &GpuBlockEncoder,
) -> Result<set::Manifest, set::SetError> {
    let preset = preset::find("ktx2").expect("preset");
    match kapaint::export::run(doc, &preset, out, progress, false, None, Some(encoder))? {
        kapaint::export::Exported::Set(m) => Ok(m),
        kapaint::export::Exported::Pbr(_) => panic!("a kapaint set"),
    }
}

/// The device lost after the first strip of an export: the CPU goes on from the strip that
/// failed, so no strip is missing and none is counted twice, and the manifest names the CPU
/// encoder that finished, and why.
fn lost_part_way_through_an_export(encoder: &GpuBlockEncoder, out: &Path) {
    assert!(encoder.failure().is_none());
    let _ = std::fs::remove_dir_all(out);
    let doc = stroke_edge_document(256, spot().as_deref()).expect("project");
    let (progress, finished) = (Progress::default(), AtomicBool::new(false));
    let (manifest, (lost_in, most, total)) = std::thread::scope(|s| {
        let watch = s.spawn(|| {
            let running = || !finished.load(Ordering::Relaxed);
            // As soon as the first strip of the first trial is counted.
            while running() && !(progress.stage() == "encode" && progress.done() > 0) {
                std::thread::sleep(Duration::from_micros(50));
            }
            encoder.gpu().device.destroy();
            let (lost_in, total) = (progress.done(), progress.total());
            let mut most = 0;
            while running() && progress.stage() == "encode" && progress.total() == total {
                most = most.max(progress.done());
                std::thread::yield_now();
            }
            (lost_in, most, total)
        });
        let manifest = ktx2_export(&doc, out, &progress, encoder);
        finished.store(true, Ordering::Relaxed);
        (manifest, watch.join().expect("watcher"))
    });
    let manifest = manifest.expect("the CPU finishes the export");
    let why = encoder.failure().expect("the lost device was noticed");
    assert!(
        Coder::best(Some(encoder)).name() == Encoder::best_cpu(),
        "a given-up encoder is not used again"
    );
    let choice = manifest.blocks.as_ref().expect("a block-compressed set");
    assert_eq!(choice.encoder, Encoder::best_cpu(), "{choice:?}");
    assert_eq!(choice.gpu_failed.as_deref(), Some(why.as_str()));
    assert!(choice.summary().contains("the GPU encoder failed part-way"));
    assert!(
        lost_in > 0 && lost_in < total && most <= total,
        "lost after {lost_in} of {total} rows, counted {most}"
    );
    for file in &manifest.files {
        // A strip left empty or written to the wrong rows falls far below this.
        for p in file.psnr.iter().flatten().flatten() {
            assert!(*p > 40.0, "{}: {p} dB", file.path);
        }
    }
    set::import(&out.join("material.json")).expect("the set reads back");
}

#[test]
fn the_cli_takes_the_gpu_encoder_only_when_asked() {
    let Some(gpu) = common::gpu() else { return };
    drop(gpu);
    let dir = std::env::temp_dir().join(format!("kapaint-gpu-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let doc = stroke_edge_document(32, spot().as_deref()).expect("project");
    let project = dir.join("p.kapaint");
    kapaint::model::project::save(&doc, &project).expect("save");
    let out = dir.join("set");
    let export = |choice: &str| {
        let _ = std::fs::remove_dir_all(&out);
        let run = Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(["export", "--preset", "ktx2", "--report", "--out"])
            .arg(&out)
            .arg(&project)
            .env("KAPAINT_BLOCK_ENCODER", choice)
            .output()
            .expect("kapaint runs");
        let report = String::from_utf8_lossy(&run.stdout).into_owned();
        assert!(
            run.status.success(),
            "{report}{}",
            String::from_utf8_lossy(&run.stderr)
        );
        set::import(&out.join("material.json")).expect("the set reads back");
        report
    };
    // `auto` (the default) encodes on the CPU, which was faster than an H100 with its
    // pipelines to build, and far faster than lavapipe; `cpu` never opens the GPU; `gpu`
    // takes any adapter.
    for choice in ["auto", "cpu"] {
        let report = export(choice);
        assert!(
            !report.contains("(Gpu encoder)") && report.contains("encoder)"),
            "{choice}: {report}"
        );
    }
    let gpu = export("gpu");
    assert!(gpu.contains("(Gpu encoder)"), "{gpu}");
    let _ = std::fs::remove_dir_all(dir);
}
