//! Inverse identification: the law fitted by the spherical-cap method,
//! corrected until the exact axisymmetric inflation of the specimen
//! reproduces the measured apex heights.
//!
//! The cap method (Tudruj et al. (2023), section 7) turns each height into a stress and
//! a strain as if the bubble were a sphere of uniform, equibiaxial strain. A
//! real bubble is not: its strain falls from the pole to the clamp, where it
//! is planar. A law fitted to those points is therefore biased, and the
//! exact solution with that law misses the measured heights by a few per
//! cent (docs/run.md). The correction keeps the model and its parameters and
//! solves
//!
//! `min_theta sum_i (h(p_i; theta) / h_i - 1)^2`
//!
//! where `h(p; theta)` is the apex height of the axisymmetric membrane
//! ([`crate::axisym::solve_pressure`]) with the law's parameters `theta`, by
//! Levenberg-Marquardt from the cap fit: first for one
//! factor on its stress parameters, then for every parameter. The Jacobian is
//! exact: the derivatives of each apex height with respect to the law's
//! parameters come from the forward sensitivity equations integrated along
//! the shot ([`axisym::height_gradient`]), and each height is found by Newton's
//! method from the last solution at its pressure (a cold solve only the first
//! time, or when Newton leaves the branch), the pressures in parallel.
//! ([`Derivatives::CentralDifferences`], two cold solves per parameter and
//! point, is kept as the reference it is timed against.) A trial law
//! with no equilibrium at some measured pressure (a limit point below it)
//! gives non-finite residuals, which the solver rejects like an uphill step.
//!
//! This is finite-element model updating with the exact axisymmetric
//! solution in place of the finite elements; the relative residual weighs
//! every photo alike, as the closed-loop target (simulated within 2 % of the
//! truth at every pressure) does.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use argmin::core::{Error as ArgminError, Jacobian, Operator};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::FitError;
use super::hyperelastic::Kind;
use super::lm;
use super::quartic;
use super::uncertainty::{self, ParamUncertainty, SourceKind, Sources};
use crate::axisym;
use crate::experiment::Specimen;
use crate::material::{Material, Model};

mod band;
mod covariance;
mod joint;
mod prebulge;
mod problem;
mod scene;
#[cfg(test)]
mod tests;

use band::*;
pub use band::{BandPoint, band};
pub use covariance::law_parameters;
use covariance::*;
pub use joint::{JointRefined, refine_joint};
pub use prebulge::refine_with_prebulge;
use problem::*;
pub use scene::refine_in_scene;

/// One measured point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Pressure, Pa (> 0).
    pub pressure_pa: f64,
    /// Apex height, m (> 0).
    pub height_m: f64,
    /// Standard deviation of the height, m, when known: the fit is then
    /// weighted and its covariance built from the given errors
    /// ([`super::uncertainty`]).
    pub height_std_m: Option<f64>,
}

impl Measured {
    /// The points of a table with the columns `pressure_pa` and `height_m`
    /// (as `bulge stress` writes them) with a positive pressure and height;
    /// `None` when the table lacks either column.
    pub fn from_table(
        t: &crate::io::Table,
    ) -> Result<Option<Vec<Measured>>, crate::io::InputError> {
        let (Some(p), Some(h)) = (
            t.optional_numbers("pressure_pa")?,
            t.optional_numbers("height_m")?,
        ) else {
            return Ok(None);
        };
        let sd = t
            .optional_numbers("height_std_m")?
            .unwrap_or_else(|| vec![None; p.len()]);
        Ok(Some(
            p.iter()
                .zip(&h)
                .zip(&sd)
                .filter_map(|((p, h), sd)| match (p, h) {
                    (Some(p), Some(h)) if *p > 0.0 && *h > 0.0 => Some(Measured {
                        pressure_pa: *p,
                        height_m: *h,
                        height_std_m: *sd,
                    }),
                    _ => None,
                })
                .collect(),
        ))
    }
}

/// How the heights' Jacobian is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Derivatives {
    /// Exact, from the forward sensitivity equations along the shot
    /// ([`axisym::height_gradient`]); each height found by Newton's method
    /// from the last solution at its pressure (the default).
    Exact,
    /// Central differences of heights each solved from scratch, two solves
    /// per parameter and point: the reference the exact ones are checked
    /// and timed against.
    CentralDifferences,
}

