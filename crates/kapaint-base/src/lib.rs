//! What every kapaint room stands on, below the reflectance maths, the meshes and the model:
//! atomic file writes that never leave half a file ([`atomic`]), the checks every input file
//! passes before it is read ([`file_check`]), memory checks before a large allocation
//! ([`memory`]), progress and cancel for long work ([`task`]), and hot loops compiled for the
//! CPU at hand ([`simd`]).

pub mod atomic;
pub mod file_check;
pub mod memory;
pub mod simd;
pub mod task;
