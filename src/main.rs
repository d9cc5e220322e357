//! The `bulge` binary: parse, call, print the error chain, exit.

mod cli;

use clap::Parser;

fn main() {
    let cli = cli::Cli::parse();
    if let Err(failure) = cli::dispatch(cli) {
        eprintln!("error: {:#}", failure.error());
        std::process::exit(failure.exit_code());
    }
}
