//! What the reports measure, without their charts: accuracy against the exact integral
//! ([`accuracy`]), and the typical documents the benches and tests paint ([`typical`]). The
//! reports the CLI prints and draws (run time against error, the per-view figures) are the
//! root package's (`kapaint::report`), beside the command line, with `plotters`.

pub mod accuracy;
pub mod typical;
