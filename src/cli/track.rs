//! `bulge track`.

use super::Failure;

/// Flags of `bulge track`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge track`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge track` is not built yet"
    )))
}
