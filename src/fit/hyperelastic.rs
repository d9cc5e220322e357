//! Incompressible hyperelastic models fitted to equibiaxial data, the state
//! at the pole of an inflated membrane (`l1 = l2 = l`, `l3 = l^-2`).
//!
//! With `J = I1 - 3 = 2 l^2 + l^-4 - 3` the equibiaxial nominal (first Piola)
//! stress `P = dW/dl1 (l, l)` of each model is (the Cauchy stress is `l P`):
//!
//! | model | `P(l)` | parameters |
//! |---|---|---|
//! | neo-Hookean | `2 C1 (l - l^-5)` | `C1` |
//! | Mooney-Rivlin | `2 (l - l^-5) (C1 + C2 l^2)` | `C1, C2` |
//! | Yeoh | `2 (l - l^-5) (C1 + 2 C2 J + 3 C3 J^2)` | `C1, C2, C3` |
//! | Ogden, N terms | `sum mu_i (l^(alpha_i - 1) - l^(-2 alpha_i - 1))` | `mu_i, alpha_i` |
//! | Gent | `mu (l - l^-5) / (1 - J / Jm)` | `mu, Jm > max J` |
//!
//! These closed forms and their derivatives in the parameters drive the
//! fit; the reported residuals are recomputed from the general energies of
//! [`crate::material`] (dual numbers), and a unit test checks that the two
//! agree.
//!
//! The residuals are `model - data` in the stress measure of the data
//! (nominal for Treloar-style tables, Cauchy for `stress_strain.csv`),
//! unweighted, or divided by each point's standard deviation
//! ([`fit_weighted`]). Neo-Hookean, Mooney-Rivlin and Yeoh are linear in their
//! parameters for either measure: their least-squares problem is convex and
//! the linear solution (the SVD) is the global minimum; it starts
//! the Levenberg-Marquardt iteration (run by argmin), which
//! then only confirms it. Ogden (in `alpha`) and Gent (in `Jm`) are not
//! convex: they are started from a grid of the nonlinear parameters, the
//! linear ones (`mu`) set at each grid point by linear least squares, and the
//! best end point kept, preferring end points that are Drucker-stable over
//! the fitted range (see [`drucker`]).
//!
//! Bounds, enforced by rejecting trial steps outside them: Gent
//! `mu > 0` and `Jm > max_i J(l_i)` (the log in `W` must stay defined at every
//! data point); Ogden `0.05 <= |alpha_i| <= 30` (an exponent of 0 makes
//! `mu/alpha` singular).

use super::FitError;
use super::StressMeasure;
use super::lm;
use super::stats::Stats;
use crate::material::Model;
use argmin::core::{Error as ArgminError, Jacobian, Operator};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

mod starts;
use starts::starting_points;

pub mod drucker;

#[cfg(test)]
mod tests;

/// Which hyperelastic model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `W = C1 (I1 - 3)`.
    NeoHookean,
    /// `W = C1 (I1 - 3) + C2 (I2 - 3)`.
    MooneyRivlin,
    /// Three-term Yeoh.
    Yeoh,
    /// Ogden with 1 to 3 terms.
    Ogden(usize),
    /// Gent.
    Gent,
}

impl Kind {
    /// All models compared by `bulge fit --model all`.
    pub fn all() -> Vec<Kind> {
        vec![
            Kind::NeoHookean,
            Kind::MooneyRivlin,
            Kind::Yeoh,
            Kind::Ogden(1),
            Kind::Ogden(2),
            Kind::Ogden(3),
            Kind::Gent,
        ]
    }

    /// Display name, e.g. `ogden-3`.
    pub fn label(&self) -> String {
        match self {
            Kind::NeoHookean => "neo-hookean".into(),
            Kind::MooneyRivlin => "mooney-rivlin".into(),
            Kind::Yeoh => "yeoh".into(),
            Kind::Ogden(n) => format!("ogden-{n}"),
            Kind::Gent => "gent".into(),
        }
    }

    /// Number of fitted parameters.
    pub fn n_params(&self) -> usize {
        match self {
            Kind::NeoHookean => 1,
            Kind::MooneyRivlin | Kind::Gent => 2,
            Kind::Yeoh => 3,
            Kind::Ogden(n) => 2 * n,
        }
    }

    /// Whether the least-squares problem is linear in the parameters.
    pub fn is_linear(&self) -> bool {
        matches!(self, Kind::NeoHookean | Kind::MooneyRivlin | Kind::Yeoh)
    }

