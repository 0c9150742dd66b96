//! Progress on stderr for the long commands (`generate`, `count`, `accuracy`, `table1`): drawn
//! only on a terminal, and only once the work has taken longer than a second.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::Duration;

/// A progress bar or spinner that appears after one second (see the module doc); with
/// `interactive` false (tests, in-process runs) it is never drawn.
pub struct Progress {
    pb: ProgressBar,
}

impl Progress {
    fn new(interactive: bool, pb: ProgressBar) -> Self {
        pb.set_draw_target(ProgressDrawTarget::hidden());
        if interactive {
            let late = pb.clone();
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_secs(1));
                if !late.is_finished() {
                    late.set_draw_target(ProgressDrawTarget::stderr());
                    late.enable_steady_tick(Duration::from_millis(200));
                }
            });
        }
        Progress { pb }
    }

    /// A spinner with elapsed time, for work whose length is not known in advance.
    #[must_use]
    pub fn spinner(interactive: bool, message: &str) -> Self {
        let pb = ProgressBar::new_spinner();
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
            pb.set_style(style);
        }
        pb.set_message(message.to_string());
        Progress::new(interactive, pb)
    }

    /// A bar of steps (set with [`Progress::set`]).
    #[must_use]
    pub fn bar(interactive: bool, message: &str) -> Self {
        let pb = ProgressBar::new(1);
        if let Ok(style) =
            ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed}, eta {eta})")
        {
            pb.set_style(style);
        }
        pb.set_message(message.to_string());
        Progress::new(interactive, pb)
    }

    /// `done` of `total` steps finished.
    pub fn set(&self, done: usize, total: usize) {
        self.pb.set_length(total as u64);
        self.pb.set_position(done as u64);
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.pb.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.pb.finish_and_clear();
    }
}
