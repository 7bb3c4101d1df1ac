//! Repository tasks, run from the repository root:
//!
//! - `cargo xtask qemu`: the on-target tests (`tests/qemu`, defmt-test under QEMU) on the
//!   Cortex-M4F, M3 and M0, the embedded example of docs/EMBEDDED.md on all three, and the
//!   panic-freedom link check; prints a per-target summary and a final `N passed, M failed`
//!   line. `--skip-suites` leaves out the on-target tests (for CI, where `cargo xtask
//!   determinism` runs the same suites).
//! - `cargo xtask panic-check`: only the panic-freedom link check (release, all three targets);
//!   on failure, lists the kernel source lines that still reach a panic.
//! - `cargo xtask size`: the footprint of the size probes on the three thumb targets (`.text`,
//!   `.rodata`, stack measured on target; see `size.rs`), arena bytes per triangle; the last
//!   stdout line is one JSON object.
//! - `cargo xtask determinism`: the golden hashes on every architecture (x86_64, aarch64 under
//!   qemu-aarch64, wasm32 under Node.js's WASI, RISC-V and the three Cortex-M cores under QEMU)
//!   and hit files compared with x86_64's; writes the table of docs/PLATFORMS.md
//!   (`determinism.rs`).
//! - `cargo xtask speed`: instructions per ray and per pixel on the emulated cores; writes the
//!   table of docs/PLATFORMS.md (`speed.rs`).
//! - `cargo xtask stress`: the kernel's stress suite over the full matrix; writes the table of
//!   docs/STRESS.md (`stress.rs`).
//! - `cargo xtask bless`: rewrites the goldens: the hash file `tests/golden/kernel_hashes.txt`
//!   (the kernel's golden test), then the snapshot PNGs `tests/golden/images/` (the host's
//!   snapshot test, which also checks its renders against the new hashes).
//!
//! Cargo reads `.cargo/config.toml` from the current directory, so every on-target command runs
//! inside `tests/qemu`.

use raykernel_testkit::golden as cases;
mod determinism;
mod platforms;
mod size;
mod speed;
mod stress;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// Target, core, QEMU machine and CPU. The M0 runs on QEMU's micro:bit machine (nRF51822) with
/// the micro:bit's own 16 KB of SRAM.
const TARGETS: [(&str, &str, &str, &str); 3] = [
    (
        "thumbv7em-none-eabihf",
        "Cortex-M4F",
        "mps2-an386",
        "cortex-m4",
    ),
    (
        "thumbv7m-none-eabi",
        "Cortex-M3",
        "lm3s6965evb",
        "cortex-m3",
    ),
    ("thumbv6m-none-eabi", "Cortex-M0", "microbit", "cortex-m0"),
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let ok = match args.first().map(String::as_str) {
        Some("qemu") => match args.get(1).map(String::as_str) {
            None => qemu(true),
            Some("--skip-suites") => qemu(false),
            Some(other) => {
                eprintln!("xtask qemu: unknown option `{other}` (the only one: --skip-suites)");
                false
            }
        },
        Some("panic-check") => {
            let r = panic_check();
            println!("{} passed, {} failed", r.0, r.1);
            r.1 == 0
        }
        Some("size") => size::size(),
        Some("determinism") => determinism::determinism(),
        Some("speed") => speed::speed(),
        Some("stress") => stress::stress(),
        Some("bless") => bless(),
        _ => {
            eprintln!(
                "usage: cargo xtask <qemu | panic-check | size | determinism | speed | stress | bless>"
            );
            false
        }
    };
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// `BLESS=1 cargo test` of the kernel's golden hashes, then of the host's snapshots, from the
/// repository root.
fn bless() -> bool {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    for (package, test) in [("raykernel", "golden"), ("raykernel-host", "snapshots")] {
        let status = Command::new(&cargo)
            .current_dir(&root)
            .args(["test", "-p", package, "--test", test])
            .env("BLESS", "1")
            .status();
        if !status.is_ok_and(|s| s.success()) {
            eprintln!("bless: `BLESS=1 cargo test -p {package} --test {test}` failed");
            return false;
        }
    }
    println!("blessed tests/golden/kernel_hashes.txt and tests/golden/images/");
    true
}

fn qemu_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/qemu")
}

/// `cargo` inside tests/qemu, without the caller's RUSTFLAGS (they would replace the target
/// config's linker scripts).
fn cargo(args: &[&str]) -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(qemu_dir())
        .args(args)
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_TARGET_DIR");
    c
}

/// Runs `c`, echoing its output; returns (success, stdout + stderr).
fn run(c: Command) -> (bool, String) {
    let (ok, text) = run_captured(c);
    print!("{text}");
    (ok, text)
}

