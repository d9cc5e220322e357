//! Time integration of a [`Membrane`]: explicit Euler, symplectic Euler,
//! position Verlet as Sudhamani & Merriliance (2019) write it, implicit Euler
//! with Newton-Raphson and a sparse LU, and position-based dynamics with
//! compliance (XPBD).
//!
//! This file holds the settings ([`DynOptions`]), the errors ([`DynError`]),
//! the run's record ([`DynRun`]) and the driver [`Dynamics::run`]: the step
//! policy, the sub-steps, the watch and the samples. The pieces:
//!
//! * `explicit_euler`, `symplectic_euler`, `verlet`, `implicit_euler`,
//!   `xpbd`: one integrator each, behind one trait (one step of `h`);
//! * `damping`: the springs' small-strain stiffness and the dashpots
//!   ([`DampingLaw`], [`reference_edge_stiffness`], [`edge_damping`]);
//! * `step_limit`: the stable step of the explicit integrators, estimated by
//!   power iteration ([`Dynamics::estimate_step`], [`StepEstimate`]) and
//!   measured ([`measure_step_limit`]).
//!
//! Masses are lumped: one third of `rho t |T0|` of every triangle to each of
//! its vertices ([`Membrane::masses`]). Loads (pressure, nodal loads) are
//! applied as a step at `t = 0` on a membrane at rest.
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

use nalgebra::{Point3, Vector3};

use super::SimError;
use super::mesh::Mesh;
use super::par::ParForces;
use super::solve::load_norm;
use super::springs::{Membrane, SpringModel};

mod damping;
mod explicit_euler;
mod implicit_euler;
mod step_limit;
mod symplectic_euler;
mod verlet;
mod xpbd;

#[cfg(test)]
mod tests;

pub use damping::{DEFAULT_DAMPING, DampingLaw, edge_damping, reference_edge_stiffness};
pub use implicit_euler::IMPLICIT_HALVINGS;
pub use step_limit::{StepEstimate, measure_step_limit};

use explicit_euler::ExplicitEuler;
use implicit_euler::ImplicitEuler;
use symplectic_euler::SymplecticEuler;
use verlet::Verlet;
use xpbd::Xpbd;

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Integrator {
    /// `x += h v; v += h a(x, v)` (both from the old state).
    ExplicitEuler,
    /// `v += h a(x, v); x += h v` (semi-implicit, symplectic when undamped).
    SymplecticEuler,
    /// Position Verlet as Sudhamani & Merriliance (2019) write it:
    /// `q += v h/2; F = f(q); v += F/m h; q += v h/2`.
    Verlet,
    /// Backward Euler, Newton-Raphson on the positions with a sparse LU.
    ImplicitEuler,
    /// Position-based dynamics with compliance (XPBD; Sudhamani & Merriliance
    /// 2019, section 1.4).
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

/// Most (sub-)steps one run may take.
const MAX_STEPS: usize = 50_000_000;

/// The refusal of a run that would need more than [`MAX_STEPS`] sub-steps
/// (`at_s`: the time at which a re-estimate of the step asked for them).
fn too_many_substeps(
    opts: &DynOptions,
    substeps: usize,
    steps: usize,
    at_s: Option<f64>,
) -> DynError {
    let when = at_s.map_or(String::new(), |t| {
        format!("at t = {t:.4e} s the stable step fell: ")
    });
    DynError::BadParameter(format!(
        "{when}the end time {} s needs {} sub-steps of {:.3e} s (the stable limit of {}); at most 5e7 are allowed: shorten the run, coarsen the mesh or use implicit-euler",
        opts.t_end_s,
        substeps.saturating_mul(steps),
        opts.dt_s / substeps as f64,
        opts.integrator.name()
    ))
}

fn limit_text(dt_crit_s: &f64) -> String {
    if dt_crit_s.is_finite() {
        format!("Its estimated step limit at the start was {dt_crit_s:.3e} s")
    } else {
        "It has no stability limit, but a step this large outruns its Newton solve".to_string()
    }
}

fn divergence_hint(integrator: &str, h_s: &f64, dt_crit_s: &f64) -> &'static str {
    if integrator == "explicit-euler" && h_s <= dt_crit_s {
        ", but explicit Euler also amplifies every slow mode its dashpots leave undamped (|1 + h lambda| > 1 for an undamped oscillation; a bubble's transverse modes are carried by tension, not by the springs' stretch): use symplectic-euler, verlet or implicit-euler"
    } else if dt_crit_s.is_finite() {
        "; use a smaller time step or implicit-euler"
    } else {
        ": use a smaller time step"
    }
}

/// What one step of an integrator cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct StepCost {
    /// Force evaluations.
    force_evaluations: usize,
    /// Newton iterations (implicit Euler).
    newton_iterations: usize,
}

