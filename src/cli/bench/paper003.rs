//! Sudhamani & Merriliance's (2019) experiments, with every parameter it leaves out stated, and
//! the sudden pressure step on the disc.
//!
//! 003 fixes a square mesh on its left edge and loads it "at the middle" or
//! "at the corner" with forces in N/m, and reports the computation time
//! against the number of points (200-4000), the time step of explicit Euler,
//! implicit Euler and Verlet, and a "deformation error" against the force
//! (0-10 N/m). It gives no size, modulus, thickness, density, damping, step,
//! simulated time or tolerance. bulge's choices ([`SheetSetup::default`]):
//!
//! * a square of 0.1 m, thickness 1 mm, E = 50 kPa, nu = 0.45, density
//!   1060 kg/m^3 (soft tissue), Van Gelder springs (Sudhamani & Merriliance's springs are linear;
//!   Van Gelder's eq 1 sets their stiffness from E and nu). Sudhamani & Merriliance's liver
//!   modulus, 3.5 kPa, moves the loaded node 21-24 mm under 10 N/m at 200
//!   points (more than three mesh spacings): the point load then inverts
//!   triangles on fine meshes and the spring lattice has several equilibria
//!   (Newton and dynamic relaxation found two 4 % apart at 1000 points).
//!   50 kPa keeps the largest load's displacement near one spacing;
//! * the load is in the plane of the sheet, along -y, on the node at the
//!   middle (or the corner) of the free edge x = L. Its N/m is read as the 2D
//!   convention of a plane model: force per unit thickness, so the nodal force
//!   is `q t` and the displacement scales as `q / E` (10 N/m / 3.5 kPa =
//!   2.9 mm at 3.5 kPa, the size of Sudhamani & Merriliance's "errors"). The nodes are held in the plane
//!   z = 0 (a flat membrane has no stiffness out of its plane);
//! * damping: 0.1 of each spring's critical value;
//! * the static reference: Newton (sparse LU) to a residual of 1e-10 of the
//!   load.

use std::time::Instant;

use nalgebra::{Point3, Vector3};

use bulge::material::{Material, Model};
use bulge::sim::dynamics::{
    DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy, measure_step_limit,
};
use bulge::sim::mesh::{self, DiscOptions, Mesh, SheetOptions};
use bulge::sim::solve::{self, Options};
use bulge::sim::springs::{Membrane, SpringModel};

/// The sheet of Sudhamani & Merriliance's experiments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetSetup {
    /// Side of the square, m.
    pub side_m: f64,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Young's modulus, Pa.
    pub young_pa: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// Density, kg/m^3.
    pub density_kg_m3: f64,
    /// Spring model.
    pub model: SpringModel,
    /// Damping.
    pub damping: DampingLaw,
}

impl Default for SheetSetup {
    fn default() -> Self {
        SheetSetup {
            side_m: 0.1,
            thickness_m: 1e-3,
            young_pa: 50_000.0,
            poisson: 0.45,
            density_kg_m3: 1060.0,
            model: SpringModel::VanGelder,
            damping: DampingLaw::Critical(0.1),
        }
    }
}

impl SheetSetup {
    /// The material.
    pub fn material(&self) -> Material {
        Material {
            model: Model::Linear {
                young_pa: self.young_pa,
            },
            poisson: self.poisson,
            fit: None,
        }
    }

    /// The in-plane sheet mesh with about `points` nodes.
    pub fn mesh(&self, points: usize) -> Mesh {
        let s = self.side_m;
        let h = (s * s * 2.0 / (3f64.sqrt() * points as f64)).sqrt();
        let mut m = mesh::sheet(SheetOptions {
            length_m: s,
            width_m: s,
            edge_length_m: h,
        })
        .expect("valid sheet");
        m.hold_in_plane();
        m
    }

    /// The membrane with the load `q` (N/m, per unit thickness) at probe `at`.
    pub fn membrane(&self, mesh: &Mesh, at: &str, q_n_m: f64) -> Membrane {
        let mut mem = Membrane::new(
            mesh,
            self.model,
            &self.material(),
            self.thickness_m,
            self.density_kg_m3,
        )
        .expect("valid membrane");
        let node = mesh.probe(at).expect("sheet probes");
        mem.node_loads = vec![(node, Vector3::new(0.0, -q_n_m * self.thickness_m, 0.0))];
        mem
    }
}

