//! Time integration of a [`Membrane`] (Sudhamani & Merriliance (2019)): explicit Euler, symplectic
//! Euler, position Verlet as 003 writes it, implicit Euler with Newton-Raphson
//! and a sparse LU, and position-based dynamics with compliance (XPBD).
//!
//! Masses are lumped: one third of `rho t |T0|` of every triangle to each of
//! its vertices ([`Membrane::masses`]). Loads (pressure, nodal loads) are
//! applied as a step at `t = 0` on a membrane at rest.
//!
//! ## Damping
//! A dashpot along every spring, `f_i = c ((v_j - v_i) . u) u` with `u` the
//! current unit edge vector.
//! * [`DampingLaw::Critical`] (default): `c = zeta * 2 sqrt(k m_red)`,
//!   `m_red = m_i m_j / (m_i + m_j)`, a fraction `zeta` of the spring's
//!   critical value. `k` is the spring's small-strain stiffness
//!   ([`reference_edge_stiffness`]).
//! * [`DampingLaw::Paper003`]: Sudhamani & Merriliance's eq 5, `d = sqrt(k (m_i + m_j)) / l0`.
//!   It is **not** a damping coefficient: `sqrt(k m)` is already N s/m, and
//!   the extra `1/l0` makes it N s/m^2, so the damping it gives depends on the
//!   unit of length and on the mesh size (a finer mesh is damped more). It is
//!   offered to reproduce 003, not recommended.
//!
//! ## Stable steps
//! [`estimate_step`] finds the stiffest mode of `M^-1 K` by power iteration
//! (matrix-free: `K v` from central differences of the forces, at most 300
//! iterations), its damping ratio `zeta` (Rayleigh quotient of the dashpots on
//! that mode), and the most damped mode of `M^-1 C`. For a mode
//! `x'' + 2 zeta w x' + w^2 x = 0` the amplification matrices give:
//! * explicit Euler: `|1 + h lambda| < 1`, i.e. `h < 2 zeta / w` for
//!   `zeta < 1` (no stable step at all without damping), `h < 2 / (w (zeta +
//!   sqrt(zeta^2 - 1)))` above;
//! * symplectic Euler and Sudhamani & Merriliance's position Verlet (drift-kick-drift with the
//!   damping evaluated at the step's start velocity) have the same
//!   characteristic polynomial, `det = 1 - 2 zeta w h`,
//!   `trace = 2 - (w h)^2 - 2 zeta w h`, stable for
//!   `h < (2 / w) (sqrt(1 + zeta^2) - zeta)` (the classical `2 / w` undamped);
//! * implicit Euler and XPBD: no step limit (they are unconditionally stable;
//!   their error grows with the step instead).
//!
//! An explicit integrator asked for a step above 0.9 of its limit either
//! sub-steps ([`StepPolicy::Substep`], the default) or refuses with the limit
//! in the message ([`StepPolicy::Refuse`]).
//!
//! ## Watch
//! Every step checks that the velocities are finite, that no node has moved
//! more than ten times the size of the body, and that the kinetic energy stays
//! below the work the loads could do over that distance. Breaking any of these
//! ends the run with [`DynError::Diverged`] (never a silent explosion, never a
//! NaN written out).

use faer::prelude::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use nalgebra::{Point3, Vector3};

use super::SimError;
use super::mesh::{Constraint, Mesh};
use super::par::ParForces;
use super::solve::{Dofs, load_norm, pattern};
use super::springs::{Membrane, SpringModel};

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// `x += h v; v += h a(x, v)` (both from the old state).
    ExplicitEuler,
    /// `v += h a(x, v); x += h v` (semi-implicit, symplectic when undamped).
    SymplecticEuler,
    /// Sudhamani & Merriliance's position Verlet: `q += v h/2; F = f(q); v += F/m h; q += v h/2`.
    Verlet,
    /// Backward Euler, Newton-Raphson on the positions with a sparse LU.
    ImplicitEuler,
    /// Position-based dynamics with compliance (003 section 1.4, XPBD).
    Xpbd,
}

impl Integrator {
    /// All integrators.
    pub const ALL: [Integrator; 5] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::Verlet,
        Integrator::ImplicitEuler,
        Integrator::Xpbd,
    ];

    /// Name on the command line and in output files.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit-euler",
            Integrator::SymplecticEuler => "symplectic-euler",
            Integrator::Verlet => "verlet",
            Integrator::ImplicitEuler => "implicit-euler",
            Integrator::Xpbd => "xpbd",
        }
    }

    /// Parses a name.
    pub fn parse(s: &str) -> Option<Integrator> {
        Self::ALL.into_iter().find(|i| i.name() == s.trim())
    }

    /// True for the integrators with a step limit.
    pub fn is_explicit(self) -> bool {
        matches!(
            self,
            Integrator::ExplicitEuler | Integrator::SymplecticEuler | Integrator::Verlet
        )
    }
}

/// How the dashpot coefficient of a spring is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DampingLaw {
    /// `c = fraction * 2 sqrt(k m_red)`.
    Critical(f64),
    /// 003 eq 5, `d = sqrt(k (m_i + m_j)) / l0` (dimensionally inconsistent).
    Paper003,
}

impl Default for DampingLaw {
    fn default() -> Self {
        DampingLaw::Critical(DEFAULT_DAMPING)
    }
}

/// Default fraction of a spring's critical damping.
pub const DEFAULT_DAMPING: f64 = 0.1;

