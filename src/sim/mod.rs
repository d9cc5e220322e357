//! Material -> membrane: meshes, spring models, loads and solvers.
//!
//! The pieces are plain data and functions on them, so that the dynamic
//! integrators (issue 7) reuse the same force evaluation:
//!
//! * [`mesh`]: [`Mesh`] (reference nodes, triangles, edges, per-node
//!   [`Constraint`]) and the scene meshes (disc, sphere segment, sheet);
//! * [`springs`]: [`Membrane`], the spring model (TP MSS, Van Gelder, Lloyd)
//!   with the modulus law of the material, follower pressure and nodal loads:
//!   [`Membrane::forces`] and [`Membrane::tangent`];
//! * [`solve`]: quasi-static solution per pressure (Newton with a sparse LU,
//!   dynamic relaxation with kinetic damping), continued from one pressure to
//!   the next;
//! * [`scene`]: the scene file and the quantities reported (apex height,
//!   sphere radii);
//! * [`vtk`]: deformed meshes for ParaView.
//!
//! ```
//! use bulge::material::{Material, Model};
//! use bulge::sim::{mesh, scene::DiscPredictor, solve, springs::{Membrane, SpringModel}};
//!
//! let m = mesh::disc(mesh::DiscOptions { radius_m: 0.0375, rings: 6, sector: true }).unwrap();
//! let mat = Material { model: Model::Linear { young_pa: 1.0e6 }, poisson: 0.45, fit: None };
//! let mut membrane = Membrane::new(&m, SpringModel::Tp, &mat, 0.35e-3, 1100.0).unwrap();
//! // a flat membrane has no stiffness out of its plane: start from Hencky's profile
//! let guess = DiscPredictor { radius_m: 0.0375, young_pa: 1.0e6, thickness_m: 0.35e-3, poisson: 0.45 };
//! let mut x = m.nodes.clone();
//! let mut workspace = None;
//! let stats = solve::continuation(
//!     &mut membrane, &m.nodes, &mut x, 0.0, 5000.0,
//!     solve::Solver::Newton, &solve::Options::default(), &guess, &mut workspace,
//! ).unwrap();
//! assert!(x[0].z > 0.015 && x[0].z < 0.03 && stats.residual < 1e-8);
//! ```

pub mod dynamics;
pub mod hard;
pub mod mesh;
pub mod paper003;
pub mod par;
pub mod scene;
pub mod solve;
pub mod springs;
pub mod validation;
pub mod vtk;

pub use mesh::{Constraint, Mesh};
pub use springs::{Membrane, SpringModel};

/// Errors of the membrane solver.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SimError {
    /// A triangle with (nearly) zero area.
    #[error(
        "triangle {triangle} (nodes {nodes:?}) is degenerate: area {area_m2:e} m^2; remove or re-mesh it"
    )]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its nodes.
        nodes: [u32; 3],
        /// Its area, m^2.
        area_m2: f64,
    },
    /// A triangle oriented against its neighbours.
    #[error(
        "triangle {triangle} (nodes {nodes:?}) is inverted: it runs a shared edge in the same direction as its neighbour; reorder its nodes"
    )]
    InvertedTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its nodes.
        nodes: [u32; 3],
    },
    /// Any other mesh problem.
    #[error("bad mesh: {0}")]
    BadMesh(String),
    /// A material or scene parameter the models cannot take.
    #[error("{0}")]
    BadParameter(String),
    /// The modulus law gave E <= 0 (or not finite) during the solve.
    #[error(
        "the material's modulus is E({strain}) = {young_pa:e} Pa <= 0 at strain {strain:.6} (triangle {triangle}); the law cannot carry that strain: refit it over a range that includes it, or lower the pressure"
    )]
    NonPositiveModulus {
        /// Strain at which it happened.
        strain: f64,
        /// The modulus, Pa.
        young_pa: f64,
        /// Triangle index.
        triangle: usize,
    },
    /// A triangle collapsed during the solve.
    #[error("triangle {triangle} collapsed (zero area) during the solve at {pressure_pa} Pa")]
    Collapsed {
        /// Triangle index.
        triangle: usize,
        /// Pressure, Pa.
        pressure_pa: f64,
    },
    /// No equilibrium found at a pressure, even with load sub-steps.
    #[error(
        "no equilibrium found at {pressure_pa} Pa ({reason}); last equilibrium at {last_pressure_pa} Pa. A pressure above the membrane's limit point has no nearby equilibrium; otherwise raise --max-iterations or loosen --tolerance"
    )]
    NoEquilibrium {
        /// The pressure asked for, Pa.
        pressure_pa: f64,
        /// The last pressure solved, Pa.
        last_pressure_pa: f64,
        /// What happened.
        reason: String,
    },
}
