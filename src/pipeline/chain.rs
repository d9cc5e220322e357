//! The whole run: each stage in order, what it returns and where it stopped.

use crate::Refusal;
use std::time::Instant;

#[cfg(feature = "opencv")]
use crate::experiment::Experiment;
use crate::experiment::Specimen;
use crate::fit::inverse;
use crate::sim::springs::HeightModel;

use super::*;

/// Every stage's output of a whole run ([`run`]).
#[cfg(feature = "opencv")]
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The specimen the run used: the experiment's, with the stress-free
    /// dome height found when `prebulge_height_m = "fit"`.
    pub specimen: Specimen,
    /// Photos -> heights; `None` when the heights were measured
    /// (`[heights]`).
    pub tracking: Option<Tracking>,
    /// Heights -> stress and strain.
    pub stress: StressOut,
    /// Stress/strain -> material.
    pub fit: FitOut,
    /// The pressures simulated, Pa.
    pub pressures_pa: Vec<f64>,
    /// Simulated heights, one run per model (the axisymmetric reference last).
    pub runs: Vec<ModelRun>,
    /// Measured against simulated heights, one row per simulated pressure.
    pub comparison: Vec<Comparison>,
    /// The corrected law's heights with their standard deviations at the
    /// simulated pressures, when the law was corrected to the heights and
    /// its uncertainty found.
    pub band: Option<Vec<Option<inverse::BandPoint>>>,
    /// Per model, whether its heights agree with the measured ones within
    /// the uncertainty.
    pub verdicts: Vec<Verdict>,
    /// The paper's chain beside the chosen law, when another law was chosen.
    pub paper_chain: Option<PaperChain>,
    /// Time per stage (track, stress, fit, simulate).
    pub timings: Vec<Timing>,
    /// Remarks made along the way (frames left out, a lowered degree, the
    /// simulator's notes), each with its stage.
    pub notes: Vec<Note>,
}

#[cfg(feature = "opencv")]
impl RunOutput {
    /// The pressures at which some model found no equilibrium, Pa (a run
    /// with any is partial).
    pub fn unsolved(&self) -> Vec<f64> {
        self.runs
            .iter()
            .flat_map(|r| r.points.iter())
            .filter(|p| p.height_m.is_none())
            .map(|p| p.pressure_pa)
            .collect()
    }

    /// The run of one model, if it was simulated.
    pub fn run_of(&self, model: HeightModel) -> Option<&ModelRun> {
        self.runs.iter().find(|r| r.model == model)
    }

    /// One model's row of the error table: per compared pressure,
    /// `(pressure_pa, (simulated - measured) / measured)`, the error `None`
    /// where either height is missing; `None` when the model was not run.
    pub fn rel_errors_of(&self, model: HeightModel) -> Option<Vec<(f64, Option<f64>)>> {
        let k = self.runs.iter().position(|r| r.model == model)?;
        Some(
            self.comparison
                .iter()
                .map(|c| (c.pressure_pa, c.rel_errors()[k]))
                .collect(),
        )
    }
}

/// The outputs of the stages that finished before a run stopped.
#[cfg(feature = "opencv")]
#[derive(Debug, Clone, Default)]
pub struct Partial {
    /// The tracking stage's output, when it finished.
    pub tracking: Option<Tracking>,
    /// The stress stage's output, when it finished.
    pub stress: Option<StressOut>,
    /// The fit stage's output, when it finished.
    pub fit: Option<FitOut>,
}

/// A run that stopped: the stage, why, and what the earlier stages made.
#[cfg(feature = "opencv")]
#[derive(Debug, thiserror::Error)]
#[error("stage `{}` {}: {error}", .stage.name(), if .error.is_bad_input() { "refused its input" } else { "failed" })]
pub struct RunError {
    /// The stage that stopped.
    pub stage: Stage,
    /// Why.
    pub error: PipelineError,
    /// The outputs of the stages before it.
    pub partial: Box<Partial>,
}

