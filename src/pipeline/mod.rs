//! The whole pipeline as library stages: photos -> heights -> stress/strain
//! -> material -> simulated heights -> comparison, each a function from its
//! input to its output in memory, so that `bulge run` only chains them and
//! writes each stage's files, and the closed-loop study
//! (`examples/closed_loop.rs`) runs the same chain without writing anything.
//!
//! Conventions shared with the single-stage commands:
//!
//! * heights: `crate::track::track` (`bulge track`; feature `opencv`);
//! * stress/strain: [`crate::mechanics::stress_strain`] with
//!   [`crate::mechanics::Options`] (`bulge stress`);
//! * fit: the quartic secant modulus [`crate::fit::quartic::fit`] on the
//!   stress stage's `(strain, secant_modulus_pa)` (what `bulge fit
//!   --model quartic` does with `stress_strain.csv`), or a hyperelastic model
//!   on `(stretch, Cauchy stress l^2 p R / 2t)` (as `bulge fit --model NAME`);
//! * simulate: the disc of the specimen, the spring models of [`crate::sim`]
//!   solved by continuation over the pressures, and the exact axisymmetric
//!   solution [`crate::axisym::solve_pressure`] of the same material.
//!
//! One file per stage: `tracking` (photos -> heights), `stress`, `fit` (with
//! the law chosen and the paper's chain), `simulate`, `compare` (verdicts),
//! and `chain` ([`run`]: the stages in order); this file holds what they
//! share (settings, errors, the observer).

use std::path::Path;

use crate::axisym::AxisymError;
use crate::experiment::Window;
use crate::fit::uncertainty::Sources;
use crate::fit::{FitError, FitModel};
use crate::mechanics::{self, Modulus, ModulusStress, StrainMeasure, StressError, TrueStress};
use crate::sim::SimError;
use crate::sim::scene::MeshSize;
use crate::sim::solve::Solver;
use crate::sim::springs::SpringModel;
#[cfg(feature = "opencv")]
use crate::track::{self, TrackError};

#[cfg(feature = "opencv")]
mod chain;
mod compare;
mod dynamic_command;
mod fit;
mod simulate;
mod simulate_command;
mod stress;
#[cfg(test)]
mod tests;
#[cfg(feature = "opencv")]
mod tracking;

#[cfg(feature = "opencv")]
pub use chain::*;
pub use compare::*;
pub use dynamic_command::*;
pub use fit::*;
pub use simulate::*;
pub use simulate_command::*;
pub use stress::*;
#[cfg(feature = "opencv")]
pub use tracking::*;

/// The five stages, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Photos -> heights.
    Track,
    /// Heights -> stress/strain.
    Stress,
    /// Stress/strain -> material.
    Fit,
    /// Material -> simulated heights.
    Simulate,
    /// Tables, plots and the HTML report.
    Report,
}

impl Stage {
    /// All stages in order.
    pub const ALL: [Stage; 5] = [
        Stage::Track,
        Stage::Stress,
        Stage::Fit,
        Stage::Simulate,
        Stage::Report,
    ];

    /// The stage's name (the subcommand that does it alone).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Track => "track",
            Stage::Stress => "stress",
            Stage::Fit => "fit",
            Stage::Simulate => "simulate",
            Stage::Report => "report",
        }
    }
}

