//! `cargo xtask stress`: runs the kernel's stress suite over the full matrix (the ignored
//! `table` test of `kernel/tests/stress.rs` with `STRESS_FULL=1`) and writes its table into
//! docs/STRESS.md.

use super::platforms;
use std::process::Command;

/// The lines the `table` test prints around the table.
const BEGIN: &str = "--- stress table ---";
const END: &str = "--- end stress table ---";

pub fn stress() -> bool {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(super::determinism::root())
        .args(["test", "-p", "raykernel", "--test", "stress", "--"])
        .args(["--ignored", "--exact", "table", "--nocapture"])
        .env("STRESS_FULL", "1")
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            println!("cannot run cargo: {e}");
            return false;
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    print!("{text}{}", String::from_utf8_lossy(&out.stderr));
    if !out.status.success() {
        println!("the stress suite failed");
        return false;
    }
    let Some(table) = text
        .split_once(BEGIN)
        .and_then(|(_, rest)| rest.split_once(END))
        .map(|(table, _)| table.trim_start_matches('\n'))
    else {
        println!("no table between `{BEGIN}` and `{END}` in the output");
        return false;
    };
    let body = format!(
        "Full run (`STRESS_FULL=1`, {} {}, {}, test profile):\n\n{table}",
        std::env::consts::ARCH,
        std::env::consts::OS,
        rustc_version(),
    );
    platforms::write_block(platforms::Doc::Stress, "stress", &body)
}

/// `rustc --version`, as in "rustc 1.95.0".
fn rustc_version() -> String {
    Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|v| {
            v.split_whitespace()
                .take(2)
                .collect::<Vec<_>>()
                .join(" ")
                .into()
        })
        .unwrap_or_else(|| "rustc (unknown version)".into())
}
