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
use bulge::report::run_files::settings_table;
use bulge::report::study_files::{StudyInfo, study_files};
use bulge::study::{RECORD, combine, in_parallel, members};

mod specimen;
use specimen::{Outcome, one};

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

    let mut info = StudyInfo {
        title: read.title,
        law: first.settings.fit.label(),
        ..StudyInfo::default()
    };
    let mut failures = Vec::new();
    let mut records = Vec::new();
    for (m, o) in members.iter().zip(outcomes) {
        match o {
            Outcome::Reused(r) => {
                eprintln!(
                    "  reused  {}: inputs and settings unchanged, read back from {}",
                    m.name,
                    out.join("specimens").join(&m.name).join(RECORD).display()
                );
                info.reused.push(m.name.clone());
                records.push((m.name.clone(), r));
            }
            Outcome::Done(r, secs) => {
                eprintln!("  done    {} in {secs:.1} s", m.name);
                records.push((m.name.clone(), r));
            }
            Outcome::Failed(f) => {
                eprintln!("  failed  {}: {:#}", m.name, f.error());
                info.failed
                    .push((m.name.clone(), format!("{:#}", f.error())));
                failures.push(f);
            }
        }
    }
    if !info.reused.is_empty() {
        eprintln!(
            "reused {} of {} specimens ({}); --redo redoes them",
            info.reused.len(),
            members.len(),
            info.reused.join(", ")
        );
    }
    if records.len() < 2 {
        let msg = anyhow!(
            "the study needs two specimens or more and only {} of {} finished (see the failures above); nothing written to {} besides the specimens' folders",
            records.len(),
            members.len(),
            out.display()
        );
        return Err(
            if failures.iter().all(|f| matches!(f, Failure::BadInput(_))) {
                Failure::BadInput(msg)
            } else {
                Failure::Failed(msg)
            },
        );
    }
    if !failures.is_empty() {
        eprintln!(
            "going on with the {} specimens that finished; {} left out: {}",
            records.len(),
            info.failed.len(),
            names(&info.failed)
        );
    }
    let c = combine(&records).map_err(|e| Failure::BadInput(e.into()))?;
    if let Some(e) = &c.joint_failed {
        eprintln!("no joint fit of the specimens' heights: {e}");
    }
    info.thickness_m = c.thickness_m;
    info.joint = c.joint;
    let study = c.study;
    info.settings = settings_table(&first.settings, &first.exp, &[])
        .into_iter()
        .filter(|(k, _)| k != "experiment" && !k.starts_with("pressures"))
        .collect();
    info.settings.push((
        "specimens".into(),
        members
            .iter()
            .map(|m| format!("{}: {}", m.name, m.exp.path.display()))
            .collect::<Vec<_>>()
            .join("; "),
    ));
    let files = study_files(&study, &info).map_err(|e| Failure::Failed(e.into()))?;
    let status = match failures.is_empty() {
        true => "complete".to_string(),
        false => format!(
            "partial: {} of {} specimens",
            study.specimens.len(),
            members.len()
        ),
    };
    top.write_set(&files.files, &status)
        .map_err(|e| Failure::Failed(e.into()))?;
    print!("\n{}", files.terminal);
    println!("\nwrote {}", out.join("study.html").display());
    if !failures.is_empty() {
        return Err(Failure::Failed(anyhow!(
            "the study is partial: {} left out ({}; see above); the study of the {} others is in {}",
            info.failed.len(),
            names(&info.failed),
            study.specimens.len(),
            out.display()
        )));
    }
    Ok(())
}
