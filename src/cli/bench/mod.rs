//! `bulge bench`: speed against error of every solver and integrator, on the
//! disc bubble (error against the exact axisymmetric solution) and on
//! Sudhamani & Merriliance's sheet (error against a converged static solution of the same mesh).
//! Writes `bench.csv`, `bench.md` and `bench.png` (log wall time against log
//! error, with each case's Pareto front); with `--sudhamani-merriliance` also
//! `sudhamani-merriliance.md`, Sudhamani & Merriliance's (2019) three experiments and the disc's pressure step
//! (see `docs/dynamics.md`).
//!
//! * [`runs`]: one measured run ([`runs::Entry`]), static or dynamic;
//! * [`speed`]: the cases and sizes measured;
//! * [`tables`]: Pareto front, CSV, Markdown table and plot;
//! * [`sudhamani`]: Sudhamani & Merriliance's experiments and their tables.

use std::path::PathBuf;

use anyhow::{Context, anyhow};

mod runs;
mod speed;
mod sudhamani;
mod tables;

use crate::cli::{Classify, Failure};
use bulge::io::write_atomic;

/// Pressure on the disc bubble, Pa.
const DISC_P: f64 = 5000.0;
/// Free radius of the disc bubble, m.
const A: f64 = 0.0375;
/// Thickness of the disc bubble, m.
const T: f64 = 0.35e-3;

/// Flags of `bulge bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder for bench.csv, bench.md and bench.png (created; files in
    /// it with those names are replaced). Default `bench`.
    #[arg(long, default_value = "bench")]
    pub out: PathBuf,
    /// Small meshes and one tolerance only: a few seconds (for tests and a
    /// first look). The default set takes one to two minutes in a release
    /// build on one core.
    #[arg(long)]
    pub quick: bool,
    /// Also reproduce Sudhamani & Merriliance's (2019) experiments (time against points, largest
    /// stable step per integrator, deformation against load) and the disc's
    /// pressure step into sudhamani-merriliance.md. Several minutes (less with --quick).
    #[arg(long)]
    pub sudhamani_merriliance: bool,
}

/// Runs `bulge bench`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out, "--out")?;
    if args.out.exists() && !args.out.is_dir() {
        return Err(Failure::BadInput(anyhow!(
            "--out {} is a file; give a folder (it is created if missing)",
            args.out.display()
        )));
    }
    let entries = speed::run_bench(args.quick).failed()?;
    let csv = tables::csv(&entries);
    let md = tables::markdown(&entries);
    let fig = tables::plot(&entries);
    let paper = if args.sudhamani_merriliance {
        Some(sudhamani::markdown(args.quick).failed()?)
    } else {
        None
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))
        .failed()?;
    csv.write(&args.out.join("bench.csv"))
        .context("writing bench.csv")
        .failed()?;
    write_atomic(&args.out.join("bench.md"), md.as_bytes())
        .context("writing bench.md")
        .failed()?;
    fig.write_png(&args.out.join("bench.png"))
        .map_err(|e| anyhow!("{e}"))
        .failed()?;
    if let Some(p) = &paper {
        write_atomic(&args.out.join("sudhamani-merriliance.md"), p.as_bytes())
            .context("writing sudhamani-merriliance.md")
            .failed()?;
    }
    println!("{md}");
    if let Some(p) = &paper {
        println!("{p}");
    }
    println!(
        "wrote {}/bench.csv, bench.md, bench.png{}",
        args.out.display(),
        if paper.is_some() {
            ", sudhamani-merriliance.md"
        } else {
            ""
        }
    );
    Ok(())
}
