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
//!
//! * [`tables`]: the three experiments on the sheet;
//! * [`markdown`]: their tables in `paper003.md`;
//! * [`disc`]: the bubble disc and its sudden pressure step.

use nalgebra::{Point3, Vector3};

use bulge::material::{Material, Model};
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use bulge::sim::mesh::{self, Mesh, SheetOptions};
use bulge::sim::solve::{self, Options};
use bulge::sim::springs::{Membrane, SpringModel};

mod disc;
mod markdown;
mod tables;
#[cfg(test)]
mod tests;

pub use disc::{bubble_disc, bubble_specimen};
pub use markdown::markdown;

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

/// Displacement magnitude of node `node`.
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
