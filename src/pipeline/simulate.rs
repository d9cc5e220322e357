//! The simulate stage: the material -> simulated heights by every membrane
//! model asked for, and the rows and warnings it writes. [`simulate_scene`]
//! is the one sweep both `bulge run` and `bulge simulate` use.

use std::time::Instant;

use crate::axisym::{self, AxisymError};
use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num, fmt_short};
use crate::material::Material;
use crate::mechanics::Point;
use crate::sim::mesh::Mesh;
use crate::sim::scene::{MeshSize, Scene, SceneKind};
use crate::sim::solve::{self, Solver};
use crate::sim::springs::{HeightModel, SpringModel};
use crate::sim::{SceneSolver, SimError, SweepPoint};

use super::*;

/// How one simulated pressure came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// An equilibrium within the tolerance.
    Solved,
    /// An equilibrium found by dynamic relaxation after the chosen solver
    /// found the dome turned inside out, or no equilibrium, from the last one.
    Relaxed,
    /// An equilibrium whose residual stopped above the tolerance, at the
    /// round-off floor of double precision: the height carries a relative
    /// error of about that residual.
    AtFloor,
    /// The apex at or below the clamp plane under a positive pressure: no
    /// equilibrium to trust (a membrane near its stress-free state has no
    /// stiffness: a domed one can fold through). No height is reported.
    Folded,
    /// No equilibrium was found; a spring model's run stops here.
    Failed,
    /// Not tried: the run stopped at a lower pressure.
    NotTried,
}

impl Outcome {
    /// True when the point has a height.
    pub fn has_height(self) -> bool {
        matches!(self, Outcome::Solved | Outcome::Relaxed | Outcome::AtFloor)
    }
}

/// One simulated pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct SimPoint {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m; `None` when no equilibrium was found.
    pub height_m: Option<f64>,
    /// The scene's other measures ([`Scene::extra_columns`]); empty for the
    /// axisymmetric reference and for a point without a height.
    pub extra: Vec<f64>,
    /// Newton iterations / relaxation steps / shots.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Time of this pressure, s.
    pub wall_s: f64,
    /// How the pressure came out.
    pub outcome: Outcome,
    /// What to know about it (every outcome but [`Outcome::Solved`]).
    pub note: Option<String>,
}

/// The heights of one model at every pressure.
#[derive(Debug, Clone)]
pub struct ModelRun {
    /// The spring model, or the axisymmetric reference.
    pub model: HeightModel,
    /// `newton`, `dr` or `shooting` (a point solved by dynamic relaxation
    /// instead says so by [`Outcome::Relaxed`]).
    pub solver: String,
    /// Solved nodes (0 for the axisymmetric reference).
    pub nodes: usize,
    /// One per pressure.
    pub points: Vec<SimPoint>,
    /// Total time, s.
    pub wall_s: f64,
    /// The membrane solver's error at the pressure where a spring model's
    /// run stopped ([`Outcome::Failed`]).
    pub stop: Option<SimError>,
}

impl ModelRun {
    /// The notes of the points that have no height because something went
    /// wrong there (not those merely left untried after a stop).
    pub fn failures(&self) -> impl Iterator<Item = &str> {
        self.points
            .iter()
            .filter(|p| matches!(p.outcome, Outcome::Failed | Outcome::Folded))
            .filter_map(|p| p.note.as_deref())
    }
}

/// What to simulate on a scene ([`simulate_scene`]).
#[derive(Debug, Clone)]
pub struct SceneRequest {
    /// Spring models, each solved with every solver.
    pub models: Vec<SpringModel>,
    /// Quasi-static solvers.
    pub solvers: Vec<Solver>,
    /// The exact axisymmetric reference too (a clamped circular disc only).
    pub axisym: bool,
    /// Keep the axisymmetric solution at the last pressure solved, with its
    /// meridian profile ([`SceneRuns::axisym_last`]).
    pub profile: bool,
    /// Solver options.
    pub options: solve::Options,
}