/// Settings of the correction.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Levenberg-Marquardt iterations at most.
    pub max_iterations: u64,
    /// The axisymmetric solver's settings.
    pub axisym: axisym::Options,
    /// How the Jacobian is found.
    pub derivatives: Derivatives,
    /// The uncertainty of the inputs besides the heights' own, carried to
    /// the parameters' covariance (default: all exact).
    pub uncertainty: Sources,
    /// Weigh each point by its independent standard deviation, `(h_sim -
    /// h) / sigma`, when every point has one, instead of the relative error
    /// `h_sim / h - 1` (default false: see docs/fit.md, "Weights").
    pub weighted: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_iterations: 40,
            axisym: axisym::Options {
                n_profile: 2,
                ..axisym::Options::default()
            },
            derivatives: Derivatives::Exact,
            uncertainty: Sources::default(),
            weighted: false,
        }
    }
}

/// The corrected law and how well each law reproduces the heights.
#[derive(Debug, Clone)]
pub struct Refined {
    /// The corrected material (same model, new parameters).
    pub material: Material,
    /// `h(p_i) / h_i - 1` of the starting law, per measured point (`None`
    /// where it has no equilibrium).
    pub before: Vec<Option<f64>>,
    /// The same for the corrected law.
    pub after: Vec<Option<f64>>,
    /// Levenberg-Marquardt iterations.
    pub iterations: u64,
    /// Axisymmetric solves spent.
    pub solves: usize,
    /// What the correction was held to, if anything (a quartic's implied
    /// stress kept increasing over its strain range).
    pub constraint: Option<String>,
    /// The stress-free dome height found beside the law, m, when it was
    /// sought ([`refine_with_prebulge`]).
    pub prebulge_height_m: Option<f64>,
    /// Its standard error, m, from the curvature of the fit's misfit in it
    /// (the law corrected again at every trial height), when determined.
    pub prebulge_std_m: Option<f64>,
    /// The non-circular window the correction simulated with the membrane
    /// model ([`refine_in_scene`]); `None` for the axisymmetric one.
    pub window: Option<String>,
    /// The corrected parameters' uncertainty (`None` when the data do not
    /// determine every parameter, or there are no residual degrees of
    /// freedom without given errors).
    pub uncertainty: Option<ParamUncertainty>,
    /// Whether the fit was weighted by the points' standard deviations.
    pub weighted: bool,
    /// The Monte Carlo of the parameters, when asked for
    /// ([`super::monte_carlo::monte_carlo`]).
    pub monte_carlo: Option<super::monte_carlo::MonteCarlo>,
}

impl Refined {
    /// Root-mean-square of the relative height errors (`None` if a point
    /// has no equilibrium).
    pub fn rms(errors: &[Option<f64>]) -> Option<f64> {
        let v: Option<Vec<f64>> = errors.iter().copied().collect();
        let v = v?;
        Some((v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt())
    }

    /// `rms height error 2.28 % -> 0.52 % (21 iterations, 3440 axisymmetric
    /// solves)`.
    pub fn describe(&self) -> String {
        let pct = |e: &[Option<f64>]| {
            Refined::rms(e).map_or("-".to_string(), |v| format!("{:.2} %", 100.0 * v))
        };
        format!(
            "rms height error {} -> {} ({} iterations, {} {})",
            pct(&self.before),
            pct(&self.after),
            self.iterations,
            self.solves,
            if self.window.is_some() {
                "membrane sweeps"
            } else {
                "axisymmetric solves"
            }
        )
    }

    /// Largest absolute relative height error (`None` as for [`Refined::rms`]).
    pub fn max_abs(errors: &[Option<f64>]) -> Option<f64> {
        let v: Option<Vec<f64>> = errors.iter().copied().collect();
        Some(v?.iter().map(|e| e.abs()).fold(0.0, f64::max))
    }
}

impl Refined {
    /// The `[fit.refined]` table of `material.toml`: the method, the rms
    /// height error before and after, the effort, and the law it started
    /// from (`cap`).
    pub fn toml_table(&self, cap: &Model) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert(
            "method".into(),
            match &self.window {
                None => "parameters corrected so that the exact axisymmetric inflation reproduces the measured heights (least squares of h_sim / h - 1)".to_string(),
                Some(w) => format!("parameters corrected so that the membrane model (constant-strain triangles) on the {w} reproduces the measured heights (least squares of h_sim / h - 1)"),
            }
            .into(),
        );
        if let Some(v) = Refined::rms(&self.before) {
            t.insert("height_rms_before".into(), v.into());
        }
        if let Some(v) = Refined::rms(&self.after) {
            t.insert("height_rms_after".into(), v.into());
        }
        if let Some(c) = &self.constraint {
            t.insert("constraint".into(), c.clone().into());
        }
        if let Some(h0) = self.prebulge_height_m {
            t.insert("prebulge_height_m".into(), h0.into());
        }
        if let Some(u) = &self.uncertainty {
            let mut u = u.toml_table();
            if let Some(mc) = &self.monte_carlo {
                u.insert("monte_carlo".into(), mc.toml_table().into());
            }
            t.insert("uncertainty".into(), u.into());
        }
        t.insert("iterations".into(), (self.iterations as i64).into());
        t.insert("axisym_solves".into(), (self.solves as i64).into());
        t.insert(
            "cap_law".into(),
            toml::Value::try_from(cap).unwrap_or_else(|e| e.to_string().into()),
        );
        t
    }
}

