//! The joint correction: several specimens' heights fitted with one law,
//! their problems stacked, and the parameters' cluster-robust deviations.

use super::*;

/// Several specimens' problems at the same unknowns: their residuals one
/// after another, their Jacobians stacked.
#[derive(Clone)]
pub(super) struct Joint<'a> {
    pub(super) parts: Vec<Problem<'a>>,
}

impl Joint<'_> {
    pub(super) fn residuals(&self, x: &[f64]) -> DVector<f64> {
        let r: Vec<f64> = self
            .parts
            .iter()
            .flat_map(|p| p.residuals(x).iter().copied().collect::<Vec<_>>())
            .collect();
        DVector::from_vec(r)
    }

    /// The relative height errors of every specimen's points.
    pub(super) fn errors(&self, x: &[f64]) -> Vec<Option<f64>> {
        self.parts.iter().flat_map(|p| p.errors(x)).collect()
    }
}

impl Operator for Joint<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, x: &DVector<f64>) -> Result<DVector<f64>, ArgminError> {
        Ok(self.residuals(x.as_slice()))
    }
}

impl Jacobian for Joint<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, x: &DVector<f64>) -> Result<DMatrix<f64>, ArgminError> {
        let blocks = self
            .parts
            .iter()
            .map(|p| p.jacobian(x))
            .collect::<Result<Vec<_>, _>>()?;
        let rows = blocks.iter().map(DMatrix::nrows).sum();
        let mut j = DMatrix::zeros(rows, x.len());
        let mut at = 0;
        for b in blocks {
            j.rows_mut(at, b.nrows()).copy_from(&b);
            at += b.nrows();
        }
        Ok(j)
    }
}

/// One law fitted to several specimens' heights together ([`refine_joint`]).
#[derive(Debug, Clone, PartialEq)]
pub struct JointRefined {
    /// The law.
    pub material: Material,
    /// RMS of the relative height errors over every point, before and
    /// after.
    pub rms_before: Option<f64>,
    /// See `rms_before`.
    pub rms_after: Option<f64>,
    /// Levenberg-Marquardt iterations (both stages).
    pub iterations: u64,
    /// Standard errors of the law's parameters ([`law_parameters`]' order),
    /// cluster-robust by specimen (see [`refine_joint`]); `None` when the
    /// fit did not improve on the start or the covariance is singular.
    pub std_errors: Option<Vec<f64>>,
}

