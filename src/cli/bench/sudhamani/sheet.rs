//! The sheet of Sudhamani & Merriliance's experiments ([`SheetSetup`]) and
//! its static reference: what the tables and the tests of the sheet share.
//! It uses the library only, so that the tests (`tests/sheet_dynamics.rs`)
//! run on it outside the binary.

use nalgebra::{Point3, Vector3};

use bulge::material::{Material, Model};
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use bulge::sim::mesh::{self, Mesh, SheetOptions};
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

/// 0.9 of Verlet's estimated step limit on the sheet at rest.
pub fn verlet_step(setup: &SheetSetup, mem: &mut Membrane, mesh: &Mesh) -> Result<f64, DynError> {
    let d = Dynamics::new(mem, mesh, setup.damping)?;
    Ok(0.9 * d.estimate_step(&mesh.nodes)?.limit(Integrator::Verlet))
}

/// A run of `integ` from rest for `t_end_s` at step `dt` (sub-stepped where
/// the integrator needs it), sampling the displacement of `node`.
#[allow(clippy::too_many_arguments)]
pub fn from_rest(
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

/// Displacement magnitude of node `node`.
pub fn displacement(mesh: &Mesh, x: &[Point3<f64>], node: usize) -> f64 {
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
