//! Brent's bracketing root finder and minimiser (Brent 1973, *Algorithms for
//! minimization without derivatives*, chapters 4 and 5), argmin's
//! `BrentRoot` and `BrentOpt`, with a fallible function so that an
//! evaluation error ends the search and comes back as it was.

use std::cell::{Cell, RefCell};

use argmin::core::{CostFunction, Executor, State, TerminationReason};
use argmin::solver::brent::{BrentOpt, BrentRoot};

/// A converged root: where, the function there, and evaluations spent.
#[derive(Debug, Clone, Copy)]
pub struct Root {
    /// The abscissa.
    pub x: f64,
    /// The function value at `x`.
    pub fx: f64,
    /// Function evaluations.
    pub evals: usize,
    /// Whether the stopping test was met (else the budget ran out).
    pub converged: bool,
}

/// `f` as an argmin cost function: every value is kept (those the caller
/// passes in are not recomputed), evaluations past the budget are refused,
/// and the first error of `f` is kept to be returned as is (argmin's own
/// error type is `anyhow::Error`).
struct Fallible<F, E> {
    f: RefCell<F>,
    seen: RefCell<Vec<(f64, f64)>>,
    budget: usize,
    evals: Cell<usize>,
    error: RefCell<Option<E>>,
}

impl<F: FnMut(f64) -> Result<f64, E>, E> Fallible<F, E> {
    fn new(f: F, known: &[(f64, f64)], budget: usize) -> Self {
        Self {
            f: RefCell::new(f),
            seen: RefCell::new(known.to_vec()),
            budget,
            evals: Cell::new(0),
            error: RefCell::new(None),
        }
    }

    /// The value at an abscissa already evaluated.
    fn at(&self, x: f64) -> Option<f64> {
        self.seen.borrow().iter().find(|p| p.0 == x).map(|p| p.1)
    }
}

impl<F: FnMut(f64) -> Result<f64, E>, E> CostFunction for &Fallible<F, E> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, x: &f64) -> Result<f64, argmin::core::Error> {
        if let Some(fx) = self.at(*x) {
            return Ok(fx);
        }
        if self.evals.get() >= self.budget {
            return Err(argmin::core::Error::msg("evaluation budget spent"));
        }
        self.evals.set(self.evals.get() + 1);
        match (self.f.borrow_mut())(*x) {
            Ok(fx) => {
                self.seen.borrow_mut().push((*x, fx));
                Ok(fx)
            }
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                Err(argmin::core::Error::msg("evaluation failed"))
            }
        }
    }
}

/// Finds a root of `f` in `[a, b]` with `f(a)`, `f(b)` of opposite signs
/// (values passed in). Stops when `|f| <= ftol` or the bracket is narrower
/// than `2 xtol`.
#[allow(clippy::too_many_arguments)]
pub fn brent_zero<E>(
    f: impl FnMut(f64) -> Result<f64, E>,
    a: f64,
    fa: f64,
    b: f64,
    fb: f64,
    xtol: f64,
    ftol: f64,
    max_evals: usize,
) -> Result<Root, E> {
    debug_assert!(fa * fb <= 0.0);
    // An end that already meets the value test is the root (argmin's
    // target-cost test sees only `f(b)` before its first step).
    let (x, fx) = if fb.abs() <= fa.abs() {
        (b, fb)
    } else {
        (a, fa)
    };
    if fx == 0.0 || fx.abs() <= ftol {
        return Ok(Root {
            x,
            fx,
            evals: 0,
            converged: true,
        });
    }
    let problem = Fallible::new(f, &[(a, fa), (b, fb)], max_evals);
    let run = Executor::new(&problem, BrentRoot::new(a, b, xtol.max(0.0)))
        .configure(|s| s.target_cost(ftol))
        .run();
    if let Some(e) = problem.error.take() {
        return Err(e);
    }
    let evals = problem.evals.get();
    let (x, converged) = match run {
        Ok(res) => (
            *res.state.get_param().expect("Brent has an iterate"),
            matches!(
                res.state.get_termination_reason(),
                Some(TerminationReason::SolverConverged | TerminationReason::TargetCostReached)
            ),
        ),
        // The budget ran out (or the ends did not bracket a root): the
        // smallest value seen.
        Err(_) => {
            let seen = problem.seen.borrow();
            let best = seen.iter().min_by(|p, q| p.1.abs().total_cmp(&q.1.abs()));
            (best.expect("the ends are seen").0, false)
        }
    };
    Ok(Root {
        x,
        fx: problem.at(x).expect("Brent returns an evaluated point"),
        evals,
        converged,
    })
}

/// A converged minimum.
#[derive(Debug, Clone, Copy)]
pub struct Min {
    /// The abscissa.
    pub x: f64,
}

/// Minimises `f` on `[a, b]` (golden section with parabolic steps), to an
/// abscissa tolerance `rel * |x| + abs`.
pub fn brent_min<E>(
    f: impl FnMut(f64) -> Result<f64, E>,
    a: f64,
    b: f64,
    rel: f64,
    abs: f64,
    max_evals: usize,
) -> Result<Min, E> {
    let problem = Fallible::new(f, &[], usize::MAX);
    // One evaluation to start, then one per iteration.
    let run = Executor::new(
        &problem,
        BrentOpt::new(a.min(b), a.max(b)).set_tolerance(rel, abs),
    )
    .configure(|s| s.max_iters(max_evals.saturating_sub(1) as u64))
    .run();
    if let Some(e) = problem.error.take() {
        return Err(e);
    }
    let res = run.expect("BrentOpt raises no error of its own");
    Ok(Min {
        x: *res.state.get_param().expect("Brent has an iterate"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_of_cubic() {
        let f = |x: f64| Ok::<_, ()>(x * x * x - 2.0 * x - 5.0);
        let r = brent_zero(
            f,
            2.0,
            f(2.0).unwrap(),
            3.0,
            f(3.0).unwrap(),
            1e-14,
            0.0,
            100,
        )
        .unwrap();
        assert!(r.converged);
        assert!((r.x - 2.094_551_481_542_326_5).abs() < 1e-13, "{}", r.x);
        assert!(r.evals < 15);
    }

    #[test]
    fn minimum_of_smooth_function() {
        // -x e^-x has its minimum at x = 1.
        let mut evals = 0;
        let f = |x: f64| {
            evals += 1;
            Ok::<_, ()>(-x * (-x).exp())
        };
        let m = brent_min(f, 0.0, 4.0, 1e-9, 1e-12, 200).unwrap();
        assert!((m.x - 1.0).abs() < 1e-7, "{}", m.x);
        assert!(evals < 40, "{evals}");
    }
}
