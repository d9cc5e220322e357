//! The clamped disc of a bubble-inflation test, inflated pressure by
//! pressure: the one pressure sweep behind `bulge simulate`, `bulge run` and
//! `bulge bench`.
//!
//! A [`DiscSolver`] owns everything a sweep needs (mesh, membrane, current
//! positions, Newton workspace and the first-guess predictor), so a caller
//! only names the pressures:
//!
//! ```
//! use bulge::{DiscSolver, Material, Specimen, SpringModel};
//!
//! let latex = Specimen { radius_m: 0.0375, thickness_m: 0.35e-3, poisson: 0.45, prebulge_height_m: 0.0 };
//! let material = Material::linear(1.0e6, 0.45);
//! let mut disc = DiscSolver::new(&latex, &material, SpringModel::Tp)?;
//! for p in [1000.0, 2000.0, 4000.0] {
//!     disc.solve_to(p)?;
//!     println!("{p} Pa: apex {:.3} mm", 1e3 * disc.apex_height_m());
//! }
//! # Ok::<(), bulge::sim::SimError>(())
//! ```

use nalgebra::Point3;

use super::SimError;
use super::mesh::Mesh;
use super::scene::{DiscPredictor, MeshSize, Scene};
use super::solve::{self, NewtonWorkspace, Options, Solver, Stats};
use super::springs::{Membrane, SpringModel};
use crate::experiment::Specimen;
use crate::material::Material;

/// A clamped circular membrane under uniform pressure, solved by
/// continuation from the last equilibrium (see [`solve::continuation`]).
pub struct DiscSolver {
    mesh: Mesh,
    membrane: Membrane,
    x: Vec<Point3<f64>>,
    apex: usize,
    pressure_pa: f64,
    solver: Solver,
    options: Options,
    predictor: DiscPredictor,
    workspace: Option<NewtonWorkspace>,
}

impl DiscSolver {
    /// The specimen's disc with the default mesh (a 60 degree sector of
    /// 16 rings: symmetry lets the sector stand for the whole disc), solved
    /// by Newton's method.
    pub fn new(spec: &Specimen, material: &Material, model: SpringModel) -> Result<Self, SimError> {
        Self::with_mesh(spec, material, model, None)
    }

    /// The specimen's disc on a mesh of the given size (`None`: the default).
    pub fn with_mesh(
        spec: &Specimen,
        material: &Material,
        model: SpringModel,
        size: Option<MeshSize>,
    ) -> Result<Self, SimError> {
        let mut scene = Scene::from_specimen(spec, material.clone(), Vec::new());
        scene.mesh.size = size;
        scene.validate(false).map_err(SimError::BadParameter)?;
        let mesh = scene.build_mesh_for(&[model])?;
        Self::on_mesh(&scene, mesh, model)
    }

    /// The disc of `scene` (a disc scene) on a mesh already built for it, so
    /// that several spring models can share one mesh.
    pub fn on_mesh(scene: &Scene, mesh: Mesh, model: SpringModel) -> Result<Self, SimError> {
        let super::scene::SceneKind::Disc { radius_m } = scene.kind else {
            return Err(SimError::BadParameter(format!(
                "a disc solver needs a disc scene, not a {}",
                scene.kind.name()
            )));
        };
        let membrane = scene.membrane(&mesh, model)?;
        let predictor = DiscPredictor {
            radius_m,
            young_pa: membrane.law.young(1.0).1,
            thickness_m: scene.thickness_m,
            poisson: scene.material.poisson,
        };
        let apex = mesh.probe("apex").unwrap_or_else(|| nearest_to_axis(&mesh));
        Ok(DiscSolver {
            x: mesh.nodes.clone(),
            mesh,
            membrane,
            apex,
            pressure_pa: 0.0,
            solver: Solver::Newton,
            options: Options::default(),
            predictor,
            workspace: None,
        })
    }

    /// Uses this quasi-static solver and these options from the next solve.
    pub fn with_solver(mut self, solver: Solver, options: Options) -> Result<Self, SimError> {
        options.validate()?;
        self.solver = solver;
        self.options = options;
        Ok(self)
    }