/// What an explicit integrator does with a step above its limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepPolicy {
    /// Split each step into sub-steps of at most 0.9 of the limit.
    Substep,
    /// Refuse with the limit in the message.
    Refuse,
    /// Take the step as given (for measuring the limit; the watch still runs).
    Unchecked,
}

/// Settings of a dynamic run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynOptions {
    /// Integrator.
    pub integrator: Integrator,
    /// Time step, s (output step when sub-stepping).
    pub dt_s: f64,
    /// End time, s.
    pub t_end_s: f64,
    /// Damping.
    pub damping: DampingLaw,
    /// Step policy of the explicit integrators.
    pub policy: StepPolicy,
    /// Implicit Euler: residual force relative to the load at which Newton
    /// stops (default 1e-8).
    pub newton_tolerance: f64,
    /// Implicit Euler: Newton iterations per step (default 25).
    pub newton_iterations: usize,
    /// XPBD: constraint iterations per step (default 20).
    pub xpbd_iterations: usize,
    /// Largest number of samples kept in the trace (default 4000).
    pub max_samples: usize,
    /// Stop early once settled: at a sample, the residual force relative to
    /// the load is below this and the kinetic energy below its square times
    /// the loads' work `sum |f_load| |x - x0|` (amplitude about this share of
    /// the displacement). Default `None`: run to `t_end_s`.
    pub settle_tolerance: Option<f64>,
}

impl Default for DynOptions {
    fn default() -> Self {
        DynOptions {
            integrator: Integrator::Verlet,
            dt_s: 1e-4,
            t_end_s: 0.1,
            damping: DampingLaw::default(),
            policy: StepPolicy::Substep,
            newton_tolerance: 1e-8,
            newton_iterations: 25,
            xpbd_iterations: 20,
            max_samples: 4000,
            settle_tolerance: None,
        }
    }
}

fn divergence_hint(integrator: &str, h_s: &f64, dt_crit_s: &f64) -> &'static str {
    if integrator == "explicit-euler" && h_s <= dt_crit_s {
        ", but explicit Euler also amplifies every slow mode its dashpots leave undamped (|1 + h lambda| > 1 for an undamped oscillation; a bubble's transverse modes are carried by tension, not by the springs' stretch): use symplectic-euler, verlet or implicit-euler"
    } else {
        "; lower --dt or use implicit-euler"
    }
}

/// Halvings of an implicit Euler step whose Newton iteration failed.
pub const IMPLICIT_HALVINGS: usize = 8;

/// Share of the step limit used when sub-stepping.
pub const STEP_SAFETY: f64 = 0.9;

/// Errors of a dynamic run.
#[derive(Debug, Clone, thiserror::Error)]
pub enum DynError {
    /// A setting out of range.
    #[error("{0}")]
    BadParameter(String),
    /// An explicit step above the stability limit, with the refuse policy.
    #[error(
        "--dt {dt_s:.4e} s is above the stable step of {integrator} for this mesh, {dt_crit_s:.4e} s (stiffest mode {omega_rad_s:.4e} rad/s, its damping ratio {zeta:.3}); use --dt {suggest_s:.3e} or smaller, or let bulge sub-step (--step-policy substep)"
    )]
    StepTooLarge {
        /// Integrator name.
        integrator: &'static str,
        /// Step asked for, s.
        dt_s: f64,
        /// Estimated limit, s.
        dt_crit_s: f64,
        /// Stiffest angular frequency, rad/s.
        omega_rad_s: f64,
        /// Its damping ratio.
        zeta: f64,
        /// A safe step, s.
        suggest_s: f64,
    },
    /// Explicit Euler without damping has no stable step.
    #[error(
        "explicit Euler is unstable at every step without damping (its amplification sqrt(1 + (w h)^2) exceeds 1 for every mode); give --damping > 0 or use symplectic-euler, verlet or implicit-euler"
    )]
    NoStableStep,
    /// The watch fired.
    #[error(
        "{integrator} diverged at t = {t_s:.4e} s (step {step}, sub-step {h_s:.3e} s): {what}. Its estimated step limit at the start was {dt_crit_s:.3e} s{}. No result was written for this run",
        divergence_hint(.integrator, .h_s, .dt_crit_s)
    )]
    Diverged {
        /// Integrator name.
        integrator: &'static str,
        /// Time reached, s.
        t_s: f64,
        /// Step index.
        step: usize,
        /// Sub-step used, s.
        h_s: f64,
        /// What was seen.
        what: String,
        /// The estimated limit, s (infinite for the implicit integrators).
        dt_crit_s: f64,
    },
    /// Newton did not converge in an implicit Euler step.
    #[error(
        "implicit Euler: Newton did not converge at t = {t_s:.4e} s ({reason}); lower --dt (the step is {dt_s:.3e} s)"
    )]
    NewtonFailed {
        /// Time, s.
        t_s: f64,
        /// Step, s.
        dt_s: f64,
        /// Why.
        reason: String,
    },
    /// The membrane solver refused (bad modulus, collapsed triangle, ...).
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// The stiffest and the most damped modes at a state, and the step limits
/// they set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepEstimate {
    /// Largest angular frequency `sqrt(lambda_max(M^-1 K))`, rad/s.
    pub omega_max: f64,
    /// Damping ratio of that mode.
    pub zeta: f64,
    /// Largest eigenvalue of `M^-1 C`, 1/s (twice `zeta w` of the most damped mode).
    pub damping_rate: f64,
    /// Gershgorin upper bound of `omega_max` (row sums of the triangle stiffnesses), rad/s.
    pub omega_gershgorin: f64,
    /// Power iterations used.
    pub iterations: usize,
}

