//! The disc of Tudruj et al.'s (2023) bubble test: its static apex height and
//! its response to a sudden pressure step, with the table of that step.

use std::fmt::Write as _;
use std::time::Instant;

use nalgebra::Vector3;

use super::super::runs::disc_reference;
use super::super::{A, DISC_P, T};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator};
use bulge::sim::mesh::{self, DiscOptions, Mesh};
use bulge::sim::scene::Scene;
use bulge::sim::solve::{Options, Solver};
use bulge::sim::springs::{Membrane, SpringModel};
use bulge::sim::{SceneSolver, SimError};

/// The disc of Tudruj et al.'s (2023) bubble test (a = 37.5 mm, t = 0.35 mm, linear
/// E = 1 MPa, nu = 0.45, rho = 1100 kg/m^3), 60 degree sector of `rings`.
pub fn bubble_disc(rings: usize) -> (Mesh, Material) {
    let m = mesh::disc(DiscOptions {
        radius_m: A,
        rings,
        sector: true,
    })
    .expect("valid disc");
    (
        m,
        Material {
            model: Model::Linear { young_pa: 1.0e6 },
            poisson: 0.45,
            fit: None,
        },
    )
}

/// The sudden pressure step on the disc.
#[derive(Debug, Clone, PartialEq)]
pub struct StepResponse {
    /// Integrator.
    pub integrator: Integrator,
    /// Step, s.
    pub dt_s: f64,
    /// Peak apex height, m.
    pub peak_m: f64,
    /// Final apex height, m.
    pub final_m: f64,
    /// Overshoot `(peak - static) / static`.
    pub overshoot: f64,
    /// Time after which the height stays within 2 % of the static height, s.
    pub settling_s: f64,
    /// Wall time, s.
    pub wall_s: f64,
    /// Steps.
    pub steps: usize,
}

/// Runs the pressure step `p` on the bubble disc from rest for `t_end_s`.
#[allow(clippy::too_many_arguments)]
pub fn pressure_step(
    rings: usize,
    model: SpringModel,
    p: f64,
    integ: Integrator,
    dt_s: f64,
    t_end_s: f64,
    damping: DampingLaw,
    static_m: f64,
) -> Result<StepResponse, DynError> {
    let (mesh, mat) = bubble_disc(rings);
    let mut mem = Membrane::new(&mesh, model, &mat, T, 1100.0)?;
    mem.pressure_pa = p;
    let mut d = Dynamics::new(&mut mem, &mesh, damping)?;
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); x.len()];
    let opts = DynOptions {
        integrator: integ,
        dt_s,
        t_end_s,
        damping,
        max_samples: 4000,
        ..DynOptions::default()
    };
    let t0 = Instant::now();
    let run = d.run(&mut x, &mut v, &opts, &|x| x[0].z)?;
    let wall = t0.elapsed().as_secs_f64();
    let peak = run.peak();
    Ok(StepResponse {
        integrator: integ,
        dt_s,
        peak_m: peak,
        final_m: run.last(),
        overshoot: (peak - static_m) / static_m,
        settling_s: run.settling_time(static_m, 0.02),
        wall_s: wall,
        steps: run.steps * run.substeps,
    })
}

/// The bubble disc's specimen (a = 37.5 mm, t = 0.35 mm, nu = 0.45).
pub fn bubble_specimen() -> Specimen {
    Specimen {
        radius_m: A,
        thickness_m: T,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    }
}

/// Static apex height of the bubble disc at `p` (Newton to 1e-10, from
/// Hencky's guess: the library's disc solver).
pub fn disc_static(rings: usize, model: SpringModel, p: f64) -> Result<f64, SimError> {
    let (mesh, mat) = bubble_disc(rings);
    let scene = Scene::from_specimen(&bubble_specimen(), mat, vec![]);
    let opts = Options {
        tolerance: 1e-10,
        ..Options::default()
    };
    let mut disc = SceneSolver::on_mesh(&scene, mesh, model)?.with_solver(Solver::Newton, opts)?;
    disc.solve_to(p)?;
    Ok(disc.apex_height_m())
}

/// The table of the sudden pressure step on the disc, each integrator from
/// rest for 0.1 s.
pub fn pressure_step_table(quick: bool) -> anyhow::Result<String> {
    let mut s = String::new();
    let rings = if quick { 4 } else { 8 };
    let hs = disc_static(rings, SpringModel::Tp, DISC_P)?;
    let (mesh, mat) = bubble_disc(rings);
    let href = disc_reference(&mat)?;
    let _ = writeln!(
        s,
        "#### Sudden pressure step on the disc\n\n{DISC_P} Pa applied at t = 0 on the flat bubble disc (a = 37.5 mm, t = 0.35 mm, E = 1 MPa, nu = 0.45, rho = 1100 kg/m^3, tp, 60 degree sector of {rings} rings); static height (Newton) {:.5e} m, axisymmetric {:.5e} m. Settling: last time outside 2 % of the static height.\n\n| integrator | damping | dt_s | peak m | overshoot | settling s | final m | final / static | steps | wall s |\n|---|---|---|---|---|---|---|---|---|---|",
        hs, href
    );
    let vl = {
        let mut mem = Membrane::new(&mesh, SpringModel::Tp, &mat, T, 1100.0)?;
        mem.pressure_pa = DISC_P;
        let d = Dynamics::new(&mut mem, &mesh, DampingLaw::Critical(1.0))?;
        d.estimate_step(&mesh.nodes)?.limit(Integrator::Verlet)
    };
    for (integ, z, f) in [
        (Integrator::Verlet, 0.1, 0.9),
        (Integrator::Verlet, 1.0, 0.9),
        (Integrator::SymplecticEuler, 1.0, 0.9),
        (Integrator::ExplicitEuler, 1.0, 0.9),
        (Integrator::ImplicitEuler, 1.0, 0.9),
        (Integrator::ImplicitEuler, 1.0, 10.0),
    ] {
        let r = pressure_step(
            rings,
            SpringModel::Tp,
            DISC_P,
            integ,
            f * vl,
            0.1,
            DampingLaw::Critical(z),
            hs,
        )?;
        let _ = writeln!(
            s,
            "| {} | {z} | {:.3e} | {:.5e} | {:.3} | {:.4} | {:.5e} | {:.5} | {} | {:.3} |",
            integ.name(),
            r.dt_s,
            r.peak_m,
            r.overshoot,
            r.settling_s,
            r.final_m,
            r.final_m / hs,
            r.steps,
            r.wall_s
        );
    }
    Ok(s)
}
