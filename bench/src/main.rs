//! `raykernel-bench`: run the benchmark, print its JSON summary as the last line of stdout, or
//! one error line on stderr with a non-zero exit code.

use clap::Parser;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = raykernel_bench::cli::BenchArgs::parse();
    match raykernel_bench::cli::run(&args) {
        Ok(report) => {
            let line = serde_json::to_string(&report).unwrap_or_default();
            // A closed stdout (e.g. `| head -0`) is not worth a panic.
            if writeln!(std::io::stdout().lock(), "{line}").is_err() {
                return ExitCode::FAILURE;
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            // Nothing better to do if stderr is gone too.
            let _ = writeln!(std::io::stderr().lock(), "error: {e}");
            ExitCode::FAILURE
        }
    }
}
