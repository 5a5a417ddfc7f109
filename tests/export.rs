//! Exported texture sets: layouts, elided channels, the manifest, round trips, k_a error, and
//! failures that leave nothing behind.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

#[path = "common/faults.rs"]
mod faults;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use kapaint::export::preset::{self, Format};
use kapaint::export::set;
use kapaint::model::brush::StrokePoint;
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Channels, Document, DocumentSettings, StrokeTool};
use kapaint::model::{PaintCommand, SettingsCommand, StrokeCommand};
use kapaint::reflectance;

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-export-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    dir
}

/// k_d painted in colour, n in a gradient, k_s grey and constant.
fn painted() -> Document {
    let mut doc = Document::new(
        200,
        120,
        DocumentSettings {
            base: MaterialValue::new(Vec3::new(0.6, 0.5, 0.4), Vec3::splat(0.3), 20.0),
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    doc.apply(SettingsCommand::SetChannels(Channels {
        kd: true,
        ks: false,
        n: true,
    }))
    .expect("channels");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.1, 0.05),
        Vec3::splat(0.3),
        900.0,
    )))
    .expect("primary");
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![
            StrokePoint {
                pos: Vec2::new(10.0, 60.0),
                pressure: 1.0,
            },
            StrokePoint {
                pos: Vec2::new(190.0, 70.0),
                pressure: 1.0,
            },
        ],
    })
    .expect("stroke");
    doc
}

fn max_rel_ka_error(a: &Document, b: &Document) -> f32 {
    let (m, x) = (a.settings().model, a.settings().approx);
    let mut worst = 0.0_f32;
    for y in 0..a.maps().height() {
        for xx in 0..a.maps().width() {
            let (p, q) = (a.maps().value(xx, y), b.maps().value(xx, y));
            let (ka, kb) = (
                reflectance::ka(m, x, p.kd, p.ks, p.n),
                reflectance::ka(m, x, q.kd, q.ks, q.n),
            );
            for c in 0..3 {
                worst = worst.max((kb[c] - ka[c]).abs() / ka[c]);
            }
        }
    }
    worst
}

