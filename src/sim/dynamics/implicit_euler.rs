//! Implicit (backward) Euler: `M (dx - h v) - h^2 f(x + dx) + h C dx = 0`,
//! solved by Newton-Raphson on the positions with a sparse LU (faer) of
//! `J = M + h^2 K + h C` (the dashpot directions frozen), and the sparse
//! workspace that keeps its pattern and factorisation across steps.
//!
//! Unconditionally stable: an undamped mode's energy falls by
//! `1 / (1 + (w h)^2)` per step. A step whose Newton iteration fails is taken
//! as two halves, at most [`IMPLICIT_HALVINGS`] times deep.

use faer::prelude::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use nalgebra::{Point3, Vector3};

use super::{DynError, DynOptions, Dynamics, Step, StepCost};
use crate::sim::SimError;
use crate::sim::solve::{Dofs, load_norm, pattern};

/// Halvings of an implicit Euler step whose Newton iteration failed.
pub const IMPLICIT_HALVINGS: usize = 8;

/// Implicit Euler: its sparse workspace and Newton settings.
pub(super) struct ImplicitEuler {
    ws: ImplicitWorkspace,
    /// Residual force relative to the load at which Newton stops.
    tolerance: f64,
    /// Newton iterations per step.
    iterations: usize,
}

impl ImplicitEuler {
    /// A stepper for the system `d` with the Newton settings of `opts`.
    pub(super) fn new(d: &Dynamics, opts: &DynOptions) -> ImplicitEuler {
        ImplicitEuler {
            ws: ImplicitWorkspace::new(d),
            tolerance: opts.newton_tolerance,
            iterations: opts.newton_iterations,
        }
    }

    /// An implicit Euler step of `h`; when Newton fails, the step is taken
    /// as two halves, at most [`IMPLICIT_HALVINGS`] times deep, before the
    /// failure is reported. Returns the Newton iterations and the force
    /// evaluations.
    fn step_halving(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        t: f64,
        depth: usize,
    ) -> Result<(usize, usize), DynError> {
        match self.newton_step(d, x, v, h, t) {
            Ok(r) => Ok(r),
            Err(DynError::NewtonFailed { .. }) if depth < IMPLICIT_HALVINGS => {
                let (a, b) = self.step_halving(d, x, v, 0.5 * h, t, depth + 1)?;
                let (c, e) = self.step_halving(d, x, v, 0.5 * h, t + 0.5 * h, depth + 1)?;
                Ok((a + c, b + e))
            }
            Err(e) => Err(e),
        }
    }

    /// One implicit Euler step: `M (dx - h v) - h^2 f(x + dx) + h C dx = 0`,
    /// Newton with `J = M + h^2 K + h C` (the dashpot directions frozen).
    /// The factorised `J` is kept across iterations and steps (modified
    /// Newton) while it contracts the residual at least fourfold per
    /// iteration; otherwise it is assembled and factorised afresh at the
    /// current iterate. The converged step is the same to the tolerance.
    fn newton_step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        t: f64,
    ) -> Result<(usize, usize), DynError> {
        let ws = &mut self.ws;
        let n = x.len();
        let m = &*d.membrane;
        let x_old = x.to_vec();
        let mut xn: Vec<Point3<f64>> = (0..n).map(|i| x[i] + v[i] * h).collect();
        let mut f = vec![Vector3::zeros(); n];
        let mut g = vec![Vector3::zeros(); n];
        let mut vn = vec![Vector3::zeros(); n];
        let mut evals = 0;
        let mut last_gn = f64::INFINITY;
        let fail = |reason: String| DynError::NewtonFailed {
            t_s: t,
            dt_s: h,
            reason,
        };
        for it in 0..self.iterations {
            // residual as a force: g/h^2 = M (dx - h v)/h^2 - f - C dx / h
            d.forces(&xn, &mut f)?;
            evals += 1;
            for i in 0..n {
                vn[i] = (xn[i] - x_old[i]) / h;
            }
            d.add_damping(&xn, &vn, &mut f);
            let mut scratch = std::mem::take(&mut g);
            let load = load_norm(m, &xn, &mut scratch).max(f64::MIN_POSITIVE);
            g = scratch;
            for i in 0..n {
                g[i] = m.masses[i] * ((xn[i] - x_old[i]) - v[i] * h) / (h * h) - f[i];
            }
            m.project(&mut g);
            let gn = g.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
            if !gn.is_finite() {
                return Err(fail("the residual is not finite".into()));
            }
            if gn <= self.tolerance * load {
                for i in 0..n {
                    v[i] = m.constraints[i].project((xn[i] - x_old[i]) / h);
                    x[i] = xn[i];
                }
                return Ok((it, evals));
            }
            let stale = ws.lu.as_ref().is_none_or(|(_, lu_h)| *lu_h != h);
            if stale || gn > 0.25 * last_gn {
                ws.assemble(d, &xn, h)?;
                ws.factor(h).map_err(|e| fail(e.to_string()))?;
            }
            last_gn = gn;
            let dx = ws.solve(&g).map_err(|e| fail(e.to_string()))?;
            for i in 0..n {
                xn[i] -= dx[i];
            }
        }
        Err(fail(format!("{} iterations reached", self.iterations)))
    }
}

impl Step for ImplicitEuler {
    fn step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        t: f64,
    ) -> Result<StepCost, DynError> {
        let (its, evals) = self.step_halving(d, x, v, h, t, 0)?;
        Ok(StepCost {
            force_evaluations: evals,
            newton_iterations: its,
        })
    }
}

