//! `bulge study`: one material across several specimens. Every specimen
//! goes through the whole pipeline (`bulge run`'s, written as `bulge run`
//! writes it under `DIR/specimens/<name>/`), in parallel; then
//! [`bulge::fit::study::gather`] gives the parameters' mean, scatter, the
//! 95 % interval of the mean, the pooled value and the outliers
//! (`study.csv`, `study.html`). A specimen whose inputs and settings did
//! not change since the last study into the same folder is read back, not
//! redone.

use std::path::PathBuf;

use anyhow::anyhow;
use indicatif::MultiProgress;

use super::run::{RunFlags, settings};
use super::{Failure, experiment_inputs};
use bulge::Refusal;
use bulge::io::OutputPlan;
use bulge::report::out_dir::OutDir;
use bulge::study::command::finish;
use bulge::study::{in_parallel, members};

mod specimen;
use specimen::one;

/// Flags of `bulge study`.
///
/// Example: `bulge study study.toml --out out/`, or
/// `bulge study s1/experiment.toml s2/experiment.toml s3/experiment.toml --out out/`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "A study file lists the specimens' experiment files (paths relative to the study file) and, \
optionally, settings shared by all in a [run] table (the keys of bulge run's [run] table; a flag overrides it, \
and it overrides each experiment's own [run]):

  [run]
  fit = \"mooney-rivlin\"

  [[specimens]]
  experiment = \"s1/experiment.toml\"
  name = \"s1\"      # optional; default: the experiment file's folder

Writes into --out: study.csv (one row per specimen, then mean, std, cv, ci95_low, ci95_high, pooled, joint), \
study.svg/png, study.html, and each specimen's run under specimens/<name>/ (the files of bulge run, with \
study_fit.toml: its corrected parameters, covariance and the fingerprint of its inputs). A specimen whose \
experiment file, input files (sizes and times, small ones by content) and settings did not change is read back \
from study_fit.toml instead of being redone. A failed specimen is left out when two others remain: the study is \
written and the exit status is 1. Exit status 2 when an input is refused."
)]
pub struct Args {
    /// A study file (TOML with [[specimens]] experiment = "..." and an
    /// optional [run] table), or two or more experiment files. Never
    /// written to.
    #[arg(required = true, num_args = 1.., value_name = "STUDY_OR_EXPERIMENTS")]
    pub inputs: Vec<PathBuf>,

    /// Output folder (created if missing; files of the same names are
    /// replaced). Required: bulge does not guess where to write.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Redo every specimen, even those whose inputs and settings did not
    /// change since the last study into --out.
    #[arg(long)]
    pub redo: bool,

    /// The settings shared by every specimen (each also a key of the study
    /// file's [run] table).
    #[command(flatten)]
    pub flags: RunFlags,
}

/// The names of the specimens left out, for messages.
fn names(failed: &[(String, String)]) -> String {
    failed
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs `bulge study`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out, "--out")?;
    let read = bulge::study::read(&args.inputs)?;
    let flags = args.flags.options().or(read.shared);
    let members = members(read.members, &flags, |exp| settings(flags.clone(), exp))?;
    let first = &members[0];
    let mut plan = OutputPlan::new().inputs(&args.inputs);
    for m in &members {
        plan = plan.inputs(experiment_inputs(&m.exp));
    }
    super::guard(plan.output_as("--out", &args.out))?;
    let out = args.out.as_path();
    let top = OutDir::lock(out).map_err(|e| match e.is_bad_input() {
        true => Failure::BadInput(anyhow!("--out: {e}")),
        false => Failure::Failed(e.into()),
    })?;
    if let Some(h) = top.taken_over() {
        eprintln!(
            "note: {} held the lock file of a study that ended without removing it ({h}); taken over, and the study resumed",
            out.display()
        );
    }
    eprintln!(
        "{} specimens, {} law corrected to each one's heights, into {}",
        members.len(),
        first.settings.fit.label(),
        out.join("specimens").display()
    );
    let bars = MultiProgress::new();
    let outcomes = in_parallel(&members, |m| one(m, out, args.redo, &bars));
    let _ = bars.clear();
    let (log, done) = finish(&members, outcomes, read.title, &top);
    for line in &log {
        eprintln!("{line}");
    }
    let f = done.map_err(super::run::failure)?;
    print!("\n{}", f.terminal);
    println!("\nwrote {}", out.join("study.html").display());
    if !f.failed.is_empty() {
        return Err(Failure::Failed(anyhow!(
            "the study is partial: {} left out ({}; see above); the study of the {} others is in {}",
            f.failed.len(),
            names(&f.failed),
            f.kept,
            out.display()
        )));
    }
    Ok(())
}
