//! Regenerates `crates/kapaint-reflectance/src/model/cook_torrance/fast_coeffs.rs` from the exact integrator, after
//! exploring which polynomial degree per octave is needed (printed to stderr).
//!
//! Usage: `cargo run --release --example fit_ct [DEGREE] > crates/kapaint-reflectance/src/model/cook_torrance/fast_coeffs.rs`
//! (with no DEGREE, the smallest degree whose worst error on `n in [0, 16384]` is <= 5e-6, a
//! quarter of the contract of 2e-5, is chosen). Exact values are cached by `x`, so the
//! reference's nodes (degree 10) are reused by degrees 2 and 5.

use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

use kapaint::reflectance::cook_torrance::chi_exact;
use kapaint::reflectance::cook_torrance::fit::{CtFit, fit_ct_with, render_rust_ct};

const TARGET: f64 = 5e-6;
const REFERENCE_DEGREE: usize = 10;

fn max_error(fit: &CtFit, reference: &CtFit, n_max: f64) -> [(f64, f64); 2] {
    let mut worst = [(0.0, 0.0); 2];
    for i in 0..=40_000 {
        let n = n_max * (f64::from(i) / 40_000.0).powi(3);
        let (got, want) = (fit.chi(n), reference.chi(n));
        for k in 0..2 {
            let e = (got[k] / want[k] - 1.0).abs();
            if e > worst[k].0 {
                worst[k] = (e, n);
            }
        }
    }
    worst
}

fn main() {
    let cache: Mutex<HashMap<u64, [f64; 2]>> = Mutex::new(HashMap::new());
    let exact = |x: f64| -> [f64; 2] {
        if let Some(v) = cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&x.to_bits())
        {
            return *v;
        }
        let v = chi_exact(x - 1.0);
        cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .insert(x.to_bits(), v);
        v
    };
    let started = std::time::Instant::now();
    let forced: Option<usize> = std::env::args().nth(1).and_then(|a| a.parse().ok());
    let mut chosen = forced.unwrap_or(0);
    if forced.is_none() {
        let reference = fit_ct_with(REFERENCE_DEGREE, exact);
        eprintln!(
            "reference (degree {REFERENCE_DEGREE}) in {:.0} s",
            started.elapsed().as_secs_f64()
        );
        eprintln!("degree  max rel error (chi1, chi0) on n in [0, 16384]; on [0, 1e6]");
        for degree in 2..=8 {
            let candidate = fit_ct_with(degree, |x| reference.chi(x - 1.0));
            let [w1, w0] = max_error(&candidate, &reference, 16384.0);
            let [v1, v0] = max_error(&candidate, &reference, 1.0e6);
            eprintln!(
                "{degree:>6}  {:.2e} (n={:.1}), {:.2e} (n={:.1}); {:.2e}, {:.2e}",
                w1.0, w1.1, w0.0, w0.1, v1.0, v0.0
            );
            if chosen == 0 && w1.0.max(w0.0) <= TARGET {
                chosen = degree;
            }
        }
        if chosen == 0 {
            chosen = 8;
        }
        eprintln!("chosen degree: {chosen}");
    }
    let fit = fit_ct_with(chosen, exact);
    eprintln!("done in {:.0} s", started.elapsed().as_secs_f64());
    print!("{}", render_rust_ct(&fit));
}
