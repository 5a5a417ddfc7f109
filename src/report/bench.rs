//! Run time against error: the `kapaint bench` report.
//!
//! For every model and approximation, derives a full `size x size` k_a map on one thread and
//! on all threads, and compares both with a plain copy of the derive's input bytes measured in
//! the same run (the memory-bandwidth limit of the machine). Cook-Torrance has kapaint's fit
//! and Karis' published environment-BRDF fit (see [`karis`]), each measured against the exact
//! `chi_1` and `chi_0` (its error is the larger of the two).

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use std::fmt::Write as _;

use rayon::prelude::*;

use super::accuracy::{CtSamples, ExactSamples, Grid, error_stats};
use crate::reflectance::cook_torrance::karis;
use crate::reflectance::{
    AmbientApprox, DERIVE_CHUNK_TEXELS, ShadingModel, TWO_OVER_PI, derive_ka, derive_ka_par,
    derive_with,
};

/// One row of the bench table.
#[derive(Clone, Debug)]
pub struct BenchRow {
    /// The lobe.
    pub model: ShadingModel,
    /// The method timed: an approximation's name, or `karis`.
    pub method: &'static str,
    /// Nanoseconds per texel, one thread.
    pub ns_per_texel_1t: f64,
    /// Nanoseconds per texel, all threads.
    pub ns_per_texel_mt: f64,
    /// Maximum relative error of `chi` on `n in [0, 16384]`.
    pub max_rel_error: f64,
    /// Derive time over copy time, one thread.
    pub copy_ratio_1t: f64,
    /// Derive time over copy time, all threads.
    pub copy_ratio_mt: f64,
}

/// The input maps of a derive: `k_d`, `k_s`, `n` with realistic spreads.
pub struct BenchMaps {
    /// Diffuse coefficients.
    pub kd: Vec<Vec3>,
    /// Specular coefficients.
    pub ks: Vec<Vec3>,
    /// Exponents, spread log-uniformly over `[0, 16384]`.
    pub n: Vec<f32>,
}

