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

use std::path::Path;
#[cfg(feature = "opencv")]
use std::path::PathBuf;
use std::time::Instant;

use crate::axisym::{self, AxisymError};
#[cfg(feature = "opencv")]
use crate::experiment::Experiment;
use crate::experiment::Specimen;
use crate::experiment::Window;
use crate::fit::data::Loaded;
use crate::fit::uncertainty::{SourceKind, Sources};
use crate::fit::{
    FitDetail, FitError, FitModel, FitSettings, FittedMaterial, fit_material, inverse, select,
};
use crate::io::{CsvOut, InputError, Table, fmt_num, fmt_short};
use crate::material::Material;
use crate::mechanics::{
    self, CORR_COLUMNS, DERIVED_COLUMNS, Modulus, ModulusStress, Point, Row, STD_COLUMNS,
    StrainMeasure, StressError, TrueStress,
};
use crate::sim::DiscSolver;
use crate::sim::SimError;
use crate::sim::scene::{MeshSize, Scene};
use crate::sim::solve::{self, Solver};
use crate::sim::springs::{HeightModel, SpringModel};
#[cfg(feature = "opencv")]
use crate::track::{self, Setup, TemplateSource, TrackError, Tracked};

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

impl PipelineError {
    /// True when the user's input was refused (exit 2), false when the work
    /// failed (exit 1).
    pub fn is_bad_input(&self) -> bool {
        match self {
            #[cfg(feature = "opencv")]
            PipelineError::Track(e) => e.is_bad_input(),
            PipelineError::Stress(_) | PipelineError::Input(_) => true,
            PipelineError::Fit(e) => !matches!(e, FitError::Solver(_)),
            PipelineError::Sim(e) => matches!(
                e,
                SimError::BadParameter(_)
                    | SimError::DegenerateTriangle { .. }
                    | SimError::InvertedTriangle { .. }
                    | SimError::BadMesh(_)
            ),
            PipelineError::Axisym(e) => matches!(
                e,
                AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)
            ),
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
    /// ([`crate::fit::coverage::monte_carlo`], seeded: the same number
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
                        toml::from_str::<Tables>(&text)
                            .err()
                            .map(|e| crate::io::toml_error(&exp.path, &text, &e).to_string())
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
                "samples = {}: each sample corrects the law to the heights once (0.1-0.5 s each), so {} would take about {} hours on two cores; take at most {max} (1000 give the intervals to a few per cent), or raise the bound with --max-samples (max_samples in [run])",
                s.samples,
                s.samples,
                (s.samples as f64 * 0.3 / 2.0 / 3600.0).ceil()
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

/// Output of the tracking stage.
#[cfg(feature = "opencv")]
#[derive(Debug, Clone)]
pub struct Tracking {
    /// What was tracked.
    pub setup: Setup,
    /// The result per frame.
    pub tracked: Tracked,
    /// Template size `[w, h]`, px.
    pub template_size: [usize; 2],
    /// Apex position inside the template, px.
    pub apex_in_template: [f64; 2],
}

#[cfg(feature = "opencv")]
impl Tracking {
    /// `heights.csv` as `bulge track` writes it.
    pub fn csv(&self) -> CsvOut {
        self.tracked.heights_csv()
    }

    /// The measured points.
    pub fn points(&self) -> Vec<Point> {
        self.tracked
            .rows
            .iter()
            .map(|r| Point {
                pressure_pa: r.pressure_pa,
                height_m: r.height_m,
                height_std_m: Some(r.height_std_m),
            })
            .collect()
    }

    /// What to draw on frame `i` of the tracked rows.
    pub fn marks(&self, i: usize) -> track::annotate::Marks {
        let r = &self.tracked.rows[i];
        let q = r.apex_quadratic_px;
        let [tw, th] = self.template_size;
        let roi = self.setup.roi;
        track::annotate::Marks {
            roi_px: [roi[0] as f64, roi[1] as f64, roi[2] as f64, roi[3] as f64],
            template_px: [
                q[0] - self.apex_in_template[0],
                q[1] - self.apex_in_template[1],
                tw as f64,
                th as f64,
            ],
            // The apex is the undistorted image's: drawn where the photo shows it.
            apex_px: self.setup.lens.map_or([r.apex_x_px, r.apex_y_px], |l| {
                l.distort([r.apex_x_px, r.apex_y_px])
            }),
        }
    }

    /// Path of the photo of tracked row `i` (of the video, for a video frame).
    pub fn photo(&self, i: usize) -> PathBuf {
        self.setup.frames[self.tracked.rows[i].frame].path.clone()
    }

    /// The frame of tracked row `i` (a photo or a video frame).
    pub fn frame(&self, i: usize) -> &track::Frame {
        &self.setup.frames[self.tracked.rows[i].frame]
    }
}

#[cfg(feature = "opencv")]
/// Stage 1: the photos of `exp` -> heights. `tick` is called per frame.
pub fn track_stage(
    exp: &Experiment,
    settings: &Settings,
    tick: &(dyn Fn() + Sync),
) -> Result<Tracking, PipelineError> {
    struct Tick<'a>(&'a (dyn Fn() + Sync));
    impl Observer for Tick<'_> {
        fn tick(&self) {
            (self.0)()
        }
    }
    track_stage_observed(exp, settings, &Tick(tick))
}

/// Stage 1, telling `obs` of the number of frames and each frame done.
#[cfg(feature = "opencv")]
fn track_stage_observed(
    exp: &Experiment,
    settings: &Settings,
    obs: &dyn Observer,
) -> Result<Tracking, PipelineError> {
    let setup = track::setup_from_experiment(exp)?;
    obs.start(Stage::Track, setup.frames.len() as u64);
    let tracked = track::track(&setup, &settings.track, &|| obs.tick())?;
    if tracked.rows.is_empty() {
        return Err(PipelineError::Input(format!(
            "every one of the {} frames scored below the minimum score {}: nothing to measure; check the template and the region",
            setup.frames.len(),
            settings.track.min_score
        )));
    }
    let template_size = match &setup.template {
        TemplateSource::Rect(r) => [r[2] as usize, r[3] as usize],
        TemplateSource::File(p) => {
            let t = track::image::read_gray(p, None)?;
            [t.width, t.height]
        }
    };
    let apex_in_template = setup.apex_in_template.unwrap_or([
        (template_size[0] as f64 - 1.0) / 2.0,
        (template_size[1] as f64 - 1.0) / 2.0,
    ]);
    Ok(Tracking {
        setup,
        tracked,
        template_size,
        apex_in_template,
    })
}