    /// Parameter names with units, in fit order.
    pub fn param_names(&self) -> Vec<String> {
        match self {
            Kind::NeoHookean => vec!["c1_pa".into()],
            Kind::MooneyRivlin => vec!["c1_pa".into(), "c2_pa".into()],
            Kind::Yeoh => vec!["c1_pa".into(), "c2_pa".into(), "c3_pa".into()],
            Kind::Ogden(n) => (1..=*n)
                .map(|i| format!("mu{i}_pa"))
                .chain((1..=*n).map(|i| format!("alpha{i}")))
                .collect(),
            Kind::Gent => vec!["mu_pa".into(), "jm".into()],
        }
    }

    /// Whether parameter `k` has the unit of stress (scaled in the fit).
    pub(crate) fn is_stress(&self, k: usize) -> bool {
        match self {
            Kind::Ogden(n) => k < *n,
            Kind::Gent => k == 0,
            _ => true,
        }
    }

    /// The material for parameters `x` (stress parameters in Pa).
    pub fn model(&self, x: &[f64]) -> Model {
        match self {
            Kind::NeoHookean => Model::NeoHookean { c1_pa: x[0] },
            Kind::MooneyRivlin => Model::MooneyRivlin {
                c1_pa: x[0],
                c2_pa: x[1],
            },
            Kind::Yeoh => Model::Yeoh {
                c1_pa: x[0],
                c2_pa: x[1],
                c3_pa: x[2],
            },
            Kind::Ogden(n) => Model::Ogden {
                mu_pa: x[..*n].to_vec(),
                alpha: x[*n..].to_vec(),
            },
            Kind::Gent => Model::Gent {
                mu_pa: x[0],
                jm: x[1],
            },
        }
    }

    /// Parameters of a material of this kind (inverse of [`Kind::model`]).
    pub fn params_of(&self, m: &Model) -> Option<Vec<f64>> {
        match (self, m) {
            (Kind::NeoHookean, Model::NeoHookean { c1_pa }) => Some(vec![*c1_pa]),
            (Kind::MooneyRivlin, Model::MooneyRivlin { c1_pa, c2_pa }) => {
                Some(vec![*c1_pa, *c2_pa])
            }
            (
                Kind::Yeoh,
                Model::Yeoh {
                    c1_pa,
                    c2_pa,
                    c3_pa,
                },
            ) => Some(vec![*c1_pa, *c2_pa, *c3_pa]),
            (Kind::Ogden(n), Model::Ogden { mu_pa, alpha })
                if mu_pa.len() == *n && alpha.len() == *n =>
            {
                Some(mu_pa.iter().chain(alpha).copied().collect())
            }
            (Kind::Gent, Model::Gent { mu_pa, jm }) => Some(vec![*mu_pa, *jm]),
            _ => None,
        }
    }
}

/// `J = I1 - 3` in equibiaxial stretch `l`.
fn j_of(l: f64) -> f64 {
    2.0 * l * l + l.powi(-4) - 3.0
}

/// Equibiaxial nominal stress of `kind` with parameters `x` at stretch `l`,
/// and its gradient in `x` written into `grad`. NaN outside the bounds.
fn nominal_and_grad(kind: Kind, x: &[f64], l: f64, grad: &mut [f64]) -> f64 {
    let b = l - l.powi(-5);
    match kind {
        Kind::NeoHookean => {
            grad[0] = 2.0 * b;
            2.0 * b * x[0]
        }
        Kind::MooneyRivlin => {
            grad[0] = 2.0 * b;
            grad[1] = 2.0 * b * l * l;
            grad[0] * x[0] + grad[1] * x[1]
        }
        Kind::Yeoh => {
            let j = j_of(l);
            grad[0] = 2.0 * b;
            grad[1] = 4.0 * b * j;
            grad[2] = 6.0 * b * j * j;
            grad[0] * x[0] + grad[1] * x[1] + grad[2] * x[2]
        }
        Kind::Ogden(n) => {
            let ln = l.ln();
            let mut p = 0.0;
            for i in 0..n {
                let (mu, a) = (x[i], x[n + i]);
                if !(OGDEN_ALPHA_MIN..=OGDEN_ALPHA_MAX).contains(&a.abs()) {
                    return f64::NAN;
                }
                let t1 = l.powf(a - 1.0);
                let t2 = l.powf(-2.0 * a - 1.0);
                grad[i] = t1 - t2;
                grad[n + i] = mu * ln * (t1 + 2.0 * t2);
                p += mu * (t1 - t2);
            }
            p
        }
        Kind::Gent => {
            let (mu, jm) = (x[0], x[1]);
            let j = j_of(l);
            let inside = mu > 0.0 && jm > j; // false for NaN too
            if !inside {
                return f64::NAN;
            }
            let f = jm / (jm - j);
            grad[0] = b * f;
            grad[1] = -mu * b * j / ((jm - j) * (jm - j));
            mu * b * f
        }
    }
}