/// The runs of [`simulate_scene`].
#[derive(Debug, Clone)]
pub struct SceneRuns {
    /// The axisymmetric reference first (when asked for), then each spring
    /// model with each solver.
    pub runs: Vec<ModelRun>,
    /// The axisymmetric solution at the last pressure it solved, when
    /// [`SceneRequest::profile`] asked for it.
    pub axisym_last: Option<axisym::Solution>,
}

/// A mesh sized for an accuracy ([`scene_mesh`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSizing {
    /// Rings of the mesh used.
    pub rings: usize,
    /// Its estimated relative height error.
    pub estimated_error: f64,
    /// Rings of the coarser mesh of the Richardson pair.
    pub coarse_rings: usize,
}

/// The scene's mesh for `models`: sized by an a-posteriori error estimate
/// when the scene asks for an accuracy (a disc), else built at its size.
pub fn scene_mesh(
    scene: &Scene,
    models: &[SpringModel],
    solver: Solver,
    options: solve::Options,
) -> Result<(Mesh, Option<MeshSizing>), PipelineError> {
    match (scene.mesh.size, scene.kind) {
        (Some(MeshSize::Accuracy(a)), SceneKind::Disc { .. }) if !models.is_empty() => {
            let s = crate::sim::disc::mesh_for_accuracy(
                scene,
                models,
                solver,
                options,
                a,
                scene.mesh.max_nodes,
            )?;
            let sizing = MeshSizing {
                rings: s.rings,
                estimated_error: s.estimated_error,
                coarse_rings: s.coarse_rings,
            };
            Ok((s.mesh, Some(sizing)))
        }
        _ => Ok((scene.build_mesh_for(models)?, None)),
    }
}