/// Output of the stress stage.
#[derive(Debug, Clone)]
pub struct StressOut {
    /// The measured points.
    pub points: Vec<Point>,
    /// Derived quantities per point.
    pub rows: Vec<Row>,
    /// Per point, how its values move for each input's error
    /// ([`crate::fit::uncertainty::point_shifts`]); empty without the
    /// experiment's standard deviations besides the heights'.
    pub shifts: Vec<PointShifts>,
}

/// How one point's derived values move for a one-standard-deviation error
/// of each input (see [`crate::fit::uncertainty::point_shifts`]).
pub type PointShifts = Vec<(SourceKind, mechanics::Derived)>;

/// Every point's [`PointShifts`] when `sources` has a standard deviation
/// (else none: the heights' own are in the `*_std` columns).
pub fn point_shifts(
    spec: &Specimen,
    opts: &mechanics::Options,
    points: &[Point],
    sources: &Sources,
) -> Result<Vec<PointShifts>, mechanics::StressError> {
    if *sources == Sources::default() {
        return Ok(Vec::new());
    }
    points
        .iter()
        .map(|p| crate::fit::uncertainty::point_shifts(spec, opts, p, sources))
        .collect()
}

/// Output column names of a shift table ([`shifts_csv`]), in the order of
/// [`DERIVED_COLUMNS`].
pub const SHIFT_COLUMNS: [&str; 7] = [
    "radius_shift_m",
    "arc_length_shift_m",
    "stretch_shift",
    "strain_shift",
    "stress_shift_pa",
    "true_stress_shift_pa",
    "secant_modulus_shift_pa",
];

/// The shift table of `bulge stress` and `bulge run`
/// (`stress_strain_sources.csv`): one row per point and input error,
/// `point` (1 for the first data row of `stress_strain.csv`),
/// `pressure_pa`, `height_m`, `source` (`height`, `pressure_noise`,
/// `pressure_gain`, `thickness`, `radius`, `scale`, `height_offset`,
/// `prebulge_height`) and
/// the signed change of every derived value for a one-standard-deviation
/// error of that source ([`SHIFT_COLUMNS`]). `None` when there are none.
pub fn shifts_csv(points: &[Point], shifts: &[PointShifts]) -> Option<CsvOut> {
    if shifts.is_empty() {
        return None;
    }
    let mut header = vec!["point", "pressure_pa", "height_m", "source"];
    header.extend(SHIFT_COLUMNS);
    let mut out = CsvOut::new(&header);
    for (i, (p, list)) in points.iter().zip(shifts).enumerate() {
        for (kind, d) in list {
            let name = match kind {
                SourceKind::Points => "height",
                k => k.name(),
            };
            let mut f = vec![
                (i + 1).to_string(),
                fmt_num(Some(p.pressure_pa)),
                fmt_num(Some(p.height_m)),
                name.to_string(),
            ];
            f.extend(d.to_array().into_iter().map(fmt_num));
            out.row(&f);
        }
    }
    Some(out)
}

/// The stress-free dome height of a slack membrane (`prebulge_height_m =
/// "fit"`), m, and a sentence saying how it was found: first from the cap
/// formulas ([`crate::mechanics::prebulge::estimate`], a few per cent low),
/// then, with `settings.refine`, beside a Mooney-Rivlin law corrected to the
/// heights ([`inverse::refine_with_prebulge`]): two parameters follow rubber
/// well and are too few to make up for a wrong reference, where a quartic's
/// five absorb it (its rms height error is flat within 0.01 percentage
/// points over +-10 % of `h0`).
pub fn prebulge_stage(
    spec: &Specimen,
    settings: &Settings,
    points: Vec<Point>,
    relative: bool,
) -> Result<(f64, Option<f64>, String), PipelineError> {
    let est = crate::mechanics::prebulge::estimate(spec, &points, relative)
        .map_err(|e| PipelineError::Input(e.to_string()))?;
    // The cap estimate's own standard deviation, where it is determined.
    let cap_std = Some(est.std_m).filter(|s| s.is_finite() && *s > 0.0);
    let cap = format!(
        "prebulge_height_m from the cap formulas {:.4e} m (std {:.1e} m, {} points)",
        est.height_m, est.std_m, est.points
    );
    if !settings.refine {
        return Ok((
            est.height_m,
            cap_std,
            format!("{cap}; used as it is (no correction to the heights)"),
        ));
    }
    let at = Specimen {
        prebulge_height_m: est.height_m,
        ..*spec
    };
    let mr = Settings {
        fit: FitModel::Hyperelastic(crate::fit::hyperelastic::Kind::MooneyRivlin),
        refine: false,
        ..settings.clone()
    };
    let beside = || -> Result<(inverse::Refined, f64), PipelineError> {
        let stress = stress_stage(&at, &mr, shift(points.clone(), relative, est.height_m))?;
        let law = fit_stage(&at, &mr, &stress)?.material;
        Ok(inverse::refine_with_prebulge(
            &law,
            &at,
            &measured_heights(&points),
            &inverse::Options::default(),
            est.height_m,
            relative,
        )?)
    };
    match beside() {
        Ok((r, h0)) => {
            let rms = inverse::Refined::rms(&r.after).map_or(f64::NAN, |v| 100.0 * v);
            let std = r.prebulge_std_m;
            let pm = std.map_or_else(String::new, |s| format!(" +- {s:.1e}"));
            Ok((
                h0,
                std,
                format!(
                    "{cap}; beside a Mooney-Rivlin law corrected to the heights (rms {rms:.2} %): prebulge_height_m = {h0:.4e}{pm} m, used by stress, fit and simulate{}",
                    if std.is_some() {
                        " (its error carried to the law's intervals)"
                    } else {
                        ""
                    }
                ),
            ))
        }
        // The cap estimate stands, said with the reason.
        Err(e) => Ok((
            est.height_m,
            cap_std,
            format!("{cap}, used as it is: the search beside a Mooney-Rivlin law failed ({e})"),
        )),
    }
}

