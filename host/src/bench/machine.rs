//! The machine line at the top of the report: CPU model, cores, compiler, profile, load.

use serde::Serialize;
use std::process::Command;

/// Where and how the benchmark ran.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Machine {
    /// CPU model (`model name` of /proc/cpuinfo), or `unknown`.
    pub cpu: String,
    /// Logical cores available to this process.
    pub cores: usize,
    /// The compiler that built this binary.
    pub rustc: String,
    /// `release` or `debug` (debug figures are not meaningful).
    pub profile: &'static str,
    /// 1-minute load average at the start (other processes competing for the cores).
    pub load_start: Option<f64>,
    /// 1-minute load average at the end.
    pub load_end: Option<f64>,
    /// UTC date of the run, `YYYY-MM-DD`.
    pub date: String,
    /// `git rev-parse --short HEAD` of the working directory, when available.
    pub commit: Option<String>,
}

impl Machine {
    /// Reads what the machine tells (best effort: missing pieces are `unknown` / `None`).
    #[must_use]
    pub fn probe() -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.trim().to_string())
            })
            .unwrap_or_else(|| "unknown CPU".into());
        let commit = Command::new("git")
            .args(["rev-parse", "--short", "HEAD"])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| s.trim().to_string());
        Self {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
            rustc: env!("HOST_RUSTC_VERSION").to_string(),
            profile: if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            },
            load_start: load_average(),
            load_end: None,
            date: utc_date(),
            commit,
        }
    }

    /// One line: `machine: CPU, N cores; rustc ...; release profile`.
    #[must_use]
    pub fn line(&self) -> String {
        format!(
            "machine: {}, {} cores; {}; {} profile",
            self.cpu, self.cores, self.rustc, self.profile
        )
    }
}

/// The 1-minute load average from /proc/loadavg.
#[must_use]
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Today's UTC date from the system clock (civil-from-days, Hinnant's algorithm).
fn utc_date() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}
