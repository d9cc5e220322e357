//! The sheet of Sudhamani & Merriliance's experiments (the harness of
//! `bulge bench --sudhamani-merriliance`): the step limits against their
//! estimates, implicit Euler's large steps, and the hard cases (a stiff
//! material with a large step, obtuse and sliver triangles, compression).
//!
//! R. Sudhamani, K. Merriliance, mesh-based simulation with a mass-spring
//! model using Euler and Verlet integration, 2019 (see the README's
//! references); the paper's tables are reproduced by the bench, not here.

// The harness, as the binary builds it (it uses the library only).
#[allow(dead_code)]
#[path = "../src/cli/bench/sudhamani/sheet.rs"]
mod sheet;
#[allow(dead_code)]
#[path = "../src/cli/bench/sudhamani/tables.rs"]
mod tables;
use sheet::*;

use bulge::sim::Constraint;
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use bulge::sim::hard::{compressed_springs, mesh_warnings};
use bulge::sim::mesh::Mesh;
use bulge::sim::solve::{self, Options};
use bulge::sim::springs::{Membrane, SpringModel};
use nalgebra::Vector3;
use tables::step_table;
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

/// Hard case: a stiff material with a large step. E = 1 GPa on the Sudhamani & Merriliance
/// sheet: Verlet at 20 times its limit sub-steps and lands on the same
/// answer as at its limit; with the refuse policy the message gives the
/// limit; unchecked, the watch stops it before any NaN.
#[test]
fn stiff_material_large_step() {
    let setup = SheetSetup {
        young_pa: 1.0e9,
        ..SheetSetup::default()
    };
    let mesh = setup.mesh(60);
    let node = mesh.probe("middle").unwrap();
    let mut mem = setup.membrane(&mesh, "middle", 1.0e5);
    let limit = {
        let d = Dynamics::new(&mut mem, &mesh, setup.damping).unwrap();
        d.estimate_step(&mesh.nodes)
            .unwrap()
            .limit(Integrator::Verlet)
    };
    let run = |mem: &mut Membrane, dt: f64, policy: StepPolicy| {
        let mut d = Dynamics::new(mem, &mesh, setup.damping).unwrap();
        let mut x = mesh.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let opts = DynOptions {
            integrator: Integrator::Verlet,
            dt_s: dt,
            t_end_s: 200.0 * limit,
            policy,
            ..DynOptions::default()
        };
        d.run(&mut x, &mut v, &opts, &|x| {
            (x[node] - mesh.nodes[node]).norm()
        })
    };
    let big = run(&mut mem, 20.0 * limit, StepPolicy::Substep).unwrap();
    assert!(big.substeps >= 22, "{}", big.substeps);
    let small = run(&mut mem, 0.5 * limit, StepPolicy::Substep).unwrap();
    assert_eq!(small.substeps, 1);
    // same time grid at the outputs: the sub-stepped run is the same run at h = dt/substeps
    assert!(big.samples.iter().all(|s| s.value_m.is_finite()));
    let e = run(&mut mem, 20.0 * limit, StepPolicy::Refuse).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, DynError::StepTooLarge { .. }), "{msg}");
    assert!(msg.contains(&format!("{limit:.4e}")), "{msg}");
    let e = run(&mut mem, 3.0 * limit, StepPolicy::Unchecked).unwrap_err();
    assert!(matches!(e, DynError::Diverged { .. }), "{e}");
}