#[test]
fn compact_sets_elide_what_is_constant_and_round_trip() {
    let dir = temp("compact");
    let doc = painted();
    let out = dir.join("set");
    let m = set::export(&doc, &preset::find("compact").expect("preset"), &out).expect("export");
    // k_s is constant: a manifest constant, no image. k_d and n share one RGBA8 image.
    assert!(m.constants.ks.is_some());
    assert_eq!(m.files.len(), 1);
    assert_eq!(m.files[0].layout, ["kd.r", "kd.g", "kd.b", "n"]);
    assert_eq!(
        m.files[0].colour_space,
        kapaint::export::set::ColourSpace::Srgb
    );
    let n = m.n_encoding.expect("n is quantised");
    assert_eq!(n.bits, 8);
    // The two shader snippets are a fixed 16 KB or so whatever the map size; on this small
    // map they would hide the images' ratio, so they are left out of it.
    let snippets: u64 = ["material.wgsl", "material.glsl"]
        .iter()
        .map(|name| std::fs::metadata(out.join(name)).expect("snippet").len())
        .sum();
    assert!(
        m.bytes.exported - snippets < m.bytes.naive / 10,
        "{:?}, snippets {snippets}",
        m.bytes
    );
    let on_disk: u64 = m.files.iter().map(|f| f.bytes).sum();
    assert_eq!(
        on_disk,
        std::fs::metadata(out.join(&m.files[0].path))
            .expect("file")
            .len()
    );

    // Import: the k_a error is the reported one; export again: the same bytes.
    let back = set::import(&out.join("material.json")).expect("import");
    let err = max_rel_ka_error(&doc, &back);
    // The reported error is the set's as a consumer decodes it; importing into a project
    // rounds once more to the project's own precision (n as a half float: 2^-11 relative).
    assert!(
        f64::from(err) <= m.ka_error.max + 1e-3,
        "{err} vs {}",
        m.ka_error.max
    );
    assert!(m.ka_error.max < 0.05, "{:?}", m.ka_error);
    let again = dir.join("again");
    let m2 = set::export(&back, &preset::find("compact").expect("preset"), &again).expect("export");
    for (a, b) in m.files.iter().zip(&m2.files) {
        assert_eq!(
            std::fs::read(out.join(&a.path)).expect("read"),
            std::fs::read(again.join(&b.path)).expect("read"),
            "{} is stable",
            a.path
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_builtin_preset_exports_and_imports() {
    let dir = temp("all");
    let mut doc = painted();
    // Colour k_s too, so it gets an RGB image.
    doc.apply(SettingsCommand::SetChannels(Channels::ALL))
        .expect("channels");
    doc.apply(PaintCommand::Fill(kapaint::model::FillRegion::Similar {
        x: 5,
        y: 5,
        channel: kapaint::model::Channel::Kd,
        tolerance: 0.01,
    }))
    .expect("fill");
    for p in preset::builtin_sets() {
        let out = dir.join(&p.name);
        let m = set::export(&doc, &p, &out).expect("export");
        assert!(out.join("material.json").is_file());
        // What the editor's notice counts is what the folder holds.
        let written = std::fs::read_dir(&out).expect("set folder").count();
        assert_eq!(m.file_count(), written, "{}", p.name);
        let back = set::import(&out.join("material.json")).expect("import");
        let err = max_rel_ka_error(&doc, &back);
        match p.format {
            Format::Exr => assert!(err < 1e-4, "{}: {err}", p.name),
            Format::Png16 => assert!(err < 1e-3, "{}: {err}", p.name),
            Format::Png8 | Format::Ktx2 | Format::GltfPbr | Format::PbrTextures => {
                assert!(err < 0.05, "{}: {err}", p.name);
            }
            Format::Ktx2Bc { .. } | Format::Ktx2Astc { .. } | Format::Ktx2Uastc { .. } => {
                assert!(err < 0.3, "{}: {err}", p.name);
                let psnr = m.files[0].psnr.as_ref().expect("psnr");
                assert!(psnr.iter().all(|p| p.is_none_or(|p| p > 30.0)), "{psnr:?}");
            }
            // One hue a block: where a stroke's edge crosses a block, dark texels miss by
            // more than their own k_a (relative max 152 % here), so the mean is what holds;
            // the import is what the report measured (below).
            Format::Ktx2Etc1s { .. } => {
                assert!(m.ka_error.mean < 0.05, "{}: {:?}", p.name, m.ka_error);
                let psnr = m.files[0].psnr.as_ref().expect("psnr");
                assert!(psnr.iter().all(|p| p.is_none_or(|p| p > 25.0)), "{psnr:?}");
            }
        }
        // What import reads is what the report measured (plus the project's own rounding).
        assert!(
            f64::from(err) <= m.ka_error.max + 2e-3,
            "{}: {err} vs {:?}",
            p.name,
            m.ka_error
        );
        if p.format.is_ktx2() {
            assert_eq!(m.files[0].mip_levels, Some(8), "{}", p.name);
        }
        assert_eq!(
            m.files
                .iter()
                .any(|f| f.layout.iter().any(|c| c.starts_with("ka"))),
            p.include_ka,
            "{}",
            p.name
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// With k_d constant, grey k_s and n share one two-component image (grey + alpha PNG, BC5 or
/// RG8 KTX2) and read back as they were written.
#[test]
fn two_component_images_pack_ks_with_n() {
    let dir = temp("ks_n");
    let mut doc = painted();
    doc.apply(SettingsCommand::SetChannels(Channels {
        kd: false,
        ks: true,
        n: true,
    }))
    .expect("channels");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::splat(0.5),
        Vec3::splat(0.8),
        3.0,
    )))
    .expect("primary");
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![
            StrokePoint {
                pos: Vec2::new(100.0, 5.0),
                pressure: 1.0,
            },
            StrokePoint {
                pos: Vec2::new(100.0, 115.0),
                pressure: 1.0,
            },
        ],
    })
    .expect("stroke");
    // Undo the k_d part of the first stroke: paint k_d back to the base everywhere.
    doc.apply(SettingsCommand::SetChannels(Channels {
        kd: true,
        ks: false,
        n: false,
    }))
    .expect("channels");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.6, 0.5, 0.4),
        Vec3::splat(0.8),
        3.0,
    )))
    .expect("primary");
    doc.apply(PaintCommand::Fill(kapaint::model::FillRegion::All))
        .expect("fill");
    for name in ["compact", "ktx2", "ktx2-raw"] {
        let out = dir.join(name);
        let m = set::export(&doc, &preset::find(name).expect("preset"), &out).expect("export");
        assert!(m.constants.kd.is_some(), "{name}");
        assert_eq!(m.files.len(), 1, "{name}: {:?}", m.files);
        assert_eq!(m.files[0].layout, ["ks", "n"], "{name}");
        let back = set::import(&out.join("material.json")).expect("import");
        let err = max_rel_ka_error(&doc, &back);
        assert!(
            f64::from(err) <= m.ka_error.max + 2e-3,
            "{name}: {err} vs {:?}",
            m.ka_error
        );
        assert!(err < 0.1, "{name}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Temporary export folders left in `dir`.
fn temporaries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    std::fs::read_dir(dir)
        .expect("dir")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.to_string_lossy().contains(".tmp-"))
        .collect()
}