impl StepEstimate {
    /// The stable step limit of an integrator, s (infinite for the implicit
    /// ones; 0 for explicit Euler without damping).
    pub fn limit(&self, integrator: Integrator) -> f64 {
        let by_mode = |w: f64, z: f64| -> f64 {
            if w.is_nan() || w <= 0.0 {
                return f64::INFINITY;
            }
            match integrator {
                Integrator::ExplicitEuler => {
                    if z < 1.0 {
                        2.0 * z / w
                    } else {
                        2.0 / (w * (z + (z * z - 1.0).sqrt()))
                    }
                }
                Integrator::SymplecticEuler | Integrator::Verlet => {
                    2.0 / w * ((1.0 + z * z).sqrt() - z)
                }
                _ => f64::INFINITY,
            }
        };
        let stiff = by_mode(self.omega_max, self.zeta);
        // the most damped mode: its rate c = 2 zeta w; with w <= omega_max its
        // limit is at least that of w = omega_max with the same c
        let damped = if self.damping_rate > 0.0 && self.omega_max > 0.0 {
            by_mode(self.omega_max, self.damping_rate / (2.0 * self.omega_max))
        } else {
            f64::INFINITY
        };
        if !integrator.is_explicit() {
            return f64::INFINITY;
        }
        stiff.min(damped)
    }
}

/// Per-spring small-strain stiffness, N/m, of a spring model with modulus
/// `young_pa`: Van Gelder eq 1, Lloyd eq 4, and for TP MSS eq 16 (its
/// stiffness under equibiaxial strain, `Q0 (a0^2 - b0^2 + c0^2)` summed over
/// the triangles). Negative contributions (obtuse triangles) are kept; the
/// damping clamps the sum at zero.
pub fn reference_edge_stiffness(
    mesh: &Mesh,
    model: SpringModel,
    young_pa: f64,
    poisson: f64,
    thickness_m: f64,
) -> Vec<f64> {
    let (e, nu, t) = (young_pa, poisson, thickness_m);
    let mut k = vec![0.0; mesh.edges.len()];
    for (tri, te) in mesh.triangles.iter().zip(&mesh.triangle_edges) {
        let p = tri.map(|i| mesh.nodes[i as usize]);
        let area = (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0;
        let l2: [f64; 3] =
            std::array::from_fn(|s| (p[(s + 2) % 3] - p[(s + 1) % 3]).norm_squared());
        for s in 0..3 {
            let (a2, b2) = (l2[(s + 1) % 3], l2[(s + 2) % 3]);
            let c2 = l2[s];
            let ks = match model {
                SpringModel::VanGelder => {
                    e * t / (1.0 + nu) * area / c2
                        + e * t * nu / (1.0 - nu * nu) * (a2 + b2 - c2) / (8.0 * area)
                }
                SpringModel::Lloyd => e * t * area / c2,
                SpringModel::Tp | SpringModel::TpPaper => {
                    e * t / (8.0 * (1.0 - nu) * area) * (a2 + b2 - c2)
                }
            };
            k[te[s] as usize] += ks;
        }
    }
    k
}

/// Dashpot coefficient per edge, N s/m.
pub fn edge_damping(mesh: &Mesh, k: &[f64], masses: &[f64], law: DampingLaw) -> Vec<f64> {
    mesh.edges
        .iter()
        .zip(k)
        .map(|(e, &k)| {
            let (mi, mj) = (masses[e[0] as usize], masses[e[1] as usize]);
            let k = k.max(0.0);
            match law {
                DampingLaw::Critical(z) => z * 2.0 * (k * mi * mj / (mi + mj)).sqrt(),
                DampingLaw::Paper003 => {
                    let l0 = (mesh.nodes[e[1] as usize] - mesh.nodes[e[0] as usize]).norm();
                    (k * (mi + mj)).sqrt() / l0
                }
            }
        })
        .collect()
}

/// One sample of a run's history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// The scene's measured quantity (apex height, loaded node's displacement), m.
    pub value_m: f64,
    /// Kinetic energy, J.
    pub kinetic_j: f64,
}

/// The outcome of a run.
#[derive(Debug, Clone)]
pub struct DynRun {
    /// History (at most `max_samples`, evenly thinned).
    pub samples: Vec<Sample>,
    /// Output steps taken.
    pub steps: usize,
    /// Sub-steps per output step.
    pub substeps: usize,
    /// Step actually integrated, s.
    pub h_s: f64,
    /// The step estimate at the start state (`None` for implicit Euler and XPBD
    /// unless asked for).
    pub estimate: Option<StepEstimate>,
    /// Force evaluations.
    pub force_evaluations: usize,
    /// Newton iterations (implicit Euler), summed.
    pub newton_iterations: usize,
    /// Residual force relative to the load at the end (how close to static
    /// equilibrium the final state is).
    pub residual: f64,
}

impl DynRun {
    /// Largest measured value.
    pub fn peak(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.value_m)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Final measured value.
    pub fn last(&self) -> f64 {
        self.samples.last().map(|s| s.value_m).unwrap_or(f64::NAN)
    }

    /// Last time the measured value was outside `final (1 +- band)`, s
    /// (sample resolution); 0 when it never left the band.
    pub fn settling_time(&self, reference: f64, band: f64) -> f64 {
        let tol = band * reference.abs();
        self.samples
            .iter()
            .rev()
            .find(|s| (s.value_m - reference).abs() > tol)
            .map(|s| s.t_s)
            .unwrap_or(0.0)
    }
}

