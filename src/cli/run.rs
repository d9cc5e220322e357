//! `bulge run`.

use super::Failure;

/// Flags of `bulge run`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge run`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge run` is not built yet"
    )))
}
