//! Reports the CLI prints and draws: accuracy against the exact integral, run time against
//! error ([`bench`](mod@bench)) and the per-view figures ([`view`]), with their charts
//! (`plotters`). What they measure without charts lives in the core ([`accuracy`], and the
//! [`typical`] documents).

pub use kapaint_core::report::{accuracy, typical};

pub mod bench;
pub mod view;
