//! A scene's membrane loaded pressure by pressure: the one pressure sweep
//! behind `bulge simulate`, `bulge run` and `bulge bench`.
//!
//! A [`SceneSolver`] owns everything a sweep needs (scene, mesh, membrane,
//! current positions, Newton workspace and the first-guess predictor), so a
//! caller only names the pressures. [`DiscSolver`] is its name for the
//! clamped disc of a bubble-inflation test, built from the specimen:
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
use std::time::Instant;

use super::mesh::Mesh;
use super::scene::{DiscPredictor, MeshSize, Scene, SceneKind, WindowPredictor};
use super::solve::{self, NewtonWorkspace, Options, Predictor, Solver, Stats, Stay};
use super::springs::{Membrane, SpringModel};
use crate::experiment::Specimen;
use crate::material::Material;

/// A membrane scene (disc, sphere segment, sheet) under uniform pressure and
/// its nodal loads, solved by continuation from the last equilibrium (see
/// [`solve::continuation`]).
pub struct SceneSolver {
    scene: Scene,
    mesh: Mesh,
    membrane: Membrane,
    x: Vec<Point3<f64>>,
    apex: usize,
    pressure_pa: f64,
    solver: Solver,
    options: Options,
    predictor: Box<dyn Predictor + Send + Sync>,
    workspace: Option<NewtonWorkspace>,
}

/// The clamped disc of a bubble-inflation test: a [`SceneSolver`] built
/// from the specimen ([`SceneSolver::new`]).
pub type DiscSolver = SceneSolver;

/// One pressure of a sweep ([`SceneSolver::sweep`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPoint {
    /// Index of the pressure in the list swept.
    pub index: usize,
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// The scene's height (the apex above the clamp plane for a disc), m.
    pub height_m: f64,
    /// The scene's other measures ([`Scene::extra_columns`]).
    pub extra: Vec<f64>,
    /// What the solve did.
    pub stats: Stats,
    /// Wall time of this pressure, s.
    pub wall_s: f64,
}

/// The pressure at which a sweep stopped, and why.
#[derive(Debug, Clone)]
pub struct SweepStop {
    /// Index of the pressure in the list swept.
    pub index: usize,
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Why no equilibrium was found.
    pub error: SimError,
    /// Wall time spent on it, s.
    pub wall_s: f64,
}