impl StepCost {
    /// A step that evaluated the forces `n` times and did no Newton iteration.
    fn forces(n: usize) -> StepCost {
        StepCost {
            force_evaluations: n,
            newton_iterations: 0,
        }
    }
}

/// One time step of an integrator. An integrator owns its buffers (forces,
/// workspaces); the system, its masses and dashpots are `d`'s.
trait Step {
    /// Advances positions `x` and velocities `v` by `h` from time `t`.
    fn step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        t: f64,
    ) -> Result<StepCost, DynError>;
}

/// Share of the step limit used when sub-stepping, with damping.
pub const STEP_SAFETY: f64 = 0.9;
/// Share of the step limit used without damping (the stiffest mode's damping
/// ratio below [`UNDAMPED_ZETA`]): `h w_max = 1` at the estimate. Undamped,
/// Verlet has nonlinear resonances below its linear limit `h w = 2`, the
/// strongest at `h w = sqrt(3)` and `sqrt(2)` (Schlick, Mandziuk, Skeel and
/// Srinivas 1998, doi:10.1006/jcph.1998.5879), and the stiffest frequency
/// rises as the membrane inflates: on the latex disc at 5 kPa, 0.6 of the
/// limit estimated at rest let the energy error grow to 42 % over 0.4 s
/// (4 rings), 0.5 keeps it bounded at 4 to 32 rings.
pub const STEP_SAFETY_UNDAMPED: f64 = 0.5;
/// Share of the limit re-estimated along a run above which the step is split
/// again, with damping.
pub const STEP_RESPLIT: f64 = 0.95;
/// The same without damping: `h w = 1.2` at most, 15 % below Verlet's
/// resonance at `h w = sqrt(2)`.
pub const STEP_RESPLIT_UNDAMPED: f64 = 0.6;
/// Re-estimates of the stable step along a sub-stepped explicit run.
pub const RECHECKS: usize = 25;
/// Below this damping ratio of the stiffest mode a run counts as undamped.
pub const UNDAMPED_ZETA: f64 = 0.05;

/// The least damping (fraction of critical) at which TP MSS's dynamics are
/// trusted: its forces are not conservative (see
/// [`non_conservative_warning`]); on the paper's latex disc at 5 kPa a run
/// diverged at 0.001 and held at 0.003.
pub const TP_MIN_DAMPING: f64 = 0.01;

/// A warning when TP MSS runs with less damping than [`TP_MIN_DAMPING`]:
/// its forces are not the gradient of an energy (its stiffness matrix is not
/// symmetric, 3.8 % on the paper's inflated latex disc), so the undamped
/// system can flutter and diverge whatever the step.
pub fn non_conservative_warning(model: SpringModel, damping: DampingLaw) -> Option<String> {
    let tp = matches!(model, SpringModel::Tp | SpringModel::TpPaper);
    match damping {
        DampingLaw::Critical(z) if tp && z < TP_MIN_DAMPING => Some(format!(
            "TP MSS's forces are not conservative (its stiffness is not symmetric: 3.8 % on the paper's inflated latex disc), so with damping {z} < {TP_MIN_DAMPING} its dynamics can flutter and diverge at any time step"
        )),
        _ => None,
    }
}