/// `points` with `h0` added to their heights when they are `relative` to a
/// reference photo of the stress-free dome.
pub fn shift(points: Vec<Point>, relative: bool, h0: f64) -> Vec<Point> {
    if !relative {
        return points;
    }
    points
        .into_iter()
        .map(|p| Point {
            height_m: p.height_m + h0,
            ..p
        })
        .collect()
}

/// Stage 2: heights -> stress and strain.
pub fn stress_stage(
    spec: &Specimen,
    settings: &Settings,
    points: Vec<Point>,
) -> Result<StressOut, PipelineError> {
    let rows = mechanics::stress_strain(spec, &settings.stress, &points)?;
    let shifts = point_shifts(spec, &settings.stress, &points, &settings.uncertainty)?;
    Ok(StressOut {
        points,
        rows,
        shifts,
    })
}

impl StressOut {
    /// `stress_strain.csv` in the columns of `bulge stress` (with `frame` and
    /// `file` first when given, and the `*_std` columns).
    pub fn csv(&self, labels: Option<&[(usize, String)]>) -> CsvOut {
        let mut header: Vec<&str> = Vec::new();
        if labels.is_some() {
            header.extend(["frame", "file"]);
        }
        header.extend(["pressure_pa", "height_m"]);
        header.extend(DERIVED_COLUMNS);
        header.push("height_std_m");
        header.extend(STD_COLUMNS);
        header.extend(CORR_COLUMNS);
        let mut out = CsvOut::new(&header);
        for (i, (p, r)) in self.points.iter().zip(&self.rows).enumerate() {
            let mut f = Vec::new();
            if let Some(l) = labels {
                f.push(l[i].0.to_string());
                f.push(l[i].1.clone());
            }
            f.push(fmt_num(Some(p.pressure_pa)));
            f.push(fmt_num(Some(p.height_m)));
            f.extend(r.value.to_array().into_iter().map(fmt_num));
            f.push(fmt_num(p.height_std_m));
            f.extend(
                r.std
                    .unwrap_or_default()
                    .to_array()
                    .into_iter()
                    .map(fmt_num),
            );
            f.extend(r.correlations().into_iter().map(fmt_num));
            out.row(&f);
        }
        out
    }
}

/// The points of a heights table (`pressure_pa`, `height_m` and optionally
/// `height_std_m`, as `bulge track` writes it). `height_std_m` given here is
/// every point's standard deviation; refused beside a `height_std_m` column
/// (one source of uncertainty, not a silent override).
pub fn heights_points(table: &Table, height_std_m: Option<f64>) -> Result<Vec<Point>, InputError> {
    let p_col = table.require("pressure_pa")?;
    let h_col = table.require("height_m")?;
    let std_col = table.column_index("height_std_m");
    if let (Some(sd), Some(_)) = (height_std_m, std_col) {
        return Err(InputError::cell(
            &table.path,
            1,
            "height_std_m",
            format!(
                "a height standard deviation of {sd} m was given for every point and the file has a height_std_m column: drop one of them (one source of uncertainty)"
            ),
        ));
    }
    (0..table.len())
        .map(|r| {
            let height_std_m = match (height_std_m, std_col) {
                (Some(sd), _) => Some(sd),
                (None, Some(c)) if !table.cell(r, c).is_empty() => Some(table.number(r, c)?),
                _ => None,
            };
            Ok(Point {
                pressure_pa: table.number(r, p_col)?,
                height_m: table.number(r, h_col)?,
                height_std_m,
            })
        })
        .collect()
}

/// The stress stage's rows checked for what a user would not trust: a
/// derived value that is not finite (inputs beyond double precision, such
/// as a pressure of 1e308 Pa or a thickness of 1e-320 m) is refused with its
/// row (index into `points`) and column; a height below a millionth of the
/// radius gets a warning (its strain is at round-off level and its secant
/// modulus meaningless).
pub fn check_stress_rows(
    spec: &Specimen,
    points: &[Point],
    rows: &[Row],
) -> Result<Vec<String>, (usize, &'static str, String)> {
    let mut warnings = Vec::new();
    for (i, (p, r)) in points.iter().zip(rows).enumerate() {
        for (name, v) in DERIVED_COLUMNS.iter().zip(r.value.to_array()) {
            if let Some(v) = v
                && !v.is_finite()
            {
                return Err((
                    i,
                    name,
                    format!(
                        "{name} is {v} for pressure {} Pa and height {} m on a disc of radius {} m and thickness {} m: \
                         the numbers are beyond double precision; check the units (Pa, m)",
                        crate::io::fmt_short(p.pressure_pa),
                        crate::io::fmt_short(p.height_m),
                        crate::io::fmt_short(spec.radius_m),
                        crate::io::fmt_short(spec.thickness_m)
                    ),
                ));
            }
        }
        if p.height_m > 0.0 && p.height_m < 1e-6 * spec.radius_m {
            warnings.push(format!(
                "point {}: the height {} m is {} of the radius: its strain is at round-off level and its secant modulus ({} Pa) meaningless",
                i + 1,
                crate::io::fmt_short(p.height_m),
                crate::io::fmt_short(p.height_m / spec.radius_m),
                crate::io::fmt_short(r.value.secant_modulus_pa.unwrap_or(f64::NAN))
            ));
        }
    }
    Ok(warnings)
}

