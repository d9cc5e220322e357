//! The least-squares problem of one specimen's heights: the apex height of
//! the exact axisymmetric inflation at each measured pressure against the
//! measured one, its exact Jacobian from the sensitivity equations, and the
//! monotone-stress penalty of a quartic law.

use super::*;

/// The least-squares problem handed to [`lm::minimize`].
#[derive(Clone)]
pub(super) struct Problem<'a> {
    pub(super) params: Params,
    pub(super) base: &'a Material,
    pub(super) specimen: &'a Specimen,
    pub(super) points: &'a [Measured],
    pub(super) opts: &'a axisym::Options,
    pub(super) solves: &'a AtomicUsize,
    /// `Some(x0)`: the unknown is one factor on `x0`'s stress-like
    /// parameters (the first stage, robust from a start far off).
    pub(super) scale_of: Option<Vec<f64>>,
    /// A quartic's strain range, over which its implied stress must rise.
    pub(super) monotone: Option<[f64; 2]>,
    /// How the Jacobian is found.
    pub(super) derivatives: Derivatives,
    /// Per point, the last solution's pole stretch and the sign of its clamp
    /// residual's slope (which tells the stable branch): Newton's start.
    pub(super) warm: &'a [Mutex<Option<(f64, f64)>>],
    /// Per point, the factor on its relative error: `h_i / sigma_i` over
    /// their mean (a weighted fit), or 1.
    pub(super) weights: Option<&'a [f64]>,
}

/// Strains of the range at which a quartic's implied-stress slope is held
/// non-negative.
pub(super) const MONOTONE_SAMPLES: usize = 24;
/// Weight of a negative slope (in units of the law's `c_0`) against the
/// relative height errors.
pub(super) const MONOTONE_WEIGHT: f64 = 10.0;
/// The slope asked for, in units of `c_0`: a small cushion, so that what the
/// penalty leaves of a violation stays on the rising side.
pub(super) const MONOTONE_MARGIN: f64 = 0.02;

/// The law at the fit's unknowns `x`: the parameters themselves, or (in the
/// scale stage) one factor on the start `x0`, with `base`'s Poisson ratio and
/// provenance.
pub(super) fn material_at(
    params: &Params,
    base: &Material,
    scale_of: Option<&[f64]>,
    x: &[f64],
) -> Material {
    let x = match scale_of {
        Some(x0) => params.scaled(x0, x[0]),
        None => x.to_vec(),
    };
    Material {
        model: params.model(&x),
        poisson: base.poisson,
        fit: base.fit.clone(),
    }
}

impl Problem<'_> {
    pub(super) fn material(&self, x: &[f64]) -> Material {
        material_at(&self.params, self.base, self.scale_of.as_deref(), x)
    }

    /// `h(p_i) / h_i - 1` per point, `None` where there is no equilibrium.
    pub(super) fn errors(&self, x: &[f64]) -> Vec<Option<f64>> {
        let m = self.material(x);
        self.solves.fetch_add(self.points.len(), Ordering::Relaxed);
        (0..self.points.len())
            .into_par_iter()
            .map(|i| {
                let q = &self.points[i];
                self.solve(&m, i, false)
                    .map(|s| s.height_m / q.height_m - 1.0)
                    .filter(|e| e.is_finite())
            })
            .collect()
    }

    /// Every point's height and its gradient in the law's `p` parameters,
    /// in parallel; `None` when a point has no solution.
    pub(super) fn gradients(&self, m: &Material, p: usize) -> Option<Vec<axisym::HeightGradient>> {
        (0..self.points.len())
            .into_par_iter()
            .map(|i| self.solve(m, i, true).filter(|g| g.gradient.len() == p))
            .collect()
    }

    /// The height at point `i` (with its gradient in the law's parameters
    /// when asked), by Newton from the point's last solution when there is
    /// one on the same branch, else from scratch.
    pub(super) fn solve(
        &self,
        m: &Material,
        i: usize,
        gradient: bool,
    ) -> Option<axisym::HeightGradient> {
        let q = &self.points[i];
        let exact = self.derivatives == Derivatives::Exact;
        if !exact {
            return axisym::solve_pressure(m, self.specimen, q.pressure_pa, self.opts)
                .ok()
                .map(|s| axisym::HeightGradient {
                    height_m: s.height_m,
                    pole_stretch: s.pole_stretch,
                    gradient: Vec::new(),
                    slope: f64::NAN,
                    shots: s.iterations,
                });
        }
        let newton = |l0: f64| {
            axisym::height_gradient(m, self.specimen, q.pressure_pa, l0, gradient, self.opts).ok()
        };
        let last = *self.warm[i].lock().unwrap_or_else(|e| e.into_inner());
        let warm = last.and_then(|(l0, sign)| newton(l0).filter(|s| s.slope.signum() == sign));
        let found = warm.or_else(|| {
            let cold = axisym::solve_pressure(m, self.specimen, q.pressure_pa, self.opts).ok()?;
            newton(cold.pole_stretch)
        })?;
        *self.warm[i].lock().unwrap_or_else(|e| e.into_inner()) =
            Some((found.pole_stretch, found.slope.signum()));
        Some(found)
    }

    /// `d theta / d x`: the law's parameters (in the order of
    /// [`axisym::height_gradient`]) per unknown, a column per unknown.
    pub(super) fn dtheta_dx(&self) -> DMatrix<f64> {
        let scale: &[f64] = match &self.params {
            Params::Quartic { scale, .. } | Params::Hyper { scale, .. } => scale,
            Params::Linear { scale } => std::slice::from_ref(scale),
        };
        let diag = DMatrix::from_diagonal(&DVector::from_column_slice(scale));
        match &self.scale_of {
            // theta = scale * scaled(x0, s): d/ds is scale * (x0 on the
            // stress-like parameters).
            Some(x0) => {
                let (one, zero) = (self.params.scaled(x0, 1.0), self.params.scaled(x0, 0.0));
                let d: Vec<f64> = one.iter().zip(&zero).map(|(a, b)| a - b).collect();
                diag * DMatrix::from_column_slice(d.len(), 1, &d)
            }
            None => diag,
        }
    }

    /// Per sampled strain, `min(0, dS/deps / c_0 - margin)` with `S = E(eps)
    /// eps` the quartic's implied stress: zero wherever the stress rises.
    pub(super) fn softening(&self, x: &[f64]) -> Vec<f64> {
        let Some([lo, hi]) = self.monotone else {
            return Vec::new();
        };
        let Model::Quartic {
            coefficients_pa, ..
        } = self.material(x).model
        else {
            return Vec::new();
        };
        let unit = coefficients_pa.first().map_or(1.0, |c| c.abs().max(1.0));
        (0..MONOTONE_SAMPLES)
            .map(|k| {
                let eps = lo + (hi - lo) * k as f64 / (MONOTONE_SAMPLES - 1) as f64;
                let slope = quartic::implied_stress_slope(&coefficients_pa, eps);
                MONOTONE_WEIGHT * (slope / unit - MONOTONE_MARGIN).min(0.0)
            })
            .collect()
    }

    /// The heights' relative errors, then the softening penalties.
    pub(super) fn n_residuals(&self) -> usize {
        self.points.len() + self.monotone.map_or(0, |_| MONOTONE_SAMPLES)
    }

    pub(super) fn residuals(&self, x: &[f64]) -> DVector<f64> {
        let w = |i: usize| self.weights.map_or(1.0, |w| w[i]);
        let heights = self
            .errors(x)
            .into_iter()
            .enumerate()
            .map(|(i, e)| e.map_or(f64::NAN, |e| e * w(i)));
        DVector::from_iterator(self.n_residuals(), heights.chain(self.softening(x)))
    }
}

