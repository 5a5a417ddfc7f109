//! Prints the exact Cook-Torrance `chi_1(n)`, `chi_0(n)` at a few `n`, at the default
//! tanh-sinh level and two levels up, with the time each took: the convergence study of
//! `reflectance::cook_torrance`.
//!
//! Usage: `cargo run --release --example ct_chi`

use kapaint::reflectance::cook_torrance::{DEFAULT_LEVEL, chi_exact_at_level};

fn main() {
    println!("n,chi1,chi0,chi1_fine,chi0_fine,rel_change_max,ms,ms_fine");
    for n in [0.0, 1.0, 3.0, 10.0, 100.0, 1000.0, 16384.0, 1.0e6] {
        let t = std::time::Instant::now();
        let [c1, c0] = chi_exact_at_level(n, DEFAULT_LEVEL);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let t = std::time::Instant::now();
        let [f1, f0] = chi_exact_at_level(n, DEFAULT_LEVEL + 2);
        let ms_fine = t.elapsed().as_secs_f64() * 1e3;
        let change = ((c1 - f1) / f1).abs().max(((c0 - f0) / f0).abs());
        println!("{n},{c1:.17e},{c0:.17e},{f1:.17e},{f0:.17e},{change:.2e},{ms:.0},{ms_fine:.0}");
    }
}
