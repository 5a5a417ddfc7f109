//! Criterion benches for the PBR import (issue 20): a 4096^2 metallic-roughness set (the spot
//! texture as base colour, a packed metallic-roughness PNG) decoded, converted for each
//! target model with its error measured (target: <= 3 s on 2 cores), and the same saved as
//! a project, as `kapaint import-pbr` does; and back: the project as glTF textures (the
//! `gltf-pbr` export), and that conversion alone.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use kapaint::pbr::NMapping;
use kapaint::pbr::import::{PbrSet, Source, import};
use kapaint::reflectance::ShadingModel;

fn imports(c: &mut Criterion) {
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let dir = std::env::temp_dir().join(format!("kapaint-pbr-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let (base, mr) = kapaint::report::typical::write_pbr_set(
        &dir,
        4096,
        texture.exists().then_some(texture.as_path()),
    )
    .expect("set");
    let set = PbrSet::MetallicRoughness {
        base: Source::file(&base, None, true),
        metallic: Source::file(&mr, Some(2), false),
        roughness: Source::file(&mr, Some(1), false),
    };
    let mut group = c.benchmark_group("pbr_import_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    for model in [
        ShadingModel::Phong,
        ShadingModel::BlinnPhong,
        ShadingModel::CookTorrance,
    ] {
        group.bench_function(model.name(), |b| {
            b.iter(|| import(&set, None, model, NMapping::default()).expect("import"));
        });
    }
    let out = dir.join("out.kapaint");
    group.bench_function("phong_and_save", |b| {
        b.iter(|| {
            let imported =
                import(&set, None, ShadingModel::Phong, NMapping::default()).expect("import");
            kapaint::model::project::save(&imported.doc, &out).expect("save");
        });
    });
    group.finish();
    // The way back: the imported project to glTF textures (convert with the round-trip error,
    // encode both PNGs, write the set), and the conversion alone.
    let imported = import(&set, None, ShadingModel::Phong, NMapping::default()).expect("import");
    let preset = kapaint::export::preset::find("gltf-pbr").expect("preset");
    let mut group = c.benchmark_group("pbr_export_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    let texels: Vec<kapaint::model::texel::Texel> = {
        let maps = imported.doc.maps();
        (0..maps.height())
            .flat_map(|y| (0..maps.width()).map(move |x| (x, y)))
            .map(|(x, y)| kapaint::model::texel::Texel::encode(maps.value(x, y)))
            .collect()
    };
    group.bench_function("convert_phong", |b| {
        b.iter(|| {
            kapaint::pbr::round_trip::convert(&texels, ShadingModel::Phong, NMapping::default())
        });
    });
    let progress = kapaint::task::Progress::default();
    group.bench_function("gltf_pbr_set", |b| {
        b.iter(|| {
            let out = dir.join("set");
            let _ = std::fs::remove_dir_all(&out);
            kapaint::export::gltf_pbr::export(&imported.doc, &preset, &out, &progress, false, None)
                .expect("export");
        });
    });
    group.finish();
    engines(c, imported.doc, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The engine presets at 4096^2, with the worst they meet: a 4096^2 normal map (bumps, which
/// PNG cannot squeeze to nothing) and a 4096^2 AO bake (target: each at most 3 s on 2 cores).
fn engines(c: &mut Criterion, doc: kapaint::model::Document, dir: &std::path::Path) {
    use kapaint::mesh::bakes::{BakeMap, BakeOptions, Baked};
    use std::sync::Arc;
    let side = doc.maps().width();
    let normal = image::RgbImage::from_fn(side, side, |x, y| {
        let (u, v) = (x as f32 / side as f32, y as f32 / side as f32);
        let n = glam::Vec3::new(0.4 * (u * 90.0).sin(), 0.4 * (v * 70.0).cos(), 1.0).normalize();
        image::Rgb(n.to_array().map(|c| ((c + 1.0) * 127.5).round() as u8))
    });
    let ao = Baked {
        map: BakeMap::Ao,
        options: BakeOptions::default(),
        mesh_hash: 0,
        width: side,
        height: side,
        data: (0..side * side)
            .map(|i| {
                let (x, y) = ((i % side) as f32, (i / side) as f32);
                (40_000.0 + 20_000.0 * (x * 0.01).sin() * (y * 0.013).cos()) as u16
            })
            .collect(),
        from_high: None,
    };
    let doc = doc
        .with_normal(Some(Arc::new(
            kapaint::model::normal::NormalMap::new(normal).expect("normal map"),
        )))
        .with_bakes(vec![Arc::new(ao)]);
    let mut group = c.benchmark_group("engine_export_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    let progress = kapaint::task::Progress::default();
    for name in ["unreal", "unity-hdrp", "unity-urp", "godot", "gltf-pbr"] {
        let preset = kapaint::export::preset::find(name).expect("preset");
        group.bench_function(name, |b| {
            b.iter(|| {
                let out = dir.join("engine");
                let _ = std::fs::remove_dir_all(&out);
                kapaint::export::run(&doc, &preset, &out, &progress, false, None, None)
                    .expect("export");
            });
        });
    }
    group.finish();
}

criterion_group!(benches, imports);
criterion_main!(benches);
