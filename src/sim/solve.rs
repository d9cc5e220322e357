//! Quasi-static equilibrium of a [`Membrane`] at one pressure, and the
//! continuation over a list of pressures.
//!
//! Convergence is measured by the residual force relative to the load:
//! `|P r| / |P f_load| <= tolerance`, with `r` the net nodal forces, `f_load`
//! the pressure (and nodal-load) forces alone and `P` the projection on the
//! directions the nodes may move in.
//!
//! * [`newton`]: Newton-Raphson on the reduced degrees of freedom (mirror
//!   planes and clamps eliminated). The tangent is assembled per triangle from
//!   central differences of its local forces ([`Membrane::triangle_stiffness`]:
//!   spring stiffness, the E(eps) dependence and the follower-pressure
//!   stiffness, which is not symmetric), in parallel; the step is solved by
//!   [`super::linear::SparseSolver`]: BiCGSTAB on the tangent, preconditioned
//!   by an AMD-ordered `LDL^T` of its symmetric part in single precision,
//!   with a sparse LU of the whole tangent as the fallback (symbolic analyses
//!   reused). Forces in parallel on meshes of 1e4 nodes and more.
//!   Backtracking line search on the residual norm. A step below 1e-8 of the shortest rest edge that no
//!   longer lowers the residual ends the solve as converged: the residual
//!   has reached its round-off floor (small loads against stiff springs),
//!   and the row reports the residual actually reached.
//! * [`dynamic_relaxation`]: pseudo-dynamics with unit step and fictitious
//!   masses `m_i = 0.6 S_i` from a Gershgorin bound `S_i` of the stiffness row
//!   (Barnes' `dt^2 S / 2` with a 20 % margin), kinetic damping (velocities
//!   zeroed at every kinetic-energy peak). Masses are refreshed every 500
//!   steps. No matrix: memory and cost per step are those of one force
//!   evaluation.
//! * [`continuation`]: from the last equilibrium to the next pressure, with a
//!   predictor; a failed solve is retried by halving the pressure increment
//!   (at most [`Options::max_halvings`] times), then reported as
//!   [`SimError::NoEquilibrium`] with the last pressure solved. Nothing loops
//!   without a cap.

use faer::sparse::SymbolicSparseColMat;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::SimError;
use super::dynamics::PAR_MIN_NODES;
use super::linear::{LinearStats, SparseSolver};
use super::par::ParForces;
use super::springs::Membrane;

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Residual force relative to the load at which a solve stops (default 1e-8).
    pub tolerance: f64,
    /// Newton iterations per pressure step (default 40).
    pub newton_iterations: usize,
    /// Dynamic-relaxation steps per pressure step (default 200 000).
    pub dr_steps: usize,
    /// Halvings of a failed pressure increment before giving up (default 6).
    pub max_halvings: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tolerance: 1e-8,
            newton_iterations: 40,
            dr_steps: 200_000,
            max_halvings: 6,
        }
    }
}

impl Options {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SimError> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(SimError::BadParameter(format!(
                "tolerance = {} must be in (0, 1): the residual force relative to the load (e.g. 1e-8)",
                self.tolerance
            )));
        }
        if self.newton_iterations == 0 || self.dr_steps == 0 {
            return Err(SimError::BadParameter(
                "the iteration caps must be at least 1".into(),
            ));
        }
        Ok(())
    }
}

/// The quasi-static solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// Newton-Raphson with a sparse LU.
    Newton,
    /// Dynamic relaxation with kinetic damping.
    Dr,
}

