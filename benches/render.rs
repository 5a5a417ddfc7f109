//! Criterion benches for the preview renderer (issue 5), on whatever adapter wgpu finds
//! (lavapipe on the 2-core CI machine; a real GPU through the device tool when lent):
//! a 1920x1080 frame of a 1M-triangle mesh with 4096^2 maps, the skip variants against the
//! full shader, and a 256x256 dirty-region upload.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use kapaint::gpu::preview::{DrawPart, Layout, PipelineKey, PreviewDrawData, begin_pass};
use kapaint::gpu::{Gpu, MapTextures, MeshBuffers, Preview};
use kapaint::mesh;
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::texel::MaterialValue;
use kapaint::model::{Channels, Document, DocumentSettings, StrokeTool};
use kapaint::model::{SettingsCommand, StrokeCommand};
use kapaint::reflectance::{AmbientApprox, ShadingModel};
use kapaint::render::{Camera, FrameSettings, Lighting, ViewMode};

fn target(gpu: &Gpu, w: u32, h: u32, format: wgpu::TextureFormat) -> wgpu::TextureView {
    gpu.texture_2d(
        "bench",
        (w, h),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    )
    .create_view(&wgpu::TextureViewDescriptor::default())
}

/// A target and mesh to draw frames into, waiting for each.
struct Frame<'a> {
    gpu: &'a Gpu,
    color: &'a wgpu::TextureView,
    depth: &'a wgpu::TextureView,
    mesh: &'a MeshBuffers,
    /// Reused from frame to frame, as the editor's viewport does.
    bindings: std::cell::RefCell<kapaint::gpu::preview::FrameBindings>,
}

impl Frame<'_> {
    fn draw(
        &self,
        preview: &Preview,
        maps: &MapTextures,
        settings: &FrameSettings,
        parts: &[DrawPart],
    ) {
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let mut bindings = self.bindings.borrow_mut();
        bindings.begin_frame();
        let data = PreviewDrawData::new(
            preview,
            self.gpu,
            (self.mesh, maps),
            settings,
            parts,
            &mut bindings,
        );
        {
            let mut pass = begin_pass(&mut encoder, self.color, self.depth);
            preview.draw(&mut pass, &data);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.wait();
    }
}

/// Paints one brush stroke through `points` at full pressure.
fn brush_stroke(doc: &mut Document, points: &[Vec2]) {
    let points = points
        .iter()
        .map(|&pos| StrokePoint { pos, pressure: 1.0 })
        .collect();
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points,
    })
    .expect("stroke");
}