/// Runs `c` and returns whether it succeeded and its stderr then stdout, printing nothing.
fn run_captured(mut c: Command) -> (bool, String) {
    match c.stdout(Stdio::piped()).stderr(Stdio::piped()).output() {
        Ok(out) => {
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&out.stderr),
                String::from_utf8_lossy(&out.stdout)
            );
            (out.status.success(), text)
        }
        Err(e) => (false, format!("cannot run {c:?}: {e}\n")),
    }
}

/// defmt-test's progress: the highest `(i/N)` seen, N, and whether it finished.
fn progress(output: &str) -> (usize, usize, bool) {
    // Several test binaries run one after the other: each restarts at `(1/n)`.
    let (mut done, mut binaries) = (0, 0);
    let (mut last, mut total) = (0, 0);
    for line in output.lines() {
        let Some(rest) = line.trim().strip_prefix('(') else {
            continue;
        };
        let Some((i, rest)) = rest.split_once('/') else {
            continue;
        };
        let Some((n, rest)) = rest.split_once(')') else {
            continue;
        };
        if let (Ok(i), Ok(n), true) = (i.parse::<usize>(), n.parse(), rest.contains("running")) {
            if i == 1 {
                done += total;
                binaries += 1;
            }
            last = i;
            total = n;
        }
    }
    let finished = binaries > 0 && output.matches("all tests passed!").count() == binaries;
    (done + last, done + total, finished)
}

fn elf(target: &str, profile: &str, bin: &str) -> PathBuf {
    qemu_dir().join(format!("target/{target}/{profile}/{bin}"))
}

/// `cargo xtask qemu`; `suites: false` leaves out the on-target test suites.
fn qemu(suites: bool) -> bool {
    let (mut passed, mut failed) = (0usize, 0usize);
    let mut summary = Vec::new();
    for (target, core, machine, _) in TARGETS.into_iter().filter(|_| suites) {
        println!("\n=== on-target tests: {core} ({target}, QEMU {machine}) ===");
        let (ok, out) = run(cargo(&["test", "--target", target]));
        let (last, total, finished) = progress(&out);
        let ok = ok && finished && total > 0 && last == total;
        let (p, f) = if ok {
            (total, 0)
        } else {
            // The failing test stopped the run: it and the ones after it count as failed.
            let p = last.saturating_sub(1);
            (p, total.max(1) - p)
        };
        passed += p;
        failed += f;
        summary.push(format!(
            "{core:<11} {target:<22} tests ({p}/{total}) {}",
            if ok { "pass" } else { "FAIL" }
        ));
    }
    for (target, core, machine, cpu) in TARGETS {
        println!("\n=== embedded example: {core} ===");
        let built = run(cargo(&[
            "build",
            "--release",
            "--bin",
            "readme_example",
            "--target",
            target,
        ]))
        .0;
        let ran = built && {
            let mut q = Command::new("timeout");
            q.args(["60", "qemu-system-arm", "-machine", machine, "-cpu", cpu])
                .args(["-display", "none", "-semihosting-config"])
                .arg("enable=on,target=native")
                .arg("-kernel")
                .arg(elf(target, "release", "readme_example"));
            run(q).0
        };
        if ran {
            passed += 1;
        } else {
            failed += 1;
        }
        summary.push(format!(
            "{core:<11} {target:<22} readme_example {}",
            if ran { "pass" } else { "FAIL" }
        ));
    }
    println!("\n=== docs/EMBEDDED.md example matches tests/qemu/src/bin/readme_example.rs ===");
    let same = readme_example_matches();
    println!(
        "{}",
        if same {
            "same code"
        } else {
            "docs/EMBEDDED.md and readme_example.rs differ"
        }
    );
    if same {
        passed += 1;
    } else {
        failed += 1;
    }
    summary.push(format!(
        "{:<34} embedded example in sync {}",
        "host",
        if same { "pass" } else { "FAIL" }
    ));
    println!("\n=== panic-freedom link check ===");
    let (p, f) = panic_check();
    passed += p;
    failed += f;
    summary.push(format!(
        "{:<34} panic_never ({p}/{}) {}",
        "all cores",
        p + f,
        if f == 0 { "pass" } else { "FAIL" }
    ));
    println!("\n=== summary ===");
    for line in &summary {
        println!("{line}");
    }
    println!("{passed} passed, {failed} failed");
    failed == 0
}

/// The code block of docs/EMBEDDED.md (under `# Embedded use`) equals the lines between the
/// `README` markers of `readme_example.rs`.
fn readme_example_matches() -> bool {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let (Ok(readme), Ok(code)) = (
        std::fs::read_to_string(root.join("docs/EMBEDDED.md")),
        std::fs::read_to_string(qemu_dir().join("src/bin/readme_example.rs")),
    ) else {
        return false;
    };
    let block = readme
        .split_once("# Embedded use")
        .and_then(|(_, rest)| rest.split_once("```rust,ignore\n"))
        .and_then(|(_, rest)| rest.split_once("```"))
        .map(|(b, _)| b.trim());
    let example = code
        .split_once("// README begin\n")
        .and_then(|(_, rest)| rest.split_once("// README end"))
        .map(|(b, _)| b.trim());
    block.is_some() && block == example
}

