//! `host`: parse the command line, run the command, print its JSON report as the last line
//! of stdout, or one error line on stderr with a non-zero exit code.
#![forbid(unsafe_code)]

use clap::Parser;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = host::cli::Cli::parse();
    match host::cli::run(&cli) {
        Ok(report) => {
            // A closed stdout (e.g. `| head -0`) is not worth a panic.
            if writeln!(std::io::stdout().lock(), "{report}").is_err() {
                return ExitCode::FAILURE;
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            // Nothing better to do if stderr is gone too.
            let _ = writeln!(std::io::stderr().lock(), "error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