/// A 4096^2 document with strokes in every channel, and one whose k_s is zero everywhere.
fn documents() -> (Document, Document) {
    let mut painted = Document::new(
        4096,
        4096,
        DocumentSettings {
            brush: BrushSettings {
                radius_px: 200.0,
                ..BrushSettings::default()
            },
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    for k in 0..8 {
        let y = 300.0 + 480.0 * k as f32;
        brush_stroke(
            &mut painted,
            &[Vec2::new(100.0, y), Vec2::new(4000.0, y + 200.0)],
        );
    }
    let matte = Document::new(
        4096,
        4096,
        DocumentSettings {
            base: MaterialValue::new(Vec3::splat(0.5), Vec3::ZERO, 1.0),
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    (painted, matte)
}

/// A Blinn-Phong frame of `view` framing `points`.
fn blinn_phong(view: ViewMode, points: &[glam::Vec3]) -> FrameSettings {
    FrameSettings {
        model: ShadingModel::BlinnPhong,
        approx: AmbientApprox::Fast,
        view,
        lighting: Lighting::default(),
        camera: Camera::default().framing(points),
    }
}

fn frames(c: &mut Criterion) {
    let Ok(gpu) = Gpu::headless() else {
        eprintln!("SKIPPED: no GPU adapter");
        return;
    };
    eprintln!("adapter: {} ({:?})", gpu.info.name, gpu.info.backend);
    let mut group = c.benchmark_group("render_1080p_1m_triangles");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    let sphere = mesh::uv_sphere(1000, 500);
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let (painted, matte) = documents();
    let painted_maps = MapTextures::new(&gpu, painted.maps()).expect("map textures");
    let matte_maps = MapTextures::new(&gpu, matte.maps()).expect("map textures");
    let preview = Preview::new(&gpu);
    let (w, h) = (1920, 1080);
    let color = target(&gpu, w, h, wgpu::TextureFormat::Rgba8UnormSrgb);
    let depth = target(&gpu, w, h, wgpu::TextureFormat::Depth32Float);
    let settings = |view| blinn_phong(view, &sphere.positions);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let cases = [
        (
            "shaded_painted_maps",
            &painted_maps,
            ViewMode::Shaded,
            false,
        ),
        (
            "shaded_full_shader_on_uniform_maps",
            &matte_maps,
            ViewMode::Shaded,
            true,
        ),
        (
            "shaded_uniform_maps_no_specular",
            &matte_maps,
            ViewMode::Shaded,
            false,
        ),
        ("view_ka_painted_maps", &painted_maps, ViewMode::Ka, false),
        ("view_kd_painted_maps", &painted_maps, ViewMode::Kd, false),
        (
            "view_ka_per_view_painted",
            &painted_maps,
            ViewMode::KaView,
            false,
        ),
        (
            "view_average_error_painted",
            &painted_maps,
            ViewMode::KaViewError,
            false,
        ),
    ];
    for (name, maps, view, full) in cases {
        let s = settings(view);
        let key = PipelineKey::for_frame(&s, &maps.uniform, format);
        let key = if full { key.full() } else { key };
        let frame = Frame {
            gpu: &gpu,
            color: &color,
            depth: &depth,
            mesh: &buffers,
            bindings: std::cell::RefCell::default(),
        };
        group.bench_function(name, |b| {
            b.iter(|| frame.draw(&preview, maps, &s, &[DrawPart::whole(key, (w, h))]));
        });
    }
    // The split compare shades each half once.
    let s = settings(ViewMode::Shaded);
    let key = PipelineKey::for_frame(&s, &painted_maps.uniform, format);
    let phong = PipelineKey {
        model: ShadingModel::Phong,
        ..key
    };
    let blinn = PipelineKey {
        model: ShadingModel::BlinnPhong,
        ..key
    };
    let frame = Frame {
        gpu: &gpu,
        color: &color,
        depth: &depth,
        mesh: &buffers,
        bindings: std::cell::RefCell::default(),
    };
    let split = Layout::Split(w / 2).parts([phong, blinn, phong], (w, h));
    group.bench_function("compare_split_painted_maps", |b| {
        b.iter(|| frame.draw(&preview, &painted_maps, &s, &split));
    });
    // Side by side: two whole pictures, each half the width.
    let side = Layout::SideBySide.parts([phong, blinn, phong], (w, h));
    group.bench_function("compare_side_by_side_painted_maps", |b| {
        b.iter(|| frame.draw(&preview, &painted_maps, &s, &side));
    });
    group.finish();
}

fn uploads(c: &mut Criterion) {
    let Ok(gpu) = Gpu::headless() else {
        eprintln!("SKIPPED: no GPU adapter");
        return;
    };
    let (painted, _) = documents();
    let mut group = c.benchmark_group("upload_4096");
    // Long enough to average over the shared VM's slow and fast spells.
    group
        .sample_size(40)
        .measurement_time(Duration::from_secs(10));
    let mut doc = painted;
    let mut maps = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    let mut k = 0_u32;
    // Each iteration paints a hard 128 px dab inside one 256x256 square (16 tiles), then the
    // timed part: sync (upload the dirty tiles) and wait for the queue.
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 128.0,
        hardness: 1.0,
        ..BrushSettings::default()
    }))
    .expect("brush");
    let mut bench = |b: &mut criterion::Bencher<'_>, wait: bool, channels: Channels| {
        doc.apply(SettingsCommand::SetChannels(channels))
            .expect("channels");
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                k += 1;
                let x0 = f32::from((k % 15) as u16) * 256.0;
                let y = 128.0 + 256.0 * (k % 7) as f32;
                // Another colour every dab: the squares repeat every 105 dabs (an odd
                // count), and a dab that changes nothing uploads nothing (a fast GPU runs
                // that many).
                let shade = if k.is_multiple_of(2) { 0.25 } else { 0.75 };
                doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
                    Vec3::splat(shade),
                    Vec3::splat(shade / 2.0),
                    16.0 / shade,
                )))
                .expect("colour");
                brush_stroke(&mut doc, &[Vec2::new(x0 + 128.0, y)]);
                let start = std::time::Instant::now();
                let n = maps.sync(&gpu, doc.maps()).expect("sync");
                if wait {
                    gpu.wait();
                }
                total += start.elapsed();
                gpu.wait();
                assert!(n > 0);
            }
            total
        });
    };
    // The whole upload, until the GPU has the texels; and the part the UI thread waits for
    // (staging, encoding, submitting: the copies themselves run on the GPU's queue).
    group.bench_function("dirty_256x256_region", |b| bench(b, true, Channels::ALL));
    group.bench_function("dirty_256x256_region_cpu_side", |b| {
        bench(b, false, Channels::ALL);
    });
    // A stroke on k_d alone stages k_d alone (8 of the 18 bytes a texel).
    let kd = Channels {
        kd: true,
        ks: false,
        n: false,
    };
    group.bench_function("dirty_256x256_region_kd_only_cpu_side", |b| {
        bench(b, false, kd);
    });
    group.finish();
}

