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

fn picking(c: &mut Criterion) {
    use glam::Vec3;
    use kapaint::mesh::pick::Bvh;
    let mut group = c.benchmark_group("pick_1m");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    let sphere = mesh::uv_sphere(1000, 500); // ~1M triangles
    assert!(sphere.triangles.len() > 990_000);
    group.bench_function("bvh_build_1m_triangles", |b| b.iter(|| Bvh::build(&sphere)));
    let bvh = Bvh::build(&sphere);
    // Rays from a camera at distance 3 through points spread over the sphere's silhouette.
    let rays: Vec<(Vec3, Vec3)> = (0..256)
        .map(|i| {
            let (a, r) = (i as f32 * 2.399, (i as f32 / 256.0).sqrt() * 0.95);
            let origin = Vec3::new(0.0, 0.0, 3.0);
            (origin, Vec3::new(r * a.cos(), r * a.sin(), 0.0) - origin)
        })
        .collect();
    let mut k = 0;
    group.bench_function("pick_1m_triangles", |b| {
        b.iter(|| {
            k = (k + 1) % rays.len();
            bvh.pick(&sphere, rays[k].0, rays[k].1).expect("hits")
        });
    });
    group.finish();
}

criterion_group!(benches, bakes, picking);
criterion_main!(benches);