/// The entry of `bulge simulate` (quasi-static) and of the simulate stage:
/// every spring model with every solver on `mesh`, at the scene's pressures
/// in order, each continued from the last, and the exact axisymmetric
/// reference when asked for. `each` sees every spring equilibrium (for the
/// deformed meshes); `tick` is called once per model and pressure.
///
/// A pressure without equilibrium ends that model's run (the rows solved
/// are kept, the rest marked [`Outcome::NotTried`]); an apex folded through
/// the clamp plane is not reported ([`Outcome::Folded`]). The call fails
/// only when a model cannot be set up, or the axisymmetric reference is
/// asked of a scene that is not a clamped circular disc.
pub fn simulate_scene(
    scene: &Scene,
    mesh: &Mesh,
    request: &SceneRequest,
    each: &mut dyn FnMut(&SceneSolver, &SweepPoint),
    tick: &dyn Fn(),
) -> Result<SceneRuns, PipelineError> {
    let pressures = scene.pressures_to_solve();
    let mut out = SceneRuns {
        runs: Vec::new(),
        axisym_last: None,
    };
    if request.axisym {
        let SceneKind::Disc {
            radius_m,
            dome_height_m,
        } = scene.kind
        else {
            return Err(PipelineError::Input(format!(
                "the axisymmetric reference solves the clamped circular disc only; this scene is the {} ([window] or the scene's kind): simulate it with the spring models (tp) or the membrane",
                scene.kind.name()
            )));
        };
        let spec = Specimen {
            radius_m,
            thickness_m: scene.thickness_m,
            poisson: scene.material.poisson,
            prebulge_height_m: dome_height_m,
        };
        let (run, last) = axisym_points(&spec, &scene.material, &pressures, request.profile, tick)?;
        out.runs.push(run);
        out.axisym_last = last;
    }
    let opts = request.options;
    for &model in &request.models {
        for &solver in &request.solvers {
            let t_model = Instant::now();
            let mut disc =
                SceneSolver::on_mesh(scene, mesh.clone(), model)?.with_solver(solver, opts)?;
            let solved = |q: &SweepPoint| sim_point(model, solver, opts.tolerance, q);
            let swept = disc.sweep(&pressures, |s, q| {
                tick();
                each(s, q);
            });
            let (points, stop) = match swept {
                Ok(done) => (done.iter().map(solved).collect(), None),
                Err((done, stop)) => {
                    let mut points: Vec<SimPoint> = done.iter().map(solved).collect();
                    let mut note = format!(
                        "{} at {} Pa: {}",
                        model.name(),
                        stop.pressure_pa,
                        stop.error
                    );
                    // the disc's limit pressure from the axisymmetric solution
                    if let SceneKind::Disc { radius_m, .. } = scene.kind
                        && let Some(limit) = crate::sim::hard::limit_note(
                            &scene.material,
                            radius_m,
                            scene.thickness_m,
                            stop.pressure_pa,
                        )
                    {
                        note.push_str(&format!(" ({limit})"));
                    }
                    points.push(SimPoint {
                        pressure_pa: stop.pressure_pa,
                        height_m: None,
                        extra: Vec::new(),
                        iterations: 0,
                        residual: f64::NAN,
                        wall_s: stop.wall_s,
                        outcome: Outcome::Failed,
                        note: Some(note),
                    });
                    for &p in &pressures[stop.index + 1..] {
                        points.push(SimPoint {
                            pressure_pa: p,
                            height_m: None,
                            extra: Vec::new(),
                            iterations: 0,
                            residual: f64::NAN,
                            wall_s: 0.0,
                            outcome: Outcome::NotTried,
                            note: Some(format!(
                                "not solved: {} stopped at a lower pressure",
                                model.name()
                            )),
                        });
                    }
                    for _ in stop.index..pressures.len() {
                        tick();
                    }
                    (points, Some(stop.error))
                }
            };
            out.runs.push(ModelRun {
                model: HeightModel::Spring(model),
                solver: solver.name().to_string(),
                nodes: mesh.nodes.len(),
                points,
                wall_s: t_model.elapsed().as_secs_f64(),
                stop,
            });
        }
    }
    Ok(out)
}

/// One spring equilibrium as a simulated point: a folded apex is dropped,
/// a relaxed or round-off-limited one says so.
fn sim_point(model: SpringModel, solver: Solver, tolerance: f64, q: &SweepPoint) -> SimPoint {
    let folded = q.pressure_pa > 0.0 && q.height_m <= 0.0;
    let (outcome, note) = if folded {
        (
            Outcome::Folded,
            Some(format!(
                "{} at {} Pa: the apex fell to {:.3e} m, at or below the clamp plane under a positive pressure (a membrane near its stress-free state has no stiffness); not reported",
                model.name(),
                q.pressure_pa,
                q.height_m
            )),
        )
    } else if q.stats.relaxed {
        (
            Outcome::Relaxed,
            Some(format!(
                "{} at {} Pa: solved by dynamic relaxation ({} found the dome turned inside out, or no equilibrium, from the last one)",
                model.name(),
                q.pressure_pa,
                solver.name()
            )),
        )
    } else if q.stats.residual > tolerance {
        (
            Outcome::AtFloor,
            Some(format!(
                "{} at {} Pa: the residual stopped at {:.2e} of the load, above the tolerance {:e}, at the round-off floor of double precision here (the membrane's internal forces dwarf the pressure's); the height carries a relative error of about that size",
                model.name(),
                q.pressure_pa,
                q.stats.residual,
                tolerance
            )),
        )
    } else {
        (Outcome::Solved, None)
    };
    SimPoint {
        pressure_pa: q.pressure_pa,
        height_m: (!folded).then_some(q.height_m),
        extra: if folded { Vec::new() } else { q.extra.clone() },
        iterations: q.stats.iterations,
        residual: q.stats.residual,
        wall_s: q.wall_s,
        outcome,
        note,
    }
}