const OGDEN_ALPHA_MIN: f64 = 0.05;
const OGDEN_ALPHA_MAX: f64 = 30.0;

/// The least-squares problem handed to argmin: parameters scaled so that
/// stress parameters are in units of `scale` Pa.
struct Problem<'a> {
    kind: Kind,
    stretch: &'a [f64],
    target: Vec<f64>,
    /// Every residual's factor: 1, or the point's inverse standard
    /// deviation over their mean (a weighted fit).
    weight: Vec<f64>,
    measure: StressMeasure,
    scale: f64,
    jm_min: f64,
}

impl<'a> Problem<'a> {
    /// The least-squares problem of `kind` on `data`, stresses over `scale`,
    /// residuals times `weight` (all 1 when `None`).
    fn on(
        kind: Kind,
        data: &'a Equibiaxial,
        weight: Option<&[f64]>,
        scale: f64,
        jm_min: f64,
    ) -> Self {
        Problem {
            kind,
            stretch: &data.stretch,
            target: data.stress_pa.iter().map(|s| s / scale).collect(),
            weight: weight.map_or_else(|| vec![1.0; data.stretch.len()], <[f64]>::to_vec),
            measure: data.measure,
            scale,
            jm_min,
        }
    }

    fn unscale(&self, x: &DVector<f64>) -> Vec<f64> {
        (0..x.len())
            .map(|k| {
                if self.kind.is_stress(k) {
                    x[k] * self.scale
                } else {
                    x[k]
                }
            })
            .collect()
    }

    /// Residuals (scaled) and Jacobian (scaled) at `x`; the points in
    /// parallel (in chunks: a few points are one task).
    fn eval(&self, x: &DVector<f64>, want_jac: bool) -> (DVector<f64>, DMatrix<f64>) {
        let p = self.kind.n_params();
        let n = self.stretch.len();
        let xu = self.unscale(x);
        let gent_ok = !matches!(self.kind, Kind::Gent) || xu[1] > self.jm_min;
        // d(v/scale)/d(x_k) with x_k = xu_k / scale for stress parameters.
        let col_scale: Vec<f64> = (0..p)
            .map(|k| {
                if self.kind.is_stress(k) {
                    1.0
                } else {
                    1.0 / self.scale
                }
            })
            .collect();
        // Row i: the residual, then the Jacobian's row.
        let mut rows = vec![0.0; n * (p + 1)];
        rows.par_chunks_mut(p + 1)
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, row)| {
                let l = self.stretch[i];
                let (head, g) = row.split_at_mut(1);
                let factor = match self.measure {
                    StressMeasure::Nominal => 1.0,
                    StressMeasure::Cauchy => l,
                };
                let v = nominal_and_grad(self.kind, &xu, l, g) * factor;
                let w = self.weight[i];
                head[0] = if gent_ok {
                    (v / self.scale - self.target[i]) * w
                } else {
                    f64::NAN
                };
                for (gk, s) in g.iter_mut().zip(&col_scale) {
                    *gk *= factor * s * w;
                }
            });
        let r = DVector::from_iterator(n, rows.iter().step_by(p + 1).copied());
        let jac = if want_jac {
            DMatrix::from_fn(n, p, |i, k| rows[i * (p + 1) + 1 + k])
        } else {
            DMatrix::zeros(0, p)
        };
        (r, jac)
    }
}

impl Operator for Problem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, x: &DVector<f64>) -> Result<DVector<f64>, ArgminError> {
        Ok(self.eval(x, false).0)
    }
}

impl Jacobian for Problem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, x: &DVector<f64>) -> Result<DMatrix<f64>, ArgminError> {
        Ok(self.eval(x, true).1)
    }
}

