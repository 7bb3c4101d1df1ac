//! The machine line at the top of the report: CPU model, cores, compiler, profile, load, and
//! how much CPU other processes took during the run.

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
    /// The instruction set the kernel's 4-wide traversal runs in (`raykernel::cpu`):
    /// `baseline` or `avx2`.
    pub traversal: &'static str,
    /// 1-minute load average at the start (other processes competing for the cores).
    pub load_start: Option<f64>,
    /// 1-minute load average at the end.
    pub load_end: Option<f64>,
    /// Cores' worth of CPU time other processes used during the run (all busy time in
    /// /proc/stat minus this process's, over the wall time); `None` where /proc is missing.
    /// Unlike the load average it does not count tasks waiting on I/O.
    pub others_cores: Option<f64>,
    /// CPU counters at the start, for `others_cores`.
    #[serde(skip)]
    start: Option<CpuCounters>,
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
            traversal: raykernel::cpu::traversal_simd().name(),
            load_start: load_average(),
            load_end: None,
            others_cores: None,
            start: CpuCounters::read(),
            date: utc_date(),
            commit,
        }
    }

    /// Records the end of the run: load average and other processes' CPU use.
    pub fn finish(&mut self) {
        self.load_end = load_average();
        self.others_cores = self
            .start
            .zip(CpuCounters::read())
            .and_then(|(a, b)| b.others_since(&a));
    }

    /// One line: `machine: CPU, N cores; rustc ...; release profile; traversal in avx2`.
    #[must_use]
    pub fn line(&self) -> String {
        format!(
            "machine: {}, {} cores; {}; {} profile; traversal in {}",
            self.cpu, self.cores, self.rustc, self.profile, self.traversal
        )
    }
}

/// Busy time of every CPU and of this process, in clock ticks, and when they were read.
#[derive(Clone, Copy, Debug, PartialEq)]
struct CpuCounters {
    all_busy: u64,
    own: u64,
    at: std::time::Instant,
}

impl CpuCounters {
    /// `/proc/stat`'s first line (user, nice, system, irq, softirq, steal; not idle or iowait)
    /// and `/proc/self/stat`'s utime + stime (every thread of this process).
    fn read() -> Option<Self> {
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        let cpu: Vec<u64> = stat
            .lines()
            .next()?
            .split_whitespace()
            .skip(1)
            .filter_map(|x| x.parse().ok())
            .collect();
        let field = |i: usize| cpu.get(i).copied().unwrap_or(0);
        let all_busy = field(0) + field(1) + field(2) + field(5) + field(6) + field(7);
        let own_stat = std::fs::read_to_string("/proc/self/stat").ok()?;
        // Fields after the command name (which may hold spaces) start at `state`: utime and
        // stime are the 12th and 13th of those.
        let rest = own_stat.rsplit_once(')')?.1;
        let mut fields = rest.split_whitespace().skip(11);
        let utime: u64 = fields.next()?.parse().ok()?;
        let stime: u64 = fields.next()?.parse().ok()?;
        Some(Self {
            all_busy,
            own: utime + stime,
            at: std::time::Instant::now(),
        })
    }

    /// Cores' worth of CPU other processes used between `start` and `self`.
    fn others_since(&self, start: &Self) -> Option<f64> {
        // Both counters tick at USER_HZ, 100 per second on Linux.
        const TICKS_PER_S: f64 = 100.0;
        let wall = self.at.duration_since(start.at).as_secs_f64();
        let busy = self.all_busy.checked_sub(start.all_busy)? as f64;
        let own = self.own.checked_sub(start.own)? as f64;
        (wall > 0.0).then(|| ((busy - own) / TICKS_PER_S / wall).max(0.0))
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