impl SceneSolver {
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
        scene
            .validate(false)
            .map_err(|e| SimError::BadParameter(e.to_string()))?;
        let mesh = scene.build_mesh_for(&[model])?;
        Self::on_mesh(&scene, mesh, model)
    }

    /// The scene on a mesh already built for it (so that several spring
    /// models can share one mesh). A disc starts from Hencky's profile, the
    /// other scenes from the last equilibrium.
    pub fn on_mesh(scene: &Scene, mesh: Mesh, model: SpringModel) -> Result<Self, SimError> {
        let membrane = scene.membrane(&mesh, model)?;
        let predictor: Box<dyn Predictor + Send + Sync> = match scene.kind {
            SceneKind::Disc { radius_m, .. } => Box::new(DiscPredictor {
                radius_m,
                young_pa: membrane.law.young(1.0).1,
                thickness_m: scene.thickness_m,
                poisson: scene.material.poisson,
            }),
            SceneKind::Ellipse { semi_axes_m } => Box::new(WindowPredictor {
                half_m: semi_axes_m,
                rectangle: false,
                young_pa: membrane.law.young(1.0).1,
                thickness_m: scene.thickness_m,
                poisson: scene.material.poisson,
            }),
            SceneKind::Rectangle { length_m, width_m } => Box::new(WindowPredictor {
                half_m: [length_m / 2.0, width_m / 2.0],
                rectangle: true,
                young_pa: membrane.law.young(1.0).1,
                thickness_m: scene.thickness_m,
                poisson: scene.material.poisson,
            }),
            _ => Box::new(Stay),
        };
        let apex = mesh.probe("apex").unwrap_or_else(|| nearest_to_axis(&mesh));
        Ok(SceneSolver {
            scene: scene.clone(),
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
    /// (halving the increment where a step fails). On error the membrane
    /// stays at the last equilibrium reached.
    pub fn solve_to(&mut self, pressure_pa: f64) -> Result<Stats, SimError> {
        let nodal_only = pressure_pa == 0.0 && !self.membrane.node_loads.is_empty();
        if !pressure_pa.is_finite() || (pressure_pa <= 0.0 && !nodal_only) {
            return Err(SimError::BadParameter(format!(
                "pressure {pressure_pa} Pa: give a positive, finite pressure"
            )));
        }
        let last = self.x.clone();
        let first = self.continue_to(pressure_pa, self.solver);
        // Under a positive pressure the membrane inflates: an equilibrium
        // with the apex below the reference's is the dome turned inside out,
        // which solves the same equations (a slack membrane's dome, or a
        // first guess below it, leads Newton there). Dynamic relaxation
        // from the last equilibrium follows the load instead; a slack
        // reference that Newton cannot continue is relaxed too.
        let slack = self.mesh.nodes[self.apex].z > 1e-9 * self.scale_m();
        let accept = match &first {
            Ok(_) => nodal_only || self.inflated(),
            Err(SimError::NoEquilibrium { .. }) => !(slack && self.solver == Solver::Newton),
            Err(_) => true,
        };
        let stats = if accept {
            first?
        } else {
            self.x.copy_from_slice(&last);
            let relaxed = self.continue_to(pressure_pa, Solver::Dr);
            match relaxed {
                Ok(s) if self.inflated() => Stats { relaxed: true, ..s },
                Ok(_) => {
                    let apex_m = self.apex_height_m();
                    self.x.copy_from_slice(&last);
                    return Err(SimError::WrongBranch {
                        pressure_pa,
                        apex_m,
                        reference_m: self.mesh.nodes[self.apex].z,
                    });
                }
                // Newton's own failure names the first cause.
                Err(e) => return Err(first.err().unwrap_or(e)),
            }
        };
        self.pressure_pa = pressure_pa;
        Ok(stats)
    }

    /// [`solve::continuation`] from the last equilibrium with `solver`.
    fn continue_to(&mut self, pressure_pa: f64, solver: Solver) -> Result<Stats, SimError> {
        solve::continuation(
            &mut self.membrane,
            &self.mesh.nodes,
            &mut self.x,
            self.pressure_pa,
            pressure_pa,
            solver,
            &self.options,
            self.predictor.as_ref(),
            &mut self.workspace,
        )
    }

    /// Whether the apex stands at or above its reference height (to a
    /// millionth of the scene's size): the inflated equilibrium.
    fn inflated(&self) -> bool {
        let rest = self.mesh.nodes[self.apex].z;
        self.x[self.apex].z >= rest - 1e-6 * self.scale_m()
    }

    /// The scene's size, m: the largest distance of a reference node from
    /// the apex's axis.
    fn scale_m(&self) -> f64 {
        self.mesh
            .nodes
            .iter()
            .map(|p| p.x.hypot(p.y))
            .fold(0.0, f64::max)
    }

    /// Solves at each pressure in turn (increasing), calling `each` after
    /// every equilibrium; stops at the first pressure without one and says
    /// which (the pressures after it are not tried: each continues from the
    /// last).
    pub fn sweep(
        &mut self,
        pressures_pa: &[f64],
        mut each: impl FnMut(&SceneSolver, &SweepPoint),
    ) -> Result<Vec<SweepPoint>, (Vec<SweepPoint>, SweepStop)> {
        let mut done = Vec::with_capacity(pressures_pa.len());
        for (index, &p) in pressures_pa.iter().enumerate() {
            let t0 = Instant::now();
            match self.solve_to(p) {
                Ok(stats) => {
                    let (height_m, extra) = self.measure();
                    let point = SweepPoint {
                        index,
                        pressure_pa: p,
                        height_m,
                        extra,
                        stats,
                        wall_s: t0.elapsed().as_secs_f64(),
                    };
                    each(self, &point);
                    done.push(point);
                }
                Err(error) => {
                    let stop = SweepStop {
                        index,
                        pressure_pa: p,
                        error,
                        wall_s: t0.elapsed().as_secs_f64(),
                    };
                    return Err((done, stop));
                }
            }
        }
        Ok(done)
    }

    /// Height of the apex above the clamp plane, m (for a disc; for other
    /// scenes the node nearest the axis of the reference mesh).
    pub fn apex_height_m(&self) -> f64 {
        self.x[self.apex].z
    }

    /// The scene's height and other measures at the current equilibrium
    /// ([`Scene::measure`]).
    pub fn measure(&self) -> (f64, Vec<f64>) {
        self.scene.measure(&self.mesh, &self.x)
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
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

/// A disc mesh sized by an a-posteriori estimate of its height error.
#[derive(Debug, Clone)]
pub struct SizedMesh {
    /// The mesh to use (the finer of the last pair).
    pub mesh: Mesh,
    /// Its rings.
    pub rings: usize,
    /// Estimated largest relative height error of that mesh against the
    /// mesh-converged heights, over the models and pressures.
    pub estimated_error: f64,
    /// The coarser mesh of the pair, rings.
    pub coarse_rings: usize,
}

/// Convergence order of the disc's apex height in the rings, measured for
/// every spring model (`C n^-1.7`, docs/simulate.md).
const DISC_ORDER: f64 = 1.7;

/// Sizes the disc mesh of `scene` until the estimated relative height error
/// of every model in `models` at every pressure of `pressures_pa` is at most
/// `target`: the sweep is solved on `n` and about `1.5 n` rings, the error of
/// the finer taken by Richardson's estimate `|h_fine - h_coarse| / (r^p - 1)`
/// with `r` the ratio of the rings and `p = 1.7` the measured order, and `n`
/// raised until it meets the target (at most `max_nodes` nodes). The
/// a-priori rule [`super::scene::disc_rings_for_accuracy`] gives the first
/// `n`. A pressure without equilibrium on either mesh is left out of the
/// estimate (the sweep stops there on the final mesh too).
pub fn mesh_for_accuracy(
    scene: &Scene,
    models: &[SpringModel],
    solver: Solver,
    options: Options,
    target: f64,
    max_nodes: usize,
) -> Result<SizedMesh, SimError> {
    let SceneKind::Disc {
        radius_m,
        dome_height_m,
    } = scene.kind
    else {
        return Err(SimError::BadParameter(format!(
            "a mesh sized by its estimated error is made for the disc, not a {}",
            scene.kind.name()
        )));
    };
    if !(target.is_finite() && target > 0.0 && target < 0.5) {
        return Err(SimError::BadParameter(format!(
            "accuracy {target} must be a relative error in (0, 0.5), e.g. 0.005"
        )));
    }
    let sector = scene.mesh.symmetry;
    let nodes = |n: usize| {
        if sector {
            (n + 1) * (n + 2) / 2
        } else {
            1 + 3 * n * (n + 1)
        }
    };
    let build = |n: usize| super::scene::disc_mesh(radius_m, dome_height_m, n, sector);
    let heights = |mesh: &Mesh, model: SpringModel| -> Result<Vec<f64>, SimError> {
        let mut s =
            SceneSolver::on_mesh(scene, mesh.clone(), model)?.with_solver(solver, options)?;
        Ok(match s.sweep(&scene.pressures_pa, |_, _| {}) {
            Ok(done) => done.iter().map(|q| q.height_m).collect(),
            Err((done, _)) => done.iter().map(|q| q.height_m).collect(),
        })
    };
    let mut n = super::scene::disc_rings_for_accuracy(target, models).max(3);
    for _ in 0..8 {
        let fine = ((n as f64) * 1.5).ceil() as usize;
        if nodes(fine) > max_nodes {
            return Err(SimError::BadParameter(format!(
                "the accuracy {target} needs more than {} rings ({} nodes), above the node limit of {max_nodes}: ask for a looser accuracy or raise the limit",
                fine,
                nodes(fine)
            )));
        }
        let (cm, fm) = (build(n)?, build(fine)?);
        let ratio = fine as f64 / n as f64;
        let mut err: f64 = 0.0;
        for &m in models {
            let (hc, hf) = (heights(&cm, m)?, heights(&fm, m)?);
            for (c, f) in hc.iter().zip(&hf) {
                if *f != 0.0 {
                    err = err.max((f - c).abs() / f.abs() / (ratio.powf(DISC_ORDER) - 1.0));
                }
            }
        }
        if err <= target {
            return Ok(SizedMesh {
                mesh: fm,
                rings: fine,
                estimated_error: err,
                coarse_rings: n,
            });
        }
        // the error of `fine` scales as fine^-p: aim at 0.8 of the target
        let grow = (err / (0.8 * target)).powf(1.0 / DISC_ORDER);
        n = ((fine as f64) * grow / 1.5).ceil().max(n as f64 + 1.0) as usize;
    }
    Err(SimError::BadParameter(format!(
        "the disc mesh did not reach the accuracy {target} in eight refinements (last: {n} rings); the heights may not converge near a limit point: ask for a looser accuracy or pressures further from it"
    )))
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

    /// A slack membrane (a stress-free dome of 0.1 a) at 50 Pa: every spring
    /// and membrane model, by Newton and by dynamic relaxation, stands on
    /// the inflated branch, above the dome, within 1 % of the exact
    /// axisymmetric height where the shooting resolves it, and within 10
    /// micrometres of the dome for a law so stiff that the strains are of
    /// order 1e-5. (From Hencky's first guess, which lies under a stiff
    /// law's dome, Newton had reached the dome turned inside out.)
    #[test]
    fn a_slack_dome_is_solved_inflated_not_inside_out() {
        let spec = Specimen {
            prebulge_height_m: 0.1 * 0.0375,
            ..latex()
        };
        let h0 = spec.prebulge_height_m;
        let neo = Material {
            model: crate::material::Model::NeoHookean { c1_pa: 0.2e6 },
            poisson: 0.45,
            fit: None,
        };
        let laws = [
            (neo, true),
            (Material::linear(1.0e7, 0.45), true),
            (Material::linear(1.0e9, 0.45), false),
        ];
        for (mat, exact) in laws {
            let reference = exact.then(|| {
                crate::axisym::solve_pressure(&mat, &spec, 50.0, &Default::default())
                    .unwrap()
                    .height_m
            });
            for model in [
                SpringModel::Tp,
                SpringModel::VanGelder,
                SpringModel::Lloyd,
                SpringModel::Membrane,
            ] {
                for solver in [Solver::Newton, Solver::Dr] {
                    let mut disc = DiscSolver::new(&spec, &mat, model)
                        .unwrap()
                        .with_solver(solver, Options::default())
                        .unwrap();
                    disc.solve_to(50.0).unwrap();
                    let h = disc.apex_height_m();
                    let what = format!("{} {model:?} {solver:?}", mat.model.name());
                    assert!(h > h0, "{what}: apex {h} m below the dome {h0} m");
                    match reference {
                        Some(r) => {
                            // Van Gelder's and Lloyd's springs are stiffer
                            // than the law by their known few per cent.
                            let tol = if matches!(model, SpringModel::Tp | SpringModel::Membrane) {
                                0.01
                            } else {
                                0.05
                            };
                            assert!((h / r - 1.0).abs() < tol, "{what}: {h} against exact {r}");
                        }
                        None => assert!(h < h0 + 1e-5, "{what}: {h} m"),
                    }
                }
            }
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

    /// `--accuracy` is kept near the limit point: a neo-Hookean disc
    /// (C1 0.2 MPa; limit 7016 Pa) at 90 % of its limit pressure, sized for
    /// 0.5 %, is within 0.5 % of the mesh-converged height of the same model
    /// (the a-priori rule alone picks 15 nodes here and is 4.5 % off).
    #[test]
    fn accuracy_is_kept_near_the_limit_point() {
        let spec = latex();
        let nh = Material {
            model: crate::material::Model::NeoHookean { c1_pa: 2.0e5 },
            poisson: 0.45,
            fit: None,
        };
        let scene = Scene::from_specimen(&spec, nh.clone(), vec![3000.0, 6300.0]);
        let sized = mesh_for_accuracy(
            &scene,
            &[SpringModel::Tp],
            Solver::Newton,
            Options::default(),
            0.005,
            100_000,
        )
        .unwrap();
        let mut coarse = SceneSolver::on_mesh(&scene, sized.mesh.clone(), SpringModel::Tp).unwrap();
        let mut fine =
            DiscSolver::with_mesh(&spec, &nh, SpringModel::Tp, Some(MeshSize::Nodes(1900)))
                .unwrap();
        for p in [3000.0, 6300.0] {
            coarse.solve_to(p).unwrap();
            fine.solve_to(p).unwrap();
            let err = coarse.apex_height_m() / fine.apex_height_m() - 1.0;
            assert!(
                err.abs() < 0.005,
                "{p} Pa: {err:+.4} on {} rings",
                sized.rings
            );
        }
        assert!(sized.estimated_error <= 0.005);
    }

    /// A mesh above the node limit is refused before it is built.
    #[test]
    fn meshes_above_the_node_limit_are_refused() {
        let spec = latex();
        let mat = Material::linear(1.0e6, spec.poisson);
        for size in [
            MeshSize::Nodes(10_000_000),
            MeshSize::EdgeLength(1e-9),
            MeshSize::Accuracy(1e-12),
        ] {
            let e = DiscSolver::with_mesh(&spec, &mat, SpringModel::Tp, Some(size))
                .err()
                .unwrap();
            assert!(e.to_string().contains("node limit"), "{size:?}: {e}");
        }
    }

    /// A slack specimen's disc is meshed on its dome whichever way the mesh
    /// is sized: the pole at `h0`, the rim on the clamp plane.
    #[test]
    fn a_domed_disc_is_meshed_on_its_dome() {
        let spec = Specimen {
            prebulge_height_m: 0.00375,
            ..Specimen::latex()
        };
        let m = Material::linear(1.0e6, 0.45);
        let mut scene = Scene::from_specimen(&spec, m, vec![5000.0]);
        let by_rings = scene.build_mesh().unwrap();
        scene.mesh.size = Some(crate::sim::scene::MeshSize::Accuracy(0.01));
        let sized = mesh_for_accuracy(
            &scene,
            &[SpringModel::Tp],
            Solver::Newton,
            Options::default(),
            0.01,
            10_000,
        )
        .unwrap()
        .mesh;
        for mesh in [by_rings, sized] {
            let top = mesh.nodes.iter().map(|p| p.z).fold(f64::MIN, f64::max);
            assert!((top - 0.00375).abs() < 1e-12, "pole at {top}");
            let rim: Vec<_> = mesh
                .nodes
                .iter()
                .filter(|p| (p.x.hypot(p.y) - 0.0375).abs() < 1e-9)
                .collect();
            assert!(!rim.is_empty() && rim.iter().all(|p| p.z.abs() < 1e-12));
        }
    }
}
