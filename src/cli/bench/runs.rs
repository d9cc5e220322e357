//! One measured run of `bulge bench`: a static solve or a dynamic run from
//! rest, timed, and its error against a reference ([`Entry`]).

use std::time::Instant;

use anyhow::anyhow;
use nalgebra::{Point3, Vector3};

use super::DISC_P;
use super::sudhamani::bubble_specimen;
use bulge::material::Material;
use bulge::sim::SceneSolver;
use bulge::sim::dynamics::{DampingLaw, DynOptions, Dynamics, Integrator};
use bulge::sim::mesh::Mesh;
use bulge::sim::scene::Scene;
use bulge::sim::solve::{self, Options, Solver};
use bulge::sim::springs::{Membrane, SpringModel};

/// One measured run.
#[derive(Debug, Clone)]
pub struct Entry {
    pub case: &'static str,
    pub method: String,
    pub model: SpringModel,
    pub nodes: usize,
    pub tolerance: f64,
    pub wall_s: f64,
    pub steps: usize,
    pub error: Option<f64>,
    pub status: String,
}

/// What a run measured: wall time, steps (iterations for a static solve),
/// the measured value (`None`: there is none), and a note (`ok`, why the
/// value is not the settled one, or why there is none).
pub struct Measured {
    wall_s: f64,
    steps: usize,
    value: Option<f64>,
    note: String,
}

impl Measured {
    /// The entry of this run for the table, its error relative to `reference`.
    pub fn entry(
        self,
        case: &'static str,
        method: &str,
        model: SpringModel,
        nodes: usize,
        tolerance: f64,
        reference: f64,
    ) -> Entry {
        let (error, status) = match self.value {
            Some(v) => (Some(((v - reference) / reference).abs()), self.note),
            None => (None, self.note),
        };
        Entry {
            case,
            method: method.to_string(),
            model,
            nodes,
            tolerance,
            wall_s: self.wall_s,
            steps: self.steps,
            error,
            status,
        }
    }
}

/// The apex height of the disc bubble at [`DISC_P`] by the axisymmetric
/// solution.
pub fn disc_reference(mat: &Material) -> anyhow::Result<f64> {
    let sol = bulge::axisym::solve_pressure(
        mat,
        &bubble_specimen(),
        DISC_P,
        &bulge::axisym::Options::default(),
    )
    .map_err(|e| anyhow!("axisymmetric reference: {e}"))?;
    Ok(sol.height_m)
}

/// A static solve of the disc bubble at [`DISC_P`] from rest by the
/// library's disc solver (Hencky's profile as the first guess), measuring
/// the apex height. Only the solve is timed.
pub fn disc_static_run(
    mesh: &Mesh,
    model: SpringModel,
    mat: &Material,
    solver: Solver,
    tol: f64,
) -> anyhow::Result<Measured> {
    let scene = Scene::from_specimen(&bubble_specimen(), mat.clone(), vec![]);
    let opts = Options {
        tolerance: tol,
        ..Options::default()
    };
    let mut disc = SceneSolver::on_mesh(&scene, mesh.clone(), model)?.with_solver(solver, opts)?;
    let t0 = Instant::now();
    let out = disc.solve_to(DISC_P);
    let wall_s = t0.elapsed().as_secs_f64();
    Ok(match out {
        Ok(s) => Measured {
            wall_s,
            steps: s.iterations,
            value: Some(disc.apex_height_m()),
            note: "ok".into(),
        },
        Err(e) => Measured {
            wall_s,
            steps: 0,
            value: None,
            note: e.to_string(),
        },
    })
}

/// A static solve of a loaded membrane (nodal loads, its own pressure) from
/// rest, each continuation step starting from the last equilibrium.
pub fn static_run(
    mem: &mut Membrane,
    mesh: &Mesh,
    solver: Solver,
    tol: f64,
    measure: &dyn Fn(&[Point3<f64>]) -> f64,
) -> Measured {
    let mut x = mesh.nodes.clone();
    let opts = Options {
        tolerance: tol,
        ..Options::default()
    };
    let mut ws = None;
    let t0 = Instant::now();
    let p = mem.pressure_pa;
    let out = solve::continuation(
        mem,
        &mesh.nodes,
        &mut x,
        0.0,
        p,
        solver,
        &opts,
        &solve::Stay,
        &mut ws,
    );
    let wall_s = t0.elapsed().as_secs_f64();
    match out {
        Ok(s) => Measured {
            wall_s,
            steps: s.iterations,
            value: Some(measure(&x)),
            note: "ok".into(),
        },
        Err(e) => Measured {
            wall_s,
            steps: 0,
            value: None,
            note: e.to_string(),
        },
    }
}

/// A dynamic run from rest with `integ` at `step_factor` of its estimated
/// step limit (of symplectic Euler's for the implicit integrators) until the motion settles to `tol` or `t_cap` s.
#[allow(clippy::too_many_arguments)]
pub fn dynamic_run(
    mem: &mut Membrane,
    mesh: &Mesh,
    integ: Integrator,
    step_factor: f64,
    damping: DampingLaw,
    tol: f64,
    t_cap: f64,
    measure: &dyn Fn(&[Point3<f64>]) -> f64,
) -> Measured {
    let t0 = Instant::now();
    let out = (|| -> anyhow::Result<(f64, usize, bool, f64)> {
        let mut d = Dynamics::new(mem, mesh, damping)?;
        let est = d.estimate_step(&mesh.nodes)?;
        // explicit integrators at a share of their own limit; the implicit
        // ones at multiples of symplectic Euler's (the conservative one)
        let dt = if integ.is_explicit() {
            step_factor * est.limit(integ)
        } else {
            step_factor * est.limit(Integrator::SymplecticEuler)
        };
        // XPBD's projections are serial and it settles to its own (compliant,
        // under-iterated) state: at most 3000 steps
        let t_cap = if integ == Integrator::Xpbd {
            t_cap.min(3000.0 * dt)
        } else {
            t_cap
        };
        let steps = (t_cap / dt).ceil();
        let opts = DynOptions {
            integrator: integ,
            dt_s: dt,
            t_end_s: t_cap,
            damping,
            settle_tolerance: Some(tol),
            max_samples: ((steps / 20.0) as usize).clamp(10, 1_000_000),
            ..DynOptions::default()
        };
        let mut x = mesh.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let run = d.run(&mut x, &mut v, &opts, measure)?;
        let settled = (run.steps as f64) < steps - 0.5;
        Ok((measure(&x), run.steps * run.substeps, settled, t_cap))
    })();
    let wall_s = t0.elapsed().as_secs_f64();
    let (steps, value, note) = match out {
        Ok((v, steps, true, _)) => (steps, Some(v), "ok".into()),
        Ok((v, steps, false, t)) => (
            steps,
            Some(v),
            format!("not settled to the tolerance by t = {t:.3e} s (error at that time)"),
        ),
        Err(e) => (0, None, format!("{e:#}")),
    };
    Measured {
        wall_s,
        steps,
        value,
        note,
    }
}