/// Sparse matrix `M/h^2 + K + C/h` on the free degrees of freedom, its
/// pattern and symbolic LU kept across steps.
struct ImplicitWorkspace {
    dofs: Dofs,
    symbolic: SymbolicSparseColMat<usize>,
    symbolic_lu: Option<SymbolicLu<usize>>,
    values: Vec<f64>,
    /// The last factorisation and the step it was made for.
    lu: Option<(Lu<usize, f64>, f64)>,
}
impl ImplicitWorkspace {
    fn new(d: &Dynamics) -> ImplicitWorkspace {
        let m = &*d.membrane;
        let dofs = Dofs::new(m);
        let symbolic = pattern(m, &dofs);
        let nnz = symbolic.row_idx().len();
        ImplicitWorkspace {
            dofs,
            symbolic,
            symbolic_lu: None,
            values: vec![0.0; nnz],
            lu: None,
        }
    }

    /// Adds the 3x3 block `k` (node a rows, node b columns).
    fn add_block(&mut self, a: usize, b: usize, k: &[[f64; 3]; 3]) {
        if self.dofs.basis[a].is_empty() {
            return;
        }
        let col_ptr = self.symbolic.col_ptr();
        let row_idx = self.symbolic.row_idx();
        for (beta, ub) in self.dofs.basis[b].iter().enumerate() {
            let col = self.dofs.start[b] + beta;
            let rows = &row_idx[col_ptr[col]..col_ptr[col + 1]];
            let pos = col_ptr[col]
                + rows
                    .binary_search(&self.dofs.start[a])
                    .expect("pattern holds every triangle's node pairs");
            let kv = Vector3::from_fn(|r, _| (0..3).map(|c| k[r][c] * ub[c]).sum());
            for (alpha, ua) in self.dofs.basis[a].iter().enumerate() {
                self.values[pos + alpha] += ua.dot(&kv);
            }
        }
    }

    fn assemble(&mut self, d: &Dynamics, x: &[Point3<f64>], h: f64) -> Result<(), SimError> {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let m = &*d.membrane;
        for t in 0..m.triangles() {
            let k = m.triangle_stiffness(t, x)?;
            let v = m.triangle_nodes(t).map(|i| i as usize);
            for (ai, &a) in v.iter().enumerate() {
                for (bi, &b) in v.iter().enumerate() {
                    let blk: [[f64; 3]; 3] =
                        std::array::from_fn(|r| std::array::from_fn(|c| k[3 * ai + r][3 * bi + c]));
                    self.add_block(a, b, &blk);
                }
            }
        }
        for (i, j, c, u) in d.dashpots(x) {
            let cb: [[f64; 3]; 3] =
                std::array::from_fn(|r| std::array::from_fn(|s| c / h * u[r] * u[s]));
            let neg: [[f64; 3]; 3] = cb.map(|row| row.map(|x| -x));
            self.add_block(i, i, &cb);
            self.add_block(j, j, &cb);
            self.add_block(i, j, &neg);
            self.add_block(j, i, &neg);
        }
        for i in 0..m.nodes() {
            let mm = m.masses[i] / (h * h);
            let blk = [[mm, 0.0, 0.0], [0.0, mm, 0.0], [0.0, 0.0, mm]];
            self.add_block(i, i, &blk);
        }
        Ok(())
    }

    /// Factorises the assembled `J` (for step `h`).
    fn factor(&mut self, h: f64) -> Result<(), LinearError> {
        let mat = SparseColMat::new(self.symbolic.clone(), self.values.clone());
        if self.symbolic_lu.is_none() {
            self.symbolic_lu = Some(
                SymbolicLu::try_new(mat.symbolic())
                    .map_err(|e| LinearError::Symbolic(format!("{e:?}")))?,
            );
        }
        let sym = self.symbolic_lu.clone().expect("set above");
        let lu = Lu::try_new_with_symbolic(sym, mat.as_ref())
            .map_err(|e| LinearError::Singular(format!("{e:?}")))?;
        self.lu = Some((lu, h));
        Ok(())
    }

    /// Solves `J d = g` (g a nodal force residual) with the last
    /// factorisation; returns nodal corrections.
    fn solve(&mut self, g: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>, LinearError> {
        let (lu, _) = self.lu.as_ref().ok_or(LinearError::NotFactorised)?;
        let mut rhs = faer::Mat::<f64>::zeros(self.dofs.len, 1);
        for (i, b) in self.dofs.basis.iter().enumerate() {
            for (a, u) in b.iter().enumerate() {
                rhs[(self.dofs.start[i] + a, 0)] = u.dot(&g[i]);
            }
        }
        lu.solve_in_place(rhs.as_mut());
        let mut out = vec![Vector3::zeros(); g.len()];
        for (i, b) in self.dofs.basis.iter().enumerate() {
            for (a, u) in b.iter().enumerate() {
                out[i] += u * rhs[(self.dofs.start[i] + a, 0)];
            }
        }
        if out.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(LinearError::Singular("non-finite Newton step".into()));
        }
        Ok(out)
    }
}

/// Why the linear system of a Newton step could not be solved.
#[derive(Debug, Clone, thiserror::Error)]
enum LinearError {
    /// The symbolic analysis of the sparsity pattern failed.
    #[error("symbolic factorisation failed ({0})")]
    Symbolic(String),
    /// The numeric factorisation met a singular matrix.
    #[error("singular system ({0})")]
    Singular(String),
    /// A solve before any factorisation.
    #[error("no factorisation")]
    NotFactorised,
}
