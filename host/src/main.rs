//! `raykernel`: parse the command line, run the command, print its JSON report as the last
//! line of stdout, or one error on stderr with a non-zero exit code. Whatever a message
//! quotes from an input is escaped and shortened before it reaches the terminal.
#![forbid(unsafe_code)]

use clap::Parser;
use host::cli::{run, Cli};
use host::console::Console;
use host::error::for_terminal;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let console = Console { quiet: cli.quiet };
    match run(&cli, &console) {
        Ok(report) => {
            // A closed stdout (e.g. `| head -0`) is not worth a panic.
            if writeln!(std::io::stdout().lock(), "{report}").is_err() {
                return ExitCode::FAILURE;
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            // Nothing better to do if stderr is gone too.
            let _ = writeln!(
                std::io::stderr().lock(),
                "error: {}",
                for_terminal(&e.to_string())
            );
            ExitCode::from(e.exit_code())
        }
    }
}
