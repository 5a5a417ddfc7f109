//! The `gltf-pbr` export (issue 20): a real glTF material (spot's mesh and texture) imported
//! and written back as glTF textures and a `.glb`, checked against the original and by the
//! `gltf` crate's validation.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;

use kapaint::export::gltf_pbr::PbrManifest;
use kapaint::pbr::convert::Conversion;
use kapaint::pbr::fit::TARGETS;
use kapaint::reflectance::ShadingModel;

#[path = "common/gltf_asset.rs"]
mod gltf_asset;
use gltf_asset::{Asset, dir, kapaint, spot, write_asset};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// `import-pbr` of the glTF `asset` for `model` into `out`.
fn import_gltf(asset: &Path, model: ShadingModel, out: &Path) {
    let o = kapaint(&[
        "import-pbr",
        "--out",
        s(out),
        "--gltf",
        s(asset),
        "--model",
        match model {
            ShadingModel::Phong => "phong",
            ShadingModel::BlinnPhong => "blinn",
            ShadingModel::CookTorrance => "cook-torrance",
        },
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// `kapaint export PROJECT --preset gltf-pbr FLAGS... --out SET`.
fn export_gltf_pbr(project: &Path, set: &Path, flags: &[&str]) -> std::process::Output {
    let mut args = vec!["export", s(project), "--preset", "gltf-pbr"];
    args.extend_from_slice(flags);
    args.extend(["--out", s(set)]);
    kapaint(&args)
}

fn manifest(set: &Path) -> PbrManifest {
    serde_json::from_slice(&std::fs::read(set.join("material.json")).expect("manifest"))
        .expect("a glTF PBR manifest")
}

#[test]
fn a_gltf_material_round_trips_through_a_project_within_one_code() {
    let d = dir("roundtrip");
    let asset = write_asset(&d, &Asset::default());
    let original = image::open(spot().join("spot_texture.png"))
        .expect("spot")
        .to_rgb8();
    let mr = image::open(d.join("mr.png")).expect("mr").to_rgb8();
    for model in TARGETS {
        let project = d.join(format!("{model:?}.kapaint"));
        import_gltf(&asset, model, &project);
        let set = d.join(format!("{model:?}-set"));
        let o = export_gltf_pbr(&project, &set, &["--no-padding"]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let stdout = text(&o.stdout);
        assert!(
            stdout.contains("round-trip error (relative, box average): max "),
            "{stdout}"
        );
        let base = image::open(set.join("base_color.png"))
            .expect("base")
            .to_rgb8();
        let back = image::open(set.join("metallic_roughness.png"))
            .expect("mr")
            .to_rgb8();
        assert_eq!(base.dimensions(), original.dimensions());
        let c = Conversion::for_model(model, kapaint::pbr::NMapping::default());
        let (mut base_off, mut rough_off) = (0_i32, 0_i32);
        for (x, y, want) in original.enumerate_pixels() {
            let got = base.get_pixel(x, y);
            for ch in 0..3 {
                base_off = base_off.max((i32::from(got[ch]) - i32::from(want[ch])).abs());
            }
            let (m, r) = (mr.get_pixel(x, y)[2], mr.get_pixel(x, y)[1]);
            assert_eq!(back.get_pixel(x, y)[2], m, "metallic at ({x}, {y})");
            assert_eq!(back.get_pixel(x, y)[0], 255, "R is unused, 255");
            // Roughness comes back where the model's exponent still tells roughnesses apart:
            // not where the fitted curve is flat (above about 0.48 for Phong and
            // Blinn-Phong), nor where it is so nearly flat that n's half-float rounding moves
            // the roughness more than a code.
            let rough = f32::from(r) / 255.0;
            if c.n(rough - 2.0 / 255.0) > c.n(rough + 2.0 / 255.0) * 1.01 {
                rough_off =
                    rough_off.max((i32::from(back.get_pixel(x, y)[1]) - i32::from(r)).abs());
            }
        }
        let m = manifest(&set);
        eprintln!(
            "{model:?}: base colour within {base_off}/255, roughness within {rough_off}/255, round-trip error {:?}",
            m.round_trip
        );
        assert!(
            base_off <= 1,
            "{model:?}: base colour off by {base_off}/255"
        );
        assert!(
            rough_off <= 1,
            "{model:?}: roughness off by {rough_off}/255"
        );
        assert_eq!(m.model, model);
        assert_eq!((m.width, m.height), original.dimensions());
        let e = m.round_trip;
        assert!(e.max >= e.p99 && e.p99 >= 0.0 && e.mean >= 0.0 && e.max.is_finite());
        if model == ShadingModel::CookTorrance {
            // Nothing is lost to the model; only the 8-bit roughness moves the exponent.
            assert!(e.max < 0.02, "{e:?}");
        } else {
            // The lobe's shape is lost either way: the error is the import's, or more.
            let import = kapaint::model::project::load(&project)
                .expect("load")
                .settings()
                .import
                .clone()
                .expect("import report");
            assert!(e.mean >= 0.9 * import.error.mean, "{e:?} vs {import:?}");
        }
    }
}

#[test]
fn the_glb_is_valid_gltf_with_the_material_embedded_and_imports_back() {
    let d = dir("glb");
    let asset = write_asset(&d, &Asset::default());
    let project = d.join("cow.kapaint");
    import_gltf(&asset, ShadingModel::BlinnPhong, &project);
    let set = d.join("set");
    let o = export_gltf_pbr(&project, &set, &["--glb"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let bytes = std::fs::read(set.join("model.glb")).expect("glb");
    // The gltf crate validates the document as it parses it.
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF");
    let blob = gltf.blob.as_deref().expect("binary chunk");
    let material = gltf.materials().next().expect("a material");
    let pbr = material.pbr_metallic_roughness();
    let image_of = |info: Option<gltf::texture::Info<'_>>| {
        let source = info.expect("texture").texture().source().source();
        let gltf::image::Source::View { view, mime_type } = source else {
            panic!("the image is not embedded");
        };
        assert_eq!(mime_type, "image/png");
        let bytes = &blob[view.offset()..view.offset() + view.length()];
        image::load_from_memory(bytes).expect("png").to_rgb8()
    };
    for (embedded, file) in [
        (image_of(pbr.base_color_texture()), "base_color.png"),
        (
            image_of(pbr.metallic_roughness_texture()),
            "metallic_roughness.png",
        ),
    ] {
        let written = image::open(set.join(file)).expect("image").to_rgb8();
        assert!(
            embedded == written,
            "{file} differs from the embedded image"
        );
    }
    // The mesh: spot's vertices, normals, and the asset's own texture coordinates back (the
    // export undoes the import's flip of v).
    let source = gltf::Gltf::open(&asset).expect("asset");
    let source_bin = std::fs::read(d.join("spot.bin")).expect("bin");
    let read = |g: &gltf::Gltf, bin: &[u8]| {
        let prim = g
            .meshes()
            .next()
            .expect("mesh")
            .primitives()
            .next()
            .expect("primitive");
        let reader = prim.reader(|_| Some(bin));
        let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).expect("uvs").into_f32().collect();
        let normals = reader.read_normals().map(Iterator::count);
        let triangles = reader.read_indices().expect("indices").into_u32().count() / 3;
        (uvs, normals, triangles)
    };
    let (uvs, normals, triangles) = read(&gltf, blob);
    let (source_uvs, _, source_triangles) = read(&source, &source_bin);
    assert_eq!(triangles, source_triangles);
    assert_eq!(normals, Some(uvs.len()));
    assert_eq!(uvs.len(), source_uvs.len());
    let worst = uvs
        .iter()
        .zip(&source_uvs)
        .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()))
        .fold(0.0_f32, f32::max);
    assert!(worst < 1e-6, "texture coordinates moved by {worst}");
    let m = manifest(&set);
    assert_eq!(
        m.files.iter().map(|f| f.path.as_str()).collect::<Vec<_>>(),
        ["base_color.png", "metallic_roughness.png", "model.glb"]
    );
    assert_eq!(m.files[2].bytes, bytes.len() as u64);

    // Imported again (images from the GLB's buffer views), the project is the same and a
    // second export writes the same images: the round trip is a fixed point.
    let again = d.join("again.kapaint");
    import_gltf(&set.join("model.glb"), ShadingModel::BlinnPhong, &again);
    let set2 = d.join("set2");
    let o = export_gltf_pbr(&again, &set2, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for file in ["base_color.png", "metallic_roughness.png"] {
        let a = image::open(set.join(file)).expect("a").to_rgb8();
        let b = image::open(set2.join(file)).expect("b").to_rgb8();
        assert!(a == b, "{file} changed on the second round trip");
    }
}

/// A double-sided glTF material (a leaf, a cloth, a sheet) comes back double-sided in the
/// `.glb`, through the project (it was dropped: the `.glb` lost `doubleSided`), from the
/// command line and from the editor's import alike (both record it in the import report); a
/// one-sided one stays one-sided.
#[test]
fn a_double_sided_material_stays_double_sided_in_the_glb() {
    let d = dir("double-sided");
    for double_sided in [true, false] {
        let tag = if double_sided { "two" } else { "one" };
        let sub = d.join(tag);
        std::fs::create_dir_all(&sub).expect("dir");
        let asset = write_asset(
            &sub,
            &Asset {
                double_sided,
                ..Asset::default()
            },
        );
        let project = sub.join("leaf.kapaint");
        import_gltf(&asset, ShadingModel::Phong, &project);
        let doc = kapaint::model::project::load(&project).expect("load");
        let report = doc.settings().import.clone().expect("import report");
        assert_eq!(report.double_sided, double_sided);
        let set = sub.join("set");
        let o = export_gltf_pbr(&project, &set, &["--glb"]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let bytes = std::fs::read(set.join("model.glb")).expect("glb");
        let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF");
        let material = gltf.materials().next().expect("a material");
        assert_eq!(material.double_sided(), double_sided, "{tag}");
    }
}

#[test]
fn glb_without_the_preset_or_a_mesh_is_one_clear_error_and_nothing_written() {
    let d = dir("bad");
    let project = d.join("plain.kapaint");
    let o = kapaint(&["new", "--out", s(&project), "--size", "64"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = d.join("set");
    let o = kapaint(&["export", s(&project), "--glb", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("--preset gltf-pbr"),
        "{}",
        text(&o.stderr)
    );
    assert!(!out.exists());
    // A project whose mesh file is gone.
    let cow = d.join("cow.kapaint");
    let mesh = d.join("cow.obj");
    std::fs::copy(spot().join("spot_triangulated.obj"), &mesh).expect("copy");
    let o = kapaint(&["new", "--out", s(&cow), "--size", "64", "--mesh", s(&mesh)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    std::fs::remove_file(&mesh).expect("rm");
    let o = export_gltf_pbr(&cow, &out, &["--glb"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("--glb needs the project's mesh"),
        "{}",
        text(&o.stderr)
    );
    assert!(!out.exists());
}

#[test]
fn the_normal_map_is_kept_passed_through_and_never_in_ka() {
    let d = dir("normal");
    let asset = write_asset(
        &d,
        &Asset {
            normal_scale: Some(1.0),
            ..Asset::default()
        },
    );
    let project = d.join("cow.kapaint");
    import_gltf(&asset, ShadingModel::Phong, &project);
    let doc = kapaint::model::project::load(&project).expect("load");
    let want = image::open(d.join("normal.png")).expect("normal").to_rgb8();
    let kept = doc.normal().expect("the normal map is kept");
    assert!(kept.image() == &want, "the normal map changed on import");

    // Passed through by the gltf-pbr export, as a file and in the .glb.
    let set = d.join("set");
    let o = export_gltf_pbr(&project, &set, &["--glb"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let written = image::open(set.join("normal.png"))
        .expect("normal")
        .to_rgb8();
    assert!(written == want, "the exported normal map differs");
    let bytes = std::fs::read(set.join("model.glb")).expect("glb");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("valid");
    let blob = gltf.blob.as_deref().expect("blob");
    let normal = gltf
        .materials()
        .next()
        .and_then(|m| m.normal_texture())
        .expect("normalTexture");
    let gltf::image::Source::View { view, .. } = normal.texture().source().source() else {
        panic!("not embedded");
    };
    let embedded = image::load_from_memory(&blob[view.offset()..view.offset() + view.length()])
        .expect("png")
        .to_rgb8();
    assert!(embedded == want, "the embedded normal map differs");
    // With the MikkTSpace tangents it is lit in, one per vertex, unit, with a sign.
    let prim = gltf
        .meshes()
        .next()
        .and_then(|m| m.primitives().next())
        .expect("primitive");
    let reader = prim.reader(|_| Some(blob));
    let tangents: Vec<[f32; 4]> = reader.read_tangents().expect("TANGENT").collect();
    assert_eq!(
        tangents.len(),
        reader.read_positions().expect("POSITION").count()
    );
    assert!(tangents.iter().all(|t| {
        let len = glam::Vec3::new(t[0], t[1], t[2]).length();
        (len - 1.0).abs() < 1e-3 && t[3].abs() == 1.0
    }));
    assert!(manifest(&set).files.iter().any(|f| f.path == "normal.png"));

    // k_a never reads it: the same maps with and without the normal map export the same
    // baked k_a.
    let mut bare = kapaint::model::project::load(&project).expect("load");
    bare.apply(kapaint::model::ImportCommand::SetNormal(
        kapaint::model::document::AttachedNormal(None),
    ))
    .expect("clear");
    let bare_path = d.join("bare.kapaint");
    kapaint::model::project::save(&bare, &bare_path).expect("save");
    let ka = |p: &Path, out: &str| {
        let out = d.join(out);
        let o = kapaint(&["export", s(p), "--preset", "with-ka", "--out", s(&out)]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        image::open(out.join("ka.png")).expect("ka").to_rgb8()
    };
    assert!(ka(&project, "with") == ka(&bare_path, "without"));

    // A glTF scale is baked in: x and y shrink, and a note says so.
    let e = dir("normal-scale");
    let scaled = write_asset(
        &e,
        &Asset {
            normal_scale: Some(0.5),
            ..Asset::default()
        },
    );
    let out = e.join("scaled.kapaint");
    let o = kapaint(&["import-pbr", "--out", s(&out), "--gltf", s(&scaled)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("scale 0.5 is baked into the texels"),
        "{}",
        text(&o.stdout)
    );
    let doc = kapaint::model::project::load(&out).expect("load");
    let map = doc.normal().expect("kept");
    let (x, y) = (7, 3);
    let p = want.get_pixel(x, y).0.map(|c| f32::from(c) / 127.5 - 1.0);
    let source = glam::Vec3::new(p[0] * 0.5, p[1] * 0.5, p[2]).normalize();
    assert!(
        map.normal(x, y).distance(source) < 0.02,
        "{:?} vs {source:?}",
        map.normal(x, y)
    );
}

/// `import-pbr` of a grey dielectric with `normal` as its normal map into `out`.
fn import_with_normal(out: &Path, normal: &Path) -> std::process::Output {
    kapaint(&[
        "import-pbr",
        "--out",
        s(out),
        "--base-color",
        "0.5",
        "--metallic",
        "0",
        "--roughness",
        "0.5",
        "--normal",
        s(normal),
    ])
}

#[test]
fn a_loose_normal_map_imports_and_a_bad_one_is_refused() {
    let d = dir("loose-normal");
    let normal = d.join("bumps.png");
    gltf_asset::bumps(64, 32).save(&normal).expect("save");
    let out = d.join("loose.kapaint");
    let o = import_with_normal(&out, &normal);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("normal map: 64x32, kept with the project"),
        "{}",
        text(&o.stdout)
    );
    let doc = kapaint::model::project::load(&out).expect("load");
    assert_eq!(
        doc.normal().map(|m| (m.width(), m.height())),
        Some((64, 32))
    );
    // Missing, or not an image: one error, nothing written.
    std::fs::write(d.join("junk.png"), b"not a png").expect("junk");
    for bad in [d.join("missing.png"), d.join("junk.png")] {
        let out = d.join("bad.kapaint");
        let o = import_with_normal(&out, &bad);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
        assert_eq!(text(&o.stderr).lines().count(), 1, "{}", text(&o.stderr));
        assert!(!out.exists());
    }
}

#[test]
fn a_texture_set_is_found_by_its_names_from_any_one_of_its_images() {
    let d = dir("named-set");
    let texture = image::open(spot().join("spot_texture.png"))
        .expect("spot")
        .to_rgb8();
    let small = image::imageops::resize(&texture, 64, 64, image::imageops::FilterType::Triangle);
    small.save(d.join("Cow_BaseColor.png")).expect("base");
    // glTF's packing in an ORM image: occlusion R, roughness G, metallic B.
    image::RgbImage::from_fn(64, 64, |x, _| {
        image::Rgb([255, 128, if x < 32 { 0 } else { 255 }])
    })
    .save(d.join("Cow_ORM.png"))
    .expect("orm");
    // A DirectX normal map: green points down, so a +Y tilt is stored with green below 128.
    image::RgbImage::from_pixel(64, 64, image::Rgb([128, 50, 230]))
        .save(d.join("Cow_Normal_DX.png"))
        .expect("normal");
    std::fs::write(d.join("Other_BaseColor.png"), b"not this set").expect("other");
    let out = d.join("cow.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--out",
        s(&out),
        "--set",
        s(&d.join("Cow_Normal_DX.png")),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(stdout.contains("Cow_BaseColor.png"), "{stdout}");
    assert!(stdout.contains("Cow_ORM.png"), "{stdout}");
    assert!(stdout.contains("flipped to glTF's"), "{stdout}");
    let doc = kapaint::model::project::load(&out).expect("load");
    // Metallic from B: the right half is a metal (k_d black), the left a dielectric.
    let (left, right) = (doc.maps().value(10, 10), doc.maps().value(50, 10));
    assert!(left.kd.max_element() > 0.01 && right.kd.max_element() < 1e-3);
    // The dielectric's F0 at the roughness' lobe height, within the energy guard per channel
    // (spot's red is white: k_d 1 leaves no k_s there).
    let height = Conversion::for_model(ShadingModel::Phong, kapaint::pbr::NMapping::default())
        .height(128.0 / 255.0);
    for c in 0..3 {
        let want = (0.04 * height).min(1.0 - left.kd[c]);
        assert!((left.ks[c] - want).abs() < 1e-3, "{left:?}");
    }
    // The DirectX green is flipped: the stored normal tilts to +Y in glTF's convention.
    let normal = doc.normal().expect("normal map").normal(5, 5);
    assert!(normal.y > 0.5, "{normal}");
    // A name that says no map, or a set without a base colour: one error, nothing written.
    std::fs::copy(d.join("Cow_ORM.png"), d.join("Lonely_Roughness.png")).expect("copy");
    std::fs::copy(d.join("Cow_ORM.png"), d.join("untitled.png")).expect("copy");
    for (file, want) in [
        ("untitled.png", "does not say which map"),
        ("Lonely_Roughness.png", "no base colour beside it"),
    ] {
        let bad = d.join("bad.kapaint");
        let o = kapaint(&["import-pbr", "--out", s(&bad), "--set", s(&d.join(file))]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
        assert!(text(&o.stderr).contains(want), "{}", text(&o.stderr));
        assert!(!bad.exists());
    }
}
