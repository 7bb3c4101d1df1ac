//! `cargo xtask determinism`: the golden hashes of `tests/golden/kernel_hashes.txt` on every
//! architecture, and the hit files of a generated mesh compared byte for byte with x86_64's.
//!
//! - x86_64 (native) is the reference: the probe `tests/determinism` checks every golden hash
//!   and writes the hit files.
//! - aarch64 (`qemu-aarch64`, F4 lanes on NEON): the kernel's lane tests (NEON against the
//!   portable backend) and its golden test, then the probe; hit files compared with x86_64's.
//! - wasm32-wasip1 (Node.js's WASI, `tests/determinism/run_wasi.mjs`): the probe; hit files
//!   compared.
//! - riscv32imac (`qemu-system-riscv32 -machine virt`): the suite of `tests/baremetal` (known
//!   answers, accelerators against brute force, every golden hash).
//! - Cortex-M4F, M3, M0 (`qemu-system-arm`): the defmt-test suite of `tests/qemu`, whose golden
//!   tests check the same file.
//!
//! Prints a per-architecture summary, writes the table into docs/PLATFORMS.md and the README,
//! and ends with one `N passed, M failed` line.

use super::{platforms, progress, run_captured, TARGETS};
use std::path::{Path, PathBuf};
use std::process::Command;

pub const AARCH64: &str = "aarch64-unknown-linux-gnu";
pub const WASM32: &str = "wasm32-wasip1";
pub const RISCV32: &str = "riscv32imac-unknown-none-elf";

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `cargo` in `dir`, without the caller's RUSTFLAGS (they would replace a target's linker
/// scripts) or target directory, with the linker and runners of the emulated targets.
pub fn cargo_in(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    let wasi = root().join("tests/determinism/run_wasi.mjs");
    c.current_dir(dir)
        .args(args)
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_TARGET_DIR")
        .env(
            "CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER",
            "aarch64-linux-gnu-gcc",
        )
        .env(
            "CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER",
            "qemu-aarch64 -L /usr/aarch64-linux-gnu",
        )
        .env(
            "CARGO_TARGET_WASM32_WASIP1_RUNNER",
            format!("node --no-warnings {}", wasi.display()),
        );
    c
}

/// One architecture's line of the table.
struct Row {
    arch: &'static str,
    how: &'static str,
    /// Golden hashes compared with the file.
    hashes: usize,
    /// Hit files compared with x86_64's (`None`: the reference, or none written).
    hit_files: Option<usize>,
    passed: usize,
    failed: usize,
}

/// What the probe printed: golden results and hit-file names.
struct ProbeRun {
    golden_ok: usize,
    golden_failed: usize,
    hit_files: Vec<String>,
    finished: bool,
}

fn parse_probe(ok: bool, out: &str) -> ProbeRun {
    let mut r = ProbeRun {
        golden_ok: 0,
        golden_failed: 0,
        hit_files: Vec::new(),
        finished: false,
    };
    for line in out.lines() {
        let mut words = line.split_whitespace();
        match (words.next(), words.next(), words.next()) {
            (Some("golden"), Some(_), Some("ok")) => r.golden_ok += 1,
            (Some("golden"), Some(_), Some(_)) => r.golden_failed += 1,
            (Some("hits"), Some(file), Some(_)) => r.hit_files.push(file.to_string()),
            _ => {}
        }
        r.finished |= line.ends_with(" failed") && line.contains(" passed, ");
    }
    r.finished &= ok;
    r
}

/// Runs `c`, then prints `title` and its output together: the groups of [`determinism`] run
/// side by side, so a command's output must not be split by another's.
fn run_titled(title: &str, c: Command) -> (bool, String) {
    let (ok, text) = run_captured(c);
    print!("\n=== {title} ===\n{text}");
    (ok, text)
}

/// Runs the probe for `target` (`None`: the host) under `title`, writing hit files into
/// `out/<arch>`.
fn probe(title: &str, target: Option<&str>, out: &Path, arch: &str) -> (ProbeRun, PathBuf) {
    let dir = out.join(arch);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::create_dir_all(&dir);
    let dir_arg = dir.display().to_string();
    let mut args = vec!["run", "--profile", "test", "-p", "raykernel-determinism"];
    if let Some(t) = target {
        args.extend(["--target", t]);
    }
    args.extend(["--", &dir_arg]);
    let (ok, text) = run_titled(title, cargo_in(&root(), &args));
    (parse_probe(ok, &text), dir)
}

