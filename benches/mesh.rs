//! Criterion benches for the mesh targets (issue 4): a 4096^2 UV bake of a ~100k-triangle
//! mesh (target <= 1 s) and of the spot mesh; BVH build and pick on 1M triangles; the
//! object-space index and a 128 px-equivalent dab on 4096^2 maps (target <= 1 ms); MikkTSpace
//! tangents for normal maps; automatic UVs for meshes that have none.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

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
    // Overlapping UVs: 10,000 copies of one triangle over half of a 1024^2 map (25 s before
    // settled texels were skipped).
    let mut group = c.benchmark_group("bake_1024");
    group.sample_size(10);
    let stack = mesh::Mesh {
        name: "stack".into(),
        positions: vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
        normals: vec![glam::Vec3::Z; 3],
        uvs: Some(vec![glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y]),
        triangles: vec![[0, 1, 2]; 10_000],
        had_normals: true,
        labels: mesh::Labels::default(),
    };
    group.bench_function("stacked_uvs_10000_copies", |b| {
        b.iter(|| bake(&stack, 1024, 1024, 0).expect("bakes"));
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

/// Object-space dabs as the editor paints them: `SurfaceStrokeTo` on a one-layer 4096^2
/// document with the mesh attached, each step 32 texels from the last (one 128 px dab at 25 %
/// spacing), back and forth across one spot so the stroke's tiles stay the same.
fn surface_dabs(c: &mut Criterion) {
    use glam::Vec3;
    use kapaint::model::StrokeCommand;
    use kapaint::model::brush::{BrushSettings, StrokePoint, SurfacePos};
    use kapaint::model::surface::Surface;
    use kapaint::model::texel::MaterialValue;
    use kapaint::model::{Document, DocumentSettings, StrokeTool};
    let mut group = c.benchmark_group("surface_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(5));
    let sphere = mesh::uv_sphere(64, 32);
    group.bench_function("surface_index_sphere", |b| {
        b.iter(|| Surface::new(sphere.clone(), 4096, 4096).expect("bakes"));
    });
    let settings = DocumentSettings {
        brush: BrushSettings {
            radius_px: 128.0,
            hardness: 0.5,
            flow: 0.5,
            ..BrushSettings::default()
        },
        primary: MaterialValue::new(Vec3::new(1.0, 0.2, 0.1), Vec3::splat(0.6), 300.0),
        ..DocumentSettings::default()
    };
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    for (name, mesh) in [("dab_128px_sphere", sphere), ("dab_128px_spot", spot)] {
        // A vertex half-way through the file: somewhere on the body.
        let center = mesh.positions[mesh.positions.len() / 2];
        let surface = std::sync::Arc::new(Surface::new(mesh, 4096, 4096).expect("bakes"));
        let step = 32.0 * surface.units_per_texel;
        let normal = surface
            .normal_near(center, 128.0 * surface.units_per_texel)
            .expect("on the surface");
        let across = normal.any_orthonormal_vector() * step;
        let mut doc = Document::new(4096, 4096, settings.clone())
            .expect("size")
            .with_surface(Some(surface))
            .expect("surface");
        let mut k = 0_u32;
        group.bench_function(name, |b| {
            b.iter(|| {
                if k.is_multiple_of(256) {
                    doc.apply(StrokeCommand::EndStroke).expect("end");
                    doc.apply(StrokeCommand::BeginStroke(StrokeTool::Brush))
                        .expect("begin");
                }
                k += 1;
                let point = if k.is_multiple_of(2) {
                    center
                } else {
                    center + across
                };
                doc.apply(StrokeCommand::SurfaceStrokeTo(StrokePoint {
                    pos: SurfacePos { point, normal },
                    pressure: 1.0,
                }))
                .expect("dab");
            });
        });
    }
    group.finish();
}

/// MikkTSpace tangents (issue 20's normal maps): what the preview's mesh upload and the `.glb`
/// export add, on the spot mesh and on ~100k triangles.
fn tangents(c: &mut Criterion) {
    let mut group = c.benchmark_group("tangents");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let sphere = mesh::uv_sphere(317, 158);
    group.bench_function("uv_sphere_100k_triangles", |b| {
        b.iter(|| mesh::tangents::generate(&sphere).expect("tangents"));
    });
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    group.bench_function("spot", |b| {
        b.iter(|| mesh::tangents::generate(&spot).expect("tangents"));
    });
    group.finish();
}

/// Automatic UVs for a 2048^2 map: teapot and suzanne (no UVs of their own; targets 0.5 s and
/// 0.2 s), and spot's own UVs replaced on request (1 s for a mesh re-unwrapped on request).
fn unwraps(c: &mut Criterion) {
    use kapaint::mesh::unwrap::{UnwrapOptions, unwrap};
    let mut group = c.benchmark_group("unwrap_2048");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (name, path) in [
        (
            "teapot_6320_triangles",
            root.join("tests/data/meshes/teapot.obj"),
        ),
        (
            "suzanne_968_triangles",
            root.join("tests/data/meshes/suzanne.obj"),
        ),
        (
            "spot_5856_triangles_rewrapped",
            root.join("../shared/testdata/spot/spot_triangulated.obj"),
        ),
    ] {
        let mesh = mesh::load(&path).expect("mesh loads");
        group.bench_function(name, |b| {
            b.iter(|| unwrap(&mesh, UnwrapOptions::for_size(2048), None).expect("unwraps"));
        });
    }
    group.finish();
}

/// The OBJ text of one polygon of `corners` corners round the unit circle, its radius (`flat`)
/// or its height (else) waving 200 times: a 3 MB file at 100,000 corners.
fn polygon_obj(corners: usize, flat: bool) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    for i in 0..corners {
        let t = std::f64::consts::TAU * i as f64 / corners as f64;
        let wave = (200.0 * t).sin();
        let (r, z) = if flat {
            (1.0 + 0.3 * wave, 0.0)
        } else {
            (1.0, 0.3 * wave)
        };
        let _ = writeln!(out, "v {:.7} {:.7} {z:.7}", r * t.cos(), r * t.sin());
    }
    out.push('f');
    for i in 1..=corners {
        let _ = write!(out, " {i}");
    }
    out.push('\n');
    out
}

/// The OBJ text of a bumpy `n x n` latitude-longitude sphere (2 n (n - 1) triangles: 1,998,000
/// at 1000), no UVs: the radius `1 + 0.02 sin(20 theta) sin(20 phi)`.
fn bumpy_sphere_obj(n: usize) -> String {
    use std::fmt::Write as _;
    let mut out = String::with_capacity(n * n * 40);
    for i in 0..=n {
        let theta = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..n {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            let r = 1.0 + 0.02 * (20.0 * theta).sin() * (20.0 * phi).sin();
            let (x, y, z) = (
                r * theta.sin() * phi.cos(),
                r * theta.cos(),
                r * theta.sin() * phi.sin(),
            );
            let _ = writeln!(out, "v {x:.7} {y:.7} {z:.7}");
        }
    }
    let at = |i: usize, j: usize| i * n + j % n + 1;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            if i > 0 {
                let _ = writeln!(out, "f {a} {b} {c}");
            }
            if i + 1 < n {
                let _ = writeln!(out, "f {b} {d} {c}");
            }
        }
    }
    out
}

