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
    group.bench_function("rank_n_encodings_8_bit", |b| {
        b.iter(|| {
            encoding::rank_encodings(doc.maps(), doc.settings().model, doc.settings().approx, 8)
        });
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
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
