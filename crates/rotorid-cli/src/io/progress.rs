//! Progress of long runs on stderr, so that a run of minutes is never silent:
//!
//! - stderr a terminal: a bar, drawn once the run has taken [`FIRST_REPORT_AFTER`];
//! - otherwise (a log file, a pipe, CI): a line such as
//!   `simulate (exact): 40% (4000 of 10000 samples), 12 s elapsed` once the run has taken
//!   [`FIRST_REPORT_AFTER`], then at each further tenth of the run and at least every
//!   [`LINE_INTERVAL`].
//!
//! Short runs print nothing, whatever their length in steps: what matters to the person
//! waiting is time (a 1e8 rad/s^2 ramp needs minutes for a few thousand samples).

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Nothing is shown before a run has taken this long (unless [`FIRST_REPORT_ENV`] says
/// otherwise).
pub const FIRST_REPORT_AFTER: Duration = Duration::from_secs(2);

/// Environment variable that replaces [`FIRST_REPORT_AFTER`]: a finite, non-negative
/// number of seconds (0: report from the first look at the clock). Any other value is
/// refused with a warning and the default kept.
pub const FIRST_REPORT_ENV: &str = "ROTORID_PROGRESS_AFTER_S";

/// [`FIRST_REPORT_AFTER`], or what [`FIRST_REPORT_ENV`] sets.
fn first_report_after() -> Duration {
    let Some(v) = std::env::var_os(FIRST_REPORT_ENV) else {
        return FIRST_REPORT_AFTER;
    };
    match v.to_str().and_then(|s| s.trim().parse::<f64>().ok()) {
        Some(s) if s.is_finite() && s >= 0.0 => Duration::from_secs_f64(s),
        _ => {
            eprintln!(
                "warning: {FIRST_REPORT_ENV}={v:?} is not a number of seconds >= 0; progress \
                 is shown after the default {} s",
                FIRST_REPORT_AFTER.as_secs()
            );
            FIRST_REPORT_AFTER
        }
    }
}

/// Without a terminal, at most this long between two lines.
pub const LINE_INTERVAL: Duration = Duration::from_secs(10);

/// Steps between two looks at the clock (a step of the fastest integrator takes tens of
/// nanoseconds, a clock read about as long).
const CHECK_STRIDE: u64 = 64;

enum Shown {
    /// Not yet decided (before [`FIRST_REPORT_AFTER`]).
    Nothing,
    Bar(ProgressBar),
    Lines {
        last: Instant,
        tenth: u64,
    },
}

/// What a run's steps count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Samples simulated or processed.
    Samples,
    /// Bytes of an input file read (shown in MB / MiB).
    Bytes,
    /// Steps of a run made of a few long ones (`paper`'s simulations and figures).
    Steps,
}

/// The progress of one run of `total` steps (module doc).
pub struct Progress {
    what: String,
    total: u64,
    unit: Unit,
    terminal: bool,
    first_after: Duration,
    start: Instant,
    next_check: u64,
    /// Steps between two looks at the clock ([`CHECK_STRIDE`] for samples, else 1).
    stride: u64,
    shown: Shown,
}

impl Progress {
    /// Progress of `total` samples labelled `what` (e.g. `simulate (exact)`).
    pub fn new(total: u64, what: &str) -> Self {
        Self::counting(total, what, Unit::Samples)
    }

    /// Progress of `total` steps of `unit` labelled `what` (e.g. `identify`).
    pub fn counting(total: u64, what: &str, unit: Unit) -> Self {
        let mut p = Self::with_terminal(total, what, std::io::stderr().is_terminal());
        p.first_after = first_report_after();
        p.unit = unit;
        if unit != Unit::Samples {
            // each update stands for much work: look at the clock every time
            p.next_check = 1;
            p.stride = 1;
        }
        p
    }

    fn with_terminal(total: u64, what: &str, terminal: bool) -> Self {
        Self {
            what: what.to_owned(),
            total: total.max(1),
            unit: Unit::Samples,
            terminal,
            first_after: FIRST_REPORT_AFTER,
            start: Instant::now(),
            next_check: CHECK_STRIDE,
            stride: CHECK_STRIDE,
            shown: Shown::Nothing,
        }
    }

    /// `done` steps are done. Cheap: looks at the clock every [`CHECK_STRIDE`] steps.
    pub fn update(&mut self, done: u64) {
        if done < self.next_check {
            return;
        }
        self.next_check = done + self.stride;
        if let Some(line) = self.report(done, Instant::now()) {
            eprintln!("{line}");
        }
    }