/// How the parameters of a model map to a vector of O(1) unknowns.
#[derive(Debug, Clone)]
enum Params {
    /// `E(eps) = sum c_k eps^k`: unknown `k` is `c_k / (c_0 / eps_max^k)`,
    /// each term's size at the largest strain in units of `c_0`.
    Quartic { template: Model, scale: Vec<f64> },
    /// A hyperelastic model: stress parameters over the largest of them,
    /// exponents and locking parameters as they are.
    Hyper { kind: Kind, scale: Vec<f64> },
    /// Linear: Young's modulus over its starting value.
    Linear { scale: f64 },
}

impl Params {
    fn of(model: &Model) -> Result<(Params, Vec<f64>), FitError> {
        match model {
            Model::Quartic {
                coefficients_pa,
                strain_range,
                ..
            } => {
                let c0 = coefficients_pa.first().copied().unwrap_or(0.0).abs();
                let top = strain_range[1].abs().max(1e-6);
                let big = coefficients_pa.iter().fold(0.0f64, |m, c| m.max(c.abs()));
                let unit = if c0 > 0.0 { c0 } else { big.max(1.0) };
                let scale: Vec<f64> = (0..coefficients_pa.len())
                    .map(|k| unit / top.powi(k as i32))
                    .collect();
                let x = coefficients_pa
                    .iter()
                    .zip(&scale)
                    .map(|(c, s)| c / s)
                    .collect();
                Ok((
                    Params::Quartic {
                        template: model.clone(),
                        scale,
                    },
                    x,
                ))
            }
            Model::Linear { young_pa } => Ok((Params::Linear { scale: *young_pa }, vec![1.0])),
            _ => {
                let kind = match model {
                    Model::NeoHookean { .. } => Kind::NeoHookean,
                    Model::MooneyRivlin { .. } => Kind::MooneyRivlin,
                    Model::Yeoh { .. } => Kind::Yeoh,
                    Model::Ogden { mu_pa, .. } => Kind::Ogden(mu_pa.len()),
                    Model::Gent { .. } => Kind::Gent,
                    Model::Linear { .. } | Model::Quartic { .. } => unreachable!("handled above"),
                };
                let p = kind.params_of(model).ok_or_else(|| {
                    FitError::Unsupported(format!("{}: parameters not recognised", model.name()))
                })?;
                let stress = (0..p.len())
                    .filter(|&k| kind.is_stress(k))
                    .fold(0.0f64, |m, k| m.max(p[k].abs()))
                    .max(1.0);
                let scale: Vec<f64> = (0..p.len())
                    .map(|k| if kind.is_stress(k) { stress } else { 1.0 })
                    .collect();
                let x = p.iter().zip(&scale).map(|(v, s)| v / s).collect();
                Ok((Params::Hyper { kind, scale }, x))
            }
        }
    }

    /// `x0` with its stress-like parameters (all but the Ogden exponents
    /// and the Gent locking parameter) multiplied by `s`.
    fn scaled(&self, x0: &[f64], s: f64) -> Vec<f64> {
        x0.iter()
            .enumerate()
            .map(|(k, &v)| match self {
                Params::Hyper { kind, .. } if !kind.is_stress(k) => v,
                _ => v * s,
            })
            .collect()
    }

    fn model(&self, x: &[f64]) -> Model {
        match self {
            Params::Quartic { template, scale } => {
                let mut m = template.clone();
                if let Model::Quartic {
                    coefficients_pa, ..
                } = &mut m
                {
                    *coefficients_pa = x.iter().zip(scale).map(|(v, s)| v * s).collect();
                }
                m
            }
            Params::Hyper { kind, scale } => {
                let p: Vec<f64> = x.iter().zip(scale).map(|(v, s)| v * s).collect();
                kind.model(&p)
            }
            Params::Linear { scale } => Model::Linear {
                young_pa: x[0] * scale,
            },
        }
    }
}

