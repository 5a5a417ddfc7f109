//! Issue 57's GPU path: AO and thickness from a high mesh cast in `shaders/bake_rays.wgsl`
//! through the very BVH the CPU casts through, held to the CPU (the reference) texel by
//! texel. On lavapipe here; on a hardware adapter where a machine has one.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod common;

use kapaint::gpu::rays::GpuCaster;
use kapaint::mesh::Mesh;
use kapaint::mesh::bake::{Coverage, bake};
use kapaint::mesh::bakes::{
    CpuCaster, HighBake, HighMap, HighOptions, HighRays, Matching, RayCaster, bake_from_high_on,
};

/// A plane with a box standing on it (the box's own part), the plane as the low mesh.
fn scene() -> (Mesh, Mesh) {
    let plane = kapaint::mesh::plane();
    let mut cube = kapaint::mesh::cube();
    for p in &mut cube.positions {
        *p = *p * 0.25 + glam::Vec3::new(0.2, 0.1, -0.1);
    }
    cube.uvs = None;
    let mut flat = plane.clone();
    flat.uvs = None;
    let high = Mesh::merged(vec![flat, cube]).expect("merges");
    (plane, high)
}

/// The bake of `map` with rays cast by `caster`.
fn baked(
    (low, high): (&Mesh, &Mesh),
    rays: &HighRays,
    options: HighOptions,
    caster: &dyn RayCaster,
) -> HighBake {
    let uv = bake(low, 96, 96, 2).expect("bakes");
    bake_from_high_on(low, &uv, (high, rays), None, options, caster, None).expect("bakes")
}

#[test]
fn ao_and_thickness_on_the_gpu_are_the_cpus() {
    let Some(gpu) = common::gpu() else {
        return;
    };
    let (low, high) = scene();
    let rays = HighRays::new(&low, &high, Matching::All).expect("builds");
    let on_gpu = GpuCaster::new(&gpu, rays.single().expect("one BVH")).expect("uploads");
    let uv = bake(&low, 96, 96, 2).expect("bakes");
    let surface: Vec<usize> = (0..uv.len())
        .filter(|&i| uv.coverage(i) == Coverage::Surface)
        .collect();
    for (map, samples, max_distance) in [
        (HighMap::Ao, 1, None),
        (HighMap::Ao, 4, Some(0.3)),
        (HighMap::Thickness, 1, None),
    ] {
        let options = HighOptions {
            rays: 32,
            samples,
            max_distance,
            front: Some(0.3),
            ..HighOptions::new(map)
        };
        let cpu = baked((&low, &high), &rays, options, &CpuCaster(rays.meshes()));
        let gpu_bake = baked((&low, &high), &rays, options, &on_gpu);
        assert!(gpu_bake.cast_on.contains("GPU"), "{}", gpu_bake.cast_on);
        assert_eq!(cpu.misses, gpu_bake.misses);
        let value = |b: &HighBake, i: usize| f32::from(b.data[i]) / 65535.0;
        let diffs: Vec<f32> = surface
            .iter()
            .map(|&i| (value(&cpu, i) - value(&gpu_bake, i)).abs())
            .collect();
        let mean =
            |b: &HighBake| surface.iter().map(|&i| value(b, i)).sum::<f32>() / surface.len() as f32;
        let (a, b) = (mean(&cpu), mean(&gpu_bake));
        let worst = diffs.iter().fold(0.0_f32, |m, &d| m.max(d));
        // The same directions through the same BVH: a ray grazing an edge may go either way
        // (one ray of 32 is 0.031), nothing more. On lavapipe every texel is the CPU's, bit
        // for bit.
        let off = diffs.iter().filter(|&&d| d > 1e-3).count();
        assert!((a - b).abs() < 2e-3, "{map:?} {samples}: means {a} vs {b}");
        assert!(
            off * 100 < surface.len(),
            "{map:?} {samples}: {off} of {} texels differ (worst {worst})",
            surface.len()
        );
        assert!(a < 0.99, "{map:?}: the box is seen ({a})");
    }
}

/// The GPU casts through one BVH: queries for BVHs of parts matched by name are refused.
#[test]
fn the_gpu_refuses_queries_for_bvhs_of_parts() {
    let Some(gpu) = common::gpu() else {
        return;
    };
    let (low, high) = scene();
    let rays = HighRays::new(&low, &high, Matching::All).expect("builds");
    let on_gpu = GpuCaster::new(&gpu, rays.single().expect("one BVH")).expect("uploads");
    let query = kapaint::mesh::bakes::RayQuery {
        group: 3,
        ..Default::default()
    };
    let directions = [glam::Vec3::Z];
    let e = on_gpu
        .cast(&kapaint::mesh::bakes::RayBatch {
            queries: &[query],
            directions: &directions,
            far: 1.0,
            kind: kapaint::mesh::bakes::RayKind::Open,
        })
        .expect_err("refused");
    assert!(e.contains("matched by name"), "{e}");
}

/// `kapaint bake --map ao --high … --device gpu` bakes on the GPU what `--device cpu` bakes,
/// and says where the rays ran.
#[test]
fn the_cli_bakes_ao_on_the_gpu_when_asked() {
    if common::gpu().is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("kapaint-bake-gpu-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot");
    let project = dir.join("spot.kapaint");
    let run = |args: &[&std::ffi::OsStr]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let os = |s: &str| std::ffi::OsStr::new(s).to_owned();
    run(&[
        &os("new"),
        &os("--size"),
        &os("128"),
        &os("--mesh"),
        spot.join("spot_triangulated.obj").as_os_str(),
        &os("--out"),
        project.as_os_str(),
    ]);
    let bake = |device: &str| {
        let out = dir.join(format!("ao-{device}.png"));
        let text = run(&[
            &os("bake"),
            project.as_os_str(),
            &os("--map"),
            &os("ao"),
            &os("--rays"),
            &os("16"),
            &os("--high"),
            spot.join("spot_quadrangulated.obj").as_os_str(),
            &os("--device"),
            &os(device),
            &os("--out"),
            out.as_os_str(),
        ]);
        (text, image::open(&out).expect("png").into_luma16())
    };
    let (cpu_text, cpu) = bake("cpu");
    let (gpu_text, gpu) = bake("gpu");
    assert!(cpu_text.contains("on the CPU"), "{cpu_text}");
    assert!(gpu_text.contains("on the GPU"), "{gpu_text}");
    let differ = cpu
        .pixels()
        .zip(gpu.pixels())
        .filter(|(a, b)| a.0[0].abs_diff(b.0[0]) > 64)
        .count();
    assert!(
        differ * 100 < (cpu.width() * cpu.height()) as usize,
        "{differ} texels differ"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
