//! Criterion benches for the material model's targets (issue 3), on 4096^2 maps with all
//! channels: a 128 px dab, a 100-dab stroke, a whole-map fill and its undo, the full k_a
//! derive against a copy of the same bytes, and project save/load.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Document, DocumentSettings, FillRegion, MaterialMaps, StrokeTool, project};
use kapaint::model::{HistoryCommand, LayerCommand, PaintCommand, SettingsCommand, StrokeCommand};
use kapaint::reflectance::{AmbientApprox, ShadingModel};
use rayon::prelude::*;

const SIDE: u32 = 4096;

/// A document whose every tile holds varied data (nothing uniform).
fn painted_document(side: u32) -> Document {
    kapaint::report::typical::varied_document(side).expect("size")
}

fn brush128() -> BrushSettings {
    BrushSettings {
        radius_px: 128.0,
        hardness: 0.5,
        flow: 0.5,
        ..BrushSettings::default()
    }
}

fn dabs(c: &mut Criterion) {
    let mut group = c.benchmark_group("model_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(4));
    // A whole stroke of 100 dabs (spacing 25 % of 128 px) on a fresh document, including
    // the copy-on-write of every tile it touches.
    let base = Document::new(
        SIDE,
        SIDE,
        DocumentSettings {
            brush: brush128(),
            ..DocumentSettings::default()
        },
    )
    .expect("size");
    let points = vec![
        StrokePoint {
            pos: Vec2::new(400.0, 2048.0),
            pressure: 1.0,
        },
        StrokePoint {
            pos: Vec2::new(400.0 + 99.0 * 32.0, 2048.0),
            pressure: 1.0,
        },
    ];
    group.bench_function("stroke_100_dabs_128px", |b| {
        b.iter_batched(
            || Document::from_parts(base.maps().clone(), base.settings().clone()),
            |mut doc| {
                doc.apply(StrokeCommand::Stroke {
                    tool: StrokeTool::Brush,
                    points: points.clone(),
                })
                .expect("stroke");
                doc
            },
            BatchSize::LargeInput,
        );
    });
    group.finish();
}

fn fills_and_derive(c: &mut Criterion) {
    let mut group = c.benchmark_group("model_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(4));
    let painted = painted_document(SIDE);
    group.bench_function("fill_whole_map", |b| {
        b.iter_batched(
            || Document::from_parts(painted.maps().clone(), painted.settings().clone()),
            |mut doc| {
                doc.apply(PaintCommand::Fill(FillRegion::All))
                    .expect("fill");
                doc
            },
            BatchSize::LargeInput,
        );
    });
    group.bench_function("undo_whole_map_fill", |b| {
        b.iter_batched(
            || {
                let mut doc =
                    Document::from_parts(painted.maps().clone(), painted.settings().clone());
                doc.apply(PaintCommand::Fill(FillRegion::All))
                    .expect("fill");
                doc
            },
            |mut doc| {
                doc.apply(HistoryCommand::Undo).expect("undo");
                doc
            },
            BatchSize::LargeInput,
        );
    });
    let texels = (SIDE * SIDE) as usize;
    let mut out = vec![Vec3::ZERO; texels];
    group.throughput(Throughput::Elements(texels as u64));
    group.bench_function("derive_ka_full_map", |b| {
        b.iter(|| {
            painted
                .maps()
                .derive_ka_into(ShadingModel::Phong, AmbientApprox::Fast, &mut out);
        });
    });
    // The same bytes as the stored maps (14 per texel), copied on all threads.
    let bytes = texels * 14;
    let src = vec![1u8; bytes];
    let mut dst = vec![0u8; bytes];
    group.bench_function("memcpy_same_bytes", |b| {
        b.iter(|| {
            dst.par_chunks_mut(1 << 20)
                .zip(src.par_chunks(1 << 20))
                .for_each(|(d, s)| d.copy_from_slice(s));
            black_box(&dst);
        });
    });
    group.finish();
}

fn project_io(c: &mut Criterion) {
    let mut group = c.benchmark_group("project_8192");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    // A typical project (the spot texture in k_d, an n gradient, 50 strokes); uniformly
    // random maps, which no PNG compresses, are the worst case and are reported separately.
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let doc = kapaint::report::typical::typical_document(
        8192,
        texture.exists().then_some(texture.as_path()),
        50,
    )
    .expect("typical document");
    let dir = std::env::temp_dir().join(format!("kapaint-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("big.kapaint");
    group.bench_function("save", |b| {
        b.iter(|| project::save(&doc, &path).expect("save"));
    });
    group.bench_function("load", |b| {
        b.iter(|| black_box(project::load(&path).expect("load")));
    });
    let _ = std::fs::remove_dir_all(&dir);
    group.finish();
}

/// Autosave on a 4096^2 painted document after a 256 px stroke: what the UI thread pays to
/// start a recovery record (a snapshot of the changed tiles and a thread), and the whole
/// record written and flushed to disk on its thread.
fn autosave(c: &mut Criterion) {
    use kapaint::model::recovery::Autosaver;
    use std::time::Instant;
    let mut group = c.benchmark_group("autosave_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(10));
    let mut doc = painted_document(SIDE);
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 128.0,
        ..BrushSettings::default()
    }))
    .expect("brush");
    let dir = std::env::temp_dir().join(format!("kapaint-bench-autosave-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut saver = Autosaver::new(Duration::ZERO, Some(&dir.join("p.kapaint")), &doc);
    let mut y = 200.0_f32;
    let mut stroke = |doc: &mut Document| {
        y = if y > 3800.0 { 200.0 } else { y + 300.0 };
        doc.apply(StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points: vec![
                StrokePoint {
                    pos: Vec2::new(1000.0, y),
                    pressure: 1.0,
                },
                StrokePoint {
                    pos: Vec2::new(1128.0, y),
                    pressure: 1.0,
                },
            ],
        })
        .expect("stroke");
    };
    // The first recovery copy is the whole project; the ones measured append to it.
    stroke(&mut doc);
    saver.poll(&doc, Instant::now());
    saver.wait().expect("a save").expect("saved");
    group.bench_function("ui_thread_starts_a_record_after_a_256px_stroke", |b| {
        b.iter_custom(|rounds| {
            let mut spent = Duration::ZERO;
            for _ in 0..rounds {
                stroke(&mut doc);
                let start = Instant::now();
                black_box(saver.poll(&doc, Instant::now()));
                spent += start.elapsed();
                saver.wait().expect("a save").expect("saved");
            }
            spent
        });
    });
    group.bench_function("record_after_a_256px_stroke_written_and_flushed", |b| {
        b.iter_custom(|rounds| {
            let mut spent = Duration::ZERO;
            for _ in 0..rounds {
                stroke(&mut doc);
                let start = Instant::now();
                saver.poll(&doc, Instant::now());
                saver.wait().expect("a save").expect("saved");
                spent += start.elapsed();
            }
            spent
        });
    });
    let _ = std::fs::remove_dir_all(&dir);
    group.finish();
}

/// Image > Resize of painted maps (every tile varied): the resampling a worker does.
fn resize(c: &mut Criterion) {
    let mut group = c.benchmark_group("resize");
    group.sample_size(10);
    let big = painted_document(SIDE);
    let small = painted_document(SIDE / 2);
    group.bench_function("4096_to_2048", |b| {
        b.iter(|| {
            kapaint::model::resize::resized(big.maps(), SIDE / 2, SIDE / 2).expect("resized")
        });
    });
    group.bench_function("2048_to_4096", |b| {
        b.iter(|| kapaint::model::resize::resized(small.maps(), SIDE, SIDE).expect("resized"));
    });
    group.finish();
}

/// Layers: toggling a painted layer's visibility recomposites every tile it touches (the
/// compositor finds them; issue 18 asks <= 60 ms on 2 cores), and the first full composite.
fn layers(c: &mut Criterion) {
    use kapaint::model::layers::Compositor;
    let mut group = c.benchmark_group("layers_4096");
    group.sample_size(10);
    let mut stack = kapaint::report::typical::layered_stack(SIDE, 16);
    let mut maps = MaterialMaps::new(SIDE, SIDE, MaterialValue::default()).expect("size");
    let mut compositor = Compositor::new();
    compositor.update(&stack, &mut maps);
    eprintln!("16 layers: {} MB of tiles", stack.heap_bytes() / 1_000_000);
    group.bench_function("toggle_visibility_16_layers", |b| {
        b.iter(|| {
            stack.layers[8].props.visible = !stack.layers[8].props.visible;
            compositor.update(&stack, &mut maps)
        });
    });
    // The 5 x 5 tiles a 128 px-radius dab covers, near the map's centre, on layer 8: a write
    // there (new stamps), then those tiles recomposited.
    let tiles_x = stack.tiles_x();
    let dab: Vec<usize> = (30..35)
        .flat_map(|ty| (30..35).map(move |tx| ty * tiles_x + tx))
        .collect();
    let mut k = 0u16;
    stack.layers[8].props.visible = true;
    compositor.update(&stack, &mut maps);
    group.bench_function("recomposite_25_tiles_after_a_dab_on_layer_8", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            for &id in &dab {
                let tile = stack.layers[8].paint_tile_mut(id).expect("paint layer");
                tile.alpha[0].data_mut()[usize::from(k) % 4096] = k;
            }
            compositor.update_tiles(&stack, &mut maps, &dab)
        });
    });
    group.bench_function("full_composite_16_layers", |b| {
        b.iter(|| Compositor::new().update(&stack, &mut maps.clone()));
    });
    group.finish();
    layer_dabs(c);
}

