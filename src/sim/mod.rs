//! Material -> membrane: meshes, spring models, loads and solvers.
//!
//! The pieces are plain data and functions on them, so that the dynamic
//! integrators reuse the same force evaluation:
//!
//! * [`mesh`]: [`Mesh`] (reference nodes, triangles, edges, per-node
//!   [`Constraint`]) and the scene meshes (disc, sphere segment, sheet);
//! * [`springs`]: [`Membrane`], the spring model (TP MSS, Van Gelder, Lloyd)
//!   with the modulus law of the material, or the constant-strain triangle
//!   membrane with the material's whole law ([`cst`]), follower pressure and
//!   nodal loads: [`Membrane::forces`] and its tangent stiffness for Newton;
//! * [`solve`]: quasi-static solution per pressure (Newton with a sparse LU,
//!   dynamic relaxation with kinetic damping), continued from one pressure to
//!   the next;
//! * [`disc`]: [`DiscSolver`], the bubble-test disc swept over pressures;
//! * [`scene`]: the scene file and the quantities reported (apex height,
//!   sphere radii);
//! * [`vtk`]: deformed meshes for ParaView.
//!
//! The bubble-test disc in a few lines ([`DiscSolver`]):
//!
//! ```
//! use bulge::{DiscSolver, Material, Specimen, SpringModel};
//!
//! let latex = Specimen { radius_m: 0.0375, thickness_m: 0.35e-3, poisson: 0.45, prebulge_height_m: 0.0 };
//! let mut disc = DiscSolver::new(&latex, &Material::linear(1.0e6, 0.45), SpringModel::Tp)?;
//! let stats = disc.solve_to(5000.0)?;
//! assert!(disc.apex_height_m() > 0.015 && disc.apex_height_m() < 0.03 && stats.residual < 1e-8);
//! # Ok::<(), bulge::sim::SimError>(())
//! ```

pub mod cst;
pub mod disc;
pub mod dynamics;
pub mod hard;
pub mod linear;
pub mod mesh;
pub mod par;
pub mod scene;
pub mod solve;
pub mod springs;
pub mod vtk;

pub use disc::{DiscSolver, SceneSolver, SweepPoint, SweepStop};
pub use mesh::{Constraint, Mesh};
pub use springs::{HeightModel, Membrane, SpringModel, UnknownHeightModel};

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
    /// The material law has no stress at a triangle's stretches (the
    /// membrane model).
    #[error(
        "triangle {triangle} is stretched to ({:.4}, {:.4}), where the material law has no finite stress (a collapsed triangle, or beyond the law's locking stretch); lower the pressure or check the law's parameters",
        stretches[0], stretches[1]
    )]
    OutsideLaw {
        /// Triangle index.
        triangle: usize,
        /// Its principal stretches.
        stretches: [f64; 2],
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
    #[error(
        "triangle {triangle} collapsed (zero area) during the solve at {} Pa",
        crate::io::fmt_short(*.pressure_pa)
    )]
    Collapsed {
        /// Triangle index.
        triangle: usize,
        /// Pressure, Pa.
        pressure_pa: f64,
    },
    /// The equilibrium found has the apex below the reference's under a
    /// positive pressure (the dome turned inside out), also by dynamic
    /// relaxation.
    #[error(
        "the equilibrium found at {} Pa is the dome turned inside out: its apex is at {} m, below the reference's {} m, and dynamic relaxation from the last equilibrium found no inflated one either; check the law's stiffness at small strain (a modulus near zero there lets the membrane snap through), or start from a lower pressure",
        crate::io::fmt_short(*.pressure_pa),
        crate::io::fmt_short(*.apex_m),
        crate::io::fmt_short(*.reference_m)
    )]
    WrongBranch {
        /// The pressure, Pa.
        pressure_pa: f64,
        /// The apex height found, m.
        apex_m: f64,
        /// The reference's apex height, m.
        reference_m: f64,
    },
    /// No equilibrium found at a pressure, even with load sub-steps.
    #[error(
        "no equilibrium found at {} Pa ({reason}); last equilibrium at {} Pa. A pressure above the membrane's limit point has no nearby equilibrium; otherwise raise the iteration cap or loosen the tolerance",
        crate::io::fmt_short(*.pressure_pa),
        crate::io::fmt_short(*.last_pressure_pa)
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

impl crate::Refusal for SimError {
    /// A parameter or a mesh that cannot be solved; the rest (no
    /// equilibrium, a law left) are results of valid input.
    fn is_bad_input(&self) -> bool {
        matches!(
            self,
            SimError::BadParameter(_)
                | SimError::DegenerateTriangle { .. }
                | SimError::InvertedTriangle { .. }
                | SimError::BadMesh(_)
        )
    }
}
