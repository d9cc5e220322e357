//! `bulge simulate`.

use super::Failure;

/// Flags of `bulge simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge simulate`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge simulate` is not built yet"
    )))
}
