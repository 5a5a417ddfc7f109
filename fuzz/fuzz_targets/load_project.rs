//! Fuzzes the `.kapaint` loader: any bytes must give either a valid document or an error,
//! never a panic, a hang or an invalid texel.
//!
//! Run with `cargo +nightly fuzz run load_project` from `fuzz/` (seed it with a few saved
//! projects in `fuzz/corpus/load_project/`).

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(doc) = kapaint::model::project::from_reader(std::io::Cursor::new(data)) {
        doc.maps.for_each_texel(|_, _, t| {
            let n = half::f16::from_bits(t.n).to_f32();
            assert!(n.is_finite() && (0.0..=kapaint::model::texel::N_MAX).contains(&n));
        });
    }
});
