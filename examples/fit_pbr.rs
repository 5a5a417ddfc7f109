//! Regenerates `crates/kapaint-pbr/src/table.rs` (the fitted exponent per roughness for
//! each target model and the conversion-error tables) and `table_height.rs` beside it (the
//! height mapping's fit) and `table_height_error.bin` (its error numerator), see
//! `kapaint::pbr::fit`, printing each row's fit to stderr.
//!
//! Usage: `cargo run --release --example fit_pbr -- crates/kapaint-pbr/src`
//! (`fit_pbr LEVEL` checks a box rule's level against the exact integrals instead).

use kapaint::pbr::fit::{
    LEVEL, LobeSamples, ct_n, fit_curve, height_error_bytes, render_height_rust, render_rust,
    table_roughness,
};

fn main() {
    let Some(arg) = std::env::args().nth(1) else {
        eprintln!("usage: fit_pbr DIR (where table.rs goes) | fit_pbr LEVEL");
        std::process::exit(2);
    };
    if let Ok(level) = arg.parse::<u32>() {
        check(level);
        return;
    }
    let dir = std::path::PathBuf::from(arg);
    let started = std::time::Instant::now();
    eprintln!(
        "roughness  n (Phong, Blinn-Phong, Cook-Torrance)  lobe distance / mean (fitted; unconstrained)  \
         height fit: n, height, distance (Phong; Blinn-Phong)"
    );
    let rows = fit_curve(&table_roughness(), LEVEL, |row| {
        eprintln!(
            "{:.4}  {:9.3} {:9.3} {:9.3}  {:.3} {:.3} {:.3}; {:.3} {:.3}  {:.4} {:.4} {:.3}; {:.4} {:.4} {:.3}",
            row.roughness,
            row.n[0],
            row.n[1],
            row.n[2],
            row.distance[0],
            row.distance[1],
            row.distance[2],
            row.free_distance[0],
            row.free_distance[1],
            row.height_fit[0].0,
            row.height_fit[0].1,
            row.height_distance[0],
            row.height_fit[1].0,
            row.height_fit[1].1,
            row.height_distance[1],
        );
    });
    eprintln!(
        "{} rows in {:.0} s",
        rows.len(),
        started.elapsed().as_secs_f64()
    );
    for (name, bytes) in [
        ("table.rs", render_rust(&rows, LEVEL).into_bytes()),
        (
            "table_height.rs",
            render_height_rust(&rows, LEVEL).into_bytes(),
        ),
        ("table_height_error.bin", height_error_bytes(&rows)),
    ] {
        if let Err(e) = kapaint::atomic::write_atomic(&dir.join(name), &bytes) {
            eprintln!("fit_pbr: {}: {e}", dir.join(name).display());
            std::process::exit(1);
        }
    }
}

/// The box rule of `level` against the exact integrals: GGX's mean and Phong's `chi`.
fn check(level: u32) {
    use kapaint::reflectance::{ShadingModel, cook_torrance, exact};
    for r in [1.0, 0.5, 0.25, 0.125, 1.0 / 32.0] {
        let t = std::time::Instant::now();
        let s = LobeSamples::new(r, level);
        let m = s.ggx_means();
        let ex = cook_torrance::chi_exact(ct_n(r).min(cook_torrance::EXACT_N_MAX));
        let np = 2.0 / (r * r * r * r);
        let phong = s.target_mean(ShadingModel::Phong, np)
            / exact::chi_exact(ShadingModel::Phong, np)
            - 1.0;
        eprintln!(
            "r {r:.4}: {} nodes, {:.2} s; GGX means {:+.1e} {:+.1e}; Phong chi({np:.0}) {phong:+.1e}",
            s.len(),
            t.elapsed().as_secs_f64(),
            m[0] / ex[0] - 1.0,
            m[1] / ex[1] - 1.0,
        );
    }
}
