//! A Levenberg-Marquardt solver for small nonlinear least-squares problems,
//! written as an [`argmin`] [`Solver`] so that argmin's [`Executor`] runs the
//! loop (problem and solver kept apart, as in argmin's own Gauss-Newton).
//!
//! Minimises `F(x) = 1/2 |r(x)|^2`. Each iteration solves the damped
//! Gauss-Newton step
//!
//! $$\begin{bmatrix} J \\ \sqrt{\mu} D \end{bmatrix} h \approx \begin{bmatrix} -r \\ 0 \end{bmatrix}$$
//!
//! by Householder QR of the stacked matrix (the normal equations
//! `(J^T J + mu D^2) h = -J^T r` are never formed, so the conditioning of `J`
//! is not squared). `D` is Marquardt's scaling, the running maximum of the
//! column norms of `J`, which makes the step invariant to the units of the
//! parameters. The damping `mu` follows Nielsen (1999): after an accepted step
//! `mu *= max(1/3, 1 - (2 rho - 1)^3)`, after a rejected one `mu *= nu, nu *= 2`,
//! with `rho` the ratio of the actual to the predicted decrease.
//!
//! Bounds: a trial point whose residuals are not all finite is rejected like
//! a step that increases the cost, so a problem enforces its parameter bounds
//! by returning non-finite residuals outside them (the iterates stay feasible).

use argmin::core::{
    Error, Executor, IterState, Jacobian, KV, Operator, Problem, Solver, State, TerminationReason,
    TerminationStatus,
};
use nalgebra::{DMatrix, DVector};

/// The state argmin keeps for this solver: parameters, Jacobian, residuals.
pub type LmState = IterState<DVector<f64>, (), DMatrix<f64>, (), DVector<f64>, f64>;

/// Levenberg-Marquardt with Nielsen's damping update and Marquardt scaling.
#[derive(Debug, Clone)]
pub struct LevenbergMarquardt {
    /// Stop when the largest gradient component `|J^T r|_inf` is below this.
    pub grad_tol: f64,
    /// Stop when the step is below `step_tol * (|x| + step_tol)`.
    pub step_tol: f64,
    /// Stop when an accepted step lowers the cost by less than this
    /// fraction of it (progress along a flat valley that no longer matters).
    pub cost_tol: f64,
    /// Stop after this many rejected trial steps in a row.
    pub max_rejections: usize,
    mu: f64,
    nu: f64,
    scale: DVector<f64>,
    done: Option<TerminationReason>,
}

impl Default for LevenbergMarquardt {
    fn default() -> Self {
        Self {
            grad_tol: 1e-12,
            step_tol: 1e-12,
            cost_tol: 1e-10,
            max_rejections: 40,
            mu: 1e-3,
            nu: 2.0,
            scale: DVector::zeros(0),
            done: None,
        }
    }
}

fn cost(r: &DVector<f64>) -> f64 {
    let c = 0.5 * r.norm_squared();
    if c.is_finite() { c } else { f64::INFINITY }
}

/// Solves `min |A h - b|` by Householder QR; `None` if `A` is rank deficient.
fn qr_solve(a: DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let p = a.ncols();
    let qr = a.qr();
    let qtb = qr.q().transpose() * b;
    let r = qr.r();
    let rmax = (0..p).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if (0..p).any(|i| r[(i, i)].abs() <= 1e-14 * rmax) || rmax == 0.0 {
        return None;
    }
    r.solve_upper_triangular(&qtb.rows(0, p).into_owned())
}