/// `n` indices evenly spaced in `0..len`, the first and the last kept;
/// `None` when there are at most `n` (or `n < 2`).
fn thin(len: usize, n: usize) -> Option<Vec<usize>> {
    (len > n && n >= 2).then(|| (0..n).map(|k| k * (len - 1) / (n - 1)).collect())
}

/// Equibiaxial data: stretch and stress in a stated measure.
#[derive(Debug, Clone)]
pub struct Equibiaxial {
    /// Equibiaxial stretch, strictly increasing, > 0.
    pub stretch: Vec<f64>,
    /// Stress, Pa.
    pub stress_pa: Vec<f64>,
    /// Which stress `stress_pa` is.
    pub measure: StressMeasure,
}

impl Equibiaxial {
    /// At most `n` points, evenly spaced in index (so in stretch, the rows
    /// being sorted), the first and the last kept.
    pub fn thinned(&self, n: usize) -> Equibiaxial {
        let Some(idx) = thin(self.stretch.len(), n) else {
            return self.clone();
        };
        Equibiaxial {
            stretch: idx.iter().map(|&i| self.stretch[i]).collect(),
            stress_pa: idx.iter().map(|&i| self.stress_pa[i]).collect(),
            measure: self.measure,
        }
    }

    /// Model stress at stretch `l` in the measure of this data set, from the
    /// general energy of [`crate::material`].
    pub fn predict(&self, model: &Model, l: f64) -> f64 {
        let h = model.hyperelastic().expect("a hyperelastic model");
        match self.measure {
            StressMeasure::Nominal => h.equibiaxial_nominal(l),
            StressMeasure::Cauchy => h.equibiaxial_cauchy(l),
        }
    }

    /// Residuals `data - model` at the data points, Pa.
    pub fn residuals(&self, model: &Model) -> Vec<f64> {
        self.stretch
            .iter()
            .zip(&self.stress_pa)
            .map(|(&l, &s)| s - self.predict(model, l))
            .collect()
    }

    fn validate(&self, kind: Kind) -> Result<(), FitError> {
        if self.stretch.len() != self.stress_pa.len() {
            return Err(FitError::LengthMismatch {
                x: self.stretch.len(),
                y: self.stress_pa.len(),
            });
        }
        super::check_finite(&self.stretch)?;
        super::check_finite(&self.stress_pa)?;
        if let Some(i) = self.stretch.iter().position(|&l| l <= 0.0) {
            return Err(FitError::NonPositiveStretch {
                index: i,
                value: self.stretch[i],
            });
        }
        super::check_increasing(&self.stretch)?;
        if self.stretch.len() < kind.n_params() {
            return Err(FitError::TooFewPoints {
                model: kind.label(),
                points: self.stretch.len(),
                parameters: kind.n_params(),
            });
        }
        Ok(())
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, Serialize)]
pub struct Param {
    /// Name with unit suffix (`c1_pa`, `alpha2`).
    pub name: String,
    /// Value (Pa for stress parameters).
    pub value: f64,
    /// Standard error from the Jacobian at the minimum; `None` without
    /// residual degrees of freedom or with a singular Jacobian.
    pub std_error: Option<f64>,
}

/// A fitted hyperelastic model.
#[derive(Debug, Clone)]
pub struct HyperFit {
    /// Which model.
    pub kind: Kind,
    /// The material, parameters in Pa.
    pub model: Model,
    /// The parameters with standard errors.
    pub params: Vec<Param>,
    /// Goodness of fit in the stress measure of the data (RMSE in Pa).
    pub stats: Stats,
    /// `data - model` at each point, Pa.
    pub residuals_pa: Vec<f64>,
    /// Drucker stability over the fitted stretch range.
    pub drucker: drucker::Report,
    /// Starting points tried.
    pub starts: usize,
    /// Levenberg-Marquardt iterations of the kept run.
    pub iterations: u64,
    /// Levenberg-Marquardt iterations summed over every start.
    pub iterations_total: u64,
    /// For a weighted fit, the weighted residuals' sum of squares per
    /// degree of freedom (about 1 when the weights' standard deviations are
    /// right and the model fits).
    pub chi2_per_dof: Option<f64>,
}

