//! The determinism probe: computes every golden case of `testkit/src/golden.rs` and compares
//! it with `tests/golden/kernel_hashes.txt` (embedded at build time, so every target checks
//! the same file), then writes the closest hits of a generated mesh and ray set, through
//! every accelerator in both modes, as hit files (`t: f32, prim: u32`, little-endian; the
//! format of `shared/bench/WORKLOAD.md`) into the directory given on the command line.
//!
//! `cargo xtask determinism` runs it natively on x86_64, under `qemu-aarch64` and under
//! Node.js's WASI, and compares the hit files byte for byte with the x86_64 run's.
//!
//! Output: one `golden <name> ok` (or `FAIL ...`) line per case, one `hits <file> <records>`
//! line per hit file, and a closing `N passed, M failed` line; the exit code is 1 if any
//! case failed.

mod hits;

use raykernel_testkit::golden as cases;

use std::path::PathBuf;
use std::process::ExitCode;

/// The golden table, read by every target from the same file.
const GOLDEN: &str = include_str!("../../golden/kernel_hashes.txt");

fn main() -> ExitCode {
    let Some(out_dir) = std::env::args().nth(1).map(PathBuf::from) else {
        eprintln!("usage: determinism <directory for the hit files>");
        return ExitCode::from(2);
    };
    let (mut passed, mut failed) = (0usize, 0usize);

    let mut file = Vec::new();
    if let Err(line) = cases::parse_golden(GOLDEN, |name, v| file.push((name.to_string(), v))) {
        println!("golden file: malformed line {line}");
        failed += 1;
    }
    for &name in &cases::NAMES {
        let want = file.iter().find(|(n, _)| n == name).map(|&(_, v)| v);
        match (cases::compute_any(name), want) {
            (Ok(got), Some(want)) if got == want => {
                println!("golden {name} ok");
                passed += 1;
            }
            (Ok(got), Some(want)) => {
                println!("golden {name} FAIL: computed {got:#018x}, file {want:#018x}");
                failed += 1;
            }
            (Ok(_), None) => {
                println!("golden {name} FAIL: missing from kernel_hashes.txt");
                failed += 1;
            }
            (Err(e), _) => {
                println!("golden {name} FAIL: {e:?}");
                failed += 1;
            }
        }
    }

    match hits::write_all(&out_dir) {
        Ok(files) => {
            for (name, records) in files {
                println!("hits {name} {records}");
                passed += 1;
            }
        }
        Err(e) => {
            println!("hits FAIL: {e}");
            failed += 1;
        }
    }
    println!("{passed} passed, {failed} failed");
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