/// One 128 px-radius dab through the document, as a stroke lays it (paint the selected layer,
/// then recomposite the texels it changed and derive `k_a` on the tiles that changed): on
/// layer 8 of 16 painted, masked layers, and on a one-layer document, in the same run (issue
/// 18: <= 1 ms, <= 2x). The stroke moves on by the spacing (25 % of the radius) each dab, along
/// rows across the map ([`kapaint::report::typical::stroke_path`]), so every dab reaches texels
/// it has not covered yet; where the path starts over, a new stroke begins, painting over the
/// first. `..._over_paint_...` paints on a layer filled first (no tile of it new to the layer);
/// `..._overlapping` goes back and forth over one place, where most of each dab is already
/// covered.
fn layer_dabs(c: &mut Criterion) {
    type Path<'a> = &'a dyn Fn(u32) -> Vec2;
    let mut group = c.benchmark_group("layers_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(4));
    let settings = DocumentSettings {
        brush: brush128(),
        primary: MaterialValue::new(Vec3::new(0.8, 0.3, 0.1), Vec3::splat(0.3), 60.0),
        ..DocumentSettings::default()
    };
    let layered = || {
        Document::from_stack(
            kapaint::report::typical::layered_stack(SIDE, 16),
            settings.clone(),
        )
        .expect("size")
    };
    let single = || Document::new(SIDE, SIDE, settings.clone()).expect("size");
    let moving = |k: u32| kapaint::report::typical::stroke_path(k);
    let overlapping = |k: u32| {
        Vec2::new(
            2000.5 + if k.is_multiple_of(2) { 0.0 } else { 32.0 },
            1500.5,
        )
    };
    let filled = || {
        let mut doc = layered();
        doc.apply(LayerCommand::SelectPath(vec![8]))
            .expect("select");
        let primary = doc.settings().primary;
        let under = kapaint::report::typical::under_paint();
        doc.apply(SettingsCommand::SetPrimary(under))
            .expect("primary");
        doc.apply(PaintCommand::Fill(FillRegion::All))
            .expect("fill");
        doc.apply(SettingsCommand::SetPrimary(primary))
            .expect("primary");
        doc
    };
    let cases: [(&str, Document, usize, Path); 4] = [
        ("dab_128px_on_layer_8_of_16", layered(), 8, &moving),
        ("dab_128px_on_1_layer", single(), 0, &moving),
        (
            "dab_128px_over_paint_on_layer_8_of_16",
            filled(),
            8,
            &moving,
        ),
        (
            "dab_128px_overlapping_on_layer_8_of_16",
            layered(),
            8,
            &overlapping,
        ),
    ];
    for (name, mut doc, layer, path) in cases {
        doc.apply(LayerCommand::SelectPath(vec![layer]))
            .expect("select");
        let mut k = 0u32;
        let mut version = doc.maps().version();
        // The k_a of the dirty tiles, kept from dab to dab as a consumer would.
        let mut ka = Vec::new();
        group.bench_function(name, |b| {
            b.iter(|| {
                if k.is_multiple_of(kapaint::report::typical::STROKE_PATH_POINTS) {
                    doc.apply(StrokeCommand::EndStroke).expect("end");
                    doc.apply(StrokeCommand::BeginStroke(StrokeTool::Brush))
                        .expect("begin");
                }
                k += 1;
                doc.apply(StrokeCommand::StrokeTo(StrokePoint {
                    pos: path(k),
                    pressure: 1.0,
                }))
                .expect("dab");
                let dirty = doc.maps().tiles_changed_since(version);
                version = doc.maps().version();
                doc.maps().derive_ka_tiles_into(
                    ShadingModel::Phong,
                    AmbientApprox::Fast,
                    &dirty,
                    &mut ka,
                );
                ka.len()
            });
        });
    }
    group.finish();
}

/// Issue 56's tools, a 128 px dab each (one a point, 12.8 texels apart) over a 4096^2 document whose
/// every texel differs (nothing uniform to read or write), beside the brush's own dab there: clone (its source 160 texels
/// along the row), smudge, and the brush through a 256 x 256 checker stencil.
fn tool_dabs(c: &mut Criterion) {
    let mut group = c.benchmark_group("tools_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(4));
    // The same document and dabs as examples/tool_dab_profile.rs.
    let path = kapaint::report::typical::tool_dab_path;
    for (name, tool) in [
        ("brush_dab_128px", StrokeTool::Brush),
        ("clone_dab_128px", StrokeTool::Clone),
        ("smudge_dab_128px", StrokeTool::Smudge),
        ("brush_dab_128px_through_stencil", StrokeTool::Brush),
    ] {
        let mut doc = kapaint::report::typical::tool_dab_document(name.ends_with("stencil"))
            .expect("document");
        let mut k = 0u32;
        group.bench_function(name, |b| {
            b.iter(|| {
                // A stroke a row: no jump between rows inside a stroke.
                if k.is_multiple_of(250) {
                    doc.apply(StrokeCommand::EndStroke).expect("end");
                    doc.apply(StrokeCommand::BeginStroke(tool)).expect("begin");
                    k %= 3000;
                }
                k += 1;
                doc.apply(StrokeCommand::StrokeTo(StrokePoint {
                    pos: path(k - 1),
                    pressure: 1.0,
                }))
                .expect("dab");
                doc.maps().version()
            });
        });
    }
    group.finish();
}

/// `ProjectImage` of a 1024^2 image at 4096^2 on the sphere: planar (with its depth map, over
/// a quarter of the sphere) and tri-planar (every texel), and `PlaceDecal` of the same image
/// half a unit wide; each one undo step, undone after.
fn projections(c: &mut Criterion) {
    use kapaint::model::paint::projection::Projection;
    let mut group = c.benchmark_group("tools_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    let logo = image::DynamicImage::ImageRgba8(image::RgbaImage::from_fn(1024, 1024, |x, y| {
        image::Rgba([
            (x / 4) as u8,
            (y / 4) as u8,
            128,
            if (x / 64 + y / 64) % 3 == 0 { 0 } else { 255 },
        ])
    }));
    let image =
        kapaint::model::paint_image::PaintImage::decoded(std::path::Path::new("logo.png"), &logo)
            .expect("image");
    let surface = std::sync::Arc::new(
        kapaint::model::surface::Surface::new(kapaint::mesh::uv_sphere(128, 64), SIDE, SIDE)
            .expect("bake"),
    );
    let mut doc = Document::new(SIDE, SIDE, DocumentSettings::default())
        .expect("size")
        .with_surface(Some(surface))
        .expect("surface");
    for (name, projection) in [
        (
            "project_planar_1024px_image",
            Projection::Planar {
                origin: Vec3::new(0.0, 0.0, 1.0),
                normal: Vec3::Z,
                up: Vec3::Y,
                width: 1.0,
                height: 1.0,
            },
        ),
        (
            "project_triplanar_1024px_image",
            Projection::Triplanar {
                scale: 2.0,
                blend: 0.5,
            },
        ),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                doc.apply(PaintCommand::ProjectImage {
                    image: image.clone(),
                    projection,
                    channels: kapaint::model::Channels::ALL,
                    opacity: 1.0,
                })
                .expect("project");
                doc.apply(HistoryCommand::Undo).expect("undo");
            });
        });
        // The same projection as a projection fill: laid (every tile at once, as the
        // composite reads them) and composited, what a new mesh costs it too.
        let fill = name.replace("project_", "projection_fill_");
        group.bench_function(fill.as_str(), |b| {
            b.iter(|| {
                doc.apply(LayerCommand::AddProjectionFill {
                    name: "Fill".into(),
                    image: image.clone(),
                    projection,
                    channels: kapaint::model::Channels::ALL,
                })
                .expect("fill");
                doc.apply(HistoryCommand::Undo).expect("undo");
            });
        });
    }
    group.bench_function("place_decal_1024px_image", |b| {
        b.iter(|| {
            doc.apply(PaintCommand::PlaceDecal {
                image: image.clone(),
                at: Vec3::new(0.3, 0.4, 1.2),
                size: 0.5,
                rotation: 20.0,
                channels: kapaint::model::Channels::ALL,
                opacity: 1.0,
            })
            .expect("decal");
            doc.apply(HistoryCommand::Undo).expect("undo");
        });
    });
    group.finish();
}

