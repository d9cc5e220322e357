//! A run written into its locked folder, stage by stage: the files of every
//! stage that finished, as one set, and a failure that names its stage and
//! says where the earlier outputs are. `bulge run`, `bulge study` and the
//! Python package run through it.

use std::path::Path;

use crate::Refusal;
use crate::experiment::Experiment;
use crate::pipeline::{self, Observer, PipelineError, RunOutput, Settings, Stage};
use crate::report::out_dir::{OutDir, OutDirError};
use crate::report::run_files::{OutFile, RunFiles, run_files, stage_files};

/// A stage that refused its input (`bad`) or failed, in words that name it
/// and the folder holding the outputs of the stages before it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct StageFailure {
    /// The user's input was refused (exit status 2), not the work.
    pub bad: bool,
    /// The stage, what went wrong and where the earlier outputs are.
    pub message: String,
}

impl Refusal for StageFailure {
    fn is_bad_input(&self) -> bool {
        self.bad
    }
}

impl StageFailure {
    /// `e` of `stage`, the earlier outputs being in `out`.
    pub fn of(stage: Stage, out: &Path, e: PipelineError) -> StageFailure {
        let bad = e.is_bad_input();
        StageFailure {
            bad,
            message: format!(
                "stage `{}` {}: {e} (the outputs of the earlier stages are kept in {})",
                stage.name(),
                if bad { "refused its input" } else { "failed" },
                out.display()
            ),
        }
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
) -> Result<Done, StageFailure> {
    let out = dir.path();
    let written =
        |e: OutDirError| StageFailure::of(Stage::Report, out, PipelineError::Output(e.to_string()));
    let o = match pipeline::run_observed(exp, s, obs) {
        Ok(o) => o,
        Err(e) => {
            let p = &e.partial;
            let files = stage_files(p.tracking.as_ref(), p.stress.as_ref(), p.fit.as_ref())
                .map_err(|err| StageFailure::of(e.stage, out, err))?;
            dir.write_set(&files, &format!("stopped at stage {}", e.stage.name()))
                .map_err(written)?;
            return Err(StageFailure::of(e.stage, out, e.error));
        }
    };
    let mut files = run_files(exp, s, &o).map_err(|e| StageFailure::of(Stage::Report, out, e))?;
    files
        .files
        .extend(extra(&o).map_err(|e| StageFailure::of(Stage::Report, out, e))?);
    let status = if o.unsolved().is_empty() {
        "complete"
    } else {
        "partial"
    };
    dir.write_set(&files.files, status).map_err(written)?;
    Ok(Done { output: o, files })
}