    /// Solves the equilibrium at `pressure_pa`, continued from the last one
    /// (halving the increment where a step fails). On error the disc stays at
    /// the last equilibrium reached.
    pub fn solve_to(&mut self, pressure_pa: f64) -> Result<Stats, SimError> {
        if !pressure_pa.is_finite() || pressure_pa <= 0.0 {
            return Err(SimError::BadParameter(format!(
                "pressure {pressure_pa} Pa: give a positive, finite pressure"
            )));
        }
        let stats = solve::continuation(
            &mut self.membrane,
            &self.mesh.nodes,
            &mut self.x,
            self.pressure_pa,
            pressure_pa,
            self.solver,
            &self.options,
            &self.predictor,
            &mut self.workspace,
        )?;
        self.pressure_pa = pressure_pa;
        Ok(stats)
    }

    /// Height of the apex above the clamp plane, m.
    pub fn apex_height_m(&self) -> f64 {
        self.x[self.apex].z
    }

    /// The pressure of the current equilibrium, Pa (0 before the first solve).
    pub fn pressure_pa(&self) -> f64 {
        self.pressure_pa
    }

    /// Node positions at the current equilibrium, m.
    pub fn positions(&self) -> &[Point3<f64>] {
        &self.x
    }

    /// The mesh (reference positions, constraints, probes).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The membrane (spring model, material law, loads).
    pub fn membrane(&self) -> &Membrane {
        &self.membrane
    }

    /// The spring model.
    pub fn model(&self) -> SpringModel {
        self.membrane.model
    }

    /// The quasi-static solver.
    pub fn solver(&self) -> Solver {
        self.solver
    }
}

/// The node closest to the disc's axis (the apex of a mesh without probes).
fn nearest_to_axis(mesh: &Mesh) -> usize {
    mesh.nodes
        .iter()
        .enumerate()
        .min_by(|a, b| {
            let ra = a.1.x * a.1.x + a.1.y * a.1.y;
            let rb = b.1.x * b.1.x + b.1.y * b.1.y;
            ra.total_cmp(&rb)
        })
        .map_or(0, |(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::scene::hencky_k;

    fn latex() -> Specimen {
        Specimen {
            radius_m: 0.0375,
            thickness_m: 0.35e-3,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        }
    }

    /// Small deflection: the apex follows Hencky's (1915) closed form
    /// `w0 = K(nu) a (p a / (E t))^(1/3)` within the mesh error of TP MSS.
    #[test]
    fn small_deflection_follows_hencky() {
        let (e, spec) = (1.0e6, latex());
        let mat = Material::linear(e, spec.poisson);
        let mut disc = DiscSolver::new(&spec, &mat, SpringModel::Tp).unwrap();
        let a = spec.radius_m;
        // w0/a = 0.02: p = (0.02 / K)^3 E t / a
        let p = (0.02 / hencky_k(spec.poisson)).powi(3) * e * spec.thickness_m / a;
        disc.solve_to(p).unwrap();
        let w0 = hencky_k(spec.poisson) * a * (p * a / (e * spec.thickness_m)).cbrt();
        let rel = disc.apex_height_m() / w0 - 1.0;
        assert!(
            rel.abs() < 0.01,
            "apex {} vs Hencky {w0}: {rel:+.4}",
            disc.apex_height_m()
        );
        assert_eq!(disc.pressure_pa(), p);
    }

    /// Continuation and a fresh solve agree; a sweep rises with pressure.
    #[test]
    fn continuation_matches_a_fresh_solve() {
        let spec = latex();
        let mat = Material::linear(1.0e6, spec.poisson);
        let mut sweep = DiscSolver::new(&spec, &mat, SpringModel::Tp).unwrap();
        let mut last = 0.0;
        for p in [500.0, 1000.0, 2000.0] {
            sweep.solve_to(p).unwrap();
            assert!(sweep.apex_height_m() > last);
            last = sweep.apex_height_m();
        }
        let mut fresh = DiscSolver::new(&spec, &mat, SpringModel::Tp).unwrap();
        fresh.solve_to(2000.0).unwrap();
        assert!((fresh.apex_height_m() - last).abs() < 1e-9 * last);
    }

    #[test]
    fn refuses_a_pressure_that_is_not_positive() {
        let spec = latex();
        let mat = Material::linear(1.0e6, spec.poisson);
        let mut disc = DiscSolver::new(&spec, &mat, SpringModel::VanGelder).unwrap();
        for p in [0.0, -1.0, f64::NAN] {
            assert!(matches!(disc.solve_to(p), Err(SimError::BadParameter(_))));
        }
    }
}
