//! The closed loop: a synthetic experiment with known truth (photos drawn
//! from the exact axisymmetric inflation of a chosen material, with noise)
//! run through the whole pipeline, and the simulated heights compared with
//! the *true* heights. It measures which stress, strain and modulus
//! conventions make the pipeline reproduce the truth (docs/run.md), and is
//! shared by `examples/closed_loop.rs` (the study) and `tests/closed_loop.rs`
//! (a cheap version).
#![allow(dead_code)]

use std::path::Path;

use bulge::axisym;
use bulge::experiment::{Experiment, Specimen};
use bulge::material::Material;
use bulge::pipeline::{self, PipelineError, Settings, Tracking};
pub use bulge::sim::{HeightModel, SpringModel};
use bulge::track::image::Encoding;
use bulge::track::synth::{self, SequenceSpec, Silhouette, SynthFrame, Truth};

/// TP MSS, the key of its errors.
pub const TP: HeightModel = HeightModel::Spring(SpringModel::Tp);
/// Van Gelder, the key of its errors.
pub const VAN_GELDER: HeightModel = HeightModel::Spring(SpringModel::VanGelder);

/// A synthetic experiment to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Name in tables.
    pub name: String,
    /// The true material.
    pub material: Material,
    /// The specimen.
    pub specimen: Specimen,
    /// Number of photos.
    pub frames: usize,
    /// Highest pressure as a fraction of the true limit-point pressure
    /// (or of `p_max_pa` when the inflation has no limit point).
    pub top_fraction: f64,
    /// Highest pressure when there is no limit point, Pa.
    pub p_max_pa: f64,
    /// Image width and height, px.
    pub size: [usize; 2],
    /// Sensor noise, grey levels; blur, px; JPEG quality (None: PNG).
    pub noise: (f64, f64, Option<u8>),
    /// Seed.
    pub seed: u64,
}

/// A drawn experiment, tracked once.
#[derive(Debug, Clone)]
pub struct Drawn {
    /// The case.
    pub case: Case,
    /// The limit-point pressure of the true material, Pa (None: none found).
    pub limit_pa: Option<f64>,
    /// The truth per photo.
    pub truth: Vec<Truth>,
    /// The experiment file read back.
    pub experiment: Experiment,
    /// The tracking result.
    pub tracking: Tracking,
}

/// Draws `case` into `dir` (photos, experiment.toml, truth) and tracks it.
pub fn draw(case: &Case, dir: &Path, settings: &Settings) -> Result<Drawn, PipelineError> {
    let opts = axisym::Options::default();
    let limit = axisym::limit_point(&case.material, &case.specimen, &opts)?;
    let limit_pa = limit.as_ref().map(|s| s.pressure_pa);
    let top = limit_pa.unwrap_or(case.p_max_pa) * case.top_fraction;
    let n = case.frames.max(1);
    let mut frames = Vec::with_capacity(n);
    for k in 1..=n {
        let p = top * k as f64 / n as f64;
        let sol = axisym::solve_pressure(&case.material, &case.specimen, p, &opts)?;
        frames.push(SynthFrame {
            pressure_pa: p,
            silhouette: Silhouette {
                rho_m: sol.profile.rho_m.clone(),
                z_m: sol.profile.z_m.clone(),
            },
        });
    }
    let spec = SequenceSpec {
        width: case.size[0],
        height: case.size[1],
        seed: case.seed,
        blur_px: case.noise.1,
        noise_grey: case.noise.0,
        drift: 0.0,
        encoding: case.noise.2.map_or(Encoding::Png, Encoding::Jpeg),
        specimen: case.specimen,
        framing: Default::default(),
        look: Default::default(),
        window: Default::default(),
    };
    let written = synth::write_sequence(dir, &spec, &frames)?;
    let experiment = Experiment::read(dir.join("experiment.toml"))
        .map_err(|e| PipelineError::Input(e.to_string()))?;
    let tracking = pipeline::track_stage(&experiment, settings, &|| {})?;
    Ok(Drawn {
        case: case.clone(),
        limit_pa,
        truth: written.truth,
        experiment,
        tracking,
    })
}

/// Errors of one pipeline run against the truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Per model (in the order of the runs): relative errors
    /// `simulated / true - 1` at every pressure below the limit point
    /// (`None` where the model found no equilibrium).
    pub errors: Vec<(HeightModel, Vec<Option<f64>>)>,
    /// Relative errors of the measured (tracked) heights against the truth.
    pub tracking_errors: Vec<f64>,
}

impl Outcome {
    /// Largest absolute error of a model; infinite when a pressure was not solved.
    pub fn max_abs(&self, model: HeightModel) -> f64 {
        self.errors
            .iter()
            .find(|(m, _)| *m == model)
            .map(|(_, e)| {
                e.iter()
                    .map(|e| e.map_or(f64::INFINITY, f64::abs))
                    .fold(0.0, f64::max)
            })
            .unwrap_or(f64::INFINITY)
    }

    /// Root-mean-square error of a model over the solved pressures.
    pub fn rms(&self, model: HeightModel) -> f64 {
        self.errors
            .iter()
            .find(|(m, _)| *m == model)
            .map(|(_, e)| {
                let v: Vec<f64> = e.iter().flatten().copied().collect();
                (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
            })
            .unwrap_or(f64::INFINITY)
    }
}

/// Runs stress, fit and simulate on a tracked experiment with `settings` and
/// compares the simulated heights with the true ones at the measured
/// pressures.
pub fn evaluate(d: &Drawn, settings: &Settings) -> Result<Outcome, PipelineError> {
    let spec = d.experiment.specimen;
    let stress = pipeline::stress_stage(&spec, settings, d.tracking.points())?;
    let fit = pipeline::fit_stage(&spec, settings, &stress)?;
    let pressures = pipeline::pressures(settings, &stress.points);
    let runs = pipeline::simulate_stage(&spec, settings, &fit.material, &pressures, &|| {})?;
    let truth_at = |p: f64| {
        d.truth
            .iter()
            .find(|t| (t.pressure_pa - p).abs() <= 1e-9 * p)
            .map(|t| t.height_m)
    };
    let below = |p: f64| d.limit_pa.is_none_or(|l| p < l);
    let errors = runs
        .iter()
        .map(|r| {
            let e = r
                .points
                .iter()
                .filter(|q| below(q.pressure_pa))
                .map(|q| match (q.height_m, truth_at(q.pressure_pa)) {
                    (Some(h), Some(t)) => Some(h / t - 1.0),
                    _ => None,
                })
                .collect();
            (r.model, e)
        })
        .collect();
    let tracking_errors = d
        .tracking
        .tracked
        .rows
        .iter()
        .filter_map(|r| truth_at(r.pressure_pa).map(|t| r.height_m / t - 1.0))
        .collect();
    Ok(Outcome {
        errors,
        tracking_errors,
    })
}
