//! One specimen of a study: read back from its record when its inputs and
//! settings are unchanged, or run into its own folder with a progress bar.

use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::anyhow;
use indicatif::{MultiProgress, ProgressBar};

use super::super::run::{Done, run_into};
use super::super::{Failure, progress};
use bulge::pipeline::{Observer, PipelineError, Stage, Timing};
use bulge::report::out_dir::OutDir;
use bulge::report::run_files::OutFile;
use bulge::study::{Member, RECORD, Record, record, reusable};

/// What became of one specimen.
pub(super) enum Outcome {
    Reused(Record),
    Done(Record, f64),
    Failed(Failure),
}

/// One bar per specimen: its name, the current stage and its steps.
struct Bar {
    name: String,
    bar: ProgressBar,
}

impl Observer for Bar {
    fn start(&self, stage: Stage, steps: u64) {
        self.bar.set_length(steps.max(1));
        self.bar.set_position(0);
        self.bar
            .set_message(format!("{} {}", self.name, stage.name()));
    }
    fn tick(&self) {
        self.bar.inc(1);
    }
    fn done(&self, t: &Timing) {
        self.bar.set_position(self.bar.length().unwrap_or(1));
        self.bar
            .set_message(format!("{} {} done", self.name, t.stage.name()));
    }
}

/// One specimen: read back, or run into its folder.
pub(super) fn one(m: &Member, out: &Path, redo: bool, bars: &MultiProgress) -> Outcome {
    let dir = out.join("specimens").join(&m.name);
    if !redo && let Some(r) = reusable(&dir, m) {
        return Outcome::Reused(r);
    }
    let lock = match OutDir::lock(&dir) {
        Ok(d) => d,
        Err(e) => return Outcome::Failed(Failure::of(e)),
    };
    let obs = Bar {
        name: m.name.clone(),
        bar: bars.add(progress(1, &m.name)),
    };
    let t = Instant::now();
    let rec: Mutex<Option<Record>> = Mutex::new(None);
    let result = run_into(&m.exp, &m.settings, &lock, &obs, |o| {
        let r = record(m, o)?;
        let text = bulge::io::to_toml_string(&r)
            .map_err(|e| PipelineError::Output(format!("{RECORD}: {e}")))?;
        *rec.lock().expect("record") = Some(r);
        Ok(vec![OutFile {
            name: RECORD,
            stage: Stage::Report,
            bytes: text.into_bytes(),
        }])
    });
    obs.bar.finish_and_clear();
    match result {
        Ok(Done { .. }) => match rec.into_inner().expect("record") {
            Some(r) => Outcome::Done(r, t.elapsed().as_secs_f64()),
            None => Outcome::Failed(Failure::Failed(anyhow!("no record written"))),
        },
        Err(f) => Outcome::Failed(f),
    }
}