impl<O> Solver<O, LmState> for LevenbergMarquardt
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn name(&self) -> &str {
        "Levenberg-Marquardt"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let x = state
            .take_param()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt needs an initial parameter vector"))?;
        let r = problem.apply(&x)?;
        let c = cost(&r);
        if !c.is_finite() {
            return Err(Error::msg(
                "Levenberg-Marquardt: the starting point is outside the bounds",
            ));
        }
        let j = problem.jacobian(&x)?;
        self.scale = DVector::from_iterator(j.ncols(), j.column_iter().map(|c| c.norm()));
        self.done = None;
        Ok((state.param(x).residuals(r).jacobian(j).cost(c), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let (x, r, j) = take_all(&mut state)?;
        let (n, p) = j.shape();
        let c0 = cost(&r);
        for (k, col) in j.column_iter().enumerate() {
            self.scale[k] = self.scale[k].max(col.norm()).max(1e-300);
        }
        let g = j.transpose() * &r;
        if g.amax() <= self.grad_tol * (1.0 + c0) {
            self.done = Some(TerminationReason::SolverConverged);
            return Ok((state.param(x).residuals(r).jacobian(j).cost(c0), None));
        }
        let mut rejections = 0;
        loop {
            let mut a = DMatrix::zeros(n + p, p);
            a.view_mut((0, 0), (n, p)).copy_from(&j);
            let sq = self.mu.sqrt();
            for k in 0..p {
                a[(n + k, k)] = sq * self.scale[k];
            }
            let mut b = DVector::zeros(n + p);
            b.rows_mut(0, n).copy_from(&(-&r));
            let step = qr_solve(a, &b);
            if let Some(h) = step {
                if h.norm() <= self.step_tol * (x.norm() + self.step_tol) {
                    self.done = Some(TerminationReason::SolverConverged);
                    return Ok((state.param(x).residuals(r).jacobian(j).cost(c0), None));
                }
                let xn = &x + &h;
                let rn = problem.apply(&xn)?;
                let c1 = cost(&rn);
                // Predicted decrease of the linear model: -g.h - 1/2 |J h|^2.
                let jh = &j * &h;
                let pred = -g.dot(&h) - 0.5 * jh.norm_squared();
                let rho = if pred > 0.0 { (c0 - c1) / pred } else { -1.0 };
                if c1.is_finite() && rho > 0.0 {
                    self.mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
                    self.nu = 2.0;
                    let jn = problem.jacobian(&xn)?;
                    if (c0 - c1) <= self.cost_tol * c0 {
                        self.done = Some(TerminationReason::SolverConverged);
                    }
                    return Ok((state.param(xn).residuals(rn).jacobian(jn).cost(c1), None));
                }
            }
            self.mu *= self.nu;
            self.nu *= 2.0;
            rejections += 1;
            if rejections >= self.max_rejections || !self.mu.is_finite() {
                self.done = Some(TerminationReason::SolverConverged);
                return Ok((state.param(x).residuals(r).jacobian(j).cost(c0), None));
            }
        }
    }

    fn terminate(&mut self, _state: &LmState) -> TerminationStatus {
        match &self.done {
            Some(reason) => TerminationStatus::Terminated(reason.clone()),
            None => TerminationStatus::NotTerminated,
        }
    }
}

/// Parameters, residuals and Jacobian.
type Taken = (DVector<f64>, DVector<f64>, DMatrix<f64>);

/// Takes the parameters, residuals and Jacobian out of argmin's state.
fn take_all(state: &mut LmState) -> Result<Taken, Error> {
    let x = state
        .take_param()
        .ok_or_else(|| Error::msg("LM: no parameters"))?;
    let r = state
        .take_residuals()
        .ok_or_else(|| Error::msg("LM: no residuals"))?;
    let j = state
        .take_jacobian()
        .ok_or_else(|| Error::msg("LM: no Jacobian"))?;
    Ok((x, r, j))
}

/// The outcome of one local minimisation.
#[derive(Debug, Clone)]
pub struct LmResult {
    /// The parameters at the minimum.
    pub x: DVector<f64>,
    /// The residuals there.
    pub residuals: DVector<f64>,
    /// The Jacobian there.
    pub jacobian: DMatrix<f64>,
    /// Iterations taken.
    pub iterations: u64,
}

/// Runs Levenberg-Marquardt on `problem` from `x0` through argmin's executor.
pub fn minimize<O>(problem: O, x0: DVector<f64>, max_iters: u64) -> Result<LmResult, Error>
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    let res = Executor::new(problem, LevenbergMarquardt::default())
        .configure(|s| s.param(x0).max_iters(max_iters))
        .timer(false)
        .run()?;
    let mut state = res.state().clone();
    let iterations = state.get_iter();
    let (x, residuals, jacobian) = take_all(&mut state)?;
    Ok(LmResult {
        x,
        residuals,
        jacobian,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as a least-squares problem: r = (10 (y - x^2), 1 - x).
    struct Rosen;
    impl Operator for Rosen {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_vec(vec![
                10.0 * (p[1] - p[0] * p[0]),
                1.0 - p[0],
            ]))
        }
    }
    impl Jacobian for Rosen {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_row_slice(
                2,
                2,
                &[-20.0 * p[0], 10.0, -1.0, 0.0],
            ))
        }
    }

    #[test]
    fn rosenbrock_minimum_found_from_classic_start() {
        let r = minimize(Rosen, DVector::from_vec(vec![-1.2, 1.0]), 200).unwrap();
        assert!((r.x[0] - 1.0).abs() < 1e-10, "{}", r.x);
        assert!((r.x[1] - 1.0).abs() < 1e-10, "{}", r.x);
    }

    /// A bound enforced by non-finite residuals: minimise (x - 2)^2 with x < 1.
    struct Bounded;
    impl Operator for Bounded {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            let v = if p[0] < 1.0 { p[0] - 2.0 } else { f64::NAN };
            Ok(DVector::from_vec(vec![v]))
        }
    }
    impl Jacobian for Bounded {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, _p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_element(1, 1, 1.0))
        }
    }

    #[test]
    fn iterates_stay_inside_the_bound() {
        let r = minimize(Bounded, DVector::from_vec(vec![0.0]), 500).unwrap();
        assert!(r.x[0] < 1.0 && r.x[0] > 0.99, "{}", r.x);
    }
}