/// Meshes as they come (issue 54, target: the 2M-triangle sphere within 60 s on 2 cores):
/// loading and unwrapping one polygon of 100,000 corners, flat and waving in height, and a
/// bumpy sphere of 1,998,000 triangles, each made here and read from an OBJ file.
fn unwraps_big(c: &mut Criterion) {
    use kapaint::mesh::unwrap::{UnwrapOptions, unwrap};
    let dir = std::env::temp_dir().join(format!("kapaint-bench-unwrap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("folder");
    let mut group = c.benchmark_group("unwrap_big");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for (name, text) in [
        ("polygon_100000_corners_flat", polygon_obj(100_000, true)),
        ("polygon_100000_corners_waving", polygon_obj(100_000, false)),
        ("bumpy_sphere_1998000_triangles", bumpy_sphere_obj(1000)),
    ] {
        let path = dir.join(format!("{name}.obj"));
        std::fs::write(&path, text).expect("written");
        group.bench_function(name, |b| {
            b.iter(|| {
                let mesh = mesh::load(&path).expect("mesh loads");
                unwrap(&mesh, UnwrapOptions::for_size(1024), None).expect("unwraps")
            });
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// An AO bake of spot at 1024^2 with 64 rays a texel (the 2048^2 figures of docs/performance.md
/// come from `kapaint bake`, a run each: one sample is 20 s).
fn ao_bakes(c: &mut Criterion) {
    use kapaint::mesh::bakes::{BakeMap, BakeOptions, bake_map};
    let mut group = c.benchmark_group("ao_1024_64_rays");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(40));
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    let uv = bake(&spot, 1024, 1024, 4).expect("bakes");
    let options = BakeOptions {
        rays: 64,
        max_distance: None,
    };
    group.bench_function("spot_5856_triangles", |b| {
        b.iter(|| bake_map(&spot, &uv, BakeMap::Ao, options, None).expect("bakes"));
    });
    group.finish();
}

/// The traced view (issue 42): the spot cow at 1024^2, 64 samples per pixel on the CPU path
/// (target under 10 s), primary rays and BVH included; and one pass of one sample, what the
/// editor's worker adds between pictures.
fn traced(c: &mut Criterion) {
    use kapaint::mesh::{bakes::RayMesh, pick::Bvh};
    use kapaint::reflectance::{AmbientApprox, ShadingModel};
    use kapaint::render::reference::Material;
    use kapaint::render::traced::Traced;
    use kapaint::render::{Camera, FrameSettings, Lighting, Sample, ViewMode};
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    let settings = FrameSettings {
        model: ShadingModel::BlinnPhong,
        approx: AmbientApprox::Fast,
        view: ViewMode::KaTraced,
        lighting: Lighting::default(),
        camera: Camera {
            yaw: 30f32.to_radians(),
            pitch: 20f32.to_radians(),
            ..Camera::default()
        }
        .framing(&spot.positions),
    };
    let material = Material::Uniform(Sample {
        kd: glam::Vec3::new(0.6, 0.5, 0.4),
        ks: glam::Vec3::splat(0.4),
        n: 80.0,
    });
    let mut group = c.benchmark_group("traced_spot");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    group.bench_function("1024x1024_64_samples", |b| {
        b.iter(|| {
            let (bvh, rays) = (Bvh::build(&spot), RayMesh::new(&spot));
            let mut t = Traced::new((&spot, &bvh, &rays), &material, &settings, 1024, 1024);
            t.pass(&rays, 64, &|| false);
            t.samples()
        });
    });
    let (bvh, rays) = (Bvh::build(&spot), RayMesh::new(&spot));
    let mut t = Traced::new((&spot, &bvh, &rays), &material, &settings, 1024, 1024);
    group.bench_function("1024x1024_one_pass_of_one_sample", |b| {
        b.iter(|| t.pass(&rays, 1, &|| false));
    });
    group.finish();
}

/// Issue 57's procedural pair: spot split four times (each triangle into four at its edges'
/// midpoints, 5,856 -> 1,499,136 triangles), displaced along its smooth normals by a sum of
/// waves (0.6 % of its size), no UVs: the high mesh. Made here, never stored.
fn sculpt(low: &mesh::Mesh) -> mesh::Mesh {
    use glam::Vec3;
    use std::collections::HashMap;
    // Welded by position first: the OBJ's vertices are split at UV seams, and split vertices
    // pushed along their own normals would open cracks in the sculpt.
    let mut first: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let welded: Vec<u32> = low
        .positions
        .iter()
        .map(|p| {
            *first
                .entry(p.to_array().map(f32::to_bits))
                .or_insert_with(|| {
                    positions.push(*p);
                    (positions.len() - 1) as u32
                })
        })
        .collect();
    let mut triangles: Vec<[u32; 3]> = low
        .triangles
        .iter()
        .map(|t| t.map(|v| welded[v as usize]))
        .collect();
    for _ in 0..4 {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut at = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]) * 0.5);
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let (ab, bc, ca) = (
                at(a, b, &mut positions),
                at(b, c, &mut positions),
                at(c, a, &mut positions),
            );
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        triangles = next;
    }
    let normals = |positions: &[Vec3]| {
        let mut sums = vec![Vec3::ZERO; positions.len()];
        for t in &triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            for v in t {
                sums[*v as usize] += (b - a).cross(c - a);
            }
        }
        sums.into_iter()
            .map(Vec3::normalize_or_zero)
            .collect::<Vec<_>>()
    };
    let smooth = normals(&positions);
    for (p, n) in positions.iter_mut().zip(&smooth) {
        let wave = (p.x * 40.0).sin() * (p.y * 37.0).cos() + 0.5 * (p.z * 83.0).sin();
        *p += *n * 0.006 * wave;
    }
    let normals = normals(&positions);
    mesh::Mesh {
        name: "spot sculpt".into(),
        positions,
        normals,
        uvs: None,
        triangles,
        had_normals: false,
        labels: mesh::Labels::default(),
    }
}

/// Normals from the sculpt onto spot at 4096^2 (issue 57: the BVH in at most 4 s, a tangent
/// normal bake at one sample in at most 15 s, on this 2-core machine).
fn high_bakes(c: &mut Criterion) {
    use kapaint::mesh::bakes::{HighMap, HighOptions, NormalSpace, RayMesh, bake_from_high};
    let spot = mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/testdata/spot/spot_triangulated.obj"),
    )
    .expect("spot loads");
    let high = sculpt(&spot);
    assert!(high.triangles.len() > 1_400_000);
    // For the peers (benches/peers/ao_high_side_by_side.sh): the sculpt as an OBJ, and no
    // bench.
    if let Ok(path) = std::env::var("KAPAINT_WRITE_SCULPT") {
        std::fs::write(&path, mesh::write_obj(&high)).expect("writes the sculpt");
        eprintln!("wrote {path}");
        return;
    }
    let uv = bake(&spot, 4096, 4096, 4).expect("bakes");
    let mut group = c.benchmark_group("bake_from_high_1_5m");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    group.bench_function("bvh_build", |b| b.iter(|| RayMesh::new(&high)));
    let options = HighOptions::new(HighMap::Normal(NormalSpace::Tangent));
    let once = bake_from_high(&spot, &uv, &high, None, options, None).expect("bakes");
    eprintln!(
        "sculpt onto spot: {} high triangles, {} texels, {} missed ({:.4} %), front {:.4} rear {:.4}",
        high.triangles.len(),
        once.covered,
        once.missed,
        once.missed as f64 / once.covered as f64 * 100.0,
        once.front,
        once.rear
    );
    group.bench_function("tangent_normal_4096", |b| {
        b.iter(|| bake_from_high(&spot, &uv, &high, None, options, None).expect("bakes"));
    });
    // AO from the sculpt at 64 rays, at 512^2 (the rays per second carry to any size).
    let uv = bake(&spot, 512, 512, 4).expect("bakes");
    let ao = HighOptions {
        rays: 64,
        ..HighOptions::new(HighMap::Ao)
    };
    // What a bake adds at its peak (the BVH's build included), per high triangle: the
    // process's peak resident memory reset first (Linux).
    let kib = |field: &str| {
        std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with(field))
                    .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
            })
            .unwrap_or(0)
    };
    if std::fs::write("/proc/self/clear_refs", "5").is_ok() {
        let before = kib("VmRSS:");
        let baked = bake_from_high(&spot, &uv, &high, None, ao, None).expect("bakes");
        let peak = kib("VmHWM:");
        eprintln!(
            "AO from the sculpt at 512^2: mean {:.4}, {} bytes a high triangle at the peak",
            baked.data.iter().map(|&v| f64::from(v)).sum::<f64>() / 65535.0 / baked.covered as f64,
            peak.saturating_sub(before) * 1024 / high.triangles.len() as u64
        );
    }
    group.bench_function("ao_64_rays_512", |b| {
        b.iter(|| bake_from_high(&spot, &uv, &high, None, ao, None).expect("bakes"));
    });
    gpu_ao(&mut group, &spot, &high, ao);
    group.finish();
}