/// The whole pipeline on an experiment: photos -> heights -> stress/strain
/// -> material -> simulated heights -> comparison, in memory (nothing is
/// written). See [`run_observed`] for progress and remarks.
#[cfg(feature = "opencv")]
pub fn run(exp: &Experiment, settings: &Settings) -> Result<RunOutput, RunError> {
    run_observed(exp, settings, &())
}

/// [`run`], telling `obs` of each stage's start, steps, remarks and end.
#[cfg(feature = "opencv")]
pub fn run_observed(
    exp: &Experiment,
    settings: &Settings,
    obs: &dyn Observer,
) -> Result<RunOutput, RunError> {
    let mut with_exp = Settings {
        window: exp.window,
        uncertainty: exp.uncertainty(),
        ..settings.clone()
    };
    let mut partial = Partial::default();
    let fail = |stage: Stage, error: PipelineError, partial: &Partial| RunError {
        stage,
        error,
        partial: Box::new(partial.clone()),
    };
    let mut specimen = exp.specimen;
    let mut timings = Vec::new();
    let mut notes = Vec::new();
    let mut note = |stage: Stage, m: String| {
        obs.note(stage, &m);
        notes.push(Note { stage, text: m });
    };
    let mut finish = |stage: Stage, t: Instant, what: String, files: bool| {
        let timing = Timing {
            stage,
            seconds: t.elapsed().as_secs_f64(),
            what,
            files,
        };
        obs.done(&timing);
        timings.push(timing);
    };

    // 1. track (or the measured heights of `[heights]`)
    let t = Instant::now();
    let (tracking, mut points, relative) = match crate::heights::of_experiment(exp) {
        Some(read) => {
            let h = read
                .map_err(|e| fail(Stage::Track, PipelineError::Input(e.to_string()), &partial))?;
            finish(
                Stage::Track,
                t,
                format!(
                    "{} measured heights read (no photos tracked)",
                    h.points.len()
                ),
                false,
            );
            (None, h.points, h.relative)
        }
        None => {
            let tracking = track_stage_observed(exp, &with_exp, obs)
                .map_err(|e| fail(Stage::Track, e, &partial))?;
            let secs = t.elapsed().as_secs_f64();
            let n = tracking.tracked.rows.len();
            for w in &tracking.tracked.warnings {
                note(Stage::Track, format!("warning: {w}"));
            }
            for sk in &tracking.tracked.skipped {
                note(
                    Stage::Track,
                    format!("skipped frame {} ({}): {}", sk.frame, sk.file, sk.reason),
                );
            }
            if tracking.setup.lens.is_none() {
                note(Stage::Track, crate::track::lens::UNCALIBRATED_NOTE.into());
            }
            finish(
                Stage::Track,
                t,
                format!(
                    "{n} of {} photos ({}x{} px), {:.1} photos/s",
                    tracking.setup.frames.len(),
                    tracking.tracked.image_size[0],
                    tracking.tracked.image_size[1],
                    n as f64 / secs.max(1e-9)
                ),
                true,
            );
            partial.tracking = Some(tracking.clone());
            let relative = matches!(
                tracking.setup.calibration.origin,
                crate::track::HeightOrigin::Reference { .. }
            );
            let points = tracking.points();
            (Some(tracking), points, relative)
        }
    };

    // 2. stress (with the stress-free dome height estimated first when the
    // experiment asks for it)
    let t = Instant::now();
    obs.start(Stage::Stress, 0);
    if exp.prebulge_fit && tracking.is_none() && with_exp.refine {
        // measured heights: the dome found with the run's own law
        let (found, what) = crate::dome::stage(&specimen, &with_exp, &points, relative)
            .map_err(|e| fail(Stage::Stress, e, &partial))?;
        specimen.prebulge_height_m = found.h0_m;
        if let Some(sd) = found.h0_std_m {
            with_exp.uncertainty.prebulge_std_m = sd;
        }
        points = shift(points, relative, found.reference_m);
        note(Stage::Stress, what);
    } else if exp.prebulge_fit {
        let (h0, std, what) = prebulge_stage(&specimen, &with_exp, points.clone(), relative)
            .map_err(|e| fail(Stage::Stress, e, &partial))?;
        specimen.prebulge_height_m = h0;
        // The law is fitted on a dome that may be off by its error.
        if let Some(sd) = std {
            with_exp.uncertainty.prebulge_std_m = sd;
            with_exp.uncertainty.prebulge_in_heights = relative;
        }
        // Relative heights: the reference photo itself (height 0) is the
        // stress-free state, not a measurement.
        if relative {
            points.retain(|p| p.height_m != 0.0);
        }
        points = shift(points, relative, h0);
        note(Stage::Stress, what);
    } else if relative && tracking.is_none() {
        // measured heights above a stress-free reference with the dome
        // given as a number (`[heights] origin = "reference"`): the apex
        // stands at the height plus `prebulge_height_m`
        points = shift(points, true, specimen.prebulge_height_m);
    }
    let spec = &specimen;
    let settings = &with_exp;
    let stress =
        stress_stage(spec, settings, points).map_err(|e| fail(Stage::Stress, e, &partial))?;
    finish(
        Stage::Stress,
        t,
        format!(
            "{} points, {}{}",
            stress.rows.len(),
            describe_stress(&settings.stress),
            if stress.shifts.is_empty() {
                ""
            } else {
                " (each input's error per point in stress_strain_sources.csv)"
            }
        ),
        true,
    );
    partial.stress = Some(stress.clone());

    // 3. fit
    let t = Instant::now();
    obs.start(Stage::Fit, 0);
    let fit = fit_stage(spec, settings, &stress).map_err(|e| fail(Stage::Fit, e, &partial))?;
    if let Some(lowered) = fit.degree_lowered {
        note(Stage::Fit, lowered.to_string());
    }
    let what = fit.summary();
    finish(Stage::Fit, t, what, true);
    partial.fit = Some(fit.clone());

    // 4. simulate
    let t = Instant::now();
    let pressures_pa = pressures(settings, &stress.points);
    // (the limit point behind these warnings is the circular window's)
    if settings.window.is_circle() {
        for w in extrapolation_warnings(spec, &fit.material, &stress.points, &pressures_pa) {
            note(Stage::Simulate, w);
        }
    }
    let n_runs =
        settings.models.len() + usize::from(settings.axisym && settings.window.is_circle());
    obs.start(Stage::Simulate, (n_runs * pressures_pa.len()) as u64);
    let runs = simulate_stage(spec, settings, &fit.material, &pressures_pa, &|| obs.tick())
        .map_err(|e| fail(Stage::Simulate, e, &partial))?;
    let what = runs
        .iter()
        .map(|r| {
            let solved = r.points.iter().filter(|p| p.height_m.is_some()).count();
            let nodes = if r.nodes > 0 {
                format!(", {} nodes", r.nodes)
            } else {
                String::new()
            };
            format!(
                "{} {}/{} in {:.3} s{nodes}",
                r.model,
                solved,
                r.points.len(),
                r.wall_s
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    finish(
        Stage::Simulate,
        t,
        format!("{} pressures: {what}", pressures_pa.len()),
        true,
    );
    for n in runs
        .iter()
        .flat_map(|r| r.points.iter())
        .filter(|p| p.outcome != Outcome::NotTried)
        .filter_map(|p| p.note.clone())
    {
        note(Stage::Simulate, n);
    }
    let comparison = compare(&stress.points, &runs, &pressures_pa);
    let band = fit
        .refined
        .as_ref()
        .and_then(|r| r.uncertainty.as_ref())
        .map(|u| {
            inverse::band(
                &fit.material,
                spec,
                u,
                &settings.uncertainty,
                &pressures_pa,
                &inverse::Options::default().axisym,
            )
        });
    let verdicts = band
        .as_ref()
        .map(|b| verdicts(&comparison, &runs, b))
        .unwrap_or_default();
    let paper_chain = paper_chain(spec, settings, &fit, &stress.points, &pressures_pa);
    Ok(RunOutput {
        specimen,
        tracking,
        stress,
        fit,
        pressures_pa,
        runs,
        comparison,
        band,
        verdicts,
        paper_chain,
        timings,
        notes,
    })
}
