//! Lines for people, apart from the JSON report: summaries on stdout as they happen (before
//! the report, which stays the last line), warnings and progress on stderr. `--quiet` keeps
//! only the report, warnings and errors.

use crate::error::for_terminal;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// Where a command's lines for people go.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Console {
    /// Print no summaries and no progress.
    pub quiet: bool,
}

impl Console {
    /// A console that prints only warnings (tests, library callers).
    pub const QUIET: Self = Self { quiet: true };

    /// Prints `text` on stdout now (flushed, so it shows before long work), unless quiet.
    pub fn line(&self, text: &str) {
        if self.quiet {
            return;
        }
        let mut out = std::io::stdout().lock();
        // A closed stdout is reported when the JSON report cannot be written.
        let _ = writeln!(out, "{}", for_terminal(text));
        let _ = out.flush();
    }

    /// Prints `warning: text` on stderr (also when quiet: a warning is about the result).
    pub fn warn(&self, text: &str) {
        let _ = writeln!(std::io::stderr().lock(), "warning: {}", for_terminal(text));
    }

    /// Progress over `total` steps named `unit` (e.g. `renders`): a bar with an estimate when
    /// stderr is a terminal, otherwise a line every [`Progress::LINE_EVERY`] once work has
    /// run that long; nothing when quiet.
    #[must_use]
    pub fn progress(&self, what: &str, unit: &'static str, total: usize) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!self.quiet && terminal).then(|| {
            let template = format!(
                "{what} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} (about {{eta}} left)"
            );
            let style = ProgressStyle::with_template(&template).map_or_else(
                |_| ProgressStyle::default_bar(),
                |s| s.progress_chars("=> "),
            );
            ProgressBar::new(total as u64).with_style(style)
        });
        let now = Instant::now();
        Progress {
            what: what.to_string(),
            unit,
            total,
            done: 0,
            start: now,
            last_line: now,
            bar,
            lines: !self.quiet && !terminal,
        }
    }
}

/// Progress of a long command (see [`Console::progress`]).
#[derive(Debug)]
pub struct Progress {
    what: String,
    unit: &'static str,
    total: usize,
    done: usize,
    start: Instant,
    last_line: Instant,
    bar: Option<ProgressBar>,
    lines: bool,
}

impl Progress {
    /// How often a line is printed when stderr is not a terminal.
    pub const LINE_EVERY: Duration = Duration::from_secs(10);

    /// One more step done.
    pub fn step(&mut self) {
        self.done += 1;
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
        if self.lines && self.done < self.total && self.last_line.elapsed() >= Self::LINE_EVERY {
            self.last_line = Instant::now();
            let line = self.status(self.start.elapsed());
            let _ = writeln!(std::io::stderr().lock(), "{line}");
        }
    }

    /// `check: 12/40 renders, 1m05s elapsed, about 2m32s left`, for `elapsed` so far.
    #[must_use]
    pub fn status(&self, elapsed: Duration) -> String {
        let left = if self.done == 0 {
            "time left unknown".to_string()
        } else {
            let per_step = elapsed.as_secs_f64() / self.done as f64;
            let rest = per_step * self.total.saturating_sub(self.done) as f64;
            format!("about {} left", clock(rest))
        };
        format!(
            "{}: {}/{} {}, {} elapsed, {left}",
            self.what,
            self.done,
            self.total,
            self.unit,
            clock(elapsed.as_secs_f64())
        )
    }

    /// Clears the bar.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}

/// `42s`, `3m07s`, `2h05m`.
fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m{:02}s", s / 60, s % 60),
        _ => format!("{}h{:02}m", s / 3600, (s % 3600) / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_estimates_the_time_left_from_the_steps_done() {
        let mut p = Console::QUIET.progress("check", "renders", 10);
        assert_eq!(
            p.status(Duration::from_secs(5)),
            "check: 0/10 renders, 5s elapsed, time left unknown"
        );
        for _ in 0..4 {
            p.step();
        }
        assert_eq!(
            p.status(Duration::from_secs(100)),
            "check: 4/10 renders, 1m40s elapsed, about 2m30s left"
        );
        assert_eq!(clock(7300.0), "2h01m");
        p.finish();
    }
}
