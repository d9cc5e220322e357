//! `bulge run`: the whole pipeline on an experiment file, with the comparison
//! report ([`bulge::report::run_dir::run_into`]: the library stages of
//! [`bulge::pipeline`] chained, each stage's outputs written whole as soon
//! as the stage is done, so that a failed stage leaves the earlier outputs
//! and a message naming the stage).

use anyhow::anyhow;

use super::{Console, Failure};
use bulge::Refusal;
use bulge::experiment::Experiment;
use bulge::io::OutputPlan;
use bulge::pipeline::{RunOptions, Settings, Stage};
use bulge::report::out_dir::OutDir;
use bulge::report::run_dir::{Done, StageFailure, run_into};

mod args;
pub use args::*;

/// `flags` over the experiment file's `[run]`/`[simulate]` tables over the
/// defaults.
pub fn settings(flags: RunOptions, exp: &Experiment) -> Result<Settings, Failure> {
    flags
        .settings_for(exp)
        .map_err(|e| Failure::BadInput(e.into()))
}

/// A stage's failure as the command line's.
pub fn failure(f: StageFailure) -> Failure {
    match f.bad {
        true => Failure::BadInput(anyhow!(f.message)),
        false => Failure::Failed(anyhow!(f.message)),
    }
}

/// Runs `bulge run`.
pub fn run(args: Args) -> Result<(), Failure> {
    let exp = Experiment::read(&args.experiment)?;
    let s = settings(args.flags.options(), &exp)?;
    let plan = OutputPlan::new().inputs(super::experiment_inputs(&exp));
    super::guard(plan.output_as("--out", &args.out))?;
    let out = args.out.as_path();
    let dir = OutDir::lock(out).map_err(|e| match e.is_bad_input() {
        true => Failure::BadInput(anyhow!("--out: {e}")),
        false => Failure::Failed(e.into()),
    })?;
    if let Some(h) = dir.taken_over() {
        eprintln!(
            "note: {} held the lock file of a run that ended without removing it ({h}); taken over",
            out.display()
        );
    }
    let console = Console::default();
    let result = run_into(&exp, &s, &dir, &console, |_| Ok(vec![]));
    console.clear();
    let Done { output: o, files } = result.map_err(failure)?;
    for w in &o.fit.warnings {
        eprintln!("         warning: {w}");
    }
    for n in o
        .notes
        .iter()
        .filter(|n| n.stage == Stage::Simulate)
        .map(|n| &n.text)
    {
        eprintln!("         note: {n}");
    }
    let unsolved = o.unsolved();
    eprintln!(
        "[5/5] {:<8} heights.svg, heights.png, report.html, summary.md",
        Stage::Report.name()
    );
    print!("{}", files.terminal);
    println!("\nwrote {}", out.join("report.html").display());
    if !unsolved.is_empty() {
        return Err(Failure::Failed(anyhow!(
            "the run is partial: {} simulated heights are missing (see the notes above and in the report); the outputs are in {}",
            unsolved.len(),
            out.display()
        )));
    }
    Ok(())
}