/// The law's free parameters and their start, once the measured points are
/// checked: at least as many as parameters, every pressure and height
/// positive and finite.
fn parameters_for(
    material: &Material,
    measured: &[Measured],
) -> Result<(Params, Vec<f64>), FitError> {
    let (params, x0) = Params::of(&material.model)?;
    if measured.len() < x0.len() {
        return Err(FitError::TooFewPoints {
            model: format!("{} (inverse fit to the heights)", material.model.name()),
            points: measured.len(),
            parameters: x0.len(),
        });
    }
    if let Some((i, q)) = measured.iter().enumerate().find(|(_, q)| {
        !(q.pressure_pa.is_finite()
            && q.pressure_pa > 0.0
            && q.height_m.is_finite()
            && q.height_m > 0.0)
    }) {
        return Err(FitError::Unsupported(format!(
            "measured point {i}: pressure {} Pa, height {} m; the inverse fit needs positive pressures and heights",
            q.pressure_pa, q.height_m
        )));
    }
    Ok((params, x0))
}

/// `h(p_i) / h_i - 1` of `material` as it is, per measured point (`None`
/// where it has no equilibrium): the exact axisymmetric heights of
/// `specimen` against `measured`, without correcting anything.
pub fn height_errors(
    material: &Material,
    specimen: &Specimen,
    measured: &[Measured],
    opts: &Options,
) -> Result<Vec<Option<f64>>, FitError> {
    // Nothing is fitted: any number of points will do.
    let (params, x0) = Params::of(&material.model)?;
    let solves = AtomicUsize::new(0);
    let warm: Vec<Mutex<Option<(f64, f64)>>> = measured.iter().map(|_| Mutex::new(None)).collect();
    let problem = Problem {
        derivatives: opts.derivatives,
        warm: &warm,
        params,
        base: material,
        specimen,
        points: measured,
        opts: &opts.axisym,
        solves: &solves,
        scale_of: None,
        weights: None,
        monotone: None,
    };
    Ok(problem.errors(&x0))
}

/// The correction's parameters, the errors there and the iterations taken.
struct Corrected {
    x: Vec<f64>,
    after: Vec<Option<f64>>,
    iterations: u64,
}

/// What the correction's two passes ([`scale_then_all`]) need of a
/// least-squares problem of the heights: the axisymmetric one
/// ([`Problem`]) and the membrane's on a window ([`scene::SceneProblem`]).
trait Correction:
    Clone
    + Operator<Param = DVector<f64>, Output = DVector<f64>>
    + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>
{
    /// The law's parameters.
    fn params(&self) -> &Params;
    /// `h(p_i) / h_i - 1` per point at `x`, `None` where there is no
    /// equilibrium.
    fn errors(&self, x: &[f64]) -> Vec<Option<f64>>;
    /// The same problem with one unknown: a factor on `x0`'s stress
    /// parameters.
    fn scaling(&self, x0: &[f64]) -> Self;
}

impl Correction for Problem<'_> {
    fn params(&self) -> &Params {
        &self.params
    }
    fn errors(&self, x: &[f64]) -> Vec<Option<f64>> {
        Problem::errors(self, x)
    }
    fn scaling(&self, x0: &[f64]) -> Self {
        Problem {
            scale_of: Some(x0.to_vec()),
            ..self.clone()
        }
    }
}

impl Correction for scene::SceneProblem<'_> {
    fn params(&self) -> &Params {
        &self.params
    }
    fn errors(&self, x: &[f64]) -> Vec<Option<f64>> {
        scene::SceneProblem::errors(self, x)
    }
    fn scaling(&self, x0: &[f64]) -> Self {
        scene::SceneProblem {
            scale_of: Some(x0.to_vec()),
            ..self.clone()
        }
    }
}