/// `stress_strain.csv` of a heights table: its other columns carried
/// through first, then pressure and height as given, the derived values,
/// and (with an uncertainty) `height_std_m` when it was given for every
/// point (`std_given`) and the standard deviations.
pub fn stress_csv_of_table(
    table: &Table,
    points: &[Point],
    rows: &[Row],
    std_given: bool,
) -> Result<CsvOut, InputError> {
    let p_col = table.require("pressure_pa")?;
    let h_col = table.require("height_m")?;
    let carried: Vec<usize> = (0..table.headers.len())
        .filter(|&c| c != p_col && c != h_col)
        .collect();
    let with_std = points.iter().any(|p| p.height_std_m.is_some());
    let written = |name: &str| {
        DERIVED_COLUMNS.contains(&name)
            || (with_std
                && (STD_COLUMNS.contains(&name)
                    || CORR_COLUMNS.contains(&name)
                    || (std_given && name == "height_std_m")))
    };
    if let Some(&c) = carried.iter().find(|&&c| written(&table.headers[c])) {
        let name = &table.headers[c];
        return Err(InputError::cell(
            &table.path,
            1,
            name,
            format!(
                "the column `{name}` is one that bulge stress writes: rename or drop it in the input"
            ),
        ));
    }
    let mut header: Vec<&str> = carried.iter().map(|&c| table.headers[c].as_str()).collect();
    header.extend(["pressure_pa", "height_m"]);
    header.extend(DERIVED_COLUMNS);
    if with_std {
        if std_given {
            header.push("height_std_m");
        }
        header.extend(STD_COLUMNS);
        header.extend(CORR_COLUMNS);
    }
    let mut out = CsvOut::new(&header);
    for (r, row) in rows.iter().enumerate() {
        let mut fields: Vec<String> = carried
            .iter()
            .map(|&c| table.cell(r, c).to_string())
            .collect();
        fields.push(table.cell(r, p_col).to_string());
        fields.push(table.cell(r, h_col).to_string());
        fields.extend(row.value.to_array().into_iter().map(fmt_num));
        if with_std {
            if std_given {
                fields.push(fmt_num(points[r].height_std_m));
            }
            fields.extend(
                row.std
                    .unwrap_or_default()
                    .to_array()
                    .into_iter()
                    .map(fmt_num),
            );
            fields.extend(row.correlations().into_iter().map(fmt_num));
        }
        out.row(&fields);
    }
    Ok(out)
}

/// Output of the fit stage.
#[derive(Debug, Clone)]
pub struct FitOut {
    /// The material for the simulators (`material.toml`), with its provenance.
    pub material: Material,
    /// The fit.
    pub detail: FitDetail,
    /// The model fitted (the degree lowered when there were few points).
    pub model: FitModel,
    /// `(strain, secant modulus, its std)` of the points the modulus law saw,
    /// sorted by strain.
    pub modulus_points: Vec<(f64, f64, Option<f64>)>,
    /// `(stretch, Cauchy stress)` of the points the hyperelastic models saw.
    pub stress_points: Vec<(f64, f64)>,
    /// `1 - nu` (biaxial) or 1 (uniaxial): `E = k S / eps`.
    pub modulus_factor: f64,
    /// Strain measure of the law.
    pub strain_measure: StrainMeasure,
    /// Warnings about the law (unphysical regions, ill conditioning).
    pub warnings: Vec<String>,
    /// The law as the stress/strain points gave it, before the correction
    /// to the heights (the same as `material` without it).
    pub cap_material: Material,
    /// The correction to the heights, when made.
    pub refined: Option<inverse::Refined>,
    /// With [`FitModel::Auto`]: every law fitted, corrected to the heights
    /// and ranked on them, and the one carried forward
    /// ([`crate::fit::select`]).
    pub laws: Option<select::Selection>,
}

/// Stage 3: stress/strain -> material ([`crate::fit::fit_material`] on the
/// stress stage's rows, then, with `settings.refine`, the correction of the
/// law to the measured heights; a correction that fails leaves the
/// points' law with a warning).
pub fn fit_stage(
    spec: &Specimen,
    settings: &Settings,
    s: &StressOut,
) -> Result<FitOut, PipelineError> {
    let data = Loaded::from_stress_rows(&s.rows, settings.stress.strain);
    let mut fit_settings = FitSettings {
        model: settings.fit,
        poisson: spec.poisson,
        modulus: settings.stress.modulus,
        modulus_stress: Some(settings.stress.modulus_stress),
        lower_degree: true,
        weighted: settings.weighted,
    };
    let source = "stress_strain.csv of bulge run";
    let (mut fitted, laws) = if settings.fit == FitModel::Auto {
        choose_law(spec, settings, s, &data, &mut fit_settings, source)?
    } else {
        let mut fitted = fit_material(&data, &fit_settings, source)?;
        if settings.refine
            && let Some(w) = crate::dome::positive_start(&mut fitted, &data)
        {
            fitted.warn(w);
        }
        (fitted, None)
    };
    if settings.refine && fitted.refined.is_none() {
        let measured = measured_heights(&s.points);
        let opts = inverse::Options {
            uncertainty: settings.uncertainty,
            weighted: settings.weighted,
            ..inverse::Options::default()
        };
        let refined = if settings.window.is_circle() {
            fitted.refine_to_heights(spec, &measured, &opts).map(|_| ())
        } else {
            let scene =
                Scene::from_window(spec, &settings.window, fitted.cap_material.clone(), vec![]);
            fitted
                .refine_in_scene(&scene, settings.mesh, &measured, &opts)
                .map(|_| ())
        };
        if let Err(e) = refined {
            fitted.warn(format!(
                "the law was not corrected to the heights ({e}); the cap-method law is used"
            ));
        } else if settings.samples > 0
            && let Err(e) = fitted.monte_carlo(spec, &measured, &opts, settings.samples, 1)
        {
            fitted.warn(format!("no Monte Carlo of the parameters: {e}"));
        }
    }
    if let Some(w) = crate::dome::stiffness_problem(
        &fitted.material.model,
        crate::dome::top_strain(&fitted.material.model, &data),
    ) {
        fitted.warn(format!(
            "the law has negative stiffness inside the measured range: {w}; a simulation can snap through or fail there (try another model or give prebulge_height_m)"
        ));
    }
    let modulus_points = data
        .strain
        .iter()
        .zip(&data.modulus_pa)
        .zip(&data.modulus_std_pa)
        .filter_map(|((&e, m), sd)| m.map(|m| (e, m, *sd)))
        .collect();
    let stress_points = data
        .equibiaxial
        .stretch
        .iter()
        .zip(&data.equibiaxial.stress_pa)
        .map(|(&l, &st)| (l, st))
        .collect();
    Ok(FitOut {
        material: fitted.material,
        detail: fitted.detail,
        model: fitted.model,
        modulus_points,
        stress_points,
        modulus_factor: settings.stress.modulus.factor(spec.poisson),
        strain_measure: settings.stress.strain,
        warnings: fitted.warnings,
        cap_material: fitted.cap_material,
        refined: fitted.refined,
        laws,
    })
}

