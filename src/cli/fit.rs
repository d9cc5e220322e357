//! `bulge fit`.

use super::Failure;

/// Flags of `bulge fit`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge fit`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge fit` is not built yet"
    )))
}
