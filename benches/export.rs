//! Criterion benches for the exporter (issue 6): a 4096^2 typical project (the spot texture in
//! k_d, a log gradient of n, 50 strokes) exported with each preset (target: compact <= 2 s;
//! KTX2 with mips, uncompressed, BC and ASTC, each block preset at most 2x `ktx2-raw`), and
//! the choice of n's encoding alone.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use kapaint::export::{encoding, preset, set};

fn exports(c: &mut Criterion) {
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let doc = kapaint::report::typical::typical_document(
        4096,
        texture.exists().then_some(texture.as_path()),
        50,
    )
    .expect("typical document");
    let dir = std::env::temp_dir().join(format!("kapaint-export-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let mut group = c.benchmark_group("export_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    for name in [
        "compact",
        "16-bit",
        "with-ka",
        "ktx2-raw",
        "ktx2",
        "ktx2-astc",
    ] {
        let p = preset::find(name).expect("preset");
        let out = dir.join(name);
        group.bench_function(name, |b| {
            b.iter(|| {
                let _ = std::fs::remove_dir_all(&out);
                set::export(&doc, &p, &out).expect("export")
            });
        });
    }
    supercompression(&mut group, &doc, &dir);
    group.bench_function("rank_n_encodings_8_bit", |b| {
        b.iter(|| {
            encoding::rank_encodings(doc.maps(), doc.settings().model, doc.settings().approx, 8)
        });
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 58's supercompression: each shipped KTX2 preset as shipped (zstd) beside the same
/// without, the files' bytes said once (target: `ktx2` at least 15 % smaller, at most 10 %
/// slower); with `KAPAINT_ZSTD_SWEEP=1`, the sizes and seconds of every tenth level over the
/// plain `ktx2` set's files first.
fn supercompression(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    doc: &kapaint::model::Document,
    dir: &std::path::Path,
) {
    let bytes = |m: &set::Manifest| m.files.iter().map(|f| f.bytes).sum::<u64>();
    for name in ["ktx2-raw", "ktx2", "ktx2-astc"] {
        let shipped = preset::find(name).expect("preset");
        let mut plain = shipped.clone();
        plain.zstd = None;
        let (a, b) = (
            dir.join(format!("{name}-z")),
            dir.join(format!("{name}-plain")),
        );
        let with = set::export(doc, &shipped, &a).expect("export");
        let without = set::export(doc, &plain, &b).expect("export");
        eprintln!(
            "{name}: zstd {:?} {} bytes, without {} bytes ({:.1} % smaller)",
            shipped.zstd,
            bytes(&with),
            bytes(&without),
            (1.0 - bytes(&with) as f64 / bytes(&without) as f64) * 100.0
        );
        if name == "ktx2" && std::env::var_os("KAPAINT_ZSTD_SWEEP").is_some() {
            let files: Vec<Vec<u8>> = without
                .files
                .iter()
                .map(|f| std::fs::read(b.join(&f.path)).expect("reads"))
                .collect();
            for level in [1, 3, 6, 9, 12, 15, 19] {
                let start = std::time::Instant::now();
                let total: usize = files
                    .iter()
                    .map(|f| {
                        kapaint::export::ktx::supercompress(f, level)
                            .expect("packs")
                            .len()
                    })
                    .sum();
                eprintln!(
                    "  zstd {level}: {total} bytes ({:.1} % smaller), {:.2} s",
                    (1.0 - total as f64 / bytes(&without) as f64) * 100.0,
                    start.elapsed().as_secs_f64()
                );
            }
        }
        group.bench_function(format!("{name}_no_zstd"), |bench| {
            bench.iter(|| {
                let _ = std::fs::remove_dir_all(&b);
                set::export(doc, &plain, &b).expect("export")
            });
        });
    }
}

/// Issue 21's project (the spot texture in k_d, soft strokes of n = 3000 and n = 2): the
/// `ktx2` export with its effort search and full mip chains (target <= 5 s on 2 cores), and,
/// side by side in the same run, the BC7 encoders alone on one thread on the packed level 0:
/// Intel's ISPC kernels and `block_compression`'s port; and ASTC 4x4 (astcenc) on the same
/// texels at its fastest and thorough searches (ISPC's own ASTC encoder beside it:
/// `benches/peers/astc_side_by_side.sh`).
fn block_compression(c: &mut Criterion) {
    use kapaint::export::blocks::{self, Coder};
    use kapaint::export::codec::{Astc, AstcBlock, Bc7, Effort};
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let doc = kapaint::report::typical::stroke_edge_document(
        4096,
        texture.exists().then_some(texture.as_path()),
    )
    .expect("document");
    let dir = std::env::temp_dir().join(format!("kapaint-bc-bench-{}", std::process::id()));
    let mut group = c.benchmark_group("ktx2_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    let p = preset::find("ktx2").expect("preset");
    group.bench_function("ktx2_stroke_edges", |b| {
        b.iter(|| {
            let _ = std::fs::remove_dir_all(&dir);
            set::export(&doc, &p, &dir).expect("export")
        });
    });
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let rgba: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let v = maps.texel(i % w, i / w).decode();
            let n = (v.n.ln_1p() / 3000.0_f32.ln_1p() * 255.0).round() as u8;
            let s = |c: f32| kapaint::model::texel::linear_to_srgb8(c);
            [s(v.kd.x), s(v.kd.y), s(v.kd.z), n]
        })
        .collect();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    for (encoder, effort) in [
        (Coder::Ispc, Effort::UltraFast),
        (Coder::Portable, Effort::UltraFast),
        (Coder::Ispc, Effort::VeryFast),
    ] {
        let bc7 = Bc7::new(true, true);
        group.bench_function(format!("bc7_one_thread_{encoder:?}_{effort:?}"), |b| {
            b.iter(|| one.install(|| blocks::encode(encoder, &bc7, effort, &rgba, (w, h), None)));
        });
    }
    // One codec value for every iteration: its astcenc contexts are built once, as an
    // export's image builds them once for its trials and mips.
    let astc = Astc::new(AstcBlock::DEFAULT, 4, true);
    for effort in [Effort::UltraFast, Effort::Basic] {
        group.bench_function(format!("astc4x4_one_thread_{effort:?}"), |b| {
            b.iter(|| {
                one.install(|| blocks::encode(Coder::Ispc, &astc, effort, &rgba, (w, h), None))
            });
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, exports, block_compression);
criterion_main!(benches);