/// Errors of a dynamic run.
#[derive(Debug, Clone, thiserror::Error)]
pub enum DynError {
    /// A setting out of range.
    #[error("{0}")]
    BadParameter(String),
    /// An explicit step above the stability limit, with the refuse policy.
    #[error(
        "the time step {dt_s:.4e} s is above the stable step of {integrator} for this mesh, {dt_crit_s:.4e} s (stiffest mode {omega_rad_s:.4e} rad/s, its damping ratio {zeta:.3}); use a step of {suggest_s:.3e} s or smaller, or let bulge sub-step (the substep policy)"
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
        "explicit Euler is unstable at every step without damping (its amplification sqrt(1 + (w h)^2) exceeds 1 for every mode); give a damping above 0 or use symplectic-euler, verlet or implicit-euler"
    )]
    NoStableStep,
    /// The watch fired.
    #[error(
        "{integrator} diverged at t = {t_s:.4e} s (step {step}, sub-step {h_s:.3e} s): {what}. {}{}. No result was written for this run",
        limit_text(.dt_crit_s),
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
        "implicit Euler: Newton did not converge at t = {t_s:.4e} s ({reason}); use a smaller time step (the step is {dt_s:.3e} s)"
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
    /// The last step estimate: at the start, or at the last re-estimate along
    /// the run (`None` for implicit Euler and XPBD unless asked for).
    pub estimate: Option<StepEstimate>,
    /// How often the step was re-estimated along the run.
    pub rechecks: usize,
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
                "damping {z} must be a fraction of critical damping >= 0 (e.g. 0.1)"
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

    /// The membrane's nodal forces at `x` (in parallel on large meshes).
    fn forces(&self, x: &[Point3<f64>], f: &mut [Vector3<f64>]) -> Result<(), SimError> {
        match &self.par {
            Some(p) => p.borrow_mut().forces(self.membrane, x, f),
            None => self.membrane.forces(x, f),
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
                "the time step {} s must be positive",
                opts.dt_s
            )));
        }
        if !(opts.t_end_s.is_finite() && opts.t_end_s > 0.0) {
            return Err(DynError::BadParameter(format!(
                "the end time {} s must be positive",
                opts.t_end_s
            )));
        }
        let steps = (opts.t_end_s / opts.dt_s).round().max(1.0) as usize;
        if steps > MAX_STEPS {
            return Err(DynError::BadParameter(format!(
                "the end time {} s over the time step {} s is {steps} steps; at most 5e7 are allowed",
                opts.t_end_s, opts.dt_s
            )));
        }
        let integ = opts.integrator;
        if integ == Integrator::Xpbd {
            xpbd::check(self)?;
        }
        let mut estimate = None;
        let mut substeps = 1;
        let mut dt_crit = f64::INFINITY;
        let mut mode = None;
        if integ.is_explicit() && opts.policy != StepPolicy::Unchecked {
            let (est, u) = self.estimate_step_from(x, None)?;
            mode = Some(u);
            dt_crit = est.limit(integ);
            estimate = Some(est);
            if integ == Integrator::ExplicitEuler && (dt_crit.is_nan() || dt_crit <= 0.0) {
                return Err(DynError::NoStableStep);
            }
            let safe = est.safety() * dt_crit;
            match opts.policy {
                StepPolicy::Substep if opts.dt_s > safe => {
                    substeps = (opts.dt_s / safe).ceil() as usize
                }
                // Refused: exactly the steps above the limit it prints.
                StepPolicy::Refuse if opts.dt_s > dt_crit => {
                    return Err(DynError::StepTooLarge {
                        integrator: integ.name(),
                        dt_s: opts.dt_s,
                        dt_crit_s: dt_crit,
                        omega_rad_s: est.omega_max,
                        zeta: est.zeta,
                        suggest_s: safe,
                    });
                }
                _ => {}
            }
            if substeps.saturating_mul(steps) > MAX_STEPS {
                return Err(too_many_substeps(opts, substeps, steps, None));
            }
        }
        let mut h = opts.dt_s / substeps as f64;
        // Under the substep policy the step is re-estimated along the run
        // (the power iteration warm-started from the last stiffest mode), a
        // few dozen times: the stiffest frequency rises as a membrane
        // inflates, and a step safe at rest may not stay so.
        let recheck = (opts.policy == StepPolicy::Substep && dt_crit.is_finite())
            .then(|| steps.div_ceil(RECHECKS).max(1));
        let mut rechecks = 0usize;
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
        let mut stepper: Box<dyn Step> = match integ {
            Integrator::ExplicitEuler => Box::new(ExplicitEuler::new(n)),
            Integrator::SymplecticEuler => Box::new(SymplecticEuler::new(n)),
            Integrator::Verlet => Box::new(Verlet::new(n, self.damping.iter().any(|&c| c > 0.0))),
            Integrator::ImplicitEuler => Box::new(ImplicitEuler::new(self, opts)),
            Integrator::Xpbd => Box::new(Xpbd::new(x, self.mesh.edges.len(), opts.xpbd_iterations)),
        };
        let mut steps_done = steps;
        for step in 0..steps {
            if let Some(every) = recheck
                && step > 0
                && step % every == 0
            {
                let (est, u) = self.estimate_step_from(x, mode.as_deref())?;
                mode = Some(u);
                rechecks += 1;
                evals += 2 * est.iterations;
                let lim = est.limit(integ);
                if lim.is_finite() && lim > 0.0 && h > est.resplit() * lim {
                    let more = (opts.dt_s / (est.safety() * lim)).ceil() as usize;
                    if more.saturating_mul(steps) > MAX_STEPS {
                        let at_s = step as f64 * opts.dt_s;
                        return Err(too_many_substeps(opts, more, steps, Some(at_s)));
                    }
                    substeps = more.max(substeps);
                    h = opts.dt_s / substeps as f64;
                }
                dt_crit = dt_crit.min(lim);
                estimate = Some(est);
            }
            for sub in 0..substeps {
                let t = step as f64 * opts.dt_s + sub as f64 * h;
                let cost = stepper.step(self, x, v, h, t)?;
                evals += cost.force_evaluations;
                newton_its += cost.newton_iterations;
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
            rechecks,
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
}
