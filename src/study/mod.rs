//! A study: one material across several specimens. Each specimen goes
//! through the whole pipeline ([`crate::pipeline::run_observed`]); what the
//! study keeps of it is a [`Record`] (its corrected parameters, covariance
//! and the heights they were corrected to), written beside its run as
//! [`RECORD`] with the [`fingerprint`] of what it was made from, so that a
//! specimen whose inputs and settings did not change is read back rather
//! than redone. [`crate::fit::study::gather`] and
//! [`crate::fit::study::joint`] then give the material across specimens.
//!
//! Files: `file` reads the study file or a list of experiment files;
//! `record` is the per-specimen record and its fingerprint; this file holds
//! the specimens' settings and the scheduler.

#[cfg(feature = "plots")]
pub mod command;
mod file;
mod record;

pub use file::{StudyInputs, input_files, read};
pub use record::{Height, RECORD, Record, fingerprint, record, reusable};

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::experiment::Experiment;
use crate::fit::inverse::{self, Measured};
use crate::fit::study::{SpecimenFit, Study, StudyInput, gather, joint};
use crate::fit::{FitError, FitModel};
use crate::io::InputError;
use crate::pipeline::{RunOptions, Settings};

/// A specimen of the study, read, with the settings it runs with.
#[derive(Debug, Clone)]
pub struct Member {
    /// Its name (its output folder's).
    pub name: String,
    /// Its experiment.
    pub exp: Experiment,
    /// The settings of its run.
    pub settings: Settings,
    /// The fingerprint of its inputs and settings.
    pub fingerprint: String,
}

/// The members of a study from what was read and the settings each gets
/// (`settings_of`: the shared options over each experiment's own). A study
/// fits one law to every specimen: with the law left to the heights
/// ([`FitModel::Auto`]) each specimen could choose its own, so a study keeps
/// the paper's polynomial E(eps) (the experiment's degree, else 4) unless a
/// law is named; two specimens that name different laws are refused.
pub fn members<E>(
    read: Vec<(String, Experiment)>,
    shared: &RunOptions,
    mut settings_of: impl FnMut(&Experiment) -> Result<Settings, E>,
) -> Result<Vec<Member>, E>
where
    E: From<InputError>,
{
    let mut out: Vec<Member> = Vec::new();
    for (name, exp) in read {
        let mut s = settings_of(&exp)?;
        if s.fit == FitModel::Auto {
            let degree = shared
                .degree
                .or_else(|| RunOptions::from_experiment(&exp).ok()?.degree)
                .unwrap_or(4);
            s.fit = FitModel::Quartic { degree };
        }
        let fingerprint = fingerprint(&exp, &s);
        out.push(Member {
            name,
            exp,
            settings: s,
            fingerprint,
        });
    }
    if let Some(first) = out.first()
        && let Some(m) = out.iter().find(|m| m.settings.fit != first.settings.fit)
    {
        return Err(InputError::file(
            &m.exp.path,
            format!(
                "specimen {} fits {} but {} fits {}: a study fits one law to every specimen; set `fit` in the study file's [run] table or give {}",
                m.name,
                m.settings.fit.label(),
                first.name,
                first.settings.fit.label(),
                crate::setting::Setting::Fit
            ),
        )
        .into());
    }
    Ok(out)
}

/// `f` on every member, on as many threads of their own as rayon has
/// workers, each taking the next member when done; the results in the
/// members' order. Not on rayon's workers: the tracker waits on its own
/// rayon jobs (the photos it decodes), which a pool whose every worker
/// waits so would never run.
pub fn in_parallel<T: Send>(members: &[Member], f: impl Fn(&Member) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<T>>> = members.iter().map(|_| Mutex::new(None)).collect();
    let threads = rayon::current_num_threads().clamp(1, members.len().max(1));
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(m) = members.get(i) else { break };
                    *slots[i].lock().expect("result slot") = Some(f(m));
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|s| {
            s.into_inner()
                .expect("result slot")
                .expect("every member done")
        })
        .collect()
}

/// The material across the specimens that finished.
#[derive(Debug, Clone)]
pub struct Combined {
    /// Mean, scatter, interval and pooled value of each parameter.
    pub study: Study,
    /// Each specimen's thickness as used, m.
    pub thickness_m: Vec<f64>,
    /// One law fitted to every specimen's heights together (values and
    /// standard errors), when every record kept its heights.
    pub joint: Option<(Vec<f64>, Option<Vec<f64>>)>,
    /// Why the joint fit was tried and failed.
    pub joint_failed: Option<FitError>,
}

/// The study of the finished specimens' records (`(name, record)`, two or
/// more): [`gather`] of their parameters, and the joint fit of their
/// heights from the first one's corrected law.
pub fn combine(records: &[(String, Record)]) -> Result<Combined, FitError> {
    let names = records
        .first()
        .map(|(_, r)| r.parameters.clone())
        .unwrap_or_default();
    let fits = records
        .iter()
        .map(|(n, r)| SpecimenFit {
            name: n.clone(),
            values: r.values.clone(),
            std_errors: r.std_errors.clone(),
            outlier: vec![],
        })
        .collect();
    let study = gather(names, fits)?;
    let inputs: Vec<StudyInput> = records
        .iter()
        .filter(|(_, r)| !r.heights.is_empty())
        .map(|(n, r)| StudyInput {
            name: n.clone(),
            specimen: r.specimen,
            measured: r
                .heights
                .iter()
                .map(|h| Measured {
                    pressure_pa: h.pressure_pa,
                    height_m: h.height_m,
                    height_std_m: h.height_std_m,
                })
                .collect(),
            options: inverse::Options::default(),
        })
        .collect();
    let (mut joint_fit, mut joint_failed) = (None, None);
    if inputs.len() == records.len() {
        match joint(&inputs, &records[0].1.material) {
            Ok(j) if j.names == study.names => joint_fit = Some((j.values, j.std_errors)),
            Ok(_) => {}
            Err(e) => joint_failed = Some(e),
        }
    }
    Ok(Combined {
        study,
        thickness_m: records.iter().map(|(_, r)| r.thickness_m).collect(),
        joint: joint_fit,
        joint_failed,
    })
}
