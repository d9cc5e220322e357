//! Tests of the sheet experiments: the step limits and implicit Euler's
//! large steps; the hard cases (stiff material, bad triangles, compression)
//! in [`hard`].

use nalgebra::Vector3;

use super::tables::step_table;
use super::{SheetSetup, displacement, static_solution};
use bulge::sim::dynamics::{DampingLaw, DynOptions, Dynamics, Integrator};

mod hard;

/// The measured step limits agree with the estimates within 20 % on a
/// small sheet (the docs table uses 1000 points).
#[test]
fn step_limits_agree_with_estimates() {
    let setup = SheetSetup::default();
    let rows = step_table(
        &setup,
        120,
        10.0,
        1500,
        &[
            Integrator::ExplicitEuler,
            Integrator::SymplecticEuler,
            Integrator::Verlet,
        ],
    )
    .unwrap();
    for r in &rows {
        let m = r.measured_s.expect("explicit integrators have a limit");
        let ratio = m / r.estimate_s;
        assert!(
            (0.8..1.2).contains(&ratio),
            "{:?}: measured {m:e} vs estimate {:e}",
            r.integrator,
            r.estimate_s
        );
    }
    // Verlet allows a much larger step than explicit Euler at 0.1 critical damping
    assert!(rows[2].estimate_s > 3.0 * rows[0].estimate_s);
}

/// Implicit Euler is stable at 100 Verlet limits; the loaded sheet settles
/// to the static answer.
#[test]
fn implicit_euler_is_stable_at_large_steps_and_settles() {
    let setup = SheetSetup::default();
    let mesh = setup.mesh(80);
    let node = mesh.probe("middle").unwrap();
    let mut mem = setup.membrane(&mesh, "middle", 5.0);
    let xs = static_solution(&mut mem, &mesh, 2).unwrap();
    let want = displacement(&mesh, &xs, node);
    let mut d = Dynamics::new(&mut mem, &mesh, DampingLaw::Critical(1.0)).unwrap();
    let vl = d
        .estimate_step(&mesh.nodes)
        .unwrap()
        .limit(Integrator::Verlet);
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); x.len()];
    let opts = DynOptions {
        integrator: Integrator::ImplicitEuler,
        dt_s: 100.0 * vl,
        t_end_s: 20000.0 * vl,
        damping: DampingLaw::Critical(1.0),
        ..DynOptions::default()
    };
    let run = d
        .run(&mut x, &mut v, &opts, &|x| displacement(&mesh, x, node))
        .unwrap();
    let got = run.last();
    assert!((got - want).abs() < 1e-3 * want, "{got} vs static {want}");
}
