//! Sudhamani & Merriliance's (2019) three experiments on the sheet: time
//! against points, the largest stable step per integrator, and deformation
//! against load.

use std::time::Instant;

use bulge::sim::dynamics::{DynError, Dynamics, Integrator, measure_step_limit};

use super::{SheetSetup, displacement, from_rest, static_solution, verlet_step};

/// Largest mesh of the time table run with implicit Euler (its Newton steps
/// at Verlet's step cost minutes above this).
pub const IMPLICIT_TIME_TABLE_MAX: usize = 1000;

/// One row of the time-against-points table.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeRow {
    /// Nodes.
    pub points: usize,
    /// Integrator.
    pub integrator: Integrator,
    /// Step asked for, s (each integrator's 0.9 of the Verlet limit).
    pub dt_s: f64,
    /// Sub-steps per step.
    pub substeps: usize,
    /// Force evaluations.
    pub evaluations: usize,
    /// Wall time, s.
    pub wall_s: f64,
    /// Loaded node's displacement at the end, m.
    pub displacement_m: f64,
    /// Static displacement, m.
    pub static_m: f64,
}

/// Sudhamani & Merriliance's Table 2.2.1: time to simulate `t_end_s` of the sheet loaded at its
/// middle with `q` N/m, for each number of points and integrator. The step is
/// the same for all integrators, 0.9 of Verlet's estimated limit; explicit
/// Euler sub-steps to its own limit; implicit Euler takes it as is.
pub fn time_table(
    setup: &SheetSetup,
    points: &[usize],
    integrators: &[Integrator],
    q_n_m: f64,
    t_end_s: f64,
) -> Result<Vec<TimeRow>, DynError> {
    let mut rows = Vec::new();
    for &np in points {
        let mesh = setup.mesh(np);
        let node = mesh.probe("middle").expect("probe");
        let mut mem = setup.membrane(&mesh, "middle", q_n_m);
        let xs = static_solution(&mut mem, &mesh, 2)?;
        let static_m = displacement(&mesh, &xs, node);
        let dt = verlet_step(setup, &mut mem, &mesh)?;
        for &integ in integrators {
            if integ == Integrator::ImplicitEuler && np > IMPLICIT_TIME_TABLE_MAX {
                continue;
            }
            let t0 = Instant::now();
            let run = from_rest(setup, &mut mem, &mesh, node, integ, dt, t_end_s, 100)?;
            let wall = t0.elapsed().as_secs_f64();
            rows.push(TimeRow {
                points: mesh.nodes.len(),
                integrator: integ,
                dt_s: dt,
                substeps: run.substeps,
                evaluations: run.force_evaluations,
                wall_s: wall,
                displacement_m: run.last(),
                static_m,
            });
        }
    }
    Ok(rows)
}

/// One row of the step-limit table.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRow {
    /// Integrator.
    pub integrator: Integrator,
    /// Estimated limit, s (infinite: none).
    pub estimate_s: f64,
    /// Measured limit by bisection, s (`None`: stable at the largest step tried).
    pub measured_s: Option<f64>,
    /// Largest step tried, s.
    pub tried_s: f64,
    /// Stiffest angular frequency, rad/s; its damping ratio; Gershgorin bound.
    pub omega: [f64; 3],
}

/// Sudhamani & Merriliance's Table 2.2.2: the largest stable step per integrator on the sheet of
/// `points` nodes loaded at the middle with `q` N/m, at its static
/// equilibrium: estimated (power iteration and the amplification
/// polynomials) and measured (bisection to 1 %, `steps` steps from the
/// equilibrium with a velocity along the stiffest mode; stable when the
/// kinetic energy has not grown).
pub fn step_table(
    setup: &SheetSetup,
    points: usize,
    q_n_m: f64,
    steps: usize,
    integrators: &[Integrator],
) -> Result<Vec<StepRow>, DynError> {
    let mesh = setup.mesh(points);
    let mut mem = setup.membrane(&mesh, "middle", q_n_m);
    let xs = static_solution(&mut mem, &mesh, 2)?;
    let mut d = Dynamics::new(&mut mem, &mesh, setup.damping)?;
    let est = d.estimate_step(&xs)?;
    let mut rows = Vec::new();
    for &integ in integrators {
        let e = est.limit(integ);
        let (lo, hi) = if e.is_finite() {
            (0.2 * e, 3.0 * e)
        } else {
            // unconditionally stable ones: try up to 1000 Verlet limits
            let v = est.limit(Integrator::Verlet);
            (v, 1000.0 * v)
        };
        // the unconditionally stable ones: a check at 1000 Verlet limits over
        // fewer steps (each is a Newton solve or a constraint sweep)
        let n_steps = if e.is_finite() { steps } else { steps.min(200) };
        let measured = measure_step_limit(&mut d, &xs, integ, lo, hi, n_steps, 0.01)?;
        rows.push(StepRow {
            integrator: integ,
            estimate_s: e,
            measured_s: measured,
            tried_s: hi,
            omega: [est.omega_max, est.zeta, est.omega_gershgorin],
        });
    }
    Ok(rows)
}

/// One row of the deformation-against-load table.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadRow {
    /// Load, N/m.
    pub q_n_m: f64,
    /// Static displacement of the loaded node, m.
    pub static_m: f64,
    /// Per integrator: displacement at `t_end`, m.
    pub dynamic_m: Vec<(Integrator, f64)>,
}

/// Sudhamani & Merriliance's Table 2.2.3: displacement of the loaded node against the load, static
/// and after `t_end_s` of each integrator from rest (same step for all,
/// 0.9 of Verlet's limit; explicit Euler sub-steps). The "deformation error"
/// is the distance from the static answer.
pub fn load_table(
    setup: &SheetSetup,
    points: usize,
    at: &str,
    loads: &[f64],
    integrators: &[Integrator],
    t_end_s: f64,
) -> Result<Vec<LoadRow>, DynError> {
    let mesh = setup.mesh(points);
    let node = mesh.probe(at).expect("probe");
    let mut rows = Vec::new();
    for &q in loads {
        let mut mem = setup.membrane(&mesh, at, q);
        let xs = static_solution(&mut mem, &mesh, 4)?;
        let static_m = if q == 0.0 {
            0.0
        } else {
            displacement(&mesh, &xs, node)
        };
        let dt = verlet_step(setup, &mut mem, &mesh)?;
        let mut dynamic = Vec::new();
        for &integ in integrators {
            if integ == Integrator::ImplicitEuler && points > IMPLICIT_TIME_TABLE_MAX {
                continue;
            }
            let run = from_rest(setup, &mut mem, &mesh, node, integ, dt, t_end_s, 10)?;
            dynamic.push((integ, run.last()));
        }
        rows.push(LoadRow {
            q_n_m: q,
            static_m,
            dynamic_m: dynamic,
        });
    }
    Ok(rows)
}