/// The correction's two passes, shared by the axisymmetric and the
/// membrane paths: first one factor on the stress parameters from `x0`
/// scaled by `start` (a start 20-40 % too stiff or soft, as other stress
/// conventions give, is mostly a scale), then every parameter from there.
/// The starting law `x0` is kept, with its errors `before`, when the
/// correction does not improve the rms error (a start without an
/// equilibrium everywhere is beaten by any law that has one).
fn scale_then_all<P: Correction>(
    problem: &P,
    x0: Vec<f64>,
    start: f64,
    before: &[Option<f64>],
    max_iterations: u64,
) -> Result<Corrected, FitError> {
    let solver = |e: ArgminError| FitError::Solver(e.to_string());
    let scale = lm::minimize(
        problem.scaling(&x0),
        DVector::from_vec(vec![start]),
        max_iterations,
    )
    .map_err(solver)?;
    let x1 = problem.params().scaled(&x0, scale.x[0]);
    let r = lm::minimize(problem.clone(), DVector::from_vec(x1), max_iterations).map_err(solver)?;
    let after = problem.errors(r.x.as_slice());
    let better = match (Refined::rms(&after), Refined::rms(before)) {
        (Some(a), Some(b)) => a < b,
        (Some(_), None) => true,
        _ => false,
    };
    Ok(if better {
        Corrected {
            x: r.x.as_slice().to_vec(),
            after,
            iterations: scale.iterations + r.iterations,
        }
    } else {
        Corrected {
            x: x0,
            after: before.to_vec(),
            iterations: scale.iterations + r.iterations,
        }
    })
}

/// Corrects `material`'s parameters so that the axisymmetric inflation of
/// `specimen` reproduces `measured` (see the module documentation).
///
/// Fails when there are fewer points than parameters, or when the starting
/// law has no equilibrium at some measured pressure (the correction needs
/// a starting point where every residual exists; leave out the photos past
/// the limit point).
pub fn refine(
    material: &Material,
    specimen: &Specimen,
    measured: &[Measured],
    opts: &Options,
) -> Result<Refined, FitError> {
    let (params, x0) = parameters_for(material, measured)?;
    let solves = AtomicUsize::new(0);
    let warm: Vec<Mutex<Option<(f64, f64)>>> = measured.iter().map(|_| Mutex::new(None)).collect();
    let problem = Problem {
        derivatives: opts.derivatives,
        warm: &warm,
        params,
        base: material,
        specimen,
        points: measured,
        opts: &opts.axisym,
        solves: &solves,
        scale_of: None,
        weights: None,
        monotone: match &material.model {
            Model::Quartic { strain_range, .. } if strain_range[1] > strain_range[0] => {
                Some(*strain_range)
            }
            _ => None,
        },
    };
    let before = problem.errors(&x0);
    if let Some(i) = before.iter().position(Option::is_none) {
        return Err(FitError::Solver(format!(
            "the starting {} law has no axisymmetric equilibrium at {} Pa (measured point {i}): the measured pressures pass its limit point",
            material.model.name(),
            measured[i].pressure_pa
        )));
    }
    // Weighted, when asked, by the points' independent errors when every
    // point has one: the height's own and the pressure noise's, through
    // dh/dp at the starting law.
    let sources = &opts.uncertainty;
    let sigma0 = if opts.weighted {
        independent_std(&problem, &x0, sources)
    } else {
        None
    };
    let weights: Option<Vec<f64>> = sigma0.as_ref().map(|s| {
        let w: Vec<f64> = measured
            .iter()
            .zip(s)
            .map(|(q, s)| q.height_m / s)
            .collect();
        let mean = w.iter().sum::<f64>() / w.len() as f64;
        w.iter().map(|v| v / mean).collect()
    });
    let problem = Problem {
        weights: weights.as_deref(),
        ..problem
    };
    let Corrected {
        x,
        after,
        iterations,
    } = scale_then_all(&problem, x0, 1.0, &before, opts.max_iterations)?;
    let sigma = match sigma0 {
        Some(s) => Some(s),
        None => independent_std(&problem, &x, sources),
    };
    let uncertainty = covariance(&problem, &x, sources, sigma.as_deref(), weights.is_some());
    Ok(Refined {
        material: Material {
            model: problem.params.model(&x),
            poisson: material.poisson,
            fit: material.fit.clone(),
        },
        before,
        after,
        iterations,
        solves: solves.load(Ordering::Relaxed),
        prebulge_height_m: None,
        prebulge_std_m: None,
        window: None,
        uncertainty,
        weighted: weights.is_some(),
        monte_carlo: None,
        constraint: problem.monotone.map(|[lo, hi]| {
            format!(
                "the implied stress E(eps)*eps kept increasing over the strain range [{lo:.6}, {hi:.6}] (a penalty on a slope below {MONOTONE_MARGIN} c0 at {MONOTONE_SAMPLES} strains, weight {MONOTONE_WEIGHT})"
            )
        }),
    })
}