/// The fit stage's choice of law ([`FitModel::Auto`]): every law fitted
/// and corrected to the heights weighted by their stated standard
/// deviations, ranked, the chosen one carried forward
/// ([`crate::fit::select`]). A consistent law keeps that weighted
/// correction (the statistically right weighting when the law holds); a
/// law that misses the heights is corrected again by the relative errors
/// `h_sim / h - 1` unless `settings.weighted` asks for the weights anyway,
/// so that no few precise heights pull a wrong law away from the rest.
/// Without the correction to the heights or with a non-circular window
/// there is nothing to choose by: the quartic, with a warning.
fn choose_law(
    spec: &Specimen,
    settings: &Settings,
    s: &StressOut,
    data: &Loaded,
    fit_settings: &mut FitSettings,
    source: &str,
) -> Result<(FittedMaterial, Option<select::Selection>), PipelineError> {
    fit_settings.model = FitModel::Quartic { degree: 4 };
    if !settings.refine || !settings.window.is_circle() {
        let mut f = fit_material(data, fit_settings, source)?;
        f.warn(format!(
            "the law was not chosen by the heights ({}): the quartic is used; name a law with --fit to fit another",
            if settings.refine {
                "the window is not circular, and the choice corrects every law through the exact axisymmetric inflation"
            } else {
                "the correction to the heights is off"
            }
        ));
        return Ok((f, None));
    }
    let measured = measured_heights(&s.points);
    let opts = inverse::Options {
        uncertainty: settings.uncertainty,
        weighted: true,
        ..inverse::Options::default()
    };
    let sel = select::select(data, fit_settings, spec, &measured, &opts, source)?;
    let row = sel.chosen_row();
    fit_settings.model = row.model;
    let mut fitted = row
        .fitted
        .clone()
        .expect("the chosen law was fitted and corrected");
    if !row.consistent() && !settings.weighted {
        let plain = inverse::Options {
            weighted: false,
            ..opts.clone()
        };
        let mut f = fit_material(data, fit_settings, source)?;
        match f.refine_to_heights(spec, &measured, &plain) {
            Ok(_) => fitted = f,
            Err(e) => fitted.warn(format!(
                "the chosen law misses the heights, and its correction by the relative errors failed ({e}): the one weighted by the heights' standard deviations is kept"
            )),
        }
    }
    if settings.samples > 0
        && let Err(e) = fitted.monte_carlo(
            spec,
            &measured,
            &fitted_opts(&fitted, &opts),
            settings.samples,
            1,
        )
    {
        fitted.warn(format!("no Monte Carlo of the parameters: {e}"));
    }
    Ok((fitted, Some(sel)))
}

/// The correction's options as the kept correction of `f` was made.
fn fitted_opts(f: &FittedMaterial, opts: &inverse::Options) -> inverse::Options {
    inverse::Options {
        weighted: f.refined.as_ref().is_some_and(|r| r.weighted),
        ..opts.clone()
    }
}

/// The measured heights that the correction to the heights matches: the
/// points with a positive pressure and height.
pub fn measured_heights(points: &[Point]) -> Vec<inverse::Measured> {
    points
        .iter()
        .filter(|p| p.pressure_pa > 0.0 && p.height_m > 0.0)
        .map(|p| inverse::Measured {
            pressure_pa: p.pressure_pa,
            height_m: p.height_m,
            height_std_m: p.height_std_m,
        })
        .collect()
}

impl FitOut {
    /// One line on the fit: the model, points, R^2, RMSE, and the correction
    /// to the heights when made.
    pub fn summary(&self) -> String {
        let what = match &self.detail {
            FitDetail::Quartic(q) => format!(
                "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                self.model.label(),
                q.stats.n,
                q.stats.r2,
                q.stats.rmse
            ),
            FitDetail::Hyper { fits, best } => {
                let h = &fits[*best];
                format!(
                    "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                    h.kind.label(),
                    h.stats.n,
                    h.stats.r2,
                    h.stats.rmse
                )
            }
        };
        let what = match &self.refined {
            Some(r) => {
                format!("{what}; corrected to the heights: {}", r.describe())
            }
            None => what,
        };
        match &self.laws {
            Some(l) => format!("{what}; chosen of {} laws: {}", l.rows.len(), l.reason),
            None => what,
        }
    }
}

/// One simulated pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct SimPoint {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m; `None` when no equilibrium was found.
    pub height_m: Option<f64>,
    /// Newton iterations / relaxation steps / shots.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Time of this pressure, s.
    pub wall_s: f64,
    /// Why there is no height.
    pub note: Option<String>,
}

/// The heights of one model at every pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelRun {
    /// The spring model, or the axisymmetric reference.
    pub model: HeightModel,
    /// `newton`, `dr` or `shooting`.
    pub solver: String,
    /// Solved nodes (0 for the axisymmetric reference).
    pub nodes: usize,
    /// One per pressure.
    pub points: Vec<SimPoint>,
    /// Total time, s.
    pub wall_s: f64,
}

/// The pressures to simulate: the given list, or the distinct positive
/// measured pressures in increasing order.
pub fn pressures(settings: &Settings, points: &[Point]) -> Vec<f64> {
    if let Some(p) = &settings.pressures_pa {
        return p.clone();
    }
    let mut p: Vec<f64> = points
        .iter()
        .map(|p| p.pressure_pa)
        .filter(|&p| p > 0.0)
        .collect();
    p.sort_by(f64::total_cmp);
    p.dedup();
    p
}

