//! The traced views in the viewport: `k_a traced` and its error, accumulated by a worker thread
//! ([`kapaint_core::render::traced`]) while the camera, the maps and the settings stay as they
//! are, and started again when any of them changes. The UI thread only hands the worker what
//! it needs, takes the newest picture it published and paints it: no tracing on it.
//!
//! The worker traces on a pool of its own that leaves one core to the UI, at most
//! [`PIXELS`] pixels (the viewport scaled down, the picture stretched back), and stops at
//! [`SAMPLES`] samples per pixel.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use egui::{Color32, ColorImage, Pos2, Rect, TextureHandle};
use kapaint_core::render::FrameSettings;
use kapaint_core::render::reference::Material;
use kapaint_core::render::traced::{self, Traced};
use kapaint_mesh::bakes::{Baked, RayMesh};
use kapaint_mesh::{Mesh, pick::Bvh};
use kapaint_model::MaterialMaps;

/// The most pixels a traced picture has.
pub const PIXELS: u32 = 400_000;

/// Samples per pixel at which the worker stops.
pub const SAMPLES: u32 = 1024;

/// What a traced picture depends on: when any of it changes, the trace starts again.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    settings: FrameSettings,
    maps: (u64, u64),
    mesh: u64,
    size: (u32, u32),
    /// Which AO bake (its address), for the AO stand-in's view.
    ao: usize,
}

/// What the worker last published.
enum Published {
    /// A picture and how far it got.
    Frame {
        image: ColorImage,
        samples: u32,
        error: Option<f32>,
    },
    /// The trace does not fit: why.
    Refused(String),
}

/// One trace in progress: what it traces, its stop flag and its newest picture.
struct Job {
    key: Key,
    stop: Arc<AtomicBool>,
    latest: Arc<Mutex<Option<Published>>>,
}

impl Drop for Job {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// The shadow-ray and picking BVHs of a mesh, kept while the mesh stays.
type Rays = Arc<Mutex<Option<(u64, Arc<(Bvh, RayMesh)>)>>>;

/// The viewport's traced view (see the module's doc).
#[derive(Default)]
pub struct TracedView {
    job: Option<Job>,
    texture: Option<TextureHandle>,
    /// Samples and standard error of the picture shown.
    status: Option<(u32, Option<f32>)>,
    refused: Option<String>,
    rays: Rays,
}

impl std::fmt::Debug for TracedView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TracedView")
            .field("status", &self.status)
            .field("refused", &self.refused)
            .finish_non_exhaustive()
    }
}

/// The traced picture's size for a viewport of `size` pixels: the same aspect, at most
/// [`PIXELS`] pixels.
pub fn picture_size((w, h): (u32, u32)) -> (u32, u32) {
    let scale = (f64::from(PIXELS) / (f64::from(w) * f64::from(h)))
        .sqrt()
        .min(1.0);
    (
        ((f64::from(w) * scale) as u32).max(1),
        ((f64::from(h) * scale) as u32).max(1),
    )
}

impl TracedView {
    /// Stops the trace (another view is shown).
    pub fn stop(&mut self) {
        self.job = None;
        self.status = None;
        self.refused = None;
    }

    /// Samples per pixel and standard error of the picture shown, if one is.
    pub fn status(&self) -> Option<(u32, Option<f32>)> {
        self.status
    }

    /// Why the trace was refused, if it was.
    pub fn refused(&self) -> Option<&str> {
        self.refused.as_deref()
    }

    /// Whether the worker is still adding samples.
    pub fn running(&self) -> bool {
        self.job.is_some() && self.refused.is_none()
    }

