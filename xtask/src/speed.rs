//! `cargo xtask speed`: instructions per closest-hit ray and per rendered pixel on each
//! emulated core, from the `speed_f32` and `speed_fixed` programs of `tests/baremetal` run under QEMU with
//! `-icount shift=0` (see its `counter.rs`); writes the table into docs/PLATFORMS.md.

use super::determinism::{cargo_in, root, RISCV32};
use super::{platforms, run, TARGETS};

/// One core's measurements: (name, count, instructions) per workload, and the calibrated
/// instructions per counter tick.
struct Measured {
    per_tick: Option<String>,
    workloads: Vec<(String, u64, u64)>,
}

fn value(line: &str, key: &str) -> Option<u64> {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('=')?.parse().ok())
}

fn parse(out: &str) -> Measured {
    let mut m = Measured {
        per_tick: None,
        workloads: Vec::new(),
    };
    for line in out.lines() {
        if line.starts_with("calibration ") {
            m.per_tick = line
                .split_whitespace()
                .find_map(|w| w.strip_prefix("instructions_per_tick="))
                .map(str::to_string);
        } else if let Some(rest) = line.strip_prefix("measure ") {
            let name = rest.split_whitespace().next().unwrap_or("").to_string();
            if let (Some(n), Some(i)) = (value(line, "count"), value(line, "instructions")) {
                m.workloads.push((name, n, i));
            }
        }
    }
    m
}

pub fn speed() -> bool {
    let mut cores = vec![(RISCV32, "RISC-V RV32IMAC", "virt", "`instret` CSR")];
    for (target, core, machine, _) in TARGETS {
        cores.push((target, core, machine, "SysTick"));
    }
    let mut ok = true;
    let mut table = String::from(
        "Rays: the closest hit of the 96 rays of `testkit/src/golden.rs` through a SAH BVH \
         (default options) over its 80-triangle icosphere, build excluded. Pixels: the \
         built-in Cornell scene at its own settings (64×64, 8 samples per pixel, a BVH per \
         object), scene setup included. Release build as the on-target suite's (opt-level \
         \"s\", LTO); every workload is checked against its golden answer. QEMU 7.2 models no \
         pipeline, so these are instructions executed, not cycles.\n\n\
         | core | QEMU machine | mode | instructions / closest-hit ray | instructions / pixel | method |\n\
         |---|---|---|---:|---:|---|\n",
    );
    for (target, core, machine, clock) in cores {
        println!("\n=== {core} ({target}, QEMU {machine}) ===");
        let mut ran = true;
        let mut out = String::new();
        for bin in ["speed_f32", "speed_fixed"] {
            let (ok, text) = run(cargo_in(
                &root().join("tests/baremetal"),
                &["run", "--release", "--bin", bin, "--target", target],
            ));
            ran &= ok;
            out.push_str(&text);
        }
        let m = parse(&out);
        let per = |name: &str| {
            m.workloads
                .iter()
                .find(|(n, _, _)| n == name)
                .map(|&(_, count, instr)| instr / count.max(1))
        };
        let Some(per_tick) = m.per_tick else {
            println!("{core}: no calibration line");
            ok = false;
            continue;
        };
        ok &= ran && m.workloads.len() == 4;
        for mode in ["f32", "fixed"] {
            let cell = |v: Option<u64>| v.map_or_else(|| "?".to_string(), group);
            table.push_str(&format!(
                "| {core} | `{machine}` | {mode} | {} | {} | `-icount shift=0`, {clock} ({per_tick} instructions per tick) |\n",
                cell(per(&format!("rays_{mode}"))),
                cell(per(&format!("pixels_cornell_{mode}"))),
            ));
        }
    }
    println!("\n=== speed table ===\n{table}");
    ok = ok && platforms::write_block(platforms::Doc::Platforms, "speed", &table);
    println!("{} passed, {} failed", usize::from(ok), usize::from(!ok));
    ok
}

/// `1234567` as `1,234,567`.
fn group(v: u64) -> String {
    let s = v.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}
