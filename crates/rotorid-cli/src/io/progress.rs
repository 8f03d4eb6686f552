//! A progress bar on stderr for long runs: shown only when stderr is a terminal and the run
//! has at least [`PROGRESS_MIN_STEPS`] steps, so pipes, logs and tests never see it.

use std::io::IsTerminal as _;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Runs shorter than this (in steps) get no progress bar.
pub const PROGRESS_MIN_STEPS: u64 = 500_000;

/// Steps between two updates of the bar (updates are cheap, but not free per sample).
pub const PROGRESS_STRIDE: u64 = 1 << 14;

/// A bar for `total` steps labelled `what`, hidden unless stderr is a terminal and
/// `total >= PROGRESS_MIN_STEPS`.
pub fn progress_bar(total: u64, what: &str) -> ProgressBar {
    if total < PROGRESS_MIN_STEPS || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{msg} [{bar:40}] {human_pos}/{human_len} samples, {elapsed} elapsed, eta {eta}",
    )
    .map(|s| s.progress_chars("=> "))
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_message(what.to_owned());
    pb
}