/// Displacement magnitude of node `node`.
/// 0.9 of Verlet's estimated step limit on the sheet at rest.
fn verlet_step(setup: &SheetSetup, mem: &mut Membrane, mesh: &Mesh) -> Result<f64, DynError> {
    let d = Dynamics::new(mem, mesh, setup.damping)?;
    Ok(0.9 * d.estimate_step(&mesh.nodes)?.limit(Integrator::Verlet))
}

/// A run of `integ` from rest for `t_end_s` at step `dt` (sub-stepped where
/// the integrator needs it), sampling the displacement of `node`.
#[allow(clippy::too_many_arguments)]
fn from_rest(
    setup: &SheetSetup,
    mem: &mut Membrane,
    mesh: &Mesh,
    node: usize,
    integ: Integrator,
    dt: f64,
    t_end_s: f64,
    max_samples: usize,
) -> Result<bulge::sim::dynamics::DynRun, DynError> {
    let mut d = Dynamics::new(mem, mesh, setup.damping)?;
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); x.len()];
    let opts = DynOptions {
        integrator: integ,
        dt_s: dt,
        t_end_s,
        damping: setup.damping,
        policy: StepPolicy::Substep,
        max_samples,
        ..DynOptions::default()
    };
    d.run(&mut x, &mut v, &opts, &|x| displacement(mesh, x, node))
}

fn displacement(mesh: &Mesh, x: &[Point3<f64>], node: usize) -> f64 {
    (x[node] - mesh.nodes[node]).norm()
}

/// Static equilibrium by Newton, load ramped in `ramp` equal steps.
pub fn static_solution(
    mem: &mut Membrane,
    mesh: &Mesh,
    ramp: usize,
) -> Result<Vec<Point3<f64>>, DynError> {
    let loads = mem.node_loads.clone();
    let mut x = mesh.nodes.clone();
    let opts = Options {
        tolerance: 1e-10,
        ..Options::default()
    };
    let mut ws = solve::NewtonWorkspace::new(mem);
    for k in 1..=ramp {
        let s = k as f64 / ramp as f64;
        mem.node_loads = loads.iter().map(|(i, f)| (*i, f * s)).collect();
        let p = mem.pressure_pa;
        solve::newton_with(mem, &mut x, p, &opts, &mut ws)?;
    }
    mem.node_loads = loads;
    Ok(x)
}

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

/// 003 Table 2.2.1: time to simulate `t_end_s` of the sheet loaded at its
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

/// 003 Table 2.2.2: the largest stable step per integrator on the sheet of
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

/// 003 Table 2.2.3: displacement of the loaded node against the load, static
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

/// The disc of Tudruj et al.'s (2023) bubble test (a = 37.5 mm, t = 0.35 mm, linear
/// E = 1 MPa, nu = 0.45, rho = 1100 kg/m^3), 60 degree sector of `rings`.
pub fn bubble_disc(rings: usize) -> (Mesh, Material) {
    let m = mesh::disc(DiscOptions {
        radius_m: 0.0375,
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
    let mut mem = Membrane::new(&mesh, model, &mat, 0.35e-3, 1100.0)?;
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

/// Static apex height of the bubble disc at `p` (Newton, from Hencky's guess).
pub fn disc_static(rings: usize, model: SpringModel, p: f64) -> Result<f64, DynError> {
    let (mesh, mat) = bubble_disc(rings);
    let mut mem = Membrane::new(&mesh, model, &mat, 0.35e-3, 1100.0)?;
    let mut x = mesh.nodes.clone();
    let pred = bulge::sim::scene::DiscPredictor {
        radius_m: 0.0375,
        young_pa: 1.0e6,
        thickness_m: 0.35e-3,
        poisson: 0.45,
    };
    let mut ws = None;
    solve::continuation(
        &mut mem,
        &mesh.nodes,
        &mut x,
        0.0,
        p,
        solve::Solver::Newton,
        &Options {
            tolerance: 1e-10,
            ..Options::default()
        },
        &pred,
        &mut ws,
    )?;
    Ok(x[0].z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bulge::sim::Constraint;
    use bulge::sim::hard::{compressed_springs, mesh_warnings};

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

    /// Hard case: a stiff material with a large step. E = 1 GPa on the 003
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

    /// Hard case: obtuse and sliver triangles. The 003 sheet (at 3.5 kPa) with every
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
}
