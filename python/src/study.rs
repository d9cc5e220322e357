//! `study`: one material across several specimens, into a folder, through
//! the library's `bulge study` ([`bulge::study::command`]).

use std::path::PathBuf;

use bulge::Refusal;
use bulge::io::{OutputPlan, chain};
use bulge::pipeline::RunOptions;
use bulge::report::out_dir::OutDir;
use bulge::study::command::{finish, one};
use bulge::study::{in_parallel, members};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use super::{Counter, bad, failed, to_toml};

/// The study's files (name, bytes), its table for the terminal, the lines
/// the command line prints as it goes and the specimens left out.
type StudyResult = (
    Vec<(String, Py<PyBytes>)>,
    String,
    Vec<String>,
    Vec<(String, String)>,
);

/// `bulge study` of a study file or of two or more experiment files into
/// the folder `out`; `settings` are keys of the `[run]` table shared by
/// every specimen; `progress(done, total)` is called as each specimen ends.
#[pyfunction]
#[pyo3(signature = (inputs, out, redo=false, settings=None, progress=None))]
pub fn study(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    out: PathBuf,
    redo: bool,
    settings: Option<Bound<'_, PyDict>>,
    progress: Option<PyObject>,
) -> PyResult<StudyResult> {
    let given = match settings {
        Some(d) => to_toml("settings", d.as_any())?
            .try_into::<RunOptions>()
            .map_err(|e| bad(format!("settings: {}", e.message())))?,
        None => RunOptions::default(),
    };
    if out.exists() && !out.is_dir() {
        return Err(bad(format!(
            "out={} is a file: give a folder for the outputs",
            out.display()
        )));
    }
    let work = move || -> Result<_, (bool, String)> {
        let refused = |m: String| (true, m);
        let read = bulge::study::read(&inputs).map_err(|e| refused(chain(&e)))?;
        let flags = given.or(read.shared);
        let members = members(read.members, &flags, |exp| flags.clone().settings_for(exp))
            .map_err(|e| refused(chain(&e)))?;
        let mut plan = OutputPlan::new().inputs(&inputs);
        for m in &members {
            plan = plan.inputs(bulge::study::input_files(&m.exp));
        }
        plan.output_as("out", &out)
            .check()
            .map_err(|e| refused(format!("{e} (inputs are never overwritten)")))?;
        let top = OutDir::lock(&out).map_err(|e| match e.is_bad_input() {
            true => refused(format!("out: {}", chain(&e))),
            false => (false, chain(&e)),
        })?;
        let counter = Counter::new(progress, members.len());
        let outcomes = in_parallel(&members, |m| {
            let o = one(m, &out, redo, &());
            counter.tick();
            o
        });
        let (log, result) = finish(&members, outcomes, read.title, &top);
        let f = result.map_err(|f| (f.bad, f.message))?;
        let files: Vec<(String, Vec<u8>)> = f
            .files
            .into_iter()
            .map(|o| (o.name.to_string(), o.bytes))
            .collect();
        Ok((files, f.terminal, log, f.failed))
    };
    match py.allow_threads(work) {
        Ok((files, terminal, log, failed_specimens)) => Ok((
            files
                .into_iter()
                .map(|(n, b)| (n, PyBytes::new(py, &b).unbind()))
                .collect(),
            terminal,
            log,
            failed_specimens,
        )),
        Err((true, m)) => Err(bad(m)),
        Err((false, m)) => Err(failed(m)),
    }
}
