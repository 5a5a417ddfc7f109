//! Criterion benches for the reflectance kernels: `chi` per method, and the k_a derive of a
//! map on one thread and on all threads against a plain copy of the same input bytes.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use kapaint::reflectance::{AmbientApprox, ShadingModel, chi_parts_f32, derive_ka, derive_ka_par};
use kapaint::report::bench::BenchMaps;
use rayon::prelude::*;

const SIDE: usize = 1024;

/// The methods a model has: Cook-Torrance has only its fit.
fn methods(model: ShadingModel) -> Vec<AmbientApprox> {
    AmbientApprox::ALL
        .into_iter()
        .filter(|a| model.has_paper_forms() || *a == AmbientApprox::Fast)
        .collect()
}

fn chi(c: &mut Criterion) {
    let ns: Vec<f32> = (0..4096).map(|i| (i as f32 * 0.0023).exp() - 1.0).collect();
    let mut group = c.benchmark_group("chi_f32");
    group.throughput(Throughput::Elements(ns.len() as u64));
    for model in ShadingModel::ALL {
        // Cook-Torrance has its fit whatever the method: one entry.
        for approx in methods(model) {
            let id = BenchmarkId::new(model.name(), approx.name());
            group.bench_function(id, |b| {
                // Both parts (Cook-Torrance's chi_0 is 0 for the others).
                b.iter(|| {
                    ns.iter()
                        .map(|&n| chi_parts_f32(model, approx, black_box(n)))
                        .fold(0.0, |acc, [a, b]| acc + a + b)
                });
            });
        }
    }
    group.finish();
}

/// `chi_view` from the per-view table (issue 42) beside `chi`'s fit, in the same run: one
/// evaluation per (n, view) pair, 4096 pairs.
fn chi_view(c: &mut Criterion) {
    let pairs: Vec<(f32, f32)> = (0..4096)
        .map(|i| {
            let n = (i as f32 * 0.0023).exp() - 1.0;
            let phi = (i as f32 * 0.618_034).fract() * 1.56;
            (n, phi)
        })
        .collect();
    let mut group = c.benchmark_group("chi_view_f32");
    group.throughput(Throughput::Elements(pairs.len() as u64));
    for model in ShadingModel::ALL {
        group.bench_function(BenchmarkId::new(model.name(), "chi_fast"), |b| {
            b.iter(|| {
                pairs
                    .iter()
                    .map(|&(n, _)| chi_parts_f32(model, AmbientApprox::Fast, black_box(n)))
                    .fold(0.0, |acc, [a, b]| acc + a + b)
            });
        });
        group.bench_function(BenchmarkId::new(model.name(), "chi_view_fast"), |b| {
            b.iter(|| {
                pairs
                    .iter()
                    .filter_map(|&(n, phi)| {
                        kapaint::reflectance::view::chi_view_fast(model, black_box(n), phi)
                    })
                    .fold(0.0, |acc, [a, b]| acc + a + b)
            });
        });
    }
    group.finish();
}

fn derive(c: &mut Criterion) {
    let texels = SIDE * SIDE;
    let maps = BenchMaps::new(texels);
    let mut out = vec![Vec3::ZERO; texels];
    let mut group = c.benchmark_group("derive_ka_1024x1024");
    group.throughput(Throughput::Elements(texels as u64));
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3));
    for model in ShadingModel::ALL {
        for approx in methods(model) {
            let name = format!("{}_{}", model.name(), approx.name());
            group.bench_function(BenchmarkId::new("one_thread", &name), |b| {
                b.iter(|| derive_ka(model, approx, &maps.kd, &maps.ks, &maps.n, &mut out));
            });
            group.bench_function(BenchmarkId::new("all_threads", &name), |b| {
                b.iter(|| derive_ka_par(model, approx, &maps.kd, &maps.ks, &maps.n, &mut out));
            });
        }
    }
    let bytes = texels * BenchMaps::BYTES_PER_TEXEL_READ;
    let src = vec![1u8; bytes];
    let mut dst = vec![0u8; bytes];
    group.bench_function("copy_inputs_one_thread", |b| {
        b.iter(|| dst.copy_from_slice(black_box(&src)));
    });
    group.bench_function("copy_inputs_all_threads", |b| {
        b.iter(|| {
            dst.par_chunks_mut(1 << 20)
                .zip(src.par_chunks(1 << 20))
                .for_each(|(d, s)| d.copy_from_slice(s));
        });
    });
    group.finish();
}

criterion_group!(benches, chi, chi_view, derive);
criterion_main!(benches);