/// Hard case: obtuse and sliver triangles. The Sudhamani & Merriliance sheet (at 3.5 kPa) with every
/// other column of nodes pulled to 0.1 of the spacing from its left
/// neighbour (angles down to about 6 deg and up to about 160 deg). tp
/// stays within 15 % of the regular mesh (13 % stiffer) and a Verlet run at its estimated step is
/// stable (the estimate falls with the small masses); Van Gelder's eq 1
/// gives the sides opposite the obtuse angles a negative stiffness, the
/// lattice has no stable equilibrium, Newton stops with NoEquilibrium and
/// [`mesh_warnings`] names the cause.
#[test]
fn obtuse_and_sliver_triangles() {
    let setup = SheetSetup {
        young_pa: 3500.0,
        ..SheetSetup::default()
    };
    let regular = setup.mesh(200);
    let mut nodes = regular.nodes.clone();
    let xs: Vec<f64> = {
        let mut v: Vec<f64> = nodes.iter().map(|p| p.x).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        v
    };
    let hx = xs[1] - xs[0];
    for p in nodes.iter_mut() {
        let c = (p.x / hx).round() as usize;
        if c % 2 == 1 {
            p.x -= 0.9 * hx;
        }
    }
    let mut bad = Mesh::new(
        nodes,
        regular.triangles.clone(),
        regular.constraints.clone(),
    )
    .unwrap();
    bad.probes = regular.probes.clone();
    bad.hold_in_plane();
    let q = bad.quality();
    assert!(
        q.non_acute_share > 0.3 && q.min_angle_deg < 15.0 && q.max_angle_deg > 140.0,
        "{q:?}"
    );
    let node = regular.probe("middle").unwrap();
    // tp: a correct result
    let s = SheetSetup {
        model: SpringModel::Tp,
        ..setup
    };
    let mut good = s.membrane(&regular, "middle", 10.0);
    let xg = static_solution(&mut good, &regular, 2).unwrap();
    let mut m = s.membrane(&bad, "middle", 10.0);
    let xb = static_solution(&mut m, &bad, 2).unwrap();
    let (ug, ub) = (
        (xg[node] - regular.nodes[node]).norm(),
        (xb[node] - bad.nodes[node]).norm(),
    );
    // measured: 13 % stiffer than the regular mesh
    assert!((ub - ug).abs() < 0.15 * ug, "tp: {ub} vs regular {ug}");
    let lim_g = Dynamics::new(&mut good, &regular, s.damping)
        .unwrap()
        .estimate_step(&regular.nodes)
        .unwrap()
        .limit(Integrator::Verlet);
    let mut d = Dynamics::new(&mut m, &bad, s.damping).unwrap();
    let lim_b = d
        .estimate_step(&bad.nodes)
        .unwrap()
        .limit(Integrator::Verlet);
    assert!(lim_b < lim_g, "{lim_b} vs {lim_g}");
    let mut x = bad.nodes.clone();
    let mut v = vec![Vector3::zeros(); x.len()];
    let opts = DynOptions {
        integrator: Integrator::Verlet,
        dt_s: 0.9 * lim_b,
        t_end_s: 300.0 * lim_b,
        ..DynOptions::default()
    };
    let r = d.run(&mut x, &mut v, &opts, &|x| x[node].y).unwrap();
    assert!(r.samples.iter().all(|s| s.value_m.is_finite()));
    let w = mesh_warnings(&bad, SpringModel::Tp, &s.material(), s.thickness_m);
    assert!(w.iter().any(|w| w.contains("acute")), "{w:?}");
    // Van Gelder: a clear message
    let s = SheetSetup {
        model: SpringModel::VanGelder,
        ..setup
    };
    let mut m = s.membrane(&bad, "middle", 10.0);
    let e = static_solution(&mut m, &bad, 2).unwrap_err();
    assert!(e.to_string().contains("no equilibrium"), "{e}");
    let w = mesh_warnings(&bad, SpringModel::VanGelder, &s.material(), s.thickness_m);
    assert!(w.iter().any(|w| w.contains("negative stiffness")), "{w:?}");
    assert!(
        mesh_warnings(
            &regular,
            SpringModel::VanGelder,
            &s.material(),
            s.thickness_m
        )
        .iter()
        .all(|w| !w.contains("negative"))
    );
}

/// Hard case: compression. In the plane, the springs carry compression
/// like a 2D plate (a real membrane would wrinkle): pushing the free edge
/// gives the tension's displacement mirrored at small load, and the
/// compressed springs are counted. Free out of its plane, a flat sheet
/// has no stiffness there: Newton stops with a clear error, no NaN.
#[test]
fn compression() {
    let setup = SheetSetup::default();
    let mesh = setup.mesh(120);
    let node = mesh.probe("middle").unwrap();
    let load = |fx: f64| {
        let mut m = setup.membrane(&mesh, "middle", 0.0);
        m.node_loads = vec![(node, Vector3::new(fx, 0.0, 0.0))];
        m
    };
    let f = 0.01 * setup.thickness_m;
    let mut mt = load(f);
    let xt = static_solution(&mut mt, &mesh, 1).unwrap();
    let mut mc = load(-f);
    let xc = static_solution(&mut mc, &mesh, 1).unwrap();
    let (ut, uc) = (
        xt[node].x - mesh.nodes[node].x,
        xc[node].x - mesh.nodes[node].x,
    );
    assert!(
        ut > 0.0 && uc < 0.0 && (ut + uc).abs() < 0.02 * ut,
        "{ut} {uc}"
    );
    let (count, min) = compressed_springs(&mesh, &xc);
    assert!(count > 0 && min < 0.0);
    // free out of plane
    let mut free = mesh.clone();
    for c in free.constraints.iter_mut() {
        if *c != Constraint::Fixed {
            *c = Constraint::Free;
        }
    }
    let mut m = setup.membrane(&free, "middle", 0.0);
    m.node_loads = vec![(node, Vector3::new(-f, 0.0, 0.0))];
    let mut x = free.nodes.clone();
    match solve::newton(&mut m, &mut x, 0.0, &Options::default()) {
        Err(e) => assert!(e.to_string().contains("equilibrium"), "{e}"),
        Ok(_) => {
            // if it converges, it converged to the in-plane answer
            assert!(x.iter().all(|p| p.z.abs() < 1e-9 && p.x.is_finite()));
        }
    }
}
