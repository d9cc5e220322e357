//! The `bulge` binary: parse, call, print the error chain, exit.

use clap::Parser;

fn main() {
    let cli = bulge::cli::Cli::parse();
    if let Err(failure) = bulge::cli::dispatch(cli) {
        eprintln!("error: {:#}", failure.error());
        std::process::exit(failure.exit_code());
    }
}
