//! Long command-line work on a terminal: a progress bar with the stage, the units done and an
//! estimate of the time left (indicatif), on stderr, drawn from the task's [`Progress`] while
//! the work runs on this thread. Where stderr is not a terminal (a script, a pipe, CI) nothing
//! is drawn and nothing is added to what the command prints.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::task::Progress;

/// How often the bar reads the task's progress.
const TICK: Duration = Duration::from_millis(100);

/// Runs `work` (which reports to `progress`) while a bar named `what` shows it on stderr,
/// when stderr is a terminal; the bar is cleared when the work ends.
pub fn with_bar<R>(what: &str, progress: &Progress, work: impl FnOnce() -> R) -> R {
    if !std::io::stderr().is_terminal() {
        return work();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{prefix} {msg:<10} [{bar:30}] {human_pos}/{human_len} ({percent} %, {eta} left)",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("#>-");
    bar.set_style(style);
    bar.set_prefix(what.to_owned());
    let finished = AtomicBool::new(false);
    std::thread::scope(|scope| {
        scope.spawn(|| {
            let mut stage = String::new();
            while !finished.load(Ordering::Relaxed) {
                let now = progress.stage();
                if now != stage {
                    // A new stage counts anew: its estimate starts over.
                    bar.reset();
                    bar.set_message(now.clone());
                    stage = now;
                }
                bar.set_length(progress.total().max(1));
                bar.set_position(progress.done());
                std::thread::sleep(TICK);
            }
            bar.finish_and_clear();
        });
        let out = work();
        finished.store(true, Ordering::Relaxed);
        out
    })
}