/// Candidate Ogden exponents for the multi-start grid.
const OGDEN_ALPHAS: [f64; 10] = [-6.0, -4.0, -2.0, -1.0, 0.5, 1.0, 2.0, 3.0, 5.0, 8.0];
/// Candidate Gent `Jm / max J` ratios.
const GENT_RATIOS: [f64; 7] = [1.02, 1.1, 1.5, 3.0, 10.0, 30.0, 100.0];
/// LM iteration cap per start.
const MAX_ITERS: u64 = 200;
/// Above this many points the starts run on an evenly spaced subset of this
/// size (see [`fit`]).
const MAX_START_POINTS: usize = 1000;
/// LM iteration cap of the polish on every point: it starts at a minimum of
/// a dense subset, so it converges in a few iterations unless the data do
/// not determine every parameter, when more iterations only crawl.
const MAX_POLISH_ITERS: u64 = 20;

/// Fits `kind` to `data` (see the module docs for the method).
pub fn fit(kind: Kind, data: &Equibiaxial) -> Result<HyperFit, FitError> {
    fit_weighted(kind, data, None)
}

/// [`fit`] with every point's residual divided by its standard deviation
/// `std_pa` (positive, Pa) when given: weighted least squares, every start
/// and the polish alike. The standard errors are scaled by the weighted
/// residuals (`chi2_per_dof`), as for the unweighted fit.
pub fn fit_weighted(
    kind: Kind,
    data: &Equibiaxial,
    std_pa: Option<&[f64]>,
) -> Result<HyperFit, FitError> {
    if let Kind::Ogden(n) = kind
        && !(1..=3).contains(&n)
    {
        return Err(FitError::Unsupported(format!(
            "Ogden with {n} terms: use 1, 2 or 3 terms"
        )));
    }
    data.validate(kind)?;
    super::check_std(data.stretch.len(), std_pa)?;
    // Inverse standard deviations over their mean: the scaled problem keeps
    // residuals of order one.
    let weight: Option<Vec<f64>> = std_pa.map(|s| {
        let mean = s.iter().map(|v| 1.0 / v).sum::<f64>() / s.len() as f64;
        s.iter().map(|v| 1.0 / (v * mean)).collect()
    });
    let scale = data.stress_pa.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    if scale == 0.0 {
        return Err(FitError::ZeroStress);
    }
    let jm_min = data.stretch.iter().map(|&l| j_of(l)).fold(0.0f64, f64::max);
    // Many points: the starts run on an evenly spaced subset (the curve is
    // as well resolved, the cost of a start no longer grows with the data),
    // then the chosen end point is polished on every point.
    let idx = thin(data.stretch.len(), MAX_START_POINTS);
    let sub = idx.as_ref().map(|_| data.thinned(MAX_START_POINTS));
    let sub_weight: Option<Vec<f64>> = idx
        .as_ref()
        .zip(weight.as_ref())
        .map(|(idx, w)| idx.iter().map(|&i| w[i]).collect());
    let starts_data = sub.as_ref().unwrap_or(data);
    let starts_weight = if sub.is_some() {
        sub_weight.as_deref()
    } else {
        weight.as_deref()
    };
    let problem = || Problem::on(kind, starts_data, starts_weight, scale, jm_min);
    let starts = starting_points(kind, starts_data, starts_weight, scale, jm_min)?;
    let n_starts = starts.len();
    let mut ends: Vec<(f64, lm::LmResult)> = Vec::new();
    let mut total_iterations = 0;
    let mut last_err = None;
    // The starts are independent: run in parallel, kept in their order.
    let runs: Vec<_> = starts
        .into_par_iter()
        .map(|x0| lm::minimize(problem(), x0, MAX_ITERS))
        .collect();
    for run in runs {
        let run = match run {
            Ok(r) => r,
            Err(e) => {
                last_err = Some(e.to_string());
                continue;
            }
        };
        total_iterations += run.iterations;
        let c = run.residuals.norm_squared();
        if c.is_finite() {
            ends.push((c, run));
        }
    }
    if ends.is_empty() {
        return Err(FitError::Solver(format!(
            "{}: no start converged ({})",
            kind.label(),
            last_err.unwrap_or_else(|| "every end point was outside the bounds".into())
        )));
    }
    ends.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut run = select_end_point(kind, starts_data, &problem(), ends);
    if sub.is_some() {
        // The polish starts at the chosen end point: on a subset as dense
        // as this one it moves little, and LM never raises the RSS.
        match lm::minimize(
            Problem::on(kind, data, weight.as_deref(), scale, jm_min),
            run.x.clone(),
            MAX_POLISH_ITERS,
        ) {
            Ok(polished) => {
                total_iterations += polished.iterations;
                run = polished;
            }
            Err(e) => {
                return Err(FitError::Solver(format!(
                    "{}: the polish on all {} points failed ({e})",
                    kind.label(),
                    data.stretch.len()
                )));
            }
        }
    }
    let pb = Problem::on(kind, data, weight.as_deref(), scale, jm_min);
    let xu = pb.unscale(&run.x);
    let model = kind.model(&xu);
    let residuals_pa = data.residuals(&model);
    let stats = Stats::new(&data.stress_pa, &residuals_pa, kind.n_params());
    // The Jacobian is the weighted one: its residuals are too.
    let rss_scaled = match &weight {
        Some(w) => residuals_pa
            .iter()
            .zip(w)
            .map(|(r, w)| (r * w / scale).powi(2))
            .sum(),
        None => stats.rss / (scale * scale),
    };
    let std_errors = param_std_errors(&run.jacobian, rss_scaled, stats.n, &kind, scale);
    let dof = stats.n.saturating_sub(kind.n_params());
    let chi2_per_dof = std_pa.filter(|_| dof > 0).map(|s| {
        residuals_pa
            .iter()
            .zip(s)
            .map(|(r, s)| (r / s).powi(2))
            .sum::<f64>()
            / dof as f64
    });
    let params = kind
        .param_names()
        .into_iter()
        .enumerate()
        .map(|(k, name)| Param {
            name,
            value: xu[k],
            std_error: std_errors.as_ref().map(|s| s[k]),
        })
        .collect();
    let drucker = drucker::check(&model, &data.stretch);
    Ok(HyperFit {
        kind,
        model,
        params,
        stats,
        residuals_pa,
        drucker,
        starts: n_starts,
        iterations: run.iterations,
        iterations_total: total_iterations,
        chi2_per_dof,
    })
}

