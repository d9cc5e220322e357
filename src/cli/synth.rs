//! `bulge synth`.

use super::Failure;

/// Flags of `bulge synth`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bulge synth`.
pub fn run(_args: Args) -> Result<(), Failure> {
    Err(Failure::Failed(anyhow::anyhow!(
        "`bulge synth` is not built yet"
    )))
}