impl BenchMaps {
    /// Deterministic pseudo-random maps of `texels` texels.
    pub fn new(texels: usize) -> Self {
        let hash = |i: usize, salt: u64| -> f32 {
            let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ salt;
            z = (z ^ (z >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z ^= z >> 29;
            (z >> 40) as f32 / (1u64 << 24) as f32
        };
        let kd = (0..texels)
            .into_par_iter()
            .map(|i| Vec3::new(hash(i, 1), hash(i, 2), hash(i, 3)))
            .collect();
        let ks = (0..texels)
            .into_par_iter()
            .map(|i| Vec3::splat(hash(i, 4)))
            .collect();
        let n = (0..texels)
            .into_par_iter()
            .map(|i| (hash(i, 5) * 16385.0_f32.ln()).exp() - 1.0)
            .collect();
        Self { kd, ks, n }
    }

    /// Bytes the derive reads per texel.
    pub const BYTES_PER_TEXEL_READ: usize = 2 * 12 + 4;
}

/// Best of `repeats` wall-clock timings of `f`, in seconds.
pub fn best_of(repeats: usize, mut f: impl FnMut()) -> f64 {
    (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Times one thread and all threads copying `bytes` bytes: `(one, all)` in seconds.
pub fn copy_baseline(bytes: usize, repeats: usize) -> (f64, f64) {
    let src = vec![1u8; bytes];
    let mut dst = vec![0u8; bytes];
    let one = best_of(repeats, || dst.copy_from_slice(std::hint::black_box(&src)));
    let chunk = (bytes / (4 * rayon::current_num_threads())).max(1 << 20);
    let all = best_of(repeats, || {
        dst.par_chunks_mut(chunk)
            .zip(src.par_chunks(chunk))
            .for_each(|(d, s)| d.copy_from_slice(s));
    });
    std::hint::black_box(&dst);
    (one, all)
}

/// Bytes the bench allocates per texel: the three input maps, the output and the two buffers
/// of the copy baseline.
pub const BYTES_PER_TEXEL: u64 =
    BenchMaps::BYTES_PER_TEXEL_READ as u64 + 12 + 2 * BenchMaps::BYTES_PER_TEXEL_READ as u64;

/// Bytes [`run`] allocates on `size x size` maps.
pub fn bytes_needed(size: usize) -> u64 {
    (size as u64).pow(2) * BYTES_PER_TEXEL
}

/// Runs the whole bench on `size x size` maps, for `models` (the copy baseline always).
pub fn run(
    size: usize,
    repeats: usize,
    error_points: usize,
    models: &[ShadingModel],
) -> Vec<BenchRow> {
    let texels = size * size;
    let maps = BenchMaps::new(texels);
    let mut out = vec![Vec3::ZERO; texels];
    let (copy_1t, copy_mt) = copy_baseline(texels * BenchMaps::BYTES_PER_TEXEL_READ, repeats);
    let grid = Grid::log_spaced(0.0, 16384.0, error_points);
    let mut rows = Vec::new();
    let mut row = |model, method, max_rel_error, (one, all): (f64, f64)| {
        rows.push(BenchRow {
            model,
            method,
            ns_per_texel_1t: one * 1e9 / texels as f64,
            ns_per_texel_mt: all * 1e9 / texels as f64,
            max_rel_error,
            copy_ratio_1t: one / copy_1t,
            copy_ratio_mt: all / copy_mt,
        });
    };
    let mut time = |derive: &dyn Fn(&mut [Vec3]), derive_par: &dyn Fn(&mut [Vec3])| {
        let times = (
            best_of(repeats, || derive(&mut out)),
            best_of(repeats, || derive_par(&mut out)),
        );
        std::hint::black_box(&out);
        times
    };
    for model in ShadingModel::PAPER
        .into_iter()
        .filter(|m| models.contains(m))
    {
        let exact = ExactSamples::compute(model, &grid);
        for approx in AmbientApprox::ALL {
            let times = time(
                &|out| derive_ka(model, approx, &maps.kd, &maps.ks, &maps.n, out),
                &|out| derive_ka_par(model, approx, &maps.kd, &maps.ks, &maps.n, out),
            );
            row(
                model,
                approx.name(),
                error_stats(approx, &exact).max_rel,
                times,
            );
        }
    }
    let ct = ShadingModel::CookTorrance;
    if models.contains(&ct) {
        let exact = CtSamples::compute(&grid);
        let fast = time(
            &|out| derive_ka(ct, AmbientApprox::Fast, &maps.kd, &maps.ks, &maps.n, out),
            &|out| derive_ka_par(ct, AmbientApprox::Fast, &maps.kd, &maps.ks, &maps.n, out),
        );
        let karis_derive = |out: &mut [Vec3], start: usize| {
            let range = start..start + out.len();
            derive_with::<true>(
                &maps.kd[range.clone()],
                &maps.ks[range.clone()],
                &maps.n[range],
                out,
                TWO_OVER_PI as f32,
                karis::chi_karis_f32,
            );
        };
        let karis_times = time(&|out| karis_derive(out, 0), &|out| {
            out.par_chunks_mut(DERIVE_CHUNK_TEXELS)
                .enumerate()
                .for_each(|(i, chunk)| karis_derive(chunk, i * DERIVE_CHUNK_TEXELS));
        });
        row(
            ct,
            AmbientApprox::Fast.name(),
            exact.max_rel(|n| {
                crate::reflectance::chi_parts_f32(ct, AmbientApprox::Fast, n as f32).map(f64::from)
            }),
            fast,
        );
        row(
            ct,
            "karis",
            exact.max_rel(|n| karis::chi_karis_f32(n as f32).map(f64::from)),
            karis_times,
        );
    }
    rows
}

/// The table as markdown.
pub fn markdown(rows: &[BenchRow], size: usize) -> String {
    let mut out = format!(
        "k_a derive of a {size}x{size} map, {} threads\n\n\
         | model | method | ns/texel (1 thread) | ns/texel (all threads) | max rel error | \
         derive/copy (1 thread) | derive/copy (all threads) |\n|---|---|---|---|---|---|---|\n",
        rayon::current_num_threads()
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} | {:.2} | {:.2e} | {:.2} | {:.2} |",
            r.model.name(),
            r.method,
            r.ns_per_texel_1t,
            r.ns_per_texel_mt,
            r.max_rel_error,
            r.copy_ratio_1t,
            r.copy_ratio_mt
        );
    }
    out
}

/// The table as CSV, one row per model and method.
pub fn csv(rows: &[BenchRow]) -> String {
    let mut out = String::from(
        "model,method,ns_per_texel_1t,ns_per_texel_mt,max_rel_error,copy_ratio_1t,copy_ratio_mt\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{}",
            r.model.name(),
            r.method,
            r.ns_per_texel_1t,
            r.ns_per_texel_mt,
            r.max_rel_error,
            r.copy_ratio_1t,
            r.copy_ratio_mt
        );
    }
    out
}

/// Plot size in pixels.
const PLOT_SIZE: (u32, u32) = (960, 640);

/// Draws the error-vs-time plot (log-log; filled markers one thread, rings all threads) and
/// writes it as a PNG.
pub fn plot(rows: &[BenchRow], path: &Path) -> Result<(), String> {
    let (w, h) = PLOT_SIZE;
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    draw_plot(rows, &mut rgb).map_err(|e| format!("cannot draw the plot: {e}"))?;
    write_png(rgb, PLOT_SIZE, path)
}

/// Writes a plot's RGB buffer of `(w, h)` pixels as a PNG at `path`, atomically.
pub(crate) fn write_png(rgb: Vec<u8>, (w, h): (u32, u32), path: &Path) -> Result<(), String> {
    let image = image::RgbImage::from_raw(w, h, rgb).ok_or("plot buffer has the wrong size")?;
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| format!("cannot encode {}: {e}", path.display()))?;
    crate::atomic::write_atomic(path, &png)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn draw_plot(rows: &[BenchRow], rgb: &mut [u8]) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    register_font()?;
    let root = BitMapBackend::with_buffer(rgb, PLOT_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    // Log-log through log10 coordinates on linear axes: plotters then picks useful ticks.
    let times = rows
        .iter()
        .flat_map(|r| [r.ns_per_texel_1t, r.ns_per_texel_mt]);
    let errors = rows.iter().map(|r| r.max_rel_error.max(1e-9));
    let (x_lo, x_hi) = times.fold((f64::INFINITY, 0.0_f64), |(a, b), x| (a.min(x), b.max(x)));
    let (y_lo, y_hi) = errors.fold((f64::INFINITY, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "k_a derive: max error of chi on [0, 16384] vs time",
            (FONT, 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            x_lo.log10() - 0.1..x_hi.log10() + 0.1,
            y_lo.log10().floor() - 0.5..y_hi.log10().ceil() + 0.5,
        )?;
    chart
        .configure_mesh()
        .x_desc("ns per texel, log scale (filled: 1 thread, ring: all threads)")
        .y_desc("max relative error, log scale")
        .x_label_formatter(&|x| format!("{:.1}", 10f64.powf(*x)))
        .y_label_formatter(&|y| format!("{:.0e}", 10f64.powf(*y)))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()?;
    for (i, r) in rows.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let error = r.max_rel_error.max(1e-9).log10();
        // Phong's two paper rows coincide; vary the marker size so both show.
        let size = 7 + (i % 3) as i32;
        chart
            .draw_series([
                Circle::new((r.ns_per_texel_1t.log10(), error), size, colour.filled()),
                Circle::new(
                    (r.ns_per_texel_mt.log10(), error),
                    size,
                    colour.stroke_width(2),
                ),
            ])?
            .label(format!("{} {}", r.model.name(), r.method))
            .legend(move |(x, y)| Circle::new((x, y), 6, colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::MiddleRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((FONT, 14))
        .draw()?;
    root.present()?;
    Ok(())
}

/// The font family name the plot registers.
pub(crate) const FONT: &str = "kapaint-mono";

/// Registers egui's bundled monospace font with plotters (no system fonts needed; plotters
/// lays proportional fonts out with collapsed spaces, a monospace font reads cleanly).
pub(crate) fn register_font() -> Result<(), String> {
    use std::sync::OnceLock;
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(
                FONT,
                plotters::style::FontStyle::Normal,
                epaint_default_fonts::HACK_REGULAR,
            )
            .map_err(|_| "the bundled plot font is unreadable".to_string())
        })
        .clone()
}