    /// The line to print now, if any (without a terminal), else drive the bar.
    fn report(&mut self, done: u64, now: Instant) -> Option<String> {
        let elapsed = now.saturating_duration_since(self.start);
        let tenth = done.min(self.total) * 10 / self.total;
        match &mut self.shown {
            Shown::Nothing if elapsed < self.first_after => None,
            Shown::Nothing if self.terminal => {
                self.shown = Shown::Bar(bar(self.total, &self.what, self.unit, done));
                None
            }
            Shown::Nothing => {
                self.shown = Shown::Lines { last: now, tenth };
                Some(self.line(done, elapsed))
            }
            Shown::Bar(pb) => {
                pb.set_position(done);
                None
            }
            Shown::Lines { last, tenth: shown } => {
                if tenth > *shown || now.saturating_duration_since(*last) >= LINE_INTERVAL {
                    (*last, *shown) = (now, tenth);
                    Some(self.line(done, elapsed))
                } else {
                    None
                }
            }
        }
    }

    fn line(&self, done: u64, elapsed: Duration) -> String {
        let of = match self.unit {
            Unit::Samples => format!("{done} of {} samples", self.total),
            Unit::Bytes => format!(
                "{:.1} of {:.1} MB read",
                done.min(self.total) as f64 / 1e6,
                self.total as f64 / 1e6
            ),
            Unit::Steps => format!("{done} of {} steps", self.total),
        };
        format!(
            "{}: {}% ({of}), {} s elapsed",
            self.what,
            done.min(self.total) * 100 / self.total,
            elapsed.as_secs()
        )
    }

    /// The run is over: clear the bar (lines stay).
    pub fn finish(self) {
        if let Shown::Bar(pb) = self.shown {
            pb.finish_and_clear();
        }
    }
}

fn bar(total: u64, what: &str, unit: Unit, done: u64) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(match unit {
        Unit::Samples => {
            "{msg} [{bar:40}] {human_pos}/{human_len} samples, {elapsed} elapsed, eta {eta}"
        }
        Unit::Bytes => "{msg} [{bar:40}] {bytes}/{total_bytes} read, {elapsed} elapsed, eta {eta}",
        Unit::Steps => "{msg} [{bar:40}] {pos}/{len} steps, {elapsed} elapsed, eta {eta}",
    })
    .map(|s| s.progress_chars("=> "))
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_message(what.to_owned());
    pb.set_position(done);
    pb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_after_a_while_then_per_tenth_or_interval() {
        let mut p = Progress::with_terminal(1000, "simulate (exact)", false);
        let t0 = p.start;
        let at = |s: u64| t0 + Duration::from_millis(s);
        assert_eq!(p.report(100, at(1000)), None, "too early");
        assert_eq!(
            p.report(250, at(2500)).as_deref(),
            Some("simulate (exact): 25% (250 of 1000 samples), 2 s elapsed")
        );
        assert_eq!(p.report(290, at(3000)), None, "same tenth");
        assert!(p.report(300, at(3100)).unwrap().contains("30%"));
        assert_eq!(p.report(301, at(4000)), None);
        assert!(p.report(302, at(13_200)).unwrap().contains("13 s elapsed"));
        assert!(p.report(1000, at(13_300)).unwrap().contains("100%"));
    }

    #[test]
    fn bytes_read_are_shown_in_megabytes() {
        let mut p = Progress::with_terminal(45_800_000, "identify", false);
        p.unit = Unit::Bytes;
        let later = p.start + Duration::from_secs(3);
        assert_eq!(
            p.report(18_320_000, later).as_deref(),
            Some("identify: 40% (18.3 of 45.8 MB read), 3 s elapsed")
        );
    }

    #[test]
    fn steps_are_counted_and_each_update_looks_at_the_clock() {
        let p = Progress::counting(27, "paper", Unit::Steps);
        assert_eq!((p.stride, p.next_check), (1, 1));
        let mut p = Progress::with_terminal(27, "paper", false);
        p.unit = Unit::Steps;
        let later = p.start + Duration::from_secs(3);
        assert_eq!(
            p.report(27, later).as_deref(),
            Some("paper: 100% (27 of 27 steps), 3 s elapsed")
        );
    }

    #[test]
    fn quick_runs_and_terminals_print_no_lines() {
        let mut p = Progress::with_terminal(10, "x", false);
        assert_eq!(p.report(10, p.start), None);
        let mut p = Progress::with_terminal(10, "x", true);
        let later = p.start + Duration::from_secs(5);
        assert_eq!(p.report(5, later), None);
        assert!(matches!(p.shown, Shown::Bar(_)));
        p.finish();
    }
}