/// Compares every hit file of `dir` named in `files` with the reference's; returns
/// (equal, different or missing).
fn compare_hits(files: &[String], dir: &Path, reference: &Path) -> (usize, usize) {
    let (mut same, mut differ) = (0, 0);
    for f in files {
        let (a, b) = (std::fs::read(dir.join(f)), std::fs::read(reference.join(f)));
        match (a, b) {
            (Ok(a), Ok(b)) if a == b => same += 1,
            (Ok(a), Ok(b)) => {
                let first = a
                    .chunks(8)
                    .zip(b.chunks(8))
                    .position(|(x, y)| x != y)
                    .unwrap_or(a.len().min(b.len()) / 8);
                println!("hit file {f} differs from x86_64's, first at record {first}");
                differ += 1;
            }
            _ => {
                println!("hit file {f}: missing here or in the x86_64 run");
                differ += 1;
            }
        }
    }
    (same, differ)
}

/// (passed, failed) summed over cargo test's `test result:` lines.
fn cargo_test_counts(out: &str) -> (usize, usize) {
    let (mut passed, mut failed) = (0, 0);
    for line in out.lines() {
        let Some(rest) = line.trim().strip_prefix("test result: ") else {
            continue;
        };
        let number_before = |word: &str| {
            rest.split(';')
                .find_map(|part| {
                    part.trim()
                        .strip_suffix(word)?
                        .trim()
                        .rsplit(' ')
                        .next()?
                        .parse::<usize>()
                        .ok()
                })
                .unwrap_or(0)
        };
        passed += number_before("passed");
        failed += number_before("failed");
    }
    (passed, failed)
}

/// The three groups have target directories of their own (the workspace's, tests/baremetal's,
/// tests/qemu's), so they run side by side: the emulators' single-threaded runs overlap the
/// other groups' builds. Each command's output is printed whole when it ends.
pub fn determinism() -> bool {
    let out = root().join("target/determinism");
    let (hosted, riscv, cortex_m) = std::thread::scope(|s| {
        let riscv = s.spawn(riscv_suite);
        let cortex_m = s.spawn(cortex_m_suites);
        let hosted = hosted_probes(&out);
        (hosted, riscv.join(), cortex_m.join())
    });
    let mut rows = hosted;
    match (riscv, cortex_m) {
        (Ok(r), Ok(c)) => {
            rows.push(r);
            rows.extend(c);
        }
        _ => {
            println!("a determinism group panicked");
            return false;
        }
    }

    let mut table = String::from(
        "| architecture | how it runs | golden hashes compared | hit files equal to x86_64's | result |\n|---|---|---:|---:|---|\n",
    );
    for r in &rows {
        let hits = r
            .hit_files
            .map_or_else(|| "–".to_string(), |n| n.to_string());
        let result = if r.failed == 0 { "pass" } else { "FAIL" };
        table.push_str(&format!(
            "| {} | {} | {} | {hits} | {result} ({} checks) |\n",
            r.arch,
            r.how,
            r.hashes,
            r.passed + r.failed
        ));
    }
    println!("\n=== determinism table ===\n{table}");
    let (passed, failed) = rows
        .iter()
        .fold((0, 0), |(p, f), r| (p + r.passed, f + r.failed));
    // The table is written only when every architecture passed, so the committed one is never
    // a failing run's.
    let written = failed == 0
        && platforms::write_block(platforms::Doc::Platforms, "determinism", &table)
        && platforms::write_block(platforms::Doc::Readme, "determinism", &table);
    let failed = failed + usize::from(failed == 0 && !written);
    println!("{passed} passed, {failed} failed");
    failed == 0
}