/// The dynamic system: membrane, masses, dashpots and the rest state.
pub struct Dynamics<'a> {
    /// The membrane (loads set on it).
    pub membrane: &'a mut Membrane,
    /// Mesh (rest positions, edges).
    pub mesh: &'a Mesh,
    /// Dashpot coefficient per edge, N s/m.
    pub damping: Vec<f64>,
    /// Spring stiffness per edge (XPBD compliance is its inverse), N/m.
    pub edge_k: Vec<f64>,
    inv_mass: Vec<f64>,
    size_m: f64,
    /// Parallel forces for meshes of [`PAR_MIN_NODES`] nodes and more when
    /// the rayon pool has more than one thread.
    par: Option<std::cell::RefCell<ParForces>>,
}

/// Meshes from this size on evaluate their forces in parallel (measured: two
/// threads 1.1-1.6 times one at 1e4 nodes, 1.3-2 times at 1e5).
pub const PAR_MIN_NODES: usize = 10_000;

impl<'a> Dynamics<'a> {
    /// Prepares masses, dashpots and the stiffness of the springs.
    pub fn new(
        membrane: &'a mut Membrane,
        mesh: &'a Mesh,
        damping: DampingLaw,
    ) -> Result<Dynamics<'a>, DynError> {
        if let DampingLaw::Critical(z) = damping
            && !(z.is_finite() && z >= 0.0)
        {
            return Err(DynError::BadParameter(format!(
                "--damping {z} must be a fraction of critical damping >= 0 (e.g. 0.1)"
            )));
        }
        let e0 = membrane.law.young(1.0).1;
        let k = reference_edge_stiffness(
            mesh,
            membrane.model,
            e0,
            membrane.poisson,
            membrane.thickness_m,
        );
        let c = edge_damping(mesh, &k, &membrane.masses, damping);
        let inv_mass = membrane
            .masses
            .iter()
            .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for p in &mesh.nodes {
            lo = lo.inf(&p.coords);
            hi = hi.sup(&p.coords);
        }
        let size_m = (hi - lo).norm().max(f64::MIN_POSITIVE);
        let par = (mesh.nodes.len() >= PAR_MIN_NODES && rayon::current_num_threads() > 1)
            .then(|| std::cell::RefCell::new(ParForces::new(mesh, membrane)));
        Ok(Dynamics {
            membrane,
            mesh,
            damping: c,
            edge_k: k,
            inv_mass,
            size_m,
            par,
        })
    }

    /// The active dashpots at positions `x`: the edge's nodes `(i, j)`, its
    /// coefficient and the unit vector from `i` to `j` (edges without
    /// damping or of zero length are left out).
    fn dashpots<'b>(
        &'b self,
        x: &'b [Point3<f64>],
    ) -> impl Iterator<Item = (usize, usize, f64, Vector3<f64>)> + 'b {
        self.mesh
            .edges
            .iter()
            .zip(&self.damping)
            .filter_map(|(e, &c)| {
                let (i, j) = (e[0] as usize, e[1] as usize);
                let d = x[j] - x[i];
                let l = d.norm();
                (c != 0.0 && l > 0.0).then(|| (i, j, c, d / l))
            })
    }

    /// The membrane's nodal forces at `x` (in parallel on large meshes).
    fn forces(&self, x: &[Point3<f64>], f: &mut [Vector3<f64>]) -> Result<(), SimError> {
        match &self.par {
            Some(p) => p.borrow_mut().forces(self.membrane, x, f),
            None => self.membrane.forces(x, f),
        }
    }

    /// Adds the dashpot forces at positions `x` and velocities `v` to `f`.
    pub fn add_damping(&self, x: &[Point3<f64>], v: &[Vector3<f64>], f: &mut [Vector3<f64>]) {
        for (i, j, c, u) in self.dashpots(x) {
            let fv = u * (c * (v[j] - v[i]).dot(&u));
            f[i] += fv;
            f[j] -= fv;
        }
    }

    /// Net force (springs, loads, dashpots), projected on the constraints.
    fn total_force(
        &self,
        x: &[Point3<f64>],
        v: &[Vector3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), DynError> {
        self.forces(x, f)?;
        self.add_damping(x, v, f);
        self.membrane.project(f);
        Ok(())
    }

    /// The stiffest mode at `x` by power iteration on `M^-1/2 K M^-1/2`
    /// (`K v` by central differences of the forces): its eigenvalue
    /// `omega^2`, the iterations taken and the unit mode `u` (mass-scaled).
    fn stiffest(&self, x: &[Point3<f64>]) -> Result<(f64, usize, Vec<Vector3<f64>>), DynError> {
        let n = x.len();
        let m = &self.membrane;
        let sqm: Vec<f64> = m.masses.iter().map(|&mi| mi.sqrt()).collect();
        // deterministic pseudo-random start vector
        let mut u: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                Vector3::new(
                    pseudo_random(i, 1),
                    pseudo_random(i, 2),
                    pseudo_random(i, 3),
                )
            })
            .collect();
        m.project(&mut u);
        normalise(&mut u);
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        let mut fp = vec![Vector3::zeros(); n];
        let mut fm = vec![Vector3::zeros(); n];
        let mut w = vec![Vector3::zeros(); n];
        let eps = 1e-7 * self.size_m;
        let mut lambda = 0.0;
        let mut iterations = 0;
        let mut history = Vec::new();
        for it in 0..300 {
            iterations = it + 1;
            // v = M^-1/2 u, K v by central differences, w = M^-1/2 K v
            let vmax = (0..n)
                .map(|i| (u[i] / sqm[i].max(f64::MIN_POSITIVE)).norm())
                .fold(0.0, f64::max);
            if vmax.is_nan() || vmax <= 0.0 {
                break;
            }
            let s = eps / vmax;
            for i in 0..n {
                let dv = u[i] * (s / sqm[i].max(f64::MIN_POSITIVE));
                xp[i] = x[i] + dv;
                xm[i] = x[i] - dv;
            }
            self.forces(&xp, &mut fp)?;
            self.forces(&xm, &mut fm)?;
            for i in 0..n {
                w[i] = -(fp[i] - fm[i]) / (2.0 * s) / sqm[i].max(f64::MIN_POSITIVE);
            }
            m.project(&mut w);
            lambda = (0..n).map(|i| u[i].dot(&w[i])).sum::<f64>();
            u.copy_from_slice(&w);
            if normalise(&mut u) == 0.0 {
                break;
            }
            history.push(lambda);
            if it >= 30 {
                let old = history[it - 10];
                if (lambda - old).abs() <= 1e-4 * lambda.abs() {
                    break;
                }
            }
        }
        Ok((lambda, iterations, u))
    }

    /// Power-iteration estimate of the stiffest and the most damped modes at
    /// positions `x` (see the module docs).
    pub fn estimate_step(&self, x: &[Point3<f64>]) -> Result<StepEstimate, DynError> {
        let n = x.len();
        let m = &self.membrane;
        let sqm: Vec<f64> = m.masses.iter().map(|&mi| mi.sqrt()).collect();
        let (lambda, iterations, u) = self.stiffest(x)?;
        let mut w = vec![Vector3::zeros(); n];
        let omega_max = lambda.max(0.0).sqrt();
        // damping ratio of that mode: u . M^-1/2 C M^-1/2 u / (2 w)
        let c_of = |u: &[Vector3<f64>], out: &mut [Vector3<f64>]| {
            let v: Vec<Vector3<f64>> = (0..n)
                .map(|i| u[i] / sqm[i].max(f64::MIN_POSITIVE))
                .collect();
            out.iter_mut().for_each(|o| *o = Vector3::zeros());
            // -C v: add_damping gives -C v as a force
            self.add_damping(x, &v, out);
            for i in 0..n {
                out[i] = -out[i] / sqm[i].max(f64::MIN_POSITIVE);
            }
            m.project(out);
        };
        c_of(&u, &mut w);
        let cu = (0..n).map(|i| u[i].dot(&w[i])).sum::<f64>();
        let zeta = if omega_max > 0.0 {
            cu / (2.0 * omega_max)
        } else {
            0.0
        };
        // most damped mode: power iteration on M^-1/2 C M^-1/2
        let mut damping_rate = 0.0;
        if self.damping.iter().any(|&c| c > 0.0) {
            let mut q = u.clone();
            for _ in 0..100 {
                c_of(&q, &mut w);
                damping_rate = (0..n).map(|i| q[i].dot(&w[i])).sum::<f64>();
                q.copy_from_slice(&w);
                if normalise(&mut q) == 0.0 {
                    break;
                }
            }
        }
        // Gershgorin bound
        let mut s = vec![0.0; n];
        m.stiffness_bounds(x, &mut s)?;
        let omega_gershgorin = (0..n)
            .filter(|&i| !matches!(m.constraints[i], Constraint::Fixed) && m.masses[i] > 0.0)
            .map(|i| s[i] / m.masses[i])
            .fold(0.0, f64::max)
            .sqrt();
        Ok(StepEstimate {
            omega_max,
            zeta,
            damping_rate: damping_rate.max(0.0),
            omega_gershgorin,
            iterations,
        })
    }

    /// Runs from positions `x` and velocities `v` (both updated) to
    /// `t_end_s`, recording `measure(x)`.
    pub fn run(
        &mut self,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        opts: &DynOptions,
        measure: &dyn Fn(&[Point3<f64>]) -> f64,
    ) -> Result<DynRun, DynError> {
        if !(opts.dt_s.is_finite() && opts.dt_s > 0.0) {
            return Err(DynError::BadParameter(format!(
                "--dt {} must be a positive time step in s",
                opts.dt_s
            )));
        }
        if !(opts.t_end_s.is_finite() && opts.t_end_s > 0.0) {
            return Err(DynError::BadParameter(format!(
                "--t-end {} must be a positive time in s",
                opts.t_end_s
            )));
        }
        let steps = (opts.t_end_s / opts.dt_s).round().max(1.0) as usize;
        if steps > 50_000_000 {
            return Err(DynError::BadParameter(format!(
                "--t-end {} s / --dt {} s is {steps} steps; at most 5e7 are allowed",
                opts.t_end_s, opts.dt_s
            )));
        }
        let integ = opts.integrator;
        if integ == Integrator::Xpbd {
            self.check_xpbd()?;
        }
        let mut estimate = None;
        let mut substeps = 1;
        let mut dt_crit = f64::INFINITY;
        if integ.is_explicit() && opts.policy != StepPolicy::Unchecked {
            let est = self.estimate_step(x)?;
            dt_crit = est.limit(integ);
            estimate = Some(est);
            if integ == Integrator::ExplicitEuler && (dt_crit.is_nan() || dt_crit <= 0.0) {
                return Err(DynError::NoStableStep);
            }
            if opts.dt_s > STEP_SAFETY * dt_crit {
                match opts.policy {
                    StepPolicy::Substep => {
                        substeps = (opts.dt_s / (STEP_SAFETY * dt_crit)).ceil() as usize
                    }
                    StepPolicy::Refuse => {
                        return Err(DynError::StepTooLarge {
                            integrator: integ.name(),
                            dt_s: opts.dt_s,
                            dt_crit_s: dt_crit,
                            omega_rad_s: est.omega_max,
                            zeta: est.zeta,
                            suggest_s: STEP_SAFETY * dt_crit,
                        });
                    }
                    StepPolicy::Unchecked => {}
                }
            }
            if substeps.saturating_mul(steps) > 50_000_000 {
                return Err(DynError::BadParameter(format!(
                    "--t-end {} s needs {} sub-steps of {:.3e} s (the stable limit of {}); at most 5e7 are allowed: shorten --t-end, coarsen the mesh or use implicit-euler",
                    opts.t_end_s,
                    substeps.saturating_mul(steps),
                    STEP_SAFETY * dt_crit,
                    integ.name()
                )));
            }
        }
        let h = opts.dt_s / substeps as f64;
        let n = x.len();
        let x0 = self.mesh.nodes.clone();
        let mut f = vec![Vector3::zeros(); n];
        let mut scratch = vec![Vector3::zeros(); n];
        let load = load_norm(self.membrane, x, &mut scratch);
        // the watch: displacement and kinetic-energy bounds
        let max_disp = 10.0 * self.size_m;
        let load_sum: f64 = scratch
            .iter()
            .map(|v| v.norm())
            .sum::<f64>()
            .max(f64::MIN_POSITIVE);
        let ke_bound = 10.0 * load_sum * max_disp
            + 10.0
                * (0..n)
                    .map(|i| 0.5 * self.membrane.masses[i] * v[i].norm_squared())
                    .sum::<f64>();
        let every = steps.div_ceil(opts.max_samples.max(2) - 1).max(1);
        let mut samples = vec![Sample {
            t_s: 0.0,
            value_m: measure(x),
            kinetic_j: self.kinetic(v),
        }];
        let mut evals = 0usize;
        let mut newton_its = 0usize;
        let mut implicit = if integ == Integrator::ImplicitEuler {
            Some(ImplicitWorkspace::new(self))
        } else {
            None
        };
        let mut xpbd_prev = x.to_vec();
        let mut lambdas = vec![0.0; self.mesh.edges.len()];
        let mut steps_done = steps;
        for step in 0..steps {
            for sub in 0..substeps {
                let t = (step * substeps + sub) as f64 * h;
                match integ {
                    Integrator::ExplicitEuler => {
                        self.total_force(x, v, &mut f)?;
                        for i in 0..n {
                            x[i] += v[i] * h;
                            v[i] += f[i] * (h * self.inv_mass[i]);
                        }
                        evals += 1;
                    }
                    Integrator::SymplecticEuler => {
                        self.total_force(x, v, &mut f)?;
                        for i in 0..n {
                            v[i] += f[i] * (h * self.inv_mass[i]);
                            x[i] += v[i] * h;
                        }
                        evals += 1;
                    }
                    Integrator::Verlet => {
                        for i in 0..n {
                            x[i] += v[i] * (0.5 * h);
                        }
                        self.total_force(x, v, &mut f)?;
                        for i in 0..n {
                            v[i] += f[i] * (h * self.inv_mass[i]);
                            x[i] += v[i] * (0.5 * h);
                        }
                        evals += 1;
                    }
                    Integrator::ImplicitEuler => {
                        let ws = implicit.as_mut().expect("created above");
                        let (its, ev) = self.implicit_step_halving(ws, x, v, h, opts, t, 0)?;
                        newton_its += its;
                        evals += ev;
                    }
                    Integrator::Xpbd => {
                        self.xpbd_step(
                            x,
                            v,
                            &mut xpbd_prev,
                            &mut lambdas,
                            &mut scratch,
                            h,
                            opts.xpbd_iterations,
                        )?;
                        evals += 1;
                    }
                }
                // the watch
                let mut ke = 0.0;
                let mut dmax = 0.0_f64;
                for i in 0..n {
                    ke += 0.5 * self.membrane.masses[i] * v[i].norm_squared();
                    dmax = dmax.max((x[i] - x0[i]).norm_squared());
                }
                let dmax = dmax.sqrt();
                let what = if !(ke.is_finite() && dmax.is_finite()) {
                    Some(
                        "the velocities or positions are no longer finite (NaN or infinite)"
                            .to_string(),
                    )
                } else if dmax > max_disp {
                    Some(format!(
                        "a node moved {dmax:.3e} m, more than ten times the body's size ({:.3e} m)",
                        self.size_m
                    ))
                } else if ke > ke_bound {
                    Some(format!(
                        "the kinetic energy {ke:.3e} J exceeds what the loads can supply ({ke_bound:.3e} J)"
                    ))
                } else {
                    None
                };
                if let Some(what) = what {
                    return Err(DynError::Diverged {
                        integrator: integ.name(),
                        t_s: t + h,
                        step,
                        h_s: h,
                        what,
                        dt_crit_s: dt_crit,
                    });
                }
            }
            if (step + 1) % every == 0 || step + 1 == steps {
                let ke = self.kinetic(v);
                samples.push(Sample {
                    t_s: (step + 1) as f64 * opts.dt_s,
                    value_m: measure(x),
                    kinetic_j: ke,
                });
                if let Some(tol) = opts.settle_tolerance {
                    self.forces(x, &mut f)?;
                    self.membrane.project(&mut f);
                    let rn = f.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
                    let ln = load_norm(self.membrane, x, &mut scratch).max(f64::MIN_POSITIVE);
                    let work: f64 = (0..n)
                        .map(|i| scratch[i].norm() * (x[i] - x0[i]).norm())
                        .sum();
                    evals += 1;
                    if rn <= tol * ln && ke <= tol * tol * work {
                        steps_done = step + 1;
                        break;
                    }
                }
            }
        }
        self.forces(x, &mut f)?;
        self.membrane.project(&mut f);
        let rn = f.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
        let residual = rn / load.max(f64::MIN_POSITIVE);
        Ok(DynRun {
            samples,
            steps: steps_done,
            substeps,
            h_s: h,
            estimate,
            force_evaluations: evals,
            newton_iterations: newton_its,
            residual,
        })
    }

    fn kinetic(&self, v: &[Vector3<f64>]) -> f64 {
        v.iter()
            .zip(&self.membrane.masses)
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum()
    }

    fn check_xpbd(&self) -> Result<(), DynError> {
        if !matches!(
            self.membrane.model,
            SpringModel::VanGelder | SpringModel::Lloyd
        ) {
            return Err(DynError::BadParameter(format!(
                "xpbd projects distance constraints with a fixed compliance 1/k per spring; the {} model's spring stiffness depends on the other sides of its triangles, so it has no such form: use --model van-gelder or lloyd with xpbd, or another integrator",
                self.membrane.model.name()
            )));
        }
        if !self.membrane.law.is_constant() {
            return Err(DynError::BadParameter(
                "xpbd needs a constant modulus (a linear material): its compliance 1/k is fixed per spring".into(),
            ));
        }
        Ok(())
    }

    /// One XPBD step (Macklin, Mueller & Chentanez 2016, with their
    /// constraint damping): predict with the external forces, project the
    /// distance constraints `|p_i - p_j| - l0` with compliance `1/k`, then
    /// velocities from positions (003 section 1.4).
    #[allow(clippy::too_many_arguments)]
    fn xpbd_step(
        &self,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        prev: &mut [Point3<f64>],
        lambdas: &mut [f64],
        fext: &mut [Vector3<f64>],
        h: f64,
        iterations: usize,
    ) -> Result<(), DynError> {
        let n = x.len();
        load_norm(self.membrane, x, fext);
        prev.copy_from_slice(x);
        let cons = &self.membrane.constraints;
        for i in 0..n {
            let dv = cons[i].project(v[i] * h + fext[i] * (h * h * self.inv_mass[i]));
            x[i] += dv;
        }
        lambdas.iter_mut().for_each(|l| *l = 0.0);
        for _ in 0..iterations.max(1) {
            for (ei, e) in self.mesh.edges.iter().enumerate() {
                let k = self.edge_k[ei];
                if k.is_nan() || k <= 0.0 {
                    continue;
                }
                let (i, j) = (e[0] as usize, e[1] as usize);
                let d = x[i] - x[j];
                let l = d.norm();
                if l <= 0.0 {
                    continue;
                }
                let nrm = d / l;
                let ni = cons[i].project(nrm);
                let nj = cons[j].project(nrm);
                let wsum =
                    ni.norm_squared() * self.inv_mass[i] + nj.norm_squared() * self.inv_mass[j];
                if wsum <= 0.0 {
                    continue;
                }
                let l0 = (self.mesh.nodes[e[1] as usize] - self.mesh.nodes[e[0] as usize]).norm();
                let alpha = 1.0 / (k * h * h);
                let gamma = self.damping[ei] / (k * h);
                let c = l - l0;
                let rate = nrm.dot(&((x[i] - prev[i]) - (x[j] - prev[j])));
                let dl = (-c - alpha * lambdas[ei] - gamma * rate) / ((1.0 + gamma) * wsum + alpha);
                lambdas[ei] += dl;
                x[i] += ni * (dl * self.inv_mass[i]);
                x[j] -= nj * (dl * self.inv_mass[j]);
            }
        }
        for i in 0..n {
            v[i] = (x[i] - prev[i]) / h;
        }
        Ok(())
    }

    /// An implicit Euler step of `h`; when Newton fails, the step is taken
    /// as two halves, at most [`IMPLICIT_HALVINGS`] times deep, before the
    /// failure is reported.
    #[allow(clippy::too_many_arguments)]
    fn implicit_step_halving(
        &self,
        ws: &mut ImplicitWorkspace,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        opts: &DynOptions,
        t: f64,
        depth: usize,
    ) -> Result<(usize, usize), DynError> {
        match self.implicit_step(ws, x, v, h, opts, t) {
            Ok(r) => Ok(r),
            Err(DynError::NewtonFailed { .. }) if depth < IMPLICIT_HALVINGS => {
                let (a, b) = self.implicit_step_halving(ws, x, v, 0.5 * h, opts, t, depth + 1)?;
                let (c, d) =
                    self.implicit_step_halving(ws, x, v, 0.5 * h, opts, t + 0.5 * h, depth + 1)?;
                Ok((a + c, b + d))
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
    fn implicit_step(
        &self,
        ws: &mut ImplicitWorkspace,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        opts: &DynOptions,
        t: f64,
    ) -> Result<(usize, usize), DynError> {
        let n = x.len();
        let m = &*self.membrane;
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
        for it in 0..opts.newton_iterations {
            // residual as a force: g/h^2 = M (dx - h v)/h^2 - f - C dx / h
            self.forces(&xn, &mut f)?;
            evals += 1;
            for i in 0..n {
                vn[i] = (xn[i] - x_old[i]) / h;
            }
            self.add_damping(&xn, &vn, &mut f);
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
            if gn <= opts.newton_tolerance * load {
                for i in 0..n {
                    v[i] = m.constraints[i].project((xn[i] - x_old[i]) / h);
                    x[i] = xn[i];
                }
                return Ok((it, evals));
            }
            let stale = ws.lu.as_ref().is_none_or(|(_, lu_h)| *lu_h != h);
            if stale || gn > 0.25 * last_gn {
                ws.assemble(self, &xn, h)?;
                ws.factor(h).map_err(fail)?;
            }
            last_gn = gn;
            let d = ws.solve(&g).map_err(fail)?;
            for i in 0..n {
                xn[i] -= d[i];
            }
        }
        Err(fail(format!(
            "{} iterations reached",
            opts.newton_iterations
        )))
    }
}

/// Scales `u` to unit norm (unless zero); returns its norm before.
fn normalise(u: &mut [Vector3<f64>]) -> f64 {
    let s = u.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    if s > 0.0 {
        u.iter_mut().for_each(|v| *v /= s);
    }
    s
}

/// A deterministic number in [-1, 1] (splitmix64 of node and component).
fn pseudo_random(i: usize, k: u64) -> f64 {
    let mut s =
        (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ k.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 31;
    s = s.wrapping_mul(0x94D0_49BB_1331_11EB);
    s ^= s >> 29;
    (s % 2001) as f64 / 1000.0 - 1.0
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
    fn factor(&mut self, h: f64) -> Result<(), String> {
        let mat = SparseColMat::new(self.symbolic.clone(), self.values.clone());
        if self.symbolic_lu.is_none() {
            self.symbolic_lu =
                Some(SymbolicLu::try_new(mat.symbolic()).map_err(|e| format!("{e:?}"))?);
        }
        let sym = self.symbolic_lu.clone().expect("set above");
        let lu = Lu::try_new_with_symbolic(sym, mat.as_ref())
            .map_err(|e| format!("singular system ({e:?})"))?;
        self.lu = Some((lu, h));
        Ok(())
    }

    /// Solves `J d = g` (g a nodal force residual) with the last
    /// factorisation; returns nodal corrections.
    fn solve(&mut self, g: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>, String> {
        let (lu, _) = self.lu.as_ref().ok_or("no factorisation")?;
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
            return Err("singular system (non-finite Newton step)".into());
        }
        Ok(out)
    }
}

/// Largest stable step of an integrator, measured: from the state `x`
/// (normally a loaded equilibrium), a velocity along the stiffest mode found
/// by [`Dynamics::estimate_step`] is integrated for `steps` steps of `h`; the
/// step is stable when the kinetic energy at the end has not grown above its
/// start. Bisection on `h` in `[lo, hi]` to a relative width `rel_tol`.
/// Returns `None` when `hi` is still stable.
pub fn measure_step_limit(
    dynamics: &mut Dynamics,
    x: &[Point3<f64>],
    integrator: Integrator,
    lo: f64,
    hi: f64,
    steps: usize,
    rel_tol: f64,
) -> Result<Option<f64>, DynError> {
    let n = x.len();
    // the stiffest mode as the start velocity
    let mode = dynamics.stiffest_mode(x)?;
    let stable = |d: &mut Dynamics, h: f64| -> Result<bool, DynError> {
        let mut xx = x.to_vec();
        let mut v: Vec<Vector3<f64>> = mode.clone();
        let ke0 = d.kinetic(&v);
        let opts = DynOptions {
            integrator,
            dt_s: h,
            t_end_s: h * steps as f64,
            policy: StepPolicy::Unchecked,
            max_samples: 2,
            ..DynOptions::default()
        };
        match d.run(&mut xx, &mut v, &opts, &|_| 0.0) {
            Ok(_) => Ok(d.kinetic(&v) <= 1.5 * ke0),
            Err(DynError::Diverged { .. }) => Ok(false),
            Err(DynError::Sim(_)) => Ok(false),
            Err(e) => Err(e),
        }
    };
    let _ = n;
    if stable(dynamics, hi)? {
        return Ok(None);
    }
    let (mut a, mut b) = (lo, hi);
    while (b - a) > rel_tol * a {
        let mid = 0.5 * (a + b);
        if stable(dynamics, mid)? {
            a = mid;
        } else {
            b = mid;
        }
    }
    Ok(Some(0.5 * (a + b)))
}

impl Dynamics<'_> {
    /// A velocity field along the stiffest mode at `x` (power iteration as
    /// in [`Dynamics::estimate_step`]), scaled to a tiny amplitude: 1e-6 of
    /// the body's size per unit of `omega_max` time.
    fn stiffest_mode(&self, x: &[Point3<f64>]) -> Result<Vec<Vector3<f64>>, DynError> {
        let n = x.len();
        let sqm: Vec<f64> = self
            .membrane
            .masses
            .iter()
            .map(|&mi| mi.sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let (lambda, _, u) = self.stiffest(x)?;
        let omega = lambda.max(0.0).sqrt();
        let amp = 1e-6 * self.size_m * omega;
        let vmax = (0..n)
            .map(|i| (u[i] / sqm[i]).norm())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        Ok((0..n).map(|i| u[i] / sqm[i] * (amp / vmax)).collect())
    }
}