/// Why a stage refused its input or failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The tracking stage.
    #[cfg(feature = "opencv")]
    #[error(transparent)]
    Track(#[from] TrackError),
    /// The stress stage.
    #[error(transparent)]
    Stress(#[from] StressError),
    /// The fit stage.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The mass-spring solver could not be set up.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The axisymmetric reference could not be set up.
    #[error(transparent)]
    Axisym(#[from] AxisymError),
    /// A setting or an input that the stage refuses.
    #[error("{0}")]
    Input(String),
    /// Writing or drawing an output failed.
    #[error("{0}")]
    Output(String),
}

impl From<crate::io::InputError> for PipelineError {
    /// A file's bad value, located: the user's input.
    fn from(e: crate::io::InputError) -> Self {
        PipelineError::Input(e.to_string())
    }
}

impl crate::Refusal for PipelineError {
    fn is_bad_input(&self) -> bool {
        match self {
            #[cfg(feature = "opencv")]
            PipelineError::Track(e) => e.is_bad_input(),
            PipelineError::Stress(e) => e.is_bad_input(),
            PipelineError::Fit(e) => e.is_bad_input(),
            PipelineError::Sim(e) => e.is_bad_input(),
            PipelineError::Axisym(e) => e.is_bad_input(),
            PipelineError::Input(_) => true,
            PipelineError::Output(_) => false,
        }
    }
}

/// Everything `bulge run` can be told.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Tracking options.
    #[cfg(feature = "opencv")]
    pub track: track::Options,
    /// Stress and strain conventions.
    pub stress: mechanics::Options,
    /// The material model to fit; [`FitModel::Auto`] (the default): every
    /// law, the one the heights call for chosen ([`crate::fit::select`]).
    pub fit: FitModel,
    /// Spring models to simulate (default TP MSS and Van Gelder).
    pub models: Vec<SpringModel>,
    /// Also solve the exact axisymmetric reference of the same material.
    pub axisym: bool,
    /// Pressures to simulate, Pa; `None`: the measured ones.
    pub pressures_pa: Option<Vec<f64>>,
    /// Mesh size of the disc; `None`: the simulate stage's default (16 rings
    /// of the 60 degree sector).
    pub mesh: Option<MeshSize>,
    /// Quasi-static solver of the mass-spring models.
    pub solver: Solver,
    /// Residual force relative to the load at which a solve stops.
    pub tolerance: f64,
    /// Correct the fitted law until the exact axisymmetric inflation
    /// reproduces the measured heights ([`crate::fit::inverse`]).
    pub refine: bool,
    /// The clamped opening (an experiment's `[window]`; `bulge run` takes
    /// it from the experiment): a non-circular one is simulated with the
    /// membrane model and the law corrected through it.
    pub window: Window,
    /// The uncertainty of the inputs besides the heights' own
    /// ([`Experiment::uncertainty`](crate::experiment::Experiment::uncertainty);
    /// [`run`] takes it from the experiment).
    pub uncertainty: Sources,
    /// Weigh the correction to the heights by the points' standard
    /// deviations instead of their relative errors, and the fit to the
    /// stress/strain points by the uncertainties carried from the heights'
    /// (default false).
    pub weighted: bool,
    /// Monte Carlo samples of the corrected parameters, 0 for none
    /// ([`crate::fit::monte_carlo::monte_carlo`], seeded: the same number
    /// gives the same result).
    pub samples: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            #[cfg(feature = "opencv")]
            track: track::Options::default(),
            stress: mechanics::Options::default(),
            fit: FitModel::Auto,
            models: vec![SpringModel::Tp, SpringModel::VanGelder],
            axisym: true,
            pressures_pa: None,
            mesh: None,
            solver: Solver::Newton,
            tolerance: 1e-8,
            refine: true,
            window: Window::Circle,
            uncertainty: Sources::default(),
            weighted: false,
            samples: 0,
        }
    }
}

/// The settings of a run as a `[run]` (or `[simulate]`) table of an
/// experiment file or as command-line flags: every field optional, the
/// defaults of [`Settings`] standing in for what is not given. The values
/// are the real enums, by name (`models = ["tp", "van-gelder"]`,
/// `fit = "mooney-rivlin"`, `strain = "log"`, `solver = "dr"`).
#[derive(Debug, Clone, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunOptions {
    /// Spring models to simulate.
    pub models: Option<Vec<SpringModel>>,
    /// Solve the exact axisymmetric reference too.
    pub axisym: Option<bool>,
    /// Correct the fitted law to the measured heights.
    pub refine: Option<bool>,
    /// Weigh the correction by the heights' standard deviations.
    pub weighted: Option<bool>,
    /// Monte Carlo samples of the corrected parameters (0: none).
    pub samples: Option<usize>,
    /// Pressures to simulate, Pa (default: the measured ones).
    pub pressures_pa: Option<Vec<f64>>,
    /// Wanted relative height error of the disc mesh, in (0, 0.5).
    pub accuracy: Option<f64>,
    /// About this many solved nodes (instead of `accuracy`).
    pub nodes: Option<usize>,
    /// The material model to fit.
    pub fit: Option<FitModel>,
    /// Degree of the polynomial modulus law, 1 to 8.
    pub degree: Option<usize>,
    /// Strain measure of the stress stage.
    pub strain: Option<StrainMeasure>,
    /// True-stress convention of the stress stage.
    pub true_stress: Option<TrueStress>,
    /// Secant modulus convention of the stress stage.
    pub modulus: Option<Modulus>,
    /// Stress in the secant modulus.
    pub modulus_stress: Option<ModulusStress>,
    /// Quasi-static solver of the spring models.
    pub solver: Option<Solver>,
    /// Minimum template-match score of a frame, in [-1, 1].
    pub min_score: Option<f64>,
    /// Leave frames below `min_score` out instead of failing the track stage.
    pub skip_bad_frames: Option<bool>,
    /// The largest `samples` taken (default [`MAX_SAMPLES`]).
    pub max_samples: Option<usize>,
}

