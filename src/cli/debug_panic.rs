//! `kapaint debug-panic` (hidden): a deliberate panic, to check what a crash looks like.

/// Panics on purpose, to check what a crash looks like (one line, a report file, exit code
/// 70).
#[derive(Debug, clap::Args)]
pub struct DebugPanicArgs {
    /// Panic in every worker thread at once instead of the main thread.
    #[arg(long)]
    workers: bool,
}

impl DebugPanicArgs {
    /// Panics.
    pub fn run(self) -> ! {
        if self.workers {
            use rayon::prelude::*;
            (0..64_u32).into_par_iter().for_each(|i| {
                std::thread::sleep(std::time::Duration::from_millis(5));
                panic!("deliberate panic in worker task {i}");
            });
        }
        panic!("deliberate panic on the main thread");
    }
}