/// Stage 4: the material on the specimen's disc at `pressures`, per model.
/// A pressure without equilibrium (above a limit point, a modulus law that
/// fails) ends that model's run with a note; the stage itself fails only
/// when a model cannot be set up.
pub fn simulate_stage(
    spec: &Specimen,
    settings: &Settings,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<Vec<ModelRun>, PipelineError> {
    crate::sim::scene::validate_pressures(pressures)
        .map_err(|m| PipelineError::Input(format!("pressures to simulate: {m}")))?;
    if pressures.windows(2).any(|w| w[1] <= w[0]) {
        return Err(PipelineError::Input(format!(
            "pressures to simulate {pressures:?}: give them in increasing order (each is continued from the previous)"
        )));
    }
    let mut scene =
        Scene::from_window(spec, &settings.window, material.clone(), pressures.to_vec());
    scene.mesh.size = settings.mesh;
    scene
        .validate(true)
        .map_err(|e| PipelineError::Input(e.to_string()))?;
    let opts = solve::Options {
        tolerance: settings.tolerance,
        ..solve::Options::default()
    };
    opts.validate()?;
    let mesh = match settings.mesh {
        Some(MeshSize::Accuracy(a)) if !settings.models.is_empty() => {
            crate::sim::disc::mesh_for_accuracy(
                &scene,
                &settings.models,
                settings.solver,
                opts,
                a,
                scene.mesh.max_nodes,
            )?
            .mesh
        }
        _ => scene.build_mesh()?,
    };
    let mut runs = Vec::new();
    for &model in &settings.models {
        let t_model = Instant::now();
        let mut disc =
            DiscSolver::on_mesh(&scene, mesh.clone(), model)?.with_solver(settings.solver, opts)?;
        // An apex at or below the clamp plane under a positive pressure is no
        // equilibrium to trust (a membrane near its stress-free state has no
        // stiffness: a domed one can fold through); it is not reported.
        let solved = |q: &crate::sim::SweepPoint| {
            let folded = q.pressure_pa > 0.0 && q.height_m <= 0.0;
            SimPoint {
                pressure_pa: q.pressure_pa,
                height_m: (!folded).then_some(q.height_m),
                iterations: q.stats.iterations,
                residual: q.stats.residual,
                wall_s: q.wall_s,
                note: if folded {
                    Some(format!(
                        "{} at {} Pa: the apex fell to {:.3e} m, at or below the clamp plane under a positive pressure (a membrane near its stress-free state has no stiffness); not reported",
                        model.name(),
                        q.pressure_pa,
                        q.height_m
                    ))
                } else if q.stats.relaxed {
                    Some(format!(
                        "{} at {} Pa: solved by dynamic relaxation ({} found the dome turned inside out, or no equilibrium, from the last one)",
                        model.name(),
                        q.pressure_pa,
                        settings.solver.name()
                    ))
                } else if q.stats.residual > opts.tolerance {
                    Some(format!(
                        "{} at {} Pa: the residual stopped at {:.2e} of the load, above the tolerance {:e}, at the round-off floor of double precision here; the height carries a relative error of about that size",
                        model.name(),
                        q.pressure_pa,
                        q.stats.residual,
                        opts.tolerance
                    ))
                } else {
                    None
                },
            }
        };
        let points = match disc.sweep(pressures, |_, _| tick()) {
            Ok(done) => done.iter().map(solved).collect(),
            Err((done, stop)) => {
                let mut points: Vec<SimPoint> = done.iter().map(solved).collect();
                points.push(SimPoint {
                    pressure_pa: stop.pressure_pa,
                    height_m: None,
                    iterations: 0,
                    residual: f64::NAN,
                    wall_s: stop.wall_s,
                    note: Some(format!(
                        "{} at {} Pa: {}",
                        model.name(),
                        stop.pressure_pa,
                        stop.error
                    )),
                });
                for &p in &pressures[stop.index + 1..] {
                    points.push(SimPoint {
                        pressure_pa: p,
                        height_m: None,
                        iterations: 0,
                        residual: f64::NAN,
                        wall_s: 0.0,
                        note: Some(format!(
                            "not solved: {} stopped at a lower pressure",
                            model.name()
                        )),
                    });
                }
                for _ in stop.index..pressures.len() {
                    tick();
                }
                points
            }
        };
        runs.push(ModelRun {
            model: HeightModel::Spring(model),
            solver: settings.solver.name().to_string(),
            nodes: mesh.nodes.len(),
            points,
            wall_s: t_model.elapsed().as_secs_f64(),
        });
    }
    // the exact axisymmetric reference holds for circular windows only
    if settings.axisym && settings.window.is_circle() {
        runs.push(axisym_run(spec, material, pressures, tick)?);
    }
    Ok(runs)
}

/// Warnings for the pressures asked for above the measured ones: the fitted
/// law is extrapolated there; past the law's limit point (the pressure
/// maximum of the exact inflation) a pressure-controlled bubble snaps through.
pub fn extrapolation_warnings(
    spec: &Specimen,
    material: &Material,
    measured: &[Point],
    pressures: &[f64],
) -> Vec<String> {
    let top = measured
        .iter()
        .map(|p| p.pressure_pa)
        .fold(f64::NEG_INFINITY, f64::max);
    let above: Vec<f64> = pressures
        .iter()
        .copied()
        .filter(|&p| top.is_finite() && p > top * (1.0 + 1e-9))
        .collect();
    if above.is_empty() {
        return Vec::new();
    }
    let list = |v: &[f64]| {
        v.iter()
            .map(|&p| fmt_short(p))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = vec![format!(
        "{} Pa above the largest measured pressure ({} Pa): the fitted law is extrapolated there and no measured height checks it",
        list(&above),
        fmt_short(top)
    )];
    if let Some((limit_pa, limit_m)) =
        crate::sim::hard::disc_limit_point(material, spec.radius_m, spec.thickness_m)
    {
        let past: Vec<f64> = above.iter().copied().filter(|&p| p > limit_pa).collect();
        if !past.is_empty() {
            out.push(format!(
                "{} Pa past the limit point of the fitted law ({} Pa, apex {} m): a pressure-controlled bubble snaps through there, so no height the springs give there is one a real bubble holds",
                list(&past),
                fmt_short(limit_pa),
                fmt_short(limit_m)
            ));
        }
    }
    out
}

/// The exact axisymmetric reference of `material` at `pressures`.
pub fn axisym_run(
    spec: &Specimen,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<ModelRun, PipelineError> {
    let t_model = Instant::now();
    let opts = axisym::Options {
        n_profile: 2,
        ..axisym::Options::default()
    };
    let mut points = Vec::new();
    for &p in pressures {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(material, spec, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        points.push(match out {
            Ok(s) => SimPoint {
                pressure_pa: p,
                height_m: Some(s.height_m),
                iterations: s.iterations,
                residual: s.residual,
                wall_s: wall,
                note: None,
            },
            Err(
                e @ (AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)),
            ) => return Err(e.into()),
            Err(e) => SimPoint {
                pressure_pa: p,
                height_m: None,
                iterations: 0,
                residual: f64::NAN,
                wall_s: wall,
                note: Some(format!("axisym at {p} Pa: {e}")),
            },
        });
        tick();
    }
    Ok(ModelRun {
        model: HeightModel::Axisym,
        solver: "shooting".into(),
        nodes: 0,
        points,
        wall_s: t_model.elapsed().as_secs_f64(),
    })
}

/// The columns every simulated-heights file starts with (`bulge simulate`,
/// `bulge simulate --dynamic`, `simulated.csv` of `bulge run`).
pub const SIMULATED_COLUMNS: [&str; 8] = [
    "pressure_pa",
    "height_m",
    "model",
    "solver",
    "nodes",
    "iterations",
    "residual",
    "wall_s",
];

/// `simulated.csv`: [`SIMULATED_COLUMNS`], solved pressures only (as
/// `bulge simulate`).
pub fn simulated_csv(runs: &[ModelRun]) -> CsvOut {
    let mut out = CsvOut::new(&SIMULATED_COLUMNS);
    for r in runs {
        for p in &r.points {
            if let Some(h) = p.height_m {
                out.row(&[
                    fmt_num(Some(p.pressure_pa)),
                    fmt_num(Some(h)),
                    r.model.to_string(),
                    r.solver.clone(),
                    r.nodes.to_string(),
                    p.iterations.to_string(),
                    format!("{:.3e}", p.residual),
                    format!("{:.4}", p.wall_s),
                ]);
            }
        }
    }
    out
}

/// One row of the comparison table (Tudruj et al. (2023), Table 3 layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Measured height, m (mean over frames at this pressure), if measured.
    pub measured_m: Option<f64>,
    /// Its standard deviation, m.
    pub measured_std_m: Option<f64>,
    /// Simulated height per model, in the order of [`RunOutput::runs`]
    /// (by model: [`RunOutput::rel_errors_of`]), m.
    pub simulated_m: Vec<Option<f64>>,
}

impl Comparison {
    /// Relative error `(simulated - measured) / measured` per model.
    pub fn rel_errors(&self) -> Vec<Option<f64>> {
        self.simulated_m
            .iter()
            .map(|s| match (s, self.measured_m) {
                (Some(s), Some(m)) if m != 0.0 => Some((s - m) / m),
                _ => None,
            })
            .collect()
    }
}

/// The comparison table: one row per simulated pressure.
pub fn compare(points: &[Point], runs: &[ModelRun], pressures: &[f64]) -> Vec<Comparison> {
    pressures
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let same: Vec<&Point> = points.iter().filter(|q| q.pressure_pa == p).collect();
            let n = same.len() as f64;
            let measured_m =
                (!same.is_empty()).then(|| same.iter().map(|q| q.height_m).sum::<f64>() / n);
            let measured_std_m = if same.is_empty() {
                None
            } else {
                let v: Option<Vec<f64>> = same.iter().map(|q| q.height_std_m).collect();
                v.map(|v| (v.iter().map(|s| s * s).sum::<f64>()).sqrt() / n)
            };
            Comparison {
                pressure_pa: p,
                measured_m,
                measured_std_m,
                simulated_m: runs
                    .iter()
                    .map(|r| r.points.get(i).and_then(|q| q.height_m))
                    .collect(),
            }
        })
        .collect()
}