/// AO at 64 rays at 4096^2 on a GPU (issue 57: at most 3 s on an H100 or H200), the BVH built
/// already, its upload and the pipeline included: on a hardware adapter, or on any with
/// `KAPAINT_BENCH_GPU=any` (lavapipe: slower than the CPU); skipped, said, without one.
fn gpu_ao(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    spot: &mesh::Mesh,
    high: &mesh::Mesh,
    ao: kapaint::mesh::bakes::HighOptions,
) {
    use kapaint::gpu::rays::{GpuCaster, RaysOn};
    use kapaint::mesh::bakes::{HighRays, Matching, bake_from_high_on};
    let choice = if std::env::var("KAPAINT_BENCH_GPU").is_ok_and(|v| v == "any") {
        RaysOn::Gpu
    } else {
        RaysOn::Auto
    };
    let Ok(Some(gpu)) = choice.open() else {
        eprintln!("ao_64_rays_4096_gpu: no hardware GPU here (KAPAINT_BENCH_GPU=any for any)");
        return;
    };
    let uv = bake(spot, 4096, 4096, 4).expect("bakes");
    let rays = HighRays::new(spot, high, Matching::All).expect("builds");
    let one = rays.single().expect("one BVH");
    let run = || {
        let caster = GpuCaster::new(&gpu, one).expect("uploads");
        bake_from_high_on(spot, &uv, (high, &rays), None, ao, &caster, None).expect("bakes")
    };
    let once = run();
    eprintln!(
        "AO on {} at 4096^2, 64 rays: {} texels, mean {:.4}",
        once.cast_on,
        once.covered,
        once.data.iter().map(|&v| f64::from(v)).sum::<f64>() / 65535.0 / once.covered as f64
    );
    group.bench_function("ao_64_rays_4096_gpu", |b| b.iter(run));
}

criterion_group!(
    benches,
    high_bakes,
    traced,
    bakes,
    picking,
    surface_dabs,
    tangents,
    unwraps,
    unwraps_big,
    ao_bakes
);
criterion_main!(benches);