    /// Keeps the trace of `settings` over `maps` on `mesh` at viewport `size` going: starts
    /// it (again) when any of them changed, and takes the worker's newest picture.
    pub fn update(
        &mut self,
        ctx: &egui::Context,
        (maps, maps_id): (&MaterialMaps, u64),
        (mesh, ao): (&(u64, Arc<Mesh>), Option<&Arc<Baked>>),
        settings: &FrameSettings,
        size: (u32, u32),
    ) {
        let ao = ao.filter(|_| settings.view.needs_ao_bake());
        let key = Key {
            settings: *settings,
            maps: (maps_id, maps.version()),
            mesh: mesh.0,
            size: picture_size(size),
            ao: ao.map_or(0, |a| Arc::as_ptr(a) as usize),
        };
        if settings.view.needs_ao_bake() && ao.is_none() {
            self.job = None;
            self.status = None;
            self.refused = Some(format!(
                "{} needs an AO bake (Mesh > Bake)",
                settings.view.label()
            ));
            return;
        }
        if self.job.as_ref().is_none_or(|j| j.key != key) {
            self.status = None;
            self.refused = None;
            let inputs = (maps.clone(), Arc::clone(&mesh.1), ao.cloned());
            self.job = Some(start(key, inputs, &self.rays));
        }
        let published = self.job.as_ref().and_then(|j| {
            j.latest
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take()
        });
        match published {
            Some(Published::Frame {
                image,
                samples,
                error,
            }) => {
                match &mut self.texture {
                    Some(t) => t.set(image, egui::TextureOptions::LINEAR),
                    None => {
                        self.texture =
                            Some(ctx.load_texture("traced", image, egui::TextureOptions::LINEAR));
                    }
                }
                self.status = Some((samples, error));
            }
            Some(Published::Refused(why)) => self.refused = Some(why),
            None => {}
        }
        if self.status.is_none_or(|(s, _)| s < SAMPLES) && self.refused.is_none() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// Paints the newest picture over `rect` (nothing before the first).
    pub fn paint(&self, painter: &egui::Painter, rect: Rect) {
        if let (Some(t), Some(_)) = (&self.texture, self.status) {
            painter.image(
                t.id(),
                rect,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
        }
    }
}

/// Starts a worker tracing `key`'s picture.
fn start(
    key: Key,
    (maps, mesh, ao): (MaterialMaps, Arc<Mesh>, Option<Arc<Baked>>),
    rays: &Rays,
) -> Job {
    let stop = Arc::new(AtomicBool::new(false));
    let latest = Arc::new(Mutex::new(None));
    let job = Job {
        key,
        stop: Arc::clone(&stop),
        latest: Arc::clone(&latest),
    };
    let rays = Arc::clone(rays);
    let publish = move |p: Published| {
        *latest.lock().unwrap_or_else(PoisonError::into_inner) = Some(p);
    };
    let spawned = std::thread::Builder::new()
        .name("traced view".into())
        .spawn(move || work(key, (&maps, &mesh, ao.as_deref()), &rays, &stop, &publish));
    if let Err(e) = spawned {
        // No thread: say so where the picture would be.
        *job.latest.lock().unwrap_or_else(PoisonError::into_inner) =
            Some(Published::Refused(format!("cannot start tracing: {e}")));
    }
    job
}

/// The worker: checks the memory, builds (or reuses) the BVHs, then adds passes of samples,
/// publishing a picture after each, until stopped or done.
fn work(
    key: Key,
    (maps, mesh, ao): (&MaterialMaps, &Mesh, Option<&Baked>),
    rays: &Rays,
    stop: &AtomicBool,
    publish: &(dyn Fn(Published) + Sync),
) {
    let (w, h) = key.size;
    let bytes = traced::ray_mesh_bytes(mesh.triangles.len())
        + u64::from(w) * u64::from(h) * traced::bytes_per_pixel();
    if let Err(e) = kapaint_base::memory::check_fits("tracing this mesh", bytes) {
        publish(Published::Refused(e));
        return;
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1));
    let Ok(pool) = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .thread_name(|i| format!("traced view {i}"))
        .build()
    else {
        publish(Published::Refused(
            "cannot start the tracing threads".into(),
        ));
        return;
    };
    pool.install(|| {
        let cached = rays
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .as_ref()
            .filter(|(id, _)| *id == key.mesh)
            .map(|(_, r)| Arc::clone(r));
        let built = cached.unwrap_or_else(|| {
            let built = Arc::new((Bvh::build(mesh), RayMesh::new(mesh)));
            *rays.lock().unwrap_or_else(PoisonError::into_inner) =
                Some((key.mesh, Arc::clone(&built)));
            built
        });
        let (bvh, ray_mesh) = &*built;
        if stop.load(Ordering::Relaxed) {
            return;
        }
        let s = &key.settings;
        let mut trace = Traced::new((mesh, bvh, ray_mesh), &Material::Maps(maps), s, w, h);
        if let Some(bake) = ao {
            trace.set_ao_bake(bake);
        }
        let mut per_pass = 1;
        while trace.samples() < SAMPLES {
            let started = std::time::Instant::now();
            if !trace.pass(ray_mesh, per_pass, &|| stop.load(Ordering::Relaxed)) {
                return;
            }
            // Passes of about a fifth of a second: often enough to watch, few enough to cost
            // little.
            if started.elapsed().as_secs_f32() < 0.1 {
                per_pass = (per_pass * 2).min(64);
            }
            let image = trace.image(s.view, s).unwrap_or_else(|| trace.ka());
            publish(Published::Frame {
                image: picture(&image, (w, h)),
                samples: trace.samples(),
                error: trace.standard_error(),
            });
        }
    });
}

/// Linear RGBA pixels as an sRGB picture (transparent where no surface).
fn picture(pixels: &[glam::Vec4], (w, h): (u32, u32)) -> ColorImage {
    let byte = kapaint_model::texel::linear_to_srgb8;
    let rgba: Vec<u8> = pixels
        .iter()
        .flat_map(|p| {
            [
                byte(p.x),
                byte(p.y),
                byte(p.z),
                (p.w.clamp(0.0, 1.0) * 255.0) as u8,
            ]
        })
        .collect();
    ColorImage::from_rgba_unmultiplied([w as usize, h as usize], &rgba)
}