/// How one model's heights stand against the measured ones within the
/// uncertainty: at each compared pressure `z = (h_model - h_measured) /
/// sd`, `sd` the standard deviation of that difference (the measured
/// height's own, and the corrected law's through the parameters'
/// covariance with the shared errors of both sides,
/// [`inverse::BandPoint::diff_std_m`]). The model is consistent when
/// every `|z|` stays below the two-sided 95 % bound for the largest of `n`
/// independent normals (Sidak's `Phi^-1(1 - (1 - 0.95^(1/n)) / 2)`: 1.96
/// for one pressure, 2.80 for ten), so that a model that is right passes
/// 95 % of the time however many pressures are compared (Z. Sidak,
/// "Rectangular confidence regions for the means of multivariate normal
/// distributions", JASA 62(318), 1967, doi:10.1080/01621459.1967.10482935).
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The model.
    pub model: HeightModel,
    /// Pressures compared.
    pub compared: usize,
    /// The largest `|z|` and its pressure, Pa.
    pub worst: Option<(f64, f64)>,
    /// The bound on `|z|`.
    pub bound: f64,
}

impl Verdict {
    /// Whether every compared height is within the bound (`None`: nothing
    /// compared).
    pub fn consistent(&self) -> Option<bool> {
        self.worst.map(|(z, _)| z <= self.bound)
    }

    /// "consistent within the uncertainty (largest |z| 1.3 of 2.80 allowed)"
    /// or "misses by 4.2 standard deviations at 3200 Pa".
    pub fn describe(&self) -> String {
        match self.worst {
            None => "no measured height with an uncertainty to compare".into(),
            Some((z, _)) if z <= self.bound => format!(
                "consistent within the uncertainty (largest |z| {z:.2} of {:.2} allowed over {} pressures)",
                self.bound, self.compared
            ),
            Some((z, p_pa)) => format!(
                "misses by {z:.1} standard deviations at {} Pa (allowed {:.2} over {} pressures)",
                fmt_short(p_pa),
                self.bound,
                self.compared
            ),
        }
    }
}