/// The most Monte Carlo samples of the corrected parameters taken unless
/// raised (`max_samples`): each sample corrects the law to the heights once
/// (0.1-0.5 s on 16 heights), so 10 000 already take about half an hour on
/// two cores, and 1000 give the intervals to a few per cent.
pub const MAX_SAMPLES: usize = 10_000;

impl RunOptions {
    /// These options, falling back to `base` for what they leave out.
    pub fn or(self, base: RunOptions) -> RunOptions {
        RunOptions {
            models: self.models.or(base.models),
            axisym: self.axisym.or(base.axisym),
            refine: self.refine.or(base.refine),
            weighted: self.weighted.or(base.weighted),
            samples: self.samples.or(base.samples),
            pressures_pa: self.pressures_pa.or(base.pressures_pa),
            accuracy: self.accuracy.or(base.accuracy),
            nodes: self.nodes.or(base.nodes),
            fit: self.fit.or(base.fit),
            degree: self.degree.or(base.degree),
            strain: self.strain.or(base.strain),
            true_stress: self.true_stress.or(base.true_stress),
            modulus: self.modulus.or(base.modulus),
            modulus_stress: self.modulus_stress.or(base.modulus_stress),
            solver: self.solver.or(base.solver),
            min_score: self.min_score.or(base.min_score),
            skip_bad_frames: self.skip_bad_frames.or(base.skip_bad_frames),
            max_samples: self.max_samples.or(base.max_samples),
        }
    }

    /// The `[simulate]` and `[run]` tables of an experiment file (`[run]`
    /// wins where both give a setting).
    pub fn from_experiment(
        exp: &crate::experiment::Experiment,
    ) -> Result<RunOptions, PipelineError> {
        let mut out = RunOptions::default();
        for table in ["simulate", "run"] {
            if let Some(v) = exp.other.get(table) {
                let f: RunOptions = v.clone().try_into().map_err(|e: toml::de::Error| {
                    // said in the file's words, with its line, when the
                    // file can be read again
                    #[derive(serde::Deserialize)]
                    #[allow(dead_code)]
                    struct Tables {
                        simulate: Option<RunOptions>,
                        run: Option<RunOptions>,
                        #[serde(flatten)]
                        rest: toml::Table,
                    }
                    let located = std::fs::read_to_string(&exp.path).ok().and_then(|text| {
                        crate::io::parse_toml::<Tables>(&exp.path, &text)
                            .err()
                            .map(|e| e.to_string())
                    });
                    PipelineError::Input(located.unwrap_or_else(|| {
                        format!("{}: [{table}]: {}", exp.path.display(), e.message())
                    }))
                })?;
                out = f.or(out);
            }
        }
        Ok(out)
    }

    /// These options (the command line's flags, say) over the experiment
    /// file's `[run]`/`[simulate]` tables over the defaults, checked; a bad
    /// value names the file.
    pub fn settings_for(
        self,
        exp: &crate::experiment::Experiment,
    ) -> Result<Settings, PipelineError> {
        let file = RunOptions::from_experiment(exp)?;
        self.or(file)
            .settings()
            .map_err(|e| PipelineError::Input(format!("{}: {e}", exp.path.display())))
    }