impl Solver {
    /// Name on the command line and in output files.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Newton => "newton",
            Solver::Dr => "dr",
        }
    }

    /// Parses a name.
    pub fn parse(s: &str) -> Option<Solver> {
        match s.trim() {
            "newton" => Some(Solver::Newton),
            "dr" => Some(Solver::Dr),
            _ => None,
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Newton iterations or relaxation steps, summed over sub-steps.
    pub iterations: usize,
    /// Final residual relative to the load.
    pub residual: f64,
    /// Pressure sub-steps taken (1 when the step went through at once).
    pub substeps: usize,
    /// Newton found no equilibrium or the wrong one (the dome turned
    /// inside out), and this one is dynamic relaxation's.
    pub relaxed: bool,
}

/// Degrees of freedom after the constraints: per node a start index and an
/// orthonormal basis of its free directions.
#[derive(Debug, Clone)]
pub struct Dofs {
    /// First degree of freedom of each node.
    pub(crate) start: Vec<usize>,
    /// Free directions of each node (empty when fixed).
    pub(crate) basis: Vec<Vec<Vector3<f64>>>,
    /// Total number of free degrees of freedom.
    pub len: usize,
}

impl Dofs {
    /// The free directions of a membrane's nodes.
    pub fn new(m: &Membrane) -> Dofs {
        let mut start = Vec::with_capacity(m.nodes());
        let mut basis = Vec::with_capacity(m.nodes());
        let mut n = 0;
        for c in &m.constraints {
            start.push(n);
            let b = c.free_basis();
            n += b.len();
            basis.push(b);
        }
        Dofs {
            start,
            basis,
            len: n,
        }
    }

    fn reduce(&self, f: &[Vector3<f64>], r: &mut [f64]) {
        for (i, b) in self.basis.iter().enumerate() {
            for (a, u) in b.iter().enumerate() {
                r[self.start[i] + a] = u.dot(&f[i]);
            }
        }
    }

    fn expand_add(&self, d: &[f64], alpha: f64, x: &mut [Point3<f64>]) {
        for (i, b) in self.basis.iter().enumerate() {
            for (a, u) in b.iter().enumerate() {
                x[i] += u * (alpha * d[self.start[i] + a]);
            }
        }
    }
}

/// Norm of the projected load (pressure on the current triangles and nodal
/// loads), N.
pub fn load_norm(m: &Membrane, x: &[Point3<f64>], scratch: &mut [Vector3<f64>]) -> f64 {
    for v in scratch.iter_mut() {
        *v = Vector3::zeros();
    }
    let p6 = m.pressure_pa / 6.0;
    for t in 0..m.triangles() {
        let [a, b, c] = m.triangle_nodes(t).map(|i| i as usize);
        let n2 = (x[b] - x[a]).cross(&(x[c] - x[a])) * p6;
        scratch[a] += n2;
        scratch[b] += n2;
        scratch[c] += n2;
    }
    for (i, l) in &m.node_loads {
        scratch[*i] += l;
    }
    m.project(scratch);
    scratch.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt()
}

/// Sparse tangent with a fixed pattern (node pairs joined by an edge) and its
/// solver ([`SparseSolver`]: the symbolic analyses are kept), reused over
/// iterations and pressures.
pub struct NewtonWorkspace {
    dofs: Dofs,
    solver: SparseSolver,
    values: Vec<f64>,
    /// Parallel forces for meshes of [`PAR_MIN_NODES`] nodes and more.
    par: Option<ParForces>,
}

/// Triangles whose stiffness is computed together, in parallel, before it is
/// added into the tangent (bounds the scratch memory: 648 bytes a triangle).
const ASSEMBLY_CHUNK: usize = 4096;

/// The sparsity pattern of a membrane's stiffness over its free degrees of
/// freedom: every pair of nodes sharing a triangle (shared by the static
/// Newton solver and the implicit integrator).
pub(crate) fn pattern(m: &Membrane, dofs: &Dofs) -> SymbolicSparseColMat<usize> {
    let n = m.nodes();
    let mut adj: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
    for t in 0..m.triangles() {
        let v = m.triangle_nodes(t);
        for &a in &v {
            for &b in &v {
                adj[a as usize].push(b as usize);
            }
        }
    }
    let mut col_ptr = vec![0usize];
    let mut row_idx = Vec::new();
    for (j, b) in dofs.basis.iter().enumerate() {
        let nb = &mut adj[j];
        nb.sort_unstable();
        nb.dedup();
        for _ in 0..b.len() {
            for &i in nb.iter() {
                for a in 0..dofs.basis[i].len() {
                    row_idx.push(dofs.start[i] + a);
                }
            }
            col_ptr.push(row_idx.len());
        }
    }
    SymbolicSparseColMat::new_checked(dofs.len, dofs.len, col_ptr, None, row_idx)
}

impl NewtonWorkspace {
    /// Builds the pattern for a membrane.
    pub fn new(m: &Membrane) -> NewtonWorkspace {
        let dofs = Dofs::new(m);
        let solver = SparseSolver::new(&pattern(m, &dofs))
            .expect("a membrane's tangent has fewer than 2^32 entries");
        let nnz = solver.pattern().row_idx().len();
        let par = (m.nodes() >= PAR_MIN_NODES && rayon::current_num_threads() > 1)
            .then(|| ParForces::for_membrane(m));
        NewtonWorkspace {
            dofs,
            solver,
            values: vec![0.0; nnz],
            par,
        }
    }

    /// Net nodal forces as [`Membrane::forces`], in parallel on large meshes.
    fn forces(
        &mut self,
        m: &Membrane,
        x: &[Point3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), SimError> {
        match &mut self.par {
            Some(p) => p.forces(m, x, f),
            None => m.forces(x, f),
        }
    }

    /// What the linear solves did so far.
    pub fn linear_stats(&self) -> LinearStats {
        self.solver.stats
    }

    /// Memory held for the Newton step, bytes: the tangent's values and the
    /// solver's patterns and factor ([`SparseSolver::bytes`]).
    pub fn bytes(&self) -> usize {
        8 * self.values.len() + self.solver.bytes()
    }

    fn assemble(&mut self, m: &Membrane, x: &[Point3<f64>]) -> Result<(), SimError> {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let col_ptr = self.solver.pattern().col_ptr();
        let row_idx = self.solver.pattern().row_idx();
        let mut chunk = Vec::with_capacity(ASSEMBLY_CHUNK.min(m.triangles()));
        for first in (0..m.triangles()).step_by(ASSEMBLY_CHUNK) {
            let last = (first + ASSEMBLY_CHUNK).min(m.triangles());
            (first..last)
                .into_par_iter()
                .map(|t| m.triangle_stiffness(t, x))
                .collect_into_vec(&mut chunk);
            for (t, k) in (first..last).zip(chunk.drain(..)) {
                let k = k?;
                let v = m.triangle_nodes(t).map(|i| i as usize);
                for (bi, &b) in v.iter().enumerate() {
                    for (beta, ub) in self.dofs.basis[b].iter().enumerate() {
                        let col = self.dofs.start[b] + beta;
                        let (c0, c1) = (col_ptr[col] as usize, col_ptr[col + 1] as usize);
                        let rows = &row_idx[c0..c1];
                        // K_ab * ub, 3-vectors for each a
                        for (ai, &a) in v.iter().enumerate() {
                            if self.dofs.basis[a].is_empty() {
                                continue;
                            }
                            let mut kv = Vector3::zeros();
                            for r in 0..3 {
                                kv[r] = (0..3).map(|c| k[3 * ai + r][3 * bi + c] * ub[c]).sum();
                            }
                            let start = self.dofs.start[a] as u32;
                            let pos = c0
                                + rows
                                    .binary_search(&start)
                                    .expect("pattern holds every triangle's node pairs");
                            for (alpha, ua) in self.dofs.basis[a].iter().enumerate() {
                                self.values[pos + alpha] += ua.dot(&kv);
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Newton step `K d = r`, with the diagonal shifted by `shift` times its
    /// largest entry (in place: the next assembly starts afresh); `None`
    /// when every solve fails or the step is not finite.
    fn step(&mut self, r: &[f64], shift: f64) -> Option<Vec<f64>> {
        if shift > 0.0 {
            let col_ptr = self.solver.pattern().col_ptr();
            let row_idx = self.solver.pattern().row_idx();
            let diag: Vec<usize> = (0..r.len())
                .map(|c| {
                    let (c0, c1) = (col_ptr[c] as usize, col_ptr[c + 1] as usize);
                    c0 + row_idx[c0..c1]
                        .binary_search(&(c as u32))
                        .expect("diagonal in pattern")
                })
                .collect();
            let dmax = diag
                .iter()
                .fold(0.0_f64, |a, &k| a.max(self.values[k].abs()));
            for &k in &diag {
                self.values[k] += shift * dmax;
            }
        }
        self.solver.solve(&self.values, r)
    }
}

/// The residual's round-off floor at `x`: how far the reduced residual `r`
/// moves when every coordinate is changed by its last bit (each by
/// `eps |x_i|`, with signs that do not cancel). A residual within a few
/// times this is as small as double precision can make it there.
fn roundoff_floor(
    m: &Membrane,
    x: &[Point3<f64>],
    r: &[f64],
    ws: &mut NewtonWorkspace,
) -> Result<f64, SimError> {
    let mut xp = x.to_vec();
    for (i, p) in xp.iter_mut().enumerate() {
        for k in 0..3 {
            // a fixed pattern of signs (a cheap hash of the index)
            let sign = if (i * 3 + k).wrapping_mul(0x9E37_79B9) & 0x100 == 0 {
                1.0
            } else {
                -1.0
            };
            p[k] += sign * f64::EPSILON * p[k].abs();
        }
    }
    let mut f = vec![Vector3::zeros(); x.len()];
    ws.forces(m, &xp, &mut f)?;
    let mut rp = vec![0.0; r.len()];
    ws.dofs.reduce(&f, &mut rp);
    Ok(rp
        .iter()
        .zip(r)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt())
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newton-Raphson at the membrane's current pressure from positions `x`.
/// On failure `x` is left where the iteration stopped (the caller restores).
pub fn newton(
    m: &mut Membrane,
    x: &mut [Point3<f64>],
    pressure_pa: f64,
    opts: &Options,
) -> Result<Stats, SimError> {
    let mut ws = NewtonWorkspace::new(m);
    newton_with(m, x, pressure_pa, opts, &mut ws)
}

/// [`newton`] with a workspace reused across pressures.
pub fn newton_with(
    m: &mut Membrane,
    x: &mut [Point3<f64>],
    pressure_pa: f64,
    opts: &Options,
    ws: &mut NewtonWorkspace,
) -> Result<Stats, SimError> {
    m.pressure_pa = pressure_pa;
    let n = ws.dofs.len;
    let mut f = vec![Vector3::zeros(); x.len()];
    let mut scratch = vec![Vector3::zeros(); x.len()];
    let mut r = vec![0.0; n];
    let mut trial = x.to_vec();
    let fail = |reason: String| SimError::NoEquilibrium {
        pressure_pa,
        last_pressure_pa: f64::NAN,
        reason,
    };
    ws.forces(m, x, &mut f)?;
    ws.dofs.reduce(&f, &mut r);
    let mut rn = norm(&r);
    for it in 0..opts.newton_iterations {
        let load = load_norm(m, x, &mut scratch).max(f64::MIN_POSITIVE);
        if !rn.is_finite() {
            return Err(fail("the residual is not finite".into()));
        }
        if rn <= opts.tolerance * load {
            return Ok(Stats {
                iterations: it,
                residual: rn / load,
                substeps: 1,
                relaxed: false,
            });
        }
        ws.assemble(m, x)?;
        // inexact Newton: the step is solved only as far as the residual it
        // removes needs (Eisenstat & Walker's forcing term, "Choosing the
        // forcing terms in an inexact Newton method", SIAM J. Sci. Comput.
        // 17(1), 1996, doi:10.1137/0917003): a tenth of the relative
        // residual, between 1e-12 and 1e-3, which keeps the convergence
        // superlinear and spares the iterations of the first steps
        ws.solver.tolerance = (0.1 * rn / load).clamp(1e-12, 1e-3);
        let d = match ws.step(&r, 0.0) {
            Some(d) => d,
            // singular tangent (a flat membrane has no stiffness out of its
            // plane): shift the diagonal by 1e-6 of its largest entry and let
            // the line search judge the step
            None => ws
                .step(&r, 1e-6)
                .ok_or_else(|| fail("singular tangent, even with a diagonal shift".into()))?,
        };
        // backtracking line search on |r|
        let mut alpha = 1.0;
        let mut accepted = false;
        let mut last_err = None;
        for _ in 0..12 {
            trial.copy_from_slice(x);
            ws.dofs.expand_add(&d, alpha, &mut trial);
            match ws.forces(m, &trial, &mut f) {
                Ok(()) => {
                    let mut rt = vec![0.0; n];
                    ws.dofs.reduce(&f, &mut rt);
                    let rtn = norm(&rt);
                    if rtn.is_finite() && rtn < rn * (1.0 - 1e-4 * alpha) {
                        x.copy_from_slice(&trial);
                        r = rt;
                        rn = rtn;
                        accepted = true;
                        break;
                    }
                }
                Err(e) => last_err = Some(e),
            }
            alpha *= 0.5;
        }
        if !accepted {
            // A step far below the mesh size that no longer lowers the residual:
            // the residual is at its round-off floor (spring forces are
            // differences of nearly equal lengths); the state is converged.
            let dmax = d.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            if last_err.is_none() && dmax <= 1e-8 * m.min_rest_edge() {
                // ... when the residual is there: within ten times what
                // a change of the coordinates' last bits moves it by
                let floor = roundoff_floor(m, x, &r, ws)?;
                if rn > 10.0 * floor {
                    return Err(fail(format!(
                        "the line search stalled at relative residual {:.3e}, above the tolerance and above the round-off floor here ({:.3e}): the tangent does not lead down; try {} dr",
                        rn / load,
                        floor / load,
                        crate::setting::Setting::Solver
                    )));
                }
                // ... unless the load itself is below that floor: then
                // nothing was solved (a pressure too small to resolve)
                if rn > 1e-3 * load {
                    return Err(fail(format!(
                        "the load is below the round-off of the spring forces (relative residual {:.3e} at the smallest step): the pressure is too small for this membrane to resolve in double precision; give a larger one",
                        rn / load
                    )));
                }
                return Ok(Stats {
                    iterations: it + 1,
                    residual: rn / load,
                    substeps: 1,
                    relaxed: false,
                });
            }
            if let Some(e @ SimError::NonPositiveModulus { .. }) = last_err {
                return Err(e);
            }
            return Err(fail(format!(
                "the line search found no decrease of the residual after {it} iterations (relative residual {:.3e})",
                rn / load
            )));
        }
    }
    let load = load_norm(m, x, &mut scratch).max(f64::MIN_POSITIVE);
    if rn <= opts.tolerance * load {
        return Ok(Stats {
            iterations: opts.newton_iterations,
            residual: rn / load,
            substeps: 1,
            relaxed: false,
        });
    }
    Err(fail(format!(
        "{} Newton iterations reached, relative residual {:.3e}",
        opts.newton_iterations,
        rn / load
    )))
}

/// Dynamic relaxation with kinetic damping at the given pressure from `x`.
pub fn dynamic_relaxation(
    m: &mut Membrane,
    x: &mut [Point3<f64>],
    pressure_pa: f64,
    opts: &Options,
) -> Result<Stats, SimError> {
    m.pressure_pa = pressure_pa;
    let nn = x.len();
    let mut f = vec![Vector3::zeros(); nn];
    let mut scratch = vec![Vector3::zeros(); nn];
    let mut v = vec![Vector3::zeros(); nn];
    let mut mass = vec![0.0; nn];
    // forces in parallel on large meshes, as Newton's
    let mut par = (nn >= PAR_MIN_NODES && rayon::current_num_threads() > 1)
        .then(|| ParForces::for_membrane(m));
    let fail = |reason: String| SimError::NoEquilibrium {
        pressure_pa,
        last_pressure_pa: f64::NAN,
        reason,
    };
    let refresh = |m: &Membrane, x: &[Point3<f64>], mass: &mut [f64]| -> Result<(), SimError> {
        m.stiffness_bounds(x, mass)?;
        let floor = mass.iter().cloned().fold(0.0, f64::max) * 1e-9;
        for s in mass.iter_mut() {
            *s = 0.6 * s.max(floor).max(f64::MIN_POSITIVE);
        }
        Ok(())
    };
    refresh(m, x, &mut mass)?;
    let mut ke_prev = 0.0;
    let mut rel = f64::INFINITY;
    for step in 0..opts.dr_steps {
        if step > 0 && step % 500 == 0 {
            refresh(m, x, &mut mass)?;
        }
        match &mut par {
            Some(p) => p.forces(m, x, &mut f)?,
            None => m.forces(x, &mut f)?,
        }
        m.project(&mut f);
        let rn = f.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
        let load = load_norm(m, x, &mut scratch).max(f64::MIN_POSITIVE);
        rel = rn / load;
        if !rel.is_finite() {
            return Err(fail(format!("the relaxation diverged at step {step}")));
        }
        if rel <= opts.tolerance {
            return Ok(Stats {
                iterations: step,
                residual: rel,
                substeps: 1,
                relaxed: false,
            });
        }
        let mut ke = 0.0;
        for i in 0..nn {
            v[i] += f[i] / mass[i];
            ke += mass[i] * v[i].norm_squared();
        }
        if ke < ke_prev {
            // kinetic-energy peak passed: restart from rest here
            v.iter_mut().for_each(|v| *v = Vector3::zeros());
            ke_prev = 0.0;
        } else {
            for i in 0..nn {
                x[i] += v[i];
            }
            ke_prev = ke;
        }
    }
    Err(fail(format!(
        "{} relaxation steps reached, relative residual {rel:.3e}",
        opts.dr_steps
    )))
}

/// Guesses positions at pressure `p1` from an equilibrium at `p0`.
pub trait Predictor {
    /// Writes the guess into `x` (which holds the equilibrium at `p0`).
    fn predict(&self, rest: &[Point3<f64>], x: &mut [Point3<f64>], p0: f64, p1: f64);
}

/// No prediction: start from the last equilibrium.
pub struct Stay;

impl Predictor for Stay {
    fn predict(&self, _: &[Point3<f64>], _: &mut [Point3<f64>], _: f64, _: f64) {}
}

/// Solves at `p1` starting from the equilibrium `x` at `p0`, halving the
/// increment on failure. On error `x` holds the last equilibrium reached
/// (at the pressure returned in the error). When no equilibrium is found and
/// some attempt met `E <= 0`, that [`SimError::NonPositiveModulus`] is returned:
/// the law running out is then the cause.
#[allow(clippy::too_many_arguments)]
pub fn continuation(
    m: &mut Membrane,
    rest: &[Point3<f64>],
    x: &mut [Point3<f64>],
    p0: f64,
    p1: f64,
    solver: Solver,
    opts: &Options,
    predictor: &dyn Predictor,
    ws: &mut Option<NewtonWorkspace>,
) -> Result<Stats, SimError> {
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        m: &mut Membrane,
        rest: &[Point3<f64>],
        x: &mut [Point3<f64>],
        p0: f64,
        p1: f64,
        solver: Solver,
        opts: &Options,
        predictor: &dyn Predictor,
        ws: &mut Option<NewtonWorkspace>,
        depth: usize,
        last_ok: &mut f64,
        seen: &mut Option<SimError>,
    ) -> Result<Stats, SimError> {
        let saved = x.to_vec();
        predictor.predict(rest, x, p0, p1);
        let out = match solver {
            Solver::Newton => {
                let w = ws.get_or_insert_with(|| NewtonWorkspace::new(m));
                newton_with(m, x, p1, opts, w)
            }
            Solver::Dr => dynamic_relaxation(m, x, p1, opts),
        };
        match out {
            Ok(s) => {
                *last_ok = p1;
                Ok(s)
            }
            Err(e) => {
                x.copy_from_slice(&saved);
                if matches!(e, SimError::NonPositiveModulus { .. }) {
                    *seen = Some(e.clone());
                }
                if depth >= opts.max_halvings || matches!(e, SimError::BadParameter(_)) {
                    return Err(e);
                }
                let pm = 0.5 * (p0 + p1);
                let a = attempt(
                    m,
                    rest,
                    x,
                    p0,
                    pm,
                    solver,
                    opts,
                    predictor,
                    ws,
                    depth + 1,
                    last_ok,
                    seen,
                )?;
                let b = attempt(
                    m,
                    rest,
                    x,
                    pm,
                    p1,
                    solver,
                    opts,
                    predictor,
                    ws,
                    depth + 1,
                    last_ok,
                    seen,
                )?;
                Ok(Stats {
                    iterations: a.iterations + b.iterations,
                    residual: b.residual,
                    substeps: a.substeps + b.substeps,
                    relaxed: false,
                })
            }
        }
    }
    let mut last_ok = p0;
    let mut seen = None;
    attempt(
        m,
        rest,
        x,
        p0,
        p1,
        solver,
        opts,
        predictor,
        ws,
        0,
        &mut last_ok,
        &mut seen,
    )
    .map_err(|e| match (e, seen) {
        // the modulus law's failure is the cause: report it with its strain
        (SimError::NoEquilibrium { .. }, Some(modulus)) => modulus,
        (SimError::NoEquilibrium { reason, .. }, None) => SimError::NoEquilibrium {
            pressure_pa: p1,
            last_pressure_pa: last_ok,
            reason,
        },
        (other, _) => other,
    })
}

#[cfg(test)]
mod tests;