/// The verdict of every run against the measured heights (see [`Verdict`]);
/// `band` at the pressures of `rows`.
pub fn verdicts(
    rows: &[Comparison],
    runs: &[ModelRun],
    band: &[Option<inverse::BandPoint>],
) -> Vec<Verdict> {
    runs.iter()
        .enumerate()
        .map(|(k, r)| {
            let z: Vec<(f64, f64)> = rows
                .iter()
                .zip(band)
                .filter_map(|(c, b)| {
                    let (h, m, b) = (c.simulated_m.get(k).copied()??, c.measured_m?, (*b)?);
                    let sd = c.measured_std_m.unwrap_or(0.0).hypot(b.diff_std_m);
                    (sd > 0.0).then(|| ((h - m).abs() / sd, c.pressure_pa))
                })
                .collect();
            let n = z.len().max(1) as f64;
            let bound =
                crate::fit::uncertainty::normal_quantile(1.0 - 0.5 * (1.0 - 0.95f64.powf(1.0 / n)));
            Verdict {
                model: r.model,
                compared: z.len(),
                worst: z.into_iter().max_by(|a, b| a.0.total_cmp(&b.0)),
                bound,
            }
        })
        .collect()
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

/// Time spent in one stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// The stage.
    pub stage: Stage,
    /// Wall time, s.
    pub seconds: f64,
    /// What it did, e.g. `12 photos, 41.3 photos/s`.
    pub what: String,
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
    /// simulator's notes), each prefixed with its stage.
    pub notes: Vec<String>,
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
        notes.push(format!("{}: {m}", stage.name()));
    };
    let mut finish = |stage: Stage, t: Instant, what: String| {
        let timing = Timing {
            stage,
            seconds: t.elapsed().as_secs_f64(),
            what,
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
            );
            (None, h.points, h.relative)
        }
        None => {
            let tracking = track_stage_observed(exp, &with_exp, obs)
                .map_err(|e| fail(Stage::Track, e, &partial))?;
            let secs = t.elapsed().as_secs_f64();
            let n = tracking.tracked.rows.len();
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
    );
    partial.stress = Some(stress.clone());

    // 3. fit
    let t = Instant::now();
    obs.start(Stage::Fit, 0);
    let fit = fit_stage(spec, settings, &stress).map_err(|e| fail(Stage::Fit, e, &partial))?;
    for w in fit.warnings.iter().filter(|w| w.starts_with("only ")) {
        note(Stage::Fit, w.clone());
    }
    let what = fit.summary();
    finish(Stage::Fit, t, what);
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
    );
    for n in runs
        .iter()
        .flat_map(|r| r.points.iter().filter_map(|p| p.note.clone()))
        .filter(|n| !n.starts_with("not solved"))
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

/// The paper's chain (Tudruj et al. 2023): the quartic secant modulus,
/// corrected to the heights, through TP MSS and the exact axisymmetric
/// solution, kept beside the law the heights called for.
#[derive(Debug, Clone)]
pub struct PaperChain {
    /// The quartic's label.
    pub law: String,
    /// Its runs: TP MSS, then the axisymmetric reference.
    pub runs: Vec<ModelRun>,
    /// Measured against its simulated heights.
    pub comparison: Vec<Comparison>,
    /// Its verdicts against the measured heights (with the quartic's own
    /// band).
    pub verdicts: Vec<Verdict>,
}

/// The paper's chain when the fit stage chose a law other than the quartic
/// and the quartic was corrected to the heights; `None` otherwise (or when
/// its simulation fails: the quartic's row in `laws.csv` still says how it
/// fits).
pub fn paper_chain(
    spec: &Specimen,
    settings: &Settings,
    fit: &FitOut,
    points: &[Point],
    pressures_pa: &[f64],
) -> Option<PaperChain> {
    let laws = fit.laws.as_ref()?;
    let k = laws
        .rows
        .iter()
        .position(|r| matches!(r.model, FitModel::Quartic { .. }))?;
    if k == laws.chosen {
        return None;
    }
    let f = laws.rows[k].fitted.as_ref()?;
    let r = f.refined.as_ref()?;
    let s = Settings {
        models: vec![SpringModel::Tp],
        axisym: true,
        ..settings.clone()
    };
    let runs = simulate_stage(spec, &s, &f.material, pressures_pa, &|| {}).ok()?;
    let comparison = compare(points, &runs, pressures_pa);
    let verdicts = r
        .uncertainty
        .as_ref()
        .map(|u| {
            let band = inverse::band(
                &f.material,
                spec,
                u,
                &settings.uncertainty,
                pressures_pa,
                &inverse::Options::default().axisym,
            );
            verdicts(&comparison, &runs, &band)
        })
        .unwrap_or_default();
    Some(PaperChain {
        law: f.model.label(),
        runs,
        comparison,
        verdicts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Model;

    /// A neo-Hookean disc's pressure peaks at `P = 3.758347 C1 t / a`
    /// (Yang & Feng 1970; see docs/theory.md): 3507.8 Pa here.
    #[test]
    fn pressures_above_the_measurements_and_the_limit_point_are_flagged() {
        let spec = Specimen {
            radius_m: 0.0375,
            thickness_m: 3.5e-4,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        };
        let material = Material {
            model: Model::NeoHookean { c1_pa: 1.0e5 },
            poisson: 0.5,
            fit: None,
        };
        let measured: Vec<Point> = [500.0, 1000.0, 2000.0]
            .map(|p| Point {
                pressure_pa: p,
                height_m: 0.01,
                height_std_m: None,
            })
            .to_vec();
        let none = extrapolation_warnings(&spec, &material, &measured, &[500.0, 2000.0]);
        assert!(none.is_empty(), "{none:?}");
        let w = extrapolation_warnings(&spec, &material, &measured, &[1500.0, 3000.0, 3600.0]);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].starts_with("3000, 3600 Pa above the largest measured pressure (2000 Pa)"));
        assert!(
            w[1].starts_with("3600 Pa past the limit point of the fitted law (3507.79"),
            "{}",
            w[1]
        );
    }
}