    /// The settings: each given value checked, the defaults for the rest.
    pub fn settings(&self) -> Result<Settings, PipelineError> {
        let bad = |m: String| Err(PipelineError::Input(m));
        let mut s = Settings::default();
        if let Some(m) = &self.models {
            s.models = m.clone();
        }
        s.axisym = self.axisym.unwrap_or(true);
        s.refine = self.refine.unwrap_or(true);
        s.weighted = self.weighted.unwrap_or(false);
        s.samples = self.samples.unwrap_or(0);
        let max = self.max_samples.unwrap_or(MAX_SAMPLES);
        if s.samples > max {
            return bad(format!(
                "samples = {}: each sample corrects the law to the heights once (0.1-0.5 s each), so {} would take about {} hours on two cores; take at most {max} (1000 give the intervals to a few per cent), or raise the bound with {} (max_samples in [run])",
                s.samples,
                s.samples,
                (s.samples as f64 * 0.3 / 2.0 / 3600.0).ceil(),
                crate::setting::Setting::MaxSamples
            ));
        }
        if s.models.is_empty() && !s.axisym {
            return bad(
                "nothing to simulate: give at least one model or keep the axisymmetric reference"
                    .into(),
            );
        }
        if let Some(p) = &self.pressures_pa {
            crate::sim::scene::validate_pressures(p)
                .map_err(|m| PipelineError::Input(format!("pressures_pa: {m}")))?;
            s.pressures_pa = Some(p.clone());
        }
        if let Some(a) = self.accuracy {
            if !(a.is_finite() && a > 0.0 && a < 0.5) {
                return bad(format!(
                    "accuracy = {a} must be a relative error in (0, 0.5), e.g. 0.005 for 0.5 %"
                ));
            }
            s.mesh = Some(MeshSize::Accuracy(a));
        } else if let Some(n) = self.nodes {
            if n < 3 {
                return bad(format!("nodes = {n}: ask for at least 3 nodes"));
            }
            s.mesh = Some(MeshSize::Nodes(n));
        }
        let degree = self.degree.unwrap_or(4);
        if !(1..=8).contains(&degree) {
            return bad(format!(
                "degree = {degree}: use 1 to 8 (4 is the quartic of Tudruj et al. 2023)"
            ));
        }
        s.fit = self.fit.unwrap_or(FitModel::Auto).with_degree(degree);
        if s.fit == FitModel::AllHyperelastic {
            return bad(
                "fit = \"all\" compares models in bulge fit; a run fits one model: name it".into(),
            );
        }
        s.stress.strain = self.strain.unwrap_or(s.stress.strain);
        s.stress.true_stress = self.true_stress.unwrap_or(s.stress.true_stress);
        s.stress.modulus = self.modulus.unwrap_or(s.stress.modulus);
        s.stress.modulus_stress = self.modulus_stress.unwrap_or(s.stress.modulus_stress);
        s.solver = self.solver.unwrap_or(s.solver);
        #[cfg(feature = "opencv")]
        {
            if let Some(m) = self.min_score {
                if !(-1.0..=1.0).contains(&m) {
                    return bad(format!(
                        "min_score = {m} is outside [-1, 1], the range of TM_CCOEFF_NORMED scores"
                    ));
                }
                s.track.min_score = m;
            }
            s.track.skip_bad_frames = self.skip_bad_frames.unwrap_or(false);
        }
        Ok(s)
    }
}

/// A one-line description of the stress conventions.
pub fn describe_stress(o: &mechanics::Options) -> String {
    format!(
        "strain {}, modulus {} = {}{} / strain, true stress {}",
        o.strain.name(),
        o.modulus.name(),
        if o.modulus == Modulus::Biaxial {
            "(1 - nu) "
        } else {
            ""
        },
        match o.modulus_stress {
            ModulusStress::Nominal => "lambda pR/2t (nominal)".to_string(),
            ModulusStress::Stress => "pR/2t (eq 18)".to_string(),
            ModulusStress::True => match o.true_stress {
                TrueStress::Paper => "lambda pR/2t (eq 25)".to_string(),
                TrueStress::Incompressible => "lambda^2 pR/2t (incompressible)".to_string(),
            },
        },
        o.true_stress.name()
    )
}

/// File name for messages.
pub fn display(p: &Path) -> String {
    p.display().to_string()
}

/// A remark of one stage on the run (a frame left out, a degree lowered, a
/// pressure not solved): the stage it came from and what it says.
#[derive(Debug, Clone, PartialEq)]
pub struct Note {
    /// The stage that made it.
    pub stage: Stage,
    /// What it says.
    pub text: String,
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.stage.name(), self.text)
    }
}

/// Time spent in one stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// The stage.
    pub stage: Stage,
    /// Wall time, s.
    pub seconds: f64,
    /// What it did, e.g. `12 photos, 41.3 photos/s`.
    pub what: String,
    /// Whether it made the stage's files (the track stage makes none when
    /// the heights were measured, `[heights]`).
    pub files: bool,
}

/// What a run tells its caller while it works (progress bars, logs). Every
/// method does nothing by default; `()` is the observer that ignores all.
pub trait Observer: Sync {
    /// `stage` starts; it will call [`Observer::tick`] about `steps` times.
    fn start(&self, _stage: Stage, _steps: u64) {}
    /// One step of the current stage is done (may be called from worker
    /// threads).
    fn tick(&self) {}
    /// A remark on the current stage (a frame left out, a degree lowered).
    fn note(&self, _stage: Stage, _message: &str) {}
    /// `stage` is done.
    fn done(&self, _timing: &Timing) {}
}

impl Observer for () {}
