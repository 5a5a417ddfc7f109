//! Reports the CLI prints: accuracy against the exact integral, and run time against error.

pub mod accuracy;
pub mod bench;
pub mod typical;
pub mod view;
