//! The window correction: the law corrected against the membrane model on
//! a non-circular window (no exact axisymmetric solution there), one sweep
//! of the membrane per trial law.

use super::*;

/// The least-squares problem of [`refine_in_scene`]: the heights of the
/// membrane model on a window, one sweep over the pressures per law.
#[derive(Clone)]
pub(super) struct SceneProblem<'a> {
    pub(super) params: Params,
    pub(super) base: &'a Material,
    pub(super) scene: &'a crate::sim::scene::Scene,
    pub(super) mesh: &'a crate::sim::Mesh,
    /// The distinct pressures, increasing, and each point's index in them.
    pub(super) pressures: Vec<f64>,
    pub(super) at: Vec<usize>,
    pub(super) points: &'a [Measured],
    pub(super) sweeps: &'a AtomicUsize,
    pub(super) scale_of: Option<Vec<f64>>,
}

impl SceneProblem<'_> {
    pub(super) fn material(&self, x: &[f64]) -> Material {
        material_at(&self.params, self.base, self.scale_of.as_deref(), x)
    }

    /// `h(p_i) / h_i - 1` per point, `None` where the sweep found no
    /// equilibrium (or the law cannot be built).
    pub(super) fn errors(&self, x: &[f64]) -> Vec<Option<f64>> {
        use crate::sim::{SceneSolver, SpringModel};
        self.sweeps.fetch_add(1, Ordering::Relaxed);
        let mut scene = self.scene.clone();
        scene.material = self.material(x);
        scene.pressures_pa = self.pressures.clone();
        let heights: Vec<f64> =
            match SceneSolver::on_mesh(&scene, self.mesh.clone(), SpringModel::Membrane) {
                Ok(mut s) => match s.sweep(&self.pressures, |_, _| {}) {
                    Ok(done) | Err((done, _)) => done.iter().map(|q| q.height_m).collect(),
                },
                Err(_) => Vec::new(),
            };
        self.points
            .iter()
            .zip(&self.at)
            .map(|(q, &k)| {
                heights
                    .get(k)
                    .map(|h| h / q.height_m - 1.0)
                    .filter(|e| e.is_finite())
            })
            .collect()
    }

    pub(super) fn residuals(&self, x: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            self.points.len(),
            self.errors(x).into_iter().map(|e| e.unwrap_or(f64::NAN)),
        )
    }
}

impl Operator for SceneProblem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, x: &DVector<f64>) -> Result<DVector<f64>, ArgminError> {
        Ok(self.residuals(x.as_slice()))
    }
}

impl Jacobian for SceneProblem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    /// Central differences, the `2 p` sweeps in parallel; one-sided where
    /// one side has no equilibrium.
    fn jacobian(&self, x: &DVector<f64>) -> Result<DMatrix<f64>, ArgminError> {
        let (n, p) = (self.points.len(), x.len());
        let steps: Vec<f64> = (0..p).map(|k| 1e-4 * x[k].abs().max(1e-2)).collect();
        let sides: Vec<DVector<f64>> = (0..2 * p)
            .into_par_iter()
            .map(|j| {
                let mut y = x.clone();
                y[j / 2] += if j % 2 == 0 {
                    steps[j / 2]
                } else {
                    -steps[j / 2]
                };
                self.residuals(y.as_slice())
            })
            .collect();
        let r0 = std::cell::OnceCell::new();
        let mut jac = DMatrix::zeros(n, p);
        for k in 0..p {
            let (rp, rm, h) = (&sides[2 * k], &sides[2 * k + 1], steps[k]);
            for i in 0..n {
                let r0 = || r0.get_or_init(|| self.residuals(x.as_slice()))[i];
                jac[(i, k)] = match (rp[i].is_finite(), rm[i].is_finite()) {
                    (true, true) => (rp[i] - rm[i]) / (2.0 * h),
                    (true, false) => (rp[i] - r0()) / h,
                    (false, true) => (r0() - rm[i]) / h,
                    (false, false) => 0.0,
                };
            }
        }
        Ok(jac)
    }
}

/// Corrects `material`'s parameters so that the membrane model
/// (constant-strain triangles with the whole law, `crate::sim::cst`) on the
/// window of `scene` (its geometry, thickness and density; meshed at
/// `mesh`, default the scene's own size) reproduces `measured`: the
/// non-circular counterpart of [`refine`], for windows where no exact
/// axisymmetric solution exists. The same two Levenberg-Marquardt stages
/// (one factor on the stress parameters, then every parameter); each
/// residual is one sweep of the membrane over the measured pressures, the
/// Jacobian central differences (`2 p` sweeps, in parallel). A quartic law
/// is corrected without the monotone-stress penalty of [`refine`] (a
/// softening result is warned about by the caller).
pub fn refine_in_scene(
    material: &Material,
    scene: &crate::sim::scene::Scene,
    mesh: Option<crate::sim::scene::MeshSize>,
    measured: &[Measured],
    opts: &Options,
) -> Result<Refined, FitError> {
    let (params, x0) = parameters_for(material, measured)?;
    let mut sc = scene.clone();
    if mesh.is_some() {
        sc.mesh.size = mesh;
    }
    let built = sc
        .build_mesh()
        .map_err(|e| FitError::Unsupported(format!("the window's mesh: {e}")))?;
    let mut pressures: Vec<f64> = measured.iter().map(|q| q.pressure_pa).collect();
    pressures.sort_by(f64::total_cmp);
    pressures.dedup();
    let at = measured
        .iter()
        .map(|q| {
            pressures
                .iter()
                .position(|p| *p == q.pressure_pa)
                .expect("every measured pressure is in the list")
        })
        .collect();
    let sweeps = AtomicUsize::new(0);
    let problem = SceneProblem {
        params,
        base: material,
        scene: &sc,
        mesh: &built,
        pressures,
        at,
        points: measured,
        sweeps: &sweeps,
        scale_of: None,
    };
    let before = problem.errors(&x0);
    // The cap formulas, made for a circle, can give a law so soft that the
    // membrane on the window has no equilibrium at the highest pressures:
    // then the start is stiffened by factors of 2 on the stress parameters
    // until every pressure has one (at most 2^6).
    let mut start = 1.0;
    let mut at_start = before.clone();
    while let Some(i) = at_start.iter().position(Option::is_none) {
        if start >= 64.0 {
            return Err(FitError::Solver(format!(
                "the starting {} law, even 64 times stiffer, has no equilibrium of the membrane on the {} window at {} Pa (measured point {i})",
                material.model.name(),
                sc.kind.name(),
                measured[i].pressure_pa
            )));
        }
        start *= 2.0;
        at_start = problem.errors(&problem.params.scaled(&x0, start));
    }
    let Corrected {
        x,
        after,
        iterations,
    } = scale_then_all(&problem, x0, start, &before, opts.max_iterations)?;
    Ok(Refined {
        material: Material {
            model: problem.params.model(&x),
            poisson: material.poisson,
            fit: material.fit.clone(),
        },
        before,
        after,
        iterations,
        solves: sweeps.load(Ordering::Relaxed),
        prebulge_height_m: None,
        prebulge_std_m: None,
        // the membrane path fits the relative errors and carries no
        // covariance yet (the exact Jacobian belongs to the axisymmetric
        // path)
        uncertainty: None,
        weighted: false,
        monte_carlo: None,
        window: Some(format!(
            "{} window ({} nodes)",
            sc.kind.name(),
            built.nodes.len()
        )),
        constraint: None,
    })
}