/// Corrects `material`'s parameters so that the axisymmetric inflation of
/// every specimen (each with its own dimensions) reproduces its own
/// measured heights, all at once: one law, least squares of every point's
/// relative error `h_sim / h - 1` (every photo of every specimen weighs
/// alike), first one factor on the stress parameters, then every
/// parameter, as [`refine`] does for one specimen. A quartic's softening
/// penalty is counted once.
///
/// The standard errors are cluster-robust by specimen (K.-Y. Liang and S. L.
/// Zeger, "Longitudinal data analysis using generalized linear models",
/// Biometrika 73, 1986, doi:10.1093/biomet/73.1.13): the points of one
/// specimen share its thickness's and calibration's errors, which make its
/// residuals move together, so the covariance is the sandwich `B M B` with
/// `B = (J^T J)^-1` and `M = sum_k (J_k^T r_k)(J_k^T r_k)^T` over the
/// specimens `k` (their Jacobian rows `J_k` and residuals `r_k`), times the
/// small-sample factor `G/(G-1) (N-1)/(N-P)` (`G` specimens, `N` points,
/// `P` parameters). With few specimens it is itself uncertain (it rests on
/// `G` terms): beside it, the study's interval of the mean.
pub fn refine_joint(
    material: &Material,
    specimens: &[(Specimen, Vec<Measured>)],
    opts: &Options,
) -> Result<JointRefined, FitError> {
    if specimens.is_empty() {
        return Err(FitError::Unsupported("a joint fit needs specimens".into()));
    }
    let mut x0 = Vec::new();
    let mut params = None;
    for (_, m) in specimens {
        let (p, x) = parameters_for(material, m)?;
        params = Some(p);
        x0 = x;
    }
    let params = params.expect("at least one specimen");
    let solves = AtomicUsize::new(0);
    // per specimen, per point: Newton's start (see `Problem::warm`)
    type Warm = Vec<Mutex<Option<(f64, f64)>>>;
    let warm: Vec<Warm> = specimens
        .iter()
        .map(|(_, m)| m.iter().map(|_| Mutex::new(None)).collect())
        .collect();
    let parts: Vec<Problem> = specimens
        .iter()
        .zip(&warm)
        .enumerate()
        .map(|(k, ((specimen, points), warm))| Problem {
            derivatives: opts.derivatives,
            warm,
            params: params.clone(),
            base: material,
            specimen,
            points,
            opts: &opts.axisym,
            solves: &solves,
            scale_of: None,
            weights: None,
            monotone: match &material.model {
                Model::Quartic { strain_range, .. }
                    if k == 0 && strain_range[1] > strain_range[0] =>
                {
                    Some(*strain_range)
                }
                _ => None,
            },
        })
        .collect();
    let joint = Joint { parts };
    let before = joint.errors(&x0);
    if let Some(i) = before.iter().position(Option::is_none) {
        return Err(FitError::Solver(format!(
            "the starting {} law has no axisymmetric equilibrium at measured point {i} of the specimens taken together: the measured pressures pass its limit point",
            material.model.name()
        )));
    }
    let scaled = Joint {
        parts: joint
            .parts
            .iter()
            .map(|p| Problem {
                scale_of: Some(x0.clone()),
                ..p.clone()
            })
            .collect(),
    };
    let scale = lm::minimize(scaled, DVector::from_vec(vec![1.0]), opts.max_iterations)
        .map_err(|e| FitError::Solver(e.to_string()))?;
    let x1 = params.scaled(&x0, scale.x[0]);
    let r = lm::minimize(joint.clone(), DVector::from_vec(x1), opts.max_iterations)
        .map_err(|e| FitError::Solver(e.to_string()))?;
    let after = joint.errors(r.x.as_slice());
    let (rms_before, rms_after) = (Refined::rms(&before), Refined::rms(&after));
    let better = matches!((rms_after, rms_before), (Some(a), Some(b)) if a < b);
    let std_errors = better.then(|| joint_std(&joint, r.x.as_slice())).flatten();
    let x = if better { r.x.as_slice().to_vec() } else { x0 };
    Ok(JointRefined {
        std_errors,
        material: Material {
            model: params.model(&x),
            poisson: material.poisson,
            fit: material.fit.clone(),
        },
        rms_before,
        rms_after: if better { rms_after } else { rms_before },
        iterations: scale.iterations + r.iterations,
    })
}

/// The joint law's cluster-robust standard errors at `x`, in the law's own
/// parameters ([`law_parameters`]): every point's relative error and its
/// gradient from the axisymmetric sensitivities, one cluster a specimen.
pub(super) fn joint_std(joint: &Joint, x: &[f64]) -> Option<Vec<f64>> {
    let mut rows: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut sizes = Vec::new();
    for part in &joint.parts {
        let m = part.material(x);
        let p = law_parameters(&m.model)?.1.len();
        let grads = part.gradients(&m, p)?;
        sizes.push(grads.len());
        rows.extend(grads.iter().zip(part.points).map(|(g, q)| {
            let h = q.height_m;
            (
                (g.height_m - h) / h,
                g.gradient.iter().map(|d| d / h).collect(),
            )
        }));
    }
    let p = rows.first()?.1.len();
    let jac = DMatrix::from_fn(rows.len(), p, |i, k| rows[i].1[k]);
    let res = DVector::from_iterator(rows.len(), rows.iter().map(|r| r.0));
    cluster_robust_std(&jac, &res, &sizes)
}

/// The cluster-robust standard errors of a least-squares fit ([`refine_joint`]):
/// `jac` and `res` at the solution, their rows in consecutive clusters of
/// `sizes` rows. `None` when `J^T J` is singular or fewer than two clusters.
pub(super) fn cluster_robust_std(
    jac: &DMatrix<f64>,
    res: &DVector<f64>,
    sizes: &[usize],
) -> Option<Vec<f64>> {
    let (n, p) = jac.shape();
    let g = sizes.len();
    if g < 2 || n <= p || sizes.iter().sum::<usize>() != n {
        return None;
    }
    let bread = (jac.transpose() * jac).try_inverse()?;
    let mut meat = DMatrix::zeros(p, p);
    let mut at = 0;
    for &m in sizes {
        let score = jac.rows(at, m).transpose() * res.rows(at, m);
        meat += &score * score.transpose();
        at += m;
    }
    let factor = (g as f64 / (g as f64 - 1.0)) * ((n as f64 - 1.0) / (n as f64 - p as f64));
    let cov = &bread * meat * &bread * factor;
    (0..p)
        .map(|k| cov[(k, k)].is_finite().then(|| cov[(k, k)].max(0.0).sqrt()))
        .collect()
}
