//! `bulge stress`.

use super::Failure;

/// Flags of `bulge stress`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge stress`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge stress` is not built yet"
    )))
}