#[test]
fn failures_leave_nothing_behind() {
    let dir = temp("fail");
    let doc = painted();
    let compact = preset::find("compact").expect("preset");
    // A non-empty target is refused and kept.
    let busy = dir.join("busy");
    std::fs::create_dir_all(&busy).expect("dir");
    std::fs::write(busy.join("keep.txt"), "mine").expect("write");
    assert!(set::export(&doc, &compact, &busy).is_err());
    assert_eq!(std::fs::read(busy.join("keep.txt")).expect("kept"), b"mine");
    // A file where the target's folder should be: an error before anything is made.
    let file = dir.join("a-file");
    std::fs::write(&file, "x").expect("write");
    assert!(set::export(&doc, &compact, &file.join("set")).is_err());
    assert!(temporaries(&dir).is_empty());
    // The last step fails: the target is an (empty) mount point, which the finished set
    // cannot replace. Every file is written by then, in the temporary folder beside it,
    // which must go too.
    let target = dir.join("mounted");
    if let Some(mount) = faults::tmpfs(&target, "size=64k") {
        let progress = kapaint::task::Progress::default();
        let err = set::export_with(&doc, &compact, &target, &progress)
            .expect_err("a mount point cannot be replaced");
        assert_eq!(progress.stage(), "measure", "it failed at the end: {err}");
        assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
        drop(mount);
    }
    // Broken sets are errors naming the file.
    let out = dir.join("set");
    set::export(&doc, &compact, &out).expect("export");
    let manifest = out.join("material.json");
    let text = std::fs::read_to_string(&manifest).expect("read");
    std::fs::write(&manifest, &text[..text.len() / 2]).expect("truncate");
    let err = set::import(&manifest).expect_err("truncated").to_string();
    assert!(err.contains("material.json"), "{err}");
    std::fs::write(&manifest, text.replace("kd_n.png", "../../etc/passwd")).expect("write");
    assert!(set::import(&manifest).is_err());
    std::fs::write(&manifest, &text).expect("write");
    std::fs::write(out.join("kd_n.png"), b"not a png").expect("write");
    let err = set::import(&manifest)
        .expect_err("corrupt image")
        .to_string();
    assert!(err.contains("kd_n.png"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn export_cli_batches_and_reports() {
    let dir = temp("cli");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .output()
            .expect("runs")
    };
    let a = dir.join("a.kapaint");
    let b = dir.join("b.kapaint");
    for (p, preset) in [(&a, "gold"), (&b, "jade")] {
        let o = run(&[
            "new",
            "--size",
            "64x32",
            "--preset",
            preset,
            "--out",
            p.to_str().expect("path"),
        ]);
        assert!(o.status.success(), "{o:?}");
    }
    let out = dir.join("sets");
    let o = run(&[
        "export",
        a.to_str().expect("path"),
        b.to_str().expect("path"),
        "--preset",
        "compact",
        "--out",
        out.to_str().expect("path"),
        "--report",
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8(o.stdout).expect("utf-8");
    assert_eq!(text.matches("exported ").count(), 2, "{text}");
    assert!(text.contains("bytes: set "), "{text}");
    assert!(out.join("a/material.json").is_file() && out.join("b/material.json").is_file());
    // A uniform project exports as constants only.
    let manifest = std::fs::read_to_string(out.join("a/material.json")).expect("read");
    assert!(manifest.contains("\"files\": []"), "{manifest}");
    let back = dir.join("back.kapaint");
    let o = run(&[
        "import-set",
        out.join("a/material.json").to_str().expect("path"),
        "--out",
        back.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    // Unknown preset: exit 2, one line, nothing written.
    let none = dir.join("none");
    let o = run(&[
        "export",
        a.to_str().expect("path"),
        "--preset",
        "nope",
        "--out",
        none.to_str().expect("path"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown export preset"));
    assert!(!none.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_set_ships_a_valid_wgsl_decode_snippet() {
    let dir = temp("snippet");
    let doc = painted();
    for p in preset::builtin_sets() {
        let out = dir.join(&p.name);
        set::export(&doc, &p, &out).expect("export");
        let source = std::fs::read_to_string(out.join("material.wgsl")).expect("snippet");
        assert!(source.contains("fn kapaint_decode_n") && source.contains("fn kapaint_ka"));
        validate_wgsl(&source, &p.name);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A compute entry point that uses a GLSL snippet's two functions, as an engine would:
/// `results[2i]` is the `n` of code `codes[i]` (8-bit), `results[2i + 1]` its `k_a`.
const GLSL_MAIN: &str = "
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Codes { float codes[]; };
layout(std430, binding = 1) buffer Results { float results[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < uint(codes.length())) {
        float n = kapaint_decode_n(codes[i] / 255.0);
        results[2u * i] = n;
        results[2u * i + 1u] = kapaint_ka(vec3(0.3), vec3(0.5), n).x;
    }
}
";

/// Parses `snippet` with naga's GLSL frontend as a GLSL 4.50 compute shader and validates it.
fn validate_glsl(snippet: &str, what: &str) {
    let source = format!("#version 450\n{snippet}{GLSL_MAIN}");
    let module = naga::front::glsl::Frontend::default()
        .parse(&naga::ShaderStage::Compute.into(), &source)
        .unwrap_or_else(|e| panic!("{what}: {}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{what}: {e:?}"));
}

fn validate_wgsl(source: &str, what: &str) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{what}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{what}: {e:?}"));
}

#[test]
fn every_set_ships_a_valid_glsl_decode_snippet_and_counts_its_bytes() {
    let dir = temp("glsl");
    let doc = painted();
    for p in preset::builtin_sets() {
        let out = dir.join(&p.name);
        let m = set::export(&doc, &p, &out).expect("export");
        let source = std::fs::read_to_string(out.join("material.glsl")).expect("snippet");
        assert!(
            source.contains("float kapaint_decode_n(float stored)")
                && source.contains("vec3 kapaint_ka(vec3 kd, vec3 ks, float n)")
                && !source.contains("#version")
                && !source.contains("#extension"),
            "{}",
            p.name
        );
        validate_glsl(&source, &p.name);
        // Every byte of the set is counted: images, both snippets and the manifest itself.
        let size = |name: &str| std::fs::metadata(out.join(name)).expect("file").len();
        let images: u64 = m.files.iter().map(|f| size(&f.path)).sum();
        assert_eq!(
            m.bytes.exported,
            images + size("material.wgsl") + size("material.glsl") + size("material.json"),
            "{}",
            p.name
        );
        let on_disk: set::Manifest =
            serde_json::from_slice(&std::fs::read(out.join("material.json")).expect("manifest"))
                .expect("manifest parses");
        assert_eq!(on_disk.bytes, m.bytes);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every way a set can store `n` (each curve, a constant, float) under every model and
/// approximation gives snippets that naga validates, in both languages.
#[test]
fn snippets_validate_for_every_n_storage_model_and_approximation() {
    use kapaint::export::encoding::{NCurve, NEncoding};
    use kapaint::export::snippet;
    let dir = temp("snippet-variants");
    let doc = painted();
    let base = set::export(&doc, &preset::find("compact").expect("preset"), &dir).expect("export");
    let curves = [NCurve::Linear, NCurve::Sqrt, NCurve::Log].map(|curve| {
        (
            Some(NEncoding {
                curve,
                lo: 1.5,
                hi: 4000.0,
                bits: 8,
            }),
            None,
        )
    });
    let storages =
        curves
            .into_iter()
            .chain([(None, Some(20.0)), (None, Some(1.0e-7)), (None, None)]);
    for (n_encoding, n) in storages {
        for model in reflectance::ShadingModel::ALL {
            for approx in ["fast", "paper", "paper-corrected"] {
                let mut m = base.clone();
                m.n_encoding = n_encoding;
                m.constants.n = n;
                m.model = model;
                m.approximation.name = reflectance::AmbientApprox::from_name(approx).expect("name");
                let what = format!("{n_encoding:?} {n:?} {model:?} {approx}");
                let glsl = snippet::glsl(&m);
                let wgsl = snippet::wgsl(&m);
                let expected_approx = match approx {
                    "paper" => "APPROX_PAPER_PRINTED",
                    "paper-corrected" => "APPROX_PAPER_CORRECTED",
                    _ => "APPROX_FAST",
                };
                let expected_model = match model {
                    reflectance::ShadingModel::Phong => "MODEL_PHONG",
                    reflectance::ShadingModel::BlinnPhong => "MODEL_BLINN",
                    reflectance::ShadingModel::CookTorrance => "MODEL_COOK_TORRANCE",
                };
                assert!(
                    glsl.contains(&format!("const uint KAPAINT_APPROX = {expected_approx};"))
                        && glsl.contains(&format!("const uint KAPAINT_MODEL = {expected_model};"))
                        && wgsl
                            .contains(&format!("const KAPAINT_APPROX: u32 = {expected_approx};")),
                    "{what}"
                );
                validate_glsl(&glsl, &what);
                validate_wgsl(&wgsl, &what);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A cancelled export stops with `Cancelled` and leaves nothing at the target or beside it,
/// whether the cancel comes before the work or during the block encoder.
#[test]
fn cancelled_exports_leave_nothing_behind() {
    let dir = temp("cancel");
    let doc = painted();
    let out = dir.join("set");
    let progress = kapaint::task::Progress::default();
    progress.cancel();
    let p = preset::find("ktx2").expect("preset");
    assert!(matches!(
        set::export_with(&doc, &p, &out, &progress),
        Err(set::SetError::Cancelled)
    ));
    assert!(!out.exists());

    // A bigger map, cancelled from another thread once encoding has started.
    let big = kapaint::report::typical::typical_document(512, None, 5).expect("doc");
    let progress = kapaint::task::Progress::default();
    let result = std::thread::scope(|scope| {
        scope.spawn(|| {
            while progress.stage() != "encode" {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            progress.cancel();
        });
        set::export_with(&big, &p, &out, &progress)
    });
    assert!(
        matches!(result, Err(set::SetError::Cancelled)),
        "{result:?}"
    );
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(&dir).expect("dir").collect();
    assert!(left.is_empty(), "{left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// With the real spot mesh attached, texels outside its UV islands are filled from the
/// nearest island: every exported texel outside holds a value some island texel holds.
#[test]
fn padding_fills_outside_the_islands_from_the_mesh_bake() {
    let obj =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_triangulated.obj");
    let mesh = kapaint::mesh::open(&obj).expect("spot");
    let surface = kapaint::model::surface::Surface::new(mesh, 200, 120).expect("bake");
    let coverage = surface.bake.coverage_grid();
    let doc = painted()
        .with_surface(Some(std::sync::Arc::new(surface)))
        .expect("surface");
    let dir = temp("padding");
    let out = dir.join("set");
    let m = set::export(&doc, &preset::find("16-bit").expect("preset"), &out).expect("export");
    assert!(m.dilated);
    let image = image::open(out.join(&m.files[0].path))
        .expect("png")
        .to_rgba16();
    let inside: std::collections::HashSet<[u16; 4]> = image
        .pixels()
        .zip(&coverage)
        .filter(|(_, c)| **c == kapaint::mesh::bake::Coverage::Surface)
        .map(|(p, _)| p.0)
        .collect();
    let mut outside = 0;
    for (p, c) in image.pixels().zip(&coverage) {
        if *c != kapaint::mesh::bake::Coverage::Surface {
            outside += 1;
            assert!(inside.contains(&p.0), "{:?} comes from no island", p.0);
        }
    }
    assert!(outside > 1000, "{outside}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_plan_shows_what_the_export_writes() {
    let doc = painted();
    for name in ["compact", "16-bit", "separate", "with-ka", "ktx2-raw"] {
        let preset = preset::find(name).expect("preset");
        let plan = kapaint::export::set::plan(&doc, &preset);
        let dir = temp(&format!("plan-{name}"));
        let m = set::export(&doc, &preset, &dir).expect("export");
        let planned: Vec<(&str, &Vec<String>)> = plan
            .files
            .iter()
            .map(|f| (f.path.as_str(), &f.layout))
            .collect();
        let written: Vec<(&str, &Vec<String>)> = m
            .files
            .iter()
            .map(|f| (f.path.as_str(), &f.layout))
            .collect();
        assert_eq!(planned, written, "{name}");
        assert_eq!(plan.n_encoding, m.n_encoding, "{name}");
        assert_eq!(plan.constants, m.constants, "{name}");
        assert_eq!(
            (plan.bytes.naive, plan.bytes.project),
            (m.bytes.naive, m.bytes.project)
        );
        // The estimate is n's quantisation alone; the set's measured error adds the other
        // channels' rounding, so it is at least as large.
        assert!(plan.ka_error.max > 0.0, "{name}: n is quantised");
        assert!(m.ka_error.max >= plan.ka_error.max * 0.999, "{name}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Exporting to a folder that holds a set asks for replacing: plain export refuses it,
/// `export_replacing` swaps the new set in (nothing of the old one, nothing beside it), and a
/// folder that holds anything else is never replaced.
#[test]
fn a_set_is_replaced_only_when_asked_and_only_a_set() {
    let dir = temp("replace");
    let doc = painted();
    let compact = preset::find("compact").expect("preset");
    let separate = preset::find("separate").expect("preset");
    let out = dir.join("set");
    set::export(&doc, &separate, &out).expect("first export");
    let kind = set::SetKind::Material;
    assert_eq!(set::target(&out, kind).expect("target"), set::Target::Set);
    let e = set::export(&doc, &compact, &out).expect_err("a set is there");
    assert!(e.to_string().contains("holds an exported set"), "{e}");
    let progress = kapaint::task::Progress::default();
    let m = set::export_replacing(&doc, &compact, &out, &progress).expect("replace");
    assert_eq!(m.preset, "compact");
    let names = |d: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(names(&out).len(), m.file_count(), "{:?}", names(&out));
    assert_eq!(names(&dir), ["set"], "nothing left beside the set");
    // A folder of other things is refused, replacing or not, and left as it was.
    let other = dir.join("photos");
    std::fs::create_dir_all(&other).expect("dir");
    std::fs::write(other.join("holiday.jpg"), b"not a set").expect("write");
    assert!(matches!(
        set::target(&other, kind).expect("target"),
        set::Target::Taken(_)
    ));
    assert!(set::export_replacing(&doc, &compact, &other, &progress).is_err());
    assert_eq!(names(&other), ["holiday.jpg"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint export` to a folder that holds a set says to pass `--replace`, and replaces it
/// with it.
#[test]
fn export_cli_replaces_a_set_with_replace() {
    let dir = temp("cli-replace");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .output()
            .expect("runs")
    };
    let project = dir.join("p.kapaint");
    let project = project.to_str().expect("path");
    let out = dir.join("set");
    let out = out.to_str().expect("path");
    assert!(
        run(&["new", "--size", "32", "--out", project])
            .status
            .success()
    );
    let export = |extra: &[&str]| {
        let mut args = vec!["export", project, "--out", out, "--no-padding"];
        args.extend_from_slice(extra);
        run(&args)
    };
    assert!(export(&[]).status.success());
    let again = export(&[]);
    assert_eq!(again.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(stderr.contains("--replace"), "{stderr}");
    let replaced = export(&["--replace", "--preset", "separate"]);
    assert!(replaced.status.success(), "{replaced:?}");
    let manifest = std::fs::read_to_string(dir.join("set/material.json")).expect("manifest");
    assert!(manifest.contains("\"preset\": \"separate\""), "{manifest}");
    let _ = std::fs::remove_dir_all(&dir);
}