/// The pressures to simulate: the given list, or the distinct positive
/// measured pressures in increasing order.
pub fn pressures(settings: &Settings, points: &[Point]) -> Vec<f64> {
    if let Some(p) = &settings.pressures_pa {
        return p.clone();
    }
    let mut p: Vec<f64> = points
        .iter()
        .map(|p| p.pressure_pa)
        .filter(|&p| p > 0.0)
        .collect();
    p.sort_by(f64::total_cmp);
    p.dedup();
    p
}

/// Stage 4: the material on the specimen's disc at `pressures`, per model.
/// A pressure without equilibrium (above a limit point, a modulus law that
/// fails) ends that model's run with a note; the stage itself fails only
/// when a model cannot be set up.
pub fn simulate_stage(
    spec: &Specimen,
    settings: &Settings,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<Vec<ModelRun>, PipelineError> {
    crate::sim::scene::validate_pressures(pressures)
        .map_err(|m| PipelineError::Input(format!("pressures to simulate: {m}")))?;
    if pressures.windows(2).any(|w| w[1] <= w[0]) {
        return Err(PipelineError::Input(format!(
            "pressures to simulate {pressures:?}: give them in increasing order (each is continued from the previous)"
        )));
    }
    let mut scene =
        Scene::from_window(spec, &settings.window, material.clone(), pressures.to_vec());
    scene.mesh.size = settings.mesh;
    scene
        .validate(true)
        .map_err(|e| PipelineError::Input(e.to_string()))?;
    let opts = solve::Options {
        tolerance: settings.tolerance,
        ..solve::Options::default()
    };
    opts.validate()?;
    let (mesh, _) = scene_mesh(&scene, &settings.models, settings.solver, opts)?;
    let request = SceneRequest {
        models: settings.models.clone(),
        solvers: vec![settings.solver],
        // the exact axisymmetric reference holds for circular windows only
        axisym: settings.axisym && settings.window.is_circle(),
        profile: false,
        options: opts,
    };
    let mut runs = simulate_scene(&scene, &mesh, &request, &mut |_, _| {}, tick)?.runs;
    // the spring models first, then the reference
    runs.rotate_left(usize::from(request.axisym));
    Ok(runs)
}

/// Warnings for the pressures asked for above the measured ones: the fitted
/// law is extrapolated there; past the law's limit point (the pressure
/// maximum of the exact inflation) a pressure-controlled bubble snaps through.
pub fn extrapolation_warnings(
    spec: &Specimen,
    material: &Material,
    measured: &[Point],
    pressures: &[f64],
) -> Vec<String> {
    let top = measured
        .iter()
        .map(|p| p.pressure_pa)
        .fold(f64::NEG_INFINITY, f64::max);
    let above: Vec<f64> = pressures
        .iter()
        .copied()
        .filter(|&p| top.is_finite() && p > top * (1.0 + 1e-9))
        .collect();
    if above.is_empty() {
        return Vec::new();
    }
    let list = |v: &[f64]| {
        v.iter()
            .map(|&p| fmt_short(p))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = vec![format!(
        "{} Pa above the largest measured pressure ({} Pa): the fitted law is extrapolated there and no measured height checks it",
        list(&above),
        fmt_short(top)
    )];
    if let Some((limit_pa, limit_m)) =
        crate::sim::hard::disc_limit_point(material, spec.radius_m, spec.thickness_m)
    {
        let past: Vec<f64> = above.iter().copied().filter(|&p| p > limit_pa).collect();
        if !past.is_empty() {
            out.push(format!(
                "{} Pa past the limit point of the fitted law ({} Pa, apex {} m): a pressure-controlled bubble snaps through there, so no height the springs give there is one a real bubble holds",
                list(&past),
                fmt_short(limit_pa),
                fmt_short(limit_m)
            ));
        }
    }
    out
}

/// The exact axisymmetric reference of `material` at `pressures`.
pub fn axisym_run(
    spec: &Specimen,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<ModelRun, PipelineError> {
    Ok(axisym_points(spec, material, pressures, false, tick)?.0)
}

/// The exact axisymmetric reference at each pressure (each solved on its
/// own: a pressure without solution leaves the others), and the solution
/// at the last pressure solved when `profile` asks for its meridian.
fn axisym_points(
    spec: &Specimen,
    material: &Material,
    pressures: &[f64],
    profile: bool,
    tick: &dyn Fn(),
) -> Result<(ModelRun, Option<axisym::Solution>), PipelineError> {
    let t_model = Instant::now();
    let defaults = axisym::Options::default();
    let opts = axisym::Options {
        // the profile's points matter only when the meridian is written
        n_profile: if profile { defaults.n_profile } else { 2 },
        ..defaults
    };
    let mut points = Vec::new();
    let mut last = None;
    for &p in pressures {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(material, spec, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        points.push(match out {
            Ok(s) => {
                let point = SimPoint {
                    pressure_pa: p,
                    height_m: Some(s.height_m),
                    extra: Vec::new(),
                    iterations: s.iterations,
                    residual: s.residual,
                    wall_s: wall,
                    outcome: Outcome::Solved,
                    note: None,
                };
                if profile {
                    last = Some(s);
                }
                point
            }
            Err(
                e @ (AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)),
            ) => return Err(e.into()),
            Err(e) => SimPoint {
                pressure_pa: p,
                height_m: None,
                extra: Vec::new(),
                iterations: 0,
                residual: f64::NAN,
                wall_s: wall,
                outcome: Outcome::Failed,
                note: Some(format!("axisym at {p} Pa: {e}")),
            },
        });
        tick();
    }
    let run = ModelRun {
        model: HeightModel::Axisym,
        solver: "shooting".into(),
        nodes: 0,
        points,
        wall_s: t_model.elapsed().as_secs_f64(),
        stop: None,
    };
    Ok((run, last))
}

/// The columns every simulated-heights file starts with (`bulge simulate`,
/// `bulge simulate --dynamic`, `simulated.csv` of `bulge run`).
pub const SIMULATED_COLUMNS: [&str; 8] = [
    "pressure_pa",
    "height_m",
    "model",
    "solver",
    "nodes",
    "iterations",
    "residual",
    "wall_s",
];

/// `simulated.csv`: [`SIMULATED_COLUMNS`], solved pressures only (as
/// `bulge simulate`).
pub fn simulated_csv(runs: &[ModelRun]) -> CsvOut {
    simulated_csv_with(runs, &[])
}

/// [`SIMULATED_COLUMNS`] and the scene's `extra` columns
/// ([`Scene::extra_columns`], blank for the axisymmetric reference), one row
/// per pressure with a height. A point solved by dynamic relaxation in place
/// of the run's solver says `dr`.
pub fn simulated_csv_with(runs: &[ModelRun], extra: &[&str]) -> CsvOut {
    let mut header: Vec<&str> = SIMULATED_COLUMNS.to_vec();
    header.extend(extra);
    let mut out = CsvOut::new(&header);
    for r in runs {
        for p in &r.points {
            if let Some(h) = p.height_m {
                let solver = if p.outcome == Outcome::Relaxed {
                    "dr"
                } else {
                    r.solver.as_str()
                };
                let mut row = vec![
                    fmt_num(Some(p.pressure_pa)),
                    fmt_num(Some(h)),
                    r.model.to_string(),
                    solver.to_string(),
                    r.nodes.to_string(),
                    p.iterations.to_string(),
                    format!("{:.3e}", p.residual),
                    format!("{:.4}", p.wall_s),
                ];
                row.extend(p.extra.iter().map(|v| fmt_num(Some(*v))));
                row.resize(header.len(), String::new());
                out.row(&row);
            }
        }
    }
    out
}