/// Relative RSS window within which end points count as equally good.
const TIE_RSS: f64 = 1e-3;

/// Picks the end point to keep from `ends` (sorted by RSS): the lowest RSS
/// among the Drucker-stable ones (the lowest overall if none is stable);
/// then, among the stable end points within [`TIE_RSS`] of it, the one with
/// the smallest sum of |stress parameters|. On data that do not determine
/// every parameter (three Ogden terms on one deformation mode) many end
/// points fit equally well, some with large terms that cancel; the smallest
/// one is the least extrapolation-prone. The stability check runs only on
/// the candidates that matter.
fn select_end_point(
    kind: Kind,
    data: &Equibiaxial,
    pb: &Problem,
    ends: Vec<(f64, lm::LmResult)>,
) -> lm::LmResult {
    let stable =
        |r: &lm::LmResult| drucker::check(&kind.model(&pb.unscale(&r.x)), &data.stretch).stable;
    let Some(first_stable) = ends.iter().position(|(_, r)| stable(r)) else {
        return ends.into_iter().next().expect("non-empty").1;
    };
    let c_best = ends[first_stable].0;
    let size = |r: &lm::LmResult| -> f64 {
        (0..r.x.len())
            .filter(|&k| kind.is_stress(k))
            .map(|k| r.x[k].abs())
            .sum()
    };
    let mut keep = first_stable;
    for (i, (c, r)) in ends.iter().enumerate().skip(first_stable + 1) {
        if *c > c_best * (1.0 + TIE_RSS) {
            break;
        }
        if size(r) < size(&ends[keep].1) && stable(r) {
            keep = i;
        }
    }
    ends.into_iter().nth(keep).expect("index in range").1
}

/// `s^2 (J^T J)^-1` on the diagonal, via the SVD of the (scaled) Jacobian,
/// unscaled to the units of the parameters.
fn param_std_errors(
    jac: &DMatrix<f64>,
    rss_scaled: f64,
    n: usize,
    kind: &Kind,
    scale: f64,
) -> Option<Vec<f64>> {
    let p = jac.ncols();
    if n <= p {
        return None;
    }
    let svd = jac.clone().svd(false, true);
    let sv = &svd.singular_values;
    let full_rank = sv.min() > 1e-13 * sv.max(); // false for NaN too
    if !full_rank {
        return None;
    }
    let vt = svd.v_t.as_ref()?;
    let s2 = rss_scaled / (n - p) as f64;
    Some(
        (0..p)
            .map(|j| {
                let var: f64 = (0..p).map(|k| (vt[(k, j)] / sv[k]).powi(2)).sum();
                let se = (s2 * var).sqrt();
                if kind.is_stress(j) { se * scale } else { se }
            })
            .collect(),
    )
}