/// One painting frame as the editor makes it: a 64 px dab on 4096^2 maps, the dirty tiles
/// synced, and a 1280 x 720 viewport frame of the built-in sphere drawn and waited for.
fn painting(c: &mut Criterion) {
    let Ok(gpu) = Gpu::headless() else {
        eprintln!("SKIPPED: no GPU adapter");
        return;
    };
    let mut group = c.benchmark_group("painting_4096");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(6));
    let sphere = mesh::builtin("sphere").expect("sphere");
    let buffers = MeshBuffers::new(&gpu, &sphere).expect("mesh buffers");
    let (mut doc, _) = documents();
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 64.0,
        ..BrushSettings::default()
    }))
    .expect("brush");
    let mut maps = MapTextures::new(&gpu, doc.maps()).expect("map textures");
    let preview = Preview::new(&gpu);
    let (w, h) = (1280, 720);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let color = target(&gpu, w, h, format);
    let depth = target(&gpu, w, h, wgpu::TextureFormat::Depth32Float);
    let s = FrameSettings {
        model: ShadingModel::Phong,
        approx: AmbientApprox::Fast,
        view: ViewMode::Shaded,
        lighting: Lighting::default(),
        camera: Camera::default().framing(&sphere.positions),
    };
    let frame = Frame {
        gpu: &gpu,
        color: &color,
        depth: &depth,
        mesh: &buffers,
        bindings: std::cell::RefCell::default(),
    };
    let mut k = 0_u32;
    group.bench_function("dab_sync_frame_1280x720", |b| {
        b.iter(|| {
            k += 1;
            let x = f32::from((k % 60) as u16) * 64.0 + 64.0;
            let y = 2048.0 + 512.0 * ((k / 60) % 3) as f32;
            brush_stroke(&mut doc, &[Vec2::new(x, y)]);
            maps.sync(&gpu, doc.maps()).expect("sync");
            let key = PipelineKey::for_frame(&s, &maps.uniform, format);
            frame.draw(&preview, &maps, &s, &[DrawPart::whole(key, (w, h))]);
        });
    });
    group.finish();
}

criterion_group!(benches, frames, uploads, painting);
criterion_main!(benches);
