//! `bulge run`: the whole pipeline on an experiment file, with the comparison
//! report. Chains the library stages of [`bulge::pipeline`] (track,
//! stress, fit, simulate) and writes each stage's outputs whole as soon as
//! the stage is done, so that a failed stage leaves the earlier outputs and
//! a message naming the stage.

use std::path::Path;

use anyhow::anyhow;

use super::{Console, Failure};
use bulge::Refusal;
use bulge::experiment::Experiment;
use bulge::io::OutputPlan;
use bulge::pipeline::{self, Observer, PipelineError, RunOptions, RunOutput, Settings, Stage};
use bulge::report::out_dir::{OutDir, OutDirError};
use bulge::report::run_files::{OutFile, RunFiles, run_files, stage_files};

mod args;
pub use args::*;

/// `flags` over the experiment file's `[run]`/`[simulate]` tables over the
/// defaults.
pub fn settings(flags: RunOptions, exp: &Experiment) -> Result<Settings, Failure> {
    let file = RunOptions::from_experiment(exp).map_err(|e| Failure::BadInput(e.into()))?;
    flags
        .or(file)
        .settings()
        .map_err(|e| Failure::BadInput(anyhow!("{}: {e}", exp.path.display())))
}

/// A failed stage: the message names it and says where the earlier outputs are.
fn stage_failure(stage: Stage, out: &Path, e: PipelineError) -> Failure {
    let bad = e.is_bad_input();
    let msg = anyhow!(
        "stage `{}` {}: {e} (the outputs of the earlier stages are kept in {})",
        stage.name(),
        if bad { "refused its input" } else { "failed" },
        out.display()
    );
    if bad {
        Failure::BadInput(msg)
    } else {
        Failure::Failed(msg)
    }
}

/// A finished run into its locked folder: the pipeline's output and its files.
pub struct Done {
    /// Every stage's output.
    pub output: RunOutput,
    /// The files written (and the terminal table).
    pub files: RunFiles,
}

/// `exp` through the whole pipeline with `s`, telling `obs`; every file of
/// the run (with `extra`'s files of the finished run) written as one set
/// into `dir`. A stopped run writes the files of the stages that finished
/// and returns the failure naming the stage.
pub fn run_into(
    exp: &Experiment,
    s: &Settings,
    dir: &OutDir,
    obs: &dyn Observer,
    extra: impl FnOnce(&RunOutput) -> Result<Vec<OutFile>, PipelineError>,
) -> Result<Done, Failure> {
    let out = dir.path();
    let written =
        |e: OutDirError| stage_failure(Stage::Report, out, PipelineError::Output(e.to_string()));
    let o = match pipeline::run_observed(exp, s, obs) {
        Ok(o) => o,
        Err(e) => {
            let p = &e.partial;
            let files = stage_files(p.tracking.as_ref(), p.stress.as_ref(), p.fit.as_ref())
                .map_err(|err| stage_failure(e.stage, out, err))?;
            dir.write_set(&files, &format!("stopped at stage {}", e.stage.name()))
                .map_err(written)?;
            return Err(stage_failure(e.stage, out, e.error));
        }
    };
    let mut files = run_files(exp, s, &o).map_err(|e| stage_failure(Stage::Report, out, e))?;
    files
        .files
        .extend(extra(&o).map_err(|e| stage_failure(Stage::Report, out, e))?);
    let status = if o.unsolved().is_empty() {
        "complete"
    } else {
        "partial"
    };
    dir.write_set(&files.files, status).map_err(written)?;
    Ok(Done { output: o, files })
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
    let Done { output: o, files } = result?;
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
