//! Criterion benches for the mesh targets (issue 4): a 4096^2 UV bake of a ~100k-triangle
//! mesh (target <= 1 s) and of the spot mesh.

#![allow(missing_docs)] // criterion_main! generates an undocumented main.
#![allow(clippy::expect_used)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use kapaint::mesh::{self, bake::bake};

fn bakes(c: &mut Criterion) {
    let mut group = c.benchmark_group("bake_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let sphere = mesh::uv_sphere(317, 158); // ~100k triangles
    assert!(sphere.triangles.len() > 99_000);
    group.bench_function("uv_sphere_100k_triangles_padding_4", |b| {
        b.iter(|| bake(&sphere, 4096, 4096, 4).expect("bakes"));
    });
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    group.bench_function("spot_padding_4", |b| {
        b.iter(|| bake(&spot, 4096, 4096, 4).expect("bakes"));
    });
    group.finish();
}

criterion_group!(benches, bakes);
criterion_main!(benches);