/// Release-links `panic_never` (BVH, brute force, rays, I16F16), `panic_never_accels` (grid,
/// kd-tree), `panic_never_bvh4` and `panic_never_bvh8` (4-wide and 8-wide BVH),
/// `panic_never_render` and `panic_never_render_fixed` (the renderer with every accelerator,
/// `f32` and fixed point) for every target; returns (passed, failed), one count per binary and
/// target.
fn panic_check() -> (usize, usize) {
    let (mut passed, mut failed) = (0, 0);
    let bins = [
        "panic_never",
        "panic_never_accels",
        "panic_never_bvh4",
        "panic_never_bvh8",
        "panic_never_render",
        "panic_never_render_fixed",
    ];
    for bin in bins {
        for (target, core, _, _) in TARGETS {
            let args = [
                "build",
                "--release",
                "--bin",
                bin,
                "--features",
                "panic-check",
                "--target",
                target,
            ];
            if run(cargo(&args)).0 {
                println!("{core} ({target}): {bin} links: no reachable panic path");
                passed += 1;
            } else {
                failed += 1;
                println!("{core} ({target}): {bin}: a panic path is reachable; call sites:");
                let mut list = args.to_vec();
                list[5] = "list-panics";
                if run(cargo(&list)).0 {
                    for site in panic_sites(&elf(target, "release", bin)) {
                        println!("  {site}");
                    }
                }
            }
        }
    }
    (passed, failed)
}

/// Source lines (innermost kernel frame of the inlining chain) of calls into core's panic
/// functions, from `arm-none-eabi-objdump` and `arm-none-eabi-addr2line`.
fn panic_sites(elf: &Path) -> Vec<String> {
    let Ok(dis) = Command::new("arm-none-eabi-objdump")
        .args(["-d", "--no-show-raw-insn"])
        .arg(elf)
        .output()
    else {
        return vec!["(arm-none-eabi-objdump not found)".into()];
    };
    let dis = String::from_utf8_lossy(&dis.stdout);
    let is_panic = |s: &str| {
        [
            "panicking",
            "slice_index_fail",
            "unwrap_failed",
            "expect_failed",
            "assert_failed",
        ]
        .iter()
        .any(|p| s.contains(p))
    };
    let mut func = String::new();
    let mut addrs = Vec::new();
    for line in dis.lines() {
        if let Some(name) = line.strip_suffix(">:").and_then(|l| l.split_once(" <")) {
            func = name.1.to_string();
            continue;
        }
        let t = line.trim_start();
        let (Some((addr, rest)), false) = (t.split_once(':'), is_panic(&func)) else {
            continue;
        };
        let rest = rest.trim_start();
        if (rest.starts_with("bl") || rest.starts_with("b.w") || rest.starts_with("b\t"))
            && rest.contains('<')
            && is_panic(rest)
        {
            addrs.push(addr.to_string());
        }
    }
    let mut sites = Vec::new();
    for a in addrs {
        let Ok(out) = Command::new("arm-none-eabi-addr2line")
            .args(["-i", "-e"])
            .arg(elf)
            .arg(&a)
            .output()
        else {
            continue;
        };
        let out = String::from_utf8_lossy(&out.stdout);
        // Innermost kernel frame of the inlining chain; call sites without one (core's own
        // helpers, the probe itself) are lumped together.
        let site = out
            .lines()
            .find(|l| l.contains("/kernel/src/"))
            .and_then(|l| l.split(" (").next())
            .map_or_else(|| "(outside kernel/src)".to_string(), str::to_string);
        if !sites.contains(&site) {
            sites.push(site);
        }
    }
    sites.sort();
    sites
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readme_example_is_in_sync() {
        assert!(
            readme_example_matches(),
            "docs/EMBEDDED.md's code block differs from tests/qemu/src/bin/readme_example.rs"
        );
    }

    #[test]
    fn progress_counts_defmt_test_lines() {
        let out = "(1/3) running `a`...\n(2/3) running `b`...\nERROR panicked\n";
        assert_eq!(progress(out), (2, 3, false));
        let out = "(1/2) running `a`...\n(2/2) running `b`...\nall tests passed!\n";
        assert_eq!(progress(out), (2, 2, true));
        assert_eq!(progress("(x/2) running"), (0, 0, false));
        // Two binaries: counts add up, and both must pass.
        let two =
            "(1/2) running `a`...\n(2/2) running `b`...\nall tests passed!\n(1/1) running `c`...\n";
        assert_eq!(progress(two), (3, 3, false));
        let two = format!("{two}all tests passed!\n");
        assert_eq!(progress(&two), (3, 3, true));
    }
}
