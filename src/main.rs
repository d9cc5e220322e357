//! The `bulge` binary: parse, call, print the error chain, exit.

mod cli;

use clap::Parser;

fn main() {
    // temporary files of unfinished writes are removed on Ctrl-C and kill
    let _ = bulge::io::install_cleanup_on_signal();
    // the library's messages name the settings to change by their flags
    bulge::setting::name_settings_with(cli::flag_of);
    let cli = cli::Cli::parse();
    if let Err(failure) = cli::dispatch(cli) {
        eprintln!("error: {:#}", failure.error());
        std::process::exit(failure.exit_code());
    }
}