/// Clone and smudge on the mesh (object space, the source found through the baked texels):
/// the brush's 128-texel dab at spacing 10 %, around the sphere's equator of
/// [`typical::mesh_tool_dab_document`] (what `examples/tool_dab_profile mesh` profiles).
fn mesh_copy_dabs(c: &mut Criterion) {
    use kapaint::report::typical;
    let mut group = c.benchmark_group("tools_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(5));
    let mut doc = typical::mesh_tool_dab_document().expect("document");
    let units = doc.surface().map_or(1.0, |s| s.units_per_texel);
    for (name, tool) in [
        ("brush_dab_on_mesh_128px", StrokeTool::Brush),
        ("clone_dab_on_mesh_128px", StrokeTool::Clone),
        ("smudge_dab_on_mesh_128px", StrokeTool::Smudge),
    ] {
        let mut k = 0u32;
        group.bench_function(name, |b| {
            b.iter(|| {
                if k.is_multiple_of(250) {
                    doc.apply(StrokeCommand::EndStroke).expect("end");
                    doc.apply(StrokeCommand::BeginStroke(tool)).expect("begin");
                }
                doc.apply(StrokeCommand::SurfaceStrokeTo(
                    typical::mesh_tool_dab_point(k, units),
                ))
                .expect("dab");
                k += 1;
                doc.maps().version()
            });
        });
        doc.apply(StrokeCommand::EndStroke).expect("end");
    }
    group.finish();
}

/// Saving and opening a 16-layer 4096^2 project (the stack of [`layered_stack`]: every
/// layer painted over 10 % of the map, with masks); issue 18 asks <= 3 s each.
fn layered_project_io(c: &mut Criterion) {
    let mut group = c.benchmark_group("layers_4096");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    let doc = Document::from_stack(
        kapaint::report::typical::layered_stack(SIDE, 16),
        DocumentSettings::default(),
    )
    .expect("size");
    let dir = std::env::temp_dir().join(format!("kapaint-bench-layers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("layers.kapaint");
    group.bench_function("save_16_layers", |b| {
        b.iter(|| project::save(&doc, &path).expect("save"));
    });
    eprintln!(
        "16-layer project: {} MB",
        std::fs::metadata(&path).map_or(0, |m| m.len() / 1_000_000)
    );
    group.bench_function("open_16_layers", |b| {
        b.iter(|| black_box(project::load(&path).expect("load")));
    });
    let _ = std::fs::remove_dir_all(&dir);
    group.finish();
}

/// A `side x side` document of `masks` fill layers over the base, each masked by a noise
/// generator (`generated`) or by a painted mask holding the same values as pixels.
fn masked_document(side: u32, masks: usize, generated: bool) -> Document {
    use kapaint::model::MaskCommand;
    let mut doc = Document::new(side, side, DocumentSettings::default()).expect("size");
    for k in 0..masks {
        doc.apply(LayerCommand::AddLayer {
            kind: kapaint::model::LayerKind::Fill,
            name: format!("Dirt {k}"),
        })
        .expect("layer");
        doc.apply(MaskCommand::SetMaskGenerator(Some(noise(8.0, k as u32))))
            .expect("generator");
        if !generated {
            doc.apply(MaskCommand::SetMaskGenerator(None))
                .expect("pixels");
        }
    }
    doc
}

/// Perlin fBm, 4 octaves, in object space.
fn noise(scale: f32, seed: u32) -> kapaint::model::generator::Generator {
    use kapaint::model::generator::{Generator, Noise, NoiseKind, Space};
    Generator::Noise(Noise {
        kind: NoiseKind::Perlin,
        scale,
        octaves: 4,
        seed,
        space: Space::Object,
    })
}

/// Generator masks (issue 41): a drag's coarse preview at 2048^2 (<= 150 ms), the full
/// result at 4096^2 (<= 1 s), and saving and opening 8 generator masks against 8 painted
/// masks of the same values at 4096^2 (no slower).
fn generators(c: &mut Criterion) {
    use kapaint::model::MaskCommand;
    let mut group = c.benchmark_group("generators");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let mut doc = masked_document(2048, 1, true);
    let mut s = 8.0;
    group.bench_function("drag_noise_2048_coarse", |b| {
        b.iter(|| {
            s += 0.01;
            doc.apply(MaskCommand::PreviewMaskGenerator(noise(s, 0)))
                .expect("preview");
        });
    });
    group.bench_function("drag_noise_2048_full", |b| {
        b.iter(|| {
            s += 0.01;
            doc.apply(MaskCommand::SetMaskGenerator(Some(noise(s, 0))))
                .expect("set");
        });
    });
    let mut doc = masked_document(SIDE, 1, true);
    group.bench_function("settle_noise_4096", |b| {
        b.iter(|| {
            s += 0.01;
            doc.apply(MaskCommand::SetMaskGenerator(Some(noise(s, 0))))
                .expect("set");
        });
    });
    drop(doc);
    let dir = std::env::temp_dir().join(format!("kapaint-bench-gen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for (name, generated) in [("painted", false), ("generated", true)] {
        let doc = masked_document(SIDE, 8, generated);
        let path = dir.join(format!("{name}.kapaint"));
        group.bench_function(format!("save_8_{name}_masks_4096"), |b| {
            b.iter(|| project::save(&doc, &path).expect("save"));
        });
        eprintln!(
            "8 {name} masks: {} MB",
            std::fs::metadata(&path).map_or(0, |m| m.len() / 1_000_000)
        );
        group.bench_function(format!("open_8_{name}_masks_4096"), |b| {
            b.iter(|| black_box(project::load(&path).expect("load")));
        });
    }
    let _ = std::fs::remove_dir_all(&dir);
    group.finish();
}

criterion_group!(
    benches,
    dabs,
    fills_and_derive,
    project_io,
    autosave,
    resize,
    layers,
    layered_project_io,
    generators,
    tool_dabs,
    projections,
    mesh_copy_dabs
);
criterion_main!(benches);
