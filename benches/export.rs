//! Criterion benches for the exporter (issue 6): a 4096^2 typical project (the spot texture in
//! k_d, a log gradient of n, 50 strokes) exported with each preset (target: compact <= 2 s;
//! KTX2 with mips, uncompressed and BC7/BC4 at the default effort, measured),
//! and the choice of n's encoding alone.

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
    for name in ["compact", "16-bit", "with-ka", "ktx2-raw", "ktx2"] {
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

criterion_group!(benches, exports);
criterion_main!(benches);