/// x86_64 (the reference), aarch64 and wasm32: golden hashes and hit files.
fn hosted_probes(out: &Path) -> Vec<Row> {
    let mut rows = Vec::new();

    let (x86, reference) = probe(
        "x86_64 (native): golden hashes, reference hit files",
        None,
        out,
        "x86_64",
    );
    let reference_ok = x86.finished && !x86.hit_files.is_empty();
    rows.push(Row {
        arch: "x86_64",
        how: "native (reference)",
        hashes: x86.golden_ok + x86.golden_failed,
        hit_files: None,
        passed: x86.golden_ok + x86.hit_files.len(),
        failed: x86.golden_failed + usize::from(!reference_ok),
    });

    let mut unit = (0, 0);
    for args in [
        &[
            "test",
            "-p",
            "raykernel",
            "--target",
            AARCH64,
            "--lib",
            "--",
            "lanes",
        ][..],
        &[
            "test",
            "-p",
            "raykernel",
            "--target",
            AARCH64,
            "--test",
            "golden",
        ][..],
    ] {
        let title = "aarch64 (qemu-aarch64): F4 lanes on NEON, the kernel's golden test";
        let (ok, text) = run_titled(title, cargo_in(&root(), args));
        let (p, f) = cargo_test_counts(&text);
        unit.0 += p;
        unit.1 += f + usize::from(!ok || p == 0);
    }
    for (arch, target, how) in [
        ("aarch64", AARCH64, "qemu-aarch64 (user mode), F4 on NEON"),
        ("wasm32", WASM32, "Node.js WASI (`node:wasi`)"),
    ] {
        let title = format!("{arch} ({target}): the probe, hit files against x86_64's");
        let (r, dir) = probe(&title, Some(target), out, arch);
        let (same, differ) = if reference_ok {
            compare_hits(&r.hit_files, &dir, &reference)
        } else {
            (0, r.hit_files.len())
        };
        let missing = usize::from(!r.finished || r.hit_files.len() != x86.hit_files.len());
        let (up, uf) = if arch == "aarch64" { unit } else { (0, 0) };
        rows.push(Row {
            arch,
            how,
            hashes: r.golden_ok + r.golden_failed,
            hit_files: Some(same + differ),
            passed: r.golden_ok + same + up,
            failed: r.golden_failed + differ + missing + uf,
        });
    }

    rows
}

/// riscv32imac: the bare-metal suite.
fn riscv_suite() -> Row {
    let (ok, text) = run_titled(
        "riscv32imac (qemu-system-riscv32 virt): tests/baremetal suite",
        cargo_in(
            &root().join("tests/baremetal"),
            &["run", "--release", "--bin", "suite", "--target", RISCV32],
        ),
    );
    let count = |suffix: &str| {
        text.lines()
            .filter(|l| l.starts_with("test ") && l.contains(suffix))
            .count()
    };
    let golden = text
        .lines()
        .filter(|l| l.starts_with("test golden_"))
        .count();
    let (p, f) = (count(" ... ok"), count(" ... FAILED"));
    Row {
        arch: "riscv32imac",
        how: "qemu-system-riscv32 `virt`, semihosting",
        hashes: golden,
        hit_files: None,
        passed: p,
        failed: f + usize::from(!ok || p == 0),
    }
}

/// The Cortex-M cores: the defmt-test suites, one core after the other (one target dir).
fn cortex_m_suites() -> Vec<Row> {
    let mut rows = Vec::new();
    for (target, core, machine, _) in TARGETS {
        let title = format!("{core} ({target}, QEMU {machine}): tests/qemu suite");
        let (ok, text) = run_titled(&title, super::cargo(&["test", "--target", target]));
        let (last, total, finished) = progress(&text);
        let ok = ok && finished && total > 0 && last == total;
        let golden = text
            .lines()
            .filter(|l| l.contains("running `golden_") && !l.contains("golden_table"))
            .count();
        rows.push(Row {
            arch: core_arch(core),
            how: machine_how(core),
            hashes: golden,
            hit_files: None,
            passed: if ok { total } else { last.saturating_sub(1) },
            failed: if ok {
                0
            } else {
                total.max(1) - last.saturating_sub(1)
            },
        });
    }

    rows
}

fn core_arch(core: &str) -> &'static str {
    match core {
        "Cortex-M4F" => "thumbv7em (Cortex-M4F, FPU)",
        "Cortex-M3" => "thumbv7m (Cortex-M3)",
        _ => "thumbv6m (Cortex-M0)",
    }
}

fn machine_how(core: &str) -> &'static str {
    match core {
        "Cortex-M4F" => "qemu-system-arm `mps2-an386`, defmt-test",
        "Cortex-M3" => "qemu-system-arm `lm3s6965evb`, defmt-test",
        _ => "qemu-system-arm `microbit` (16 KB), defmt-test",
    }
}
