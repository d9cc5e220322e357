//! `bulge bench`.

use super::Failure;

/// Flags of `bulge bench`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge bench`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge bench` is not built yet"
    )))
}
