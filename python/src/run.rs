//! `run`: the whole pipeline on an experiment file (`bulge run` without
//! writing files): track, stress, fit, simulate and the report's files.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use bulge::Refusal;
use bulge::experiment::Experiment;
use bulge::pipeline::{self, Observer, RunOptions, Stage};
use bulge::report::run_files::run_files;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use super::{File, bad, chain, failed, to_toml};

/// The outcome of the work done without the GIL.
enum Outcome {
    Done {
        files: Vec<(String, String, Vec<u8>)>,
        notes: Vec<(String, String)>,
        warnings: Vec<String>,
        unsolved: Vec<f64>,
    },
    Bad(String),
    Failed(String),
}

fn stage_message(stage: Stage, e: &pipeline::PipelineError) -> Outcome {
    let verb = if e.is_bad_input() {
        "refused its input"
    } else {
        "failed"
    };
    let msg = format!("stage `{}` {verb}: {}", stage.name(), chain(e));
    if e.is_bad_input() {
        Outcome::Bad(msg)
    } else {
        Outcome::Failed(msg)
    }
}

/// Tells a Python callback `progress(stage, done, total)` as each stage
/// starts and steps.
struct Progress {
    callback: PyObject,
    stage: Mutex<(&'static str, u64)>,
    done: AtomicU64,
}

impl Progress {
    fn tell(&self, done: u64) {
        let (stage, total) = *self.stage.lock().expect("stage");
        Python::with_gil(|py| {
            // a callback's own error is printed, and the run goes on
            if let Err(e) = self.callback.call1(py, (stage, done, total)) {
                e.print(py);
            }
        });
    }
}

impl Observer for Progress {
    fn start(&self, stage: Stage, steps: u64) {
        *self.stage.lock().expect("stage") = (stage.name(), steps);
        self.done.store(0, Ordering::Relaxed);
        self.tell(0);
    }
    fn tick(&self) {
        self.tell(self.done.fetch_add(1, Ordering::Relaxed) + 1);
    }
}

fn work(experiment: PathBuf, given: RunOptions, obs: &dyn Observer) -> Outcome {
    let exp = match Experiment::read(&experiment) {
        Ok(e) => e,
        Err(e) => return Outcome::Bad(chain(&e)),
    };
    let s = match given.settings_for(&exp) {
        Ok(s) => s,
        Err(e) => return Outcome::Bad(chain(&e)),
    };
    let o = match pipeline::run_observed(&exp, &s, obs) {
        Ok(o) => o,
        Err(e) => return stage_message(e.stage, &e.error),
    };
    let files = match run_files(&exp, &s, &o) {
        Ok(f) => f,
        Err(e) => return stage_message(Stage::Report, &e),
    };
    Outcome::Done {
        files: files
            .files
            .into_iter()
            .map(|f| (f.name.to_string(), f.stage.name().to_string(), f.bytes))
            .collect(),
        notes: o
            .notes
            .iter()
            .map(|n| (n.stage.name().to_string(), n.text.clone()))
            .collect(),
        warnings: o.fit.warnings.clone(),
        unsolved: o.unsolved(),
    }
}

/// The run's files, its notes (stage, text), the fit's warnings and the
/// pressures left unsolved.
type RunResult = (Vec<File>, Vec<(String, String)>, Vec<String>, Vec<f64>);

/// Runs the whole pipeline on an experiment file (as `bulge run`), the GIL
/// released; returns the files `bulge run` writes, in memory. `settings`
/// are keys of the `[run]` table (as the command line's flags, they win
/// over the experiment file's own `[run]` and `[simulate]`).
#[pyfunction]
#[pyo3(signature = (experiment, settings=None, progress=None))]
pub fn run(
    py: Python<'_>,
    experiment: PathBuf,
    settings: Option<Bound<'_, PyDict>>,
    progress: Option<PyObject>,
) -> PyResult<RunResult> {
    let given = match settings {
        Some(d) => {
            let t = to_toml("settings", d.as_any())?;
            t.try_into::<RunOptions>()
                .map_err(|e| bad(format!("settings: {}", e.message())))?
        }
        None => RunOptions::default(),
    };
    let observer = progress.map(|callback| Progress {
        callback,
        stage: Mutex::new(("", 0)),
        done: AtomicU64::new(0),
    });
    let outcome = py.allow_threads(move || match &observer {
        Some(o) => work(experiment, given, o),
        None => work(experiment, given, &()),
    });
    match outcome {
        Outcome::Done {
            files,
            notes,
            warnings,
            unsolved,
        } => {
            let files = files
                .into_iter()
                .map(|(n, s, b)| (n, s, PyBytes::new(py, &b).unbind()))
                .collect();
            Ok((files, notes, warnings, unsolved))
        }
        Outcome::Bad(m) => Err(bad(m)),
        Outcome::Failed(m) => Err(failed(m)),
    }
}
