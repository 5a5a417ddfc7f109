//! Exporting compact texture sets: presets ([`preset`]), the choice of `n`'s
//! encoding by the `k_a` error it causes ([`encoding`]), and sets of images with a
//! `material.json` manifest written atomically and read back ([`set`]).

pub mod encoding;
pub mod ktx;
pub mod preset;
pub mod set;
pub mod snippet;