impl Operator for Problem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, x: &DVector<f64>) -> Result<DVector<f64>, ArgminError> {
        Ok(self.residuals(x.as_slice()))
    }
}

impl Jacobian for Problem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, x: &DVector<f64>) -> Result<DMatrix<f64>, ArgminError> {
        match self.derivatives {
            Derivatives::Exact => Ok(self.exact_jacobian(x.as_slice())),
            Derivatives::CentralDifferences => Ok(self.differences(x, true)),
        }
    }
}

impl Problem<'_> {
    /// The heights' rows from the exact gradients, the penalty's rows (no
    /// solves: a polynomial in the coefficients) by central differences.
    pub(super) fn exact_jacobian(&self, x: &[f64]) -> DMatrix<f64> {
        let m = self.material(x);
        let n = self.points.len();
        self.solves.fetch_add(n, Ordering::Relaxed);
        let rows: Vec<Option<Vec<f64>>> = (0..n)
            .into_par_iter()
            .map(|i| self.solve(&m, i, true).map(|s| s.gradient))
            .collect();
        let dth = self.dtheta_dx();
        let mut jac = self.differences(&DVector::from_column_slice(x), false);
        for (i, row) in rows.iter().enumerate() {
            if let Some(g) = row {
                let g = DMatrix::from_row_slice(1, g.len(), g) * &dth;
                let w = self.weights.map_or(1.0, |w| w[i]);
                for k in 0..jac.ncols() {
                    jac[(i, k)] = w * g[(0, k)] / self.points[i].height_m;
                }
            }
        }
        jac
    }

    /// Central differences of the residuals: all rows (`heights`), or the
    /// penalty's rows only (the heights' rows left zero).
    pub(super) fn differences(&self, x: &DVector<f64>, heights: bool) -> DMatrix<f64> {
        let (n, p) = (self.n_residuals(), x.len());
        let np = self.points.len();
        let mut jac = DMatrix::zeros(n, p);
        if !heights && n == np {
            return jac;
        }
        let res = |x: &DVector<f64>| {
            if heights {
                self.residuals(x.as_slice())
            } else {
                let pen = self.softening(x.as_slice());
                DVector::from_iterator(n, std::iter::repeat_n(0.0, np).chain(pen))
            }
        };
        let r0 = std::cell::OnceCell::new();
        for k in 0..p {
            let h = 1e-5 * x[k].abs().max(1e-2);
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[k] += h;
            xm[k] -= h;
            let (rp, rm) = (res(&xp), res(&xm));
            for i in 0..n {
                // A one-sided difference where one side has no equilibrium.
                let r0 = || r0.get_or_init(|| res(x))[i];
                jac[(i, k)] = match (rp[i].is_finite(), rm[i].is_finite()) {
                    (true, true) => (rp[i] - rm[i]) / (2.0 * h),
                    (true, false) => (rp[i] - r0()) / h,
                    (false, true) => (r0() - rm[i]) / h,
                    (false, false) => 0.0,
                };
            }
        }
        jac
    }
}
