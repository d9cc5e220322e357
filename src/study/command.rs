//! `bulge study` into a folder, for the command line and the Python package
//! alike: each specimen read back from its record or run into
//! `specimens/<name>/` ([`one`]), then the material across those that
//! finished, written as one set ([`finish`]). What the command line prints
//! between is returned as lines, in order.

use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

use super::{Member, RECORD, Record, combine, record, reusable};
use crate::Refusal;
use crate::pipeline::{Observer, PipelineError, Stage};
use crate::report::out_dir::OutDir;
use crate::report::run_dir::{Done, StageFailure, run_into};
use crate::report::run_files::{OutFile, settings_table};
use crate::report::study_files::{StudyInfo, study_files};

/// What became of one specimen.
pub enum Outcome {
    /// Its inputs and settings did not change: read back from its record.
    Reused(Record),
    /// Run, in this many seconds.
    Done(Record, f64),
    /// Its run stopped, or its folder could not be taken.
    Failed(StageFailure),
}

/// One specimen: read back from `out/specimens/<name>/` when its inputs and
/// settings did not change (unless `redo`), else run into that folder,
/// telling `obs`.
pub fn one(m: &Member, out: &Path, redo: bool, obs: &dyn Observer) -> Outcome {
    let dir = out.join("specimens").join(&m.name);
    if !redo && let Some(r) = reusable(&dir, m) {
        return Outcome::Reused(r);
    }
    let lock = match OutDir::lock(&dir) {
        Ok(d) => d,
        Err(e) => {
            return Outcome::Failed(StageFailure {
                bad: e.is_bad_input(),
                message: crate::io::chain(&e),
            });
        }
    };
    let t = Instant::now();
    let rec: Mutex<Option<Record>> = Mutex::new(None);
    let result = run_into(&m.exp, &m.settings, &lock, obs, |o| {
        let r = record(m, o)?;
        let text = crate::io::to_toml_string(&r)
            .map_err(|e| PipelineError::Output(format!("{RECORD}: {e}")))?;
        *rec.lock().expect("record") = Some(r);
        Ok(vec![OutFile {
            name: RECORD,
            stage: Stage::Report,
            bytes: text.into_bytes(),
        }])
    });
    match result {
        Ok(Done { .. }) => match rec.into_inner().expect("record") {
            Some(r) => Outcome::Done(r, t.elapsed().as_secs_f64()),
            None => Outcome::Failed(StageFailure {
                bad: false,
                message: "no record written".into(),
            }),
        },
        Err(f) => Outcome::Failed(f),
    }
}

/// A study written: its files, what to print, and the specimens left out.
pub struct Finished {
    /// The study's table in the terminal.
    pub terminal: String,
    /// The files written into the folder (study.csv, study.html, ...).
    pub files: Vec<OutFile>,
    /// Specimens left out, with why.
    pub failed: Vec<(String, String)>,
    /// Specimens in the study.
    pub kept: usize,
}

/// The material across the specimens of `members` that finished
/// (`outcomes`, in the same order), written as one set into the locked
/// folder `top`, and what the command line prints as it goes (reused,
/// done, failed, the joint fit's failure), in order. Fewer than two
/// finished: nothing is written and the failure says so (bad input when
/// every failure was).
pub fn finish(
    members: &[Member],
    outcomes: Vec<Outcome>,
    title: String,
    top: &OutDir,
) -> (Vec<String>, Result<Finished, StageFailure>) {
    let mut log = Vec::new();
    let result = gather_and_write(members, outcomes, title, top, &mut log);
    (log, result)
}

fn gather_and_write(
    members: &[Member],
    outcomes: Vec<Outcome>,
    title: String,
    top: &OutDir,
    log: &mut Vec<String>,
) -> Result<Finished, StageFailure> {
    let out = top.path();
    let mut info = StudyInfo {
        title,
        law: members[0].settings.fit.label(),
        ..StudyInfo::default()
    };
    let mut all_bad = true;
    let mut records = Vec::new();
    for (m, o) in members.iter().zip(outcomes) {
        match o {
            Outcome::Reused(r) => {
                log.push(format!(
                    "  reused  {}: inputs and settings unchanged, read back from {}",
                    m.name,
                    out.join("specimens").join(&m.name).join(RECORD).display()
                ));
                info.reused.push(m.name.clone());
                records.push((m.name.clone(), r));
            }
            Outcome::Done(r, secs) => {
                log.push(format!("  done    {} in {secs:.1} s", m.name));
                records.push((m.name.clone(), r));
            }
            Outcome::Failed(f) => {
                log.push(format!("  failed  {}: {}", m.name, f.message));
                info.failed.push((m.name.clone(), f.message.clone()));
                all_bad &= f.bad;
            }
        }
    }
    let names = |failed: &[(String, String)]| {
        failed
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !info.reused.is_empty() {
        log.push(format!(
            "reused {} of {} specimens ({}); --redo redoes them",
            info.reused.len(),
            members.len(),
            info.reused.join(", ")
        ));
    }
    if records.len() < 2 {
        return Err(StageFailure {
            bad: all_bad,
            message: format!(
                "the study needs two specimens or more and only {} of {} finished (see the failures above); nothing written to {} besides the specimens' folders",
                records.len(),
                members.len(),
                out.display()
            ),
        });
    }
    if !info.failed.is_empty() {
        log.push(format!(
            "going on with the {} specimens that finished; {} left out: {}",
            records.len(),
            info.failed.len(),
            names(&info.failed)
        ));
    }
    let c = combine(&records).map_err(|e| StageFailure {
        bad: true,
        message: crate::io::chain(&e),
    })?;
    if let Some(e) = &c.joint_failed {
        log.push(format!("no joint fit of the specimens' heights: {e}"));
    }
    info.thickness_m = c.thickness_m;
    info.joint = c.joint;
    let study = c.study;
    let first = &members[0];
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
    let files = study_files(&study, &info).map_err(|e| StageFailure {
        bad: false,
        message: crate::io::chain(&e),
    })?;
    let status = match info.failed.is_empty() {
        true => "complete".to_string(),
        false => format!(
            "partial: {} of {} specimens",
            study.specimens.len(),
            members.len()
        ),
    };
    top.write_set(&files.files, &status)
        .map_err(|e| StageFailure {
            bad: false,
            message: crate::io::chain(&e),
        })?;
    Ok(Finished {
        terminal: files.terminal,
        files: files.files,
        failed: info.failed,
        kept: study.specimens.len(),
    })
}
