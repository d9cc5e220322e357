//! The cases of `bulge bench`: every static solver and integrator on the
//! disc bubble and on Sudhamani & Merriliance's sheet, at each mesh size and
//! tolerance.

use nalgebra::Point3;

use super::runs::{Entry, disc_reference, disc_static_run, dynamic_run, static_run};
use super::sudhamani::{self, SheetSetup};
use super::{DISC_P, T};
use bulge::sim::dynamics::{DampingLaw, Integrator};
use bulge::sim::solve::Solver;
use bulge::sim::springs::{Membrane, SpringModel};

/// Step of each integrator, as a multiple of its own estimated limit (of
/// symplectic Euler's for the implicit ones).
fn step_factor(integ: Integrator) -> f64 {
    match integ {
        Integrator::Xpbd => 10.0,
        Integrator::ImplicitEuler => 30.0,
        _ => 0.9,
    }
}

/// Every run of the bench (`quick`: small meshes, one tolerance).
pub fn run_bench(quick: bool) -> anyhow::Result<Vec<Entry>> {
    let tols: &[f64] = if quick { &[1e-3] } else { &[1e-3, 1e-6] };
    let pb = crate::cli::progress(0, "bench");
    let mut out = Vec::new();
    disc_runs(quick, tols, &mut out, &|| pb.tick())?;
    sheet_runs(quick, tols, &mut out, &|| pb.tick())?;
    pb.finish_and_clear();
    Ok(out)
}

/// The disc bubble: error of the apex height against the axisymmetric
/// solution.
fn disc_runs(
    quick: bool,
    tols: &[f64],
    out: &mut Vec<Entry>,
    tick: &dyn Fn(),
) -> anyhow::Result<()> {
    let (_, mat) = sudhamani::bubble_disc(2);
    let href = disc_reference(&mat)?;
    let rings: &[usize] = if quick { &[3, 5] } else { &[4, 8, 16, 32] };
    let dyn_rings: &[usize] = if quick { &[3] } else { &[4, 8] };
    for &n in rings {
        let (mesh, _) = sudhamani::bubble_disc(n);
        let nodes = mesh.nodes.len();
        for &model in &[
            SpringModel::Tp,
            SpringModel::VanGelder,
            SpringModel::Membrane,
        ] {
            for solver in [Solver::Newton, Solver::Dr] {
                if solver == Solver::Dr && n > 16 {
                    continue;
                }
                for &tol in tols {
                    let r = disc_static_run(&mesh, model, &mat, solver, tol)?;
                    out.push(r.entry("disc", solver.name(), model, nodes, tol, href));
                    tick();
                }
            }
        }
        if !dyn_rings.contains(&n) {
            continue;
        }
        let measure = |x: &[Point3<f64>]| x[0].z;
        for integ in Integrator::ALL {
            let model = match integ {
                Integrator::Xpbd => SpringModel::VanGelder,
                _ => SpringModel::Tp,
            };
            for &tol in tols {
                let mut mem = Membrane::new(&mesh, model, &mat, T, 1100.0)?;
                mem.pressure_pa = DISC_P;
                let r = dynamic_run(
                    &mut mem,
                    &mesh,
                    integ,
                    step_factor(integ),
                    DampingLaw::Critical(1.0),
                    tol,
                    0.5,
                    &measure,
                );
                out.push(r.entry("disc", integ.name(), model, nodes, tol, href));
                tick();
            }
        }
    }
    Ok(())
}

/// Sudhamani & Merriliance's (2019) sheet, loaded at the middle with 10 N/m:
/// error of the loaded node's displacement against Newton at 1e-10 on the
/// same mesh.
fn sheet_runs(
    quick: bool,
    tols: &[f64],
    out: &mut Vec<Entry>,
    tick: &dyn Fn(),
) -> anyhow::Result<()> {
    let setup = SheetSetup::default();
    let points: &[usize] = if quick { &[60] } else { &[200, 1000] };
    let dyn_points: usize = if quick { 60 } else { 200 };
    for &np in points {
        let mesh = setup.mesh(np);
        let nodes = mesh.nodes.len();
        let node = mesh.probe("middle").expect("sheet probe");
        let measure = |x: &[Point3<f64>]| (x[node] - mesh.nodes[node]).norm();
        let mut mem = setup.membrane(&mesh, "middle", 10.0);
        let xs = sudhamani::static_solution(&mut mem, &mesh, 2)?;
        let uref = measure(&xs);
        for solver in [Solver::Newton, Solver::Dr] {
            for &tol in tols {
                let mut m = setup.membrane(&mesh, "middle", 10.0);
                let r = static_run(&mut m, &mesh, solver, tol, &measure);
                out.push(r.entry("sheet", solver.name(), setup.model, nodes, tol, uref));
                tick();
            }
        }
        if nodes > 2 * dyn_points {
            continue;
        }
        for integ in Integrator::ALL {
            for &tol in tols {
                let mut m = setup.membrane(&mesh, "middle", 10.0);
                let r = dynamic_run(
                    &mut m,
                    &mesh,
                    integ,
                    step_factor(integ),
                    DampingLaw::Critical(1.0),
                    tol,
                    60.0,
                    &measure,
                );
                out.push(r.entry("sheet", integ.name(), setup.model, nodes, tol, uref));
                tick();
            }
        }
    }
    Ok(())
}
