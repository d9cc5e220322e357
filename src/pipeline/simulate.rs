//! The simulate stage: the material -> simulated heights by every membrane
//! model asked for, and the rows and warnings it writes.

use std::time::Instant;

use crate::axisym::{self, AxisymError};
use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num, fmt_short};
use crate::material::Material;
use crate::mechanics::Point;
use crate::sim::DiscSolver;
use crate::sim::scene::{MeshSize, Scene};
use crate::sim::solve;
use crate::sim::springs::HeightModel;

use super::*;

/// One simulated pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct SimPoint {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m; `None` when no equilibrium was found.
    pub height_m: Option<f64>,
    /// Newton iterations / relaxation steps / shots.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Time of this pressure, s.
    pub wall_s: f64,
    /// Why there is no height.
    pub note: Option<String>,
}

/// The heights of one model at every pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelRun {
    /// The spring model, or the axisymmetric reference.
    pub model: HeightModel,
    /// `newton`, `dr` or `shooting`.
    pub solver: String,
    /// Solved nodes (0 for the axisymmetric reference).
    pub nodes: usize,
    /// One per pressure.
    pub points: Vec<SimPoint>,
    /// Total time, s.
    pub wall_s: f64,
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
    let mesh = match settings.mesh {
        Some(MeshSize::Accuracy(a)) if !settings.models.is_empty() => {
            crate::sim::disc::mesh_for_accuracy(
                &scene,
                &settings.models,
                settings.solver,
                opts,
                a,
                scene.mesh.max_nodes,
            )?
            .mesh
        }
        _ => scene.build_mesh()?,
    };
    let mut runs = Vec::new();
    for &model in &settings.models {
        let t_model = Instant::now();
        let mut disc =
            DiscSolver::on_mesh(&scene, mesh.clone(), model)?.with_solver(settings.solver, opts)?;
        // An apex at or below the clamp plane under a positive pressure is no
        // equilibrium to trust (a membrane near its stress-free state has no
        // stiffness: a domed one can fold through); it is not reported.
        let solved = |q: &crate::sim::SweepPoint| {
            let folded = q.pressure_pa > 0.0 && q.height_m <= 0.0;
            SimPoint {
                pressure_pa: q.pressure_pa,
                height_m: (!folded).then_some(q.height_m),
                iterations: q.stats.iterations,
                residual: q.stats.residual,
                wall_s: q.wall_s,
                note: if folded {
                    Some(format!(
                        "{} at {} Pa: the apex fell to {:.3e} m, at or below the clamp plane under a positive pressure (a membrane near its stress-free state has no stiffness); not reported",
                        model.name(),
                        q.pressure_pa,
                        q.height_m
                    ))
                } else if q.stats.relaxed {
                    Some(format!(
                        "{} at {} Pa: solved by dynamic relaxation ({} found the dome turned inside out, or no equilibrium, from the last one)",
                        model.name(),
                        q.pressure_pa,
                        settings.solver.name()
                    ))
                } else if q.stats.residual > opts.tolerance {
                    Some(format!(
                        "{} at {} Pa: the residual stopped at {:.2e} of the load, above the tolerance {:e}, at the round-off floor of double precision here; the height carries a relative error of about that size",
                        model.name(),
                        q.pressure_pa,
                        q.stats.residual,
                        opts.tolerance
                    ))
                } else {
                    None
                },
            }
        };
        let points = match disc.sweep(pressures, |_, _| tick()) {
            Ok(done) => done.iter().map(solved).collect(),
            Err((done, stop)) => {
                let mut points: Vec<SimPoint> = done.iter().map(solved).collect();
                points.push(SimPoint {
                    pressure_pa: stop.pressure_pa,
                    height_m: None,
                    iterations: 0,
                    residual: f64::NAN,
                    wall_s: stop.wall_s,
                    note: Some(format!(
                        "{} at {} Pa: {}",
                        model.name(),
                        stop.pressure_pa,
                        stop.error
                    )),
                });
                for &p in &pressures[stop.index + 1..] {
                    points.push(SimPoint {
                        pressure_pa: p,
                        height_m: None,
                        iterations: 0,
                        residual: f64::NAN,
                        wall_s: 0.0,
                        note: Some(format!(
                            "not solved: {} stopped at a lower pressure",
                            model.name()
                        )),
                    });
                }
                for _ in stop.index..pressures.len() {
                    tick();
                }
                points
            }
        };
        runs.push(ModelRun {
            model: HeightModel::Spring(model),
            solver: settings.solver.name().to_string(),
            nodes: mesh.nodes.len(),
            points,
            wall_s: t_model.elapsed().as_secs_f64(),
        });
    }
    // the exact axisymmetric reference holds for circular windows only
    if settings.axisym && settings.window.is_circle() {
        runs.push(axisym_run(spec, material, pressures, tick)?);
    }
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
    let t_model = Instant::now();
    let opts = axisym::Options {
        n_profile: 2,
        ..axisym::Options::default()
    };
    let mut points = Vec::new();
    for &p in pressures {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(material, spec, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        points.push(match out {
            Ok(s) => SimPoint {
                pressure_pa: p,
                height_m: Some(s.height_m),
                iterations: s.iterations,
                residual: s.residual,
                wall_s: wall,
                note: None,
            },
            Err(
                e @ (AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)),
            ) => return Err(e.into()),
            Err(e) => SimPoint {
                pressure_pa: p,
                height_m: None,
                iterations: 0,
                residual: f64::NAN,
                wall_s: wall,
                note: Some(format!("axisym at {p} Pa: {e}")),
            },
        });
        tick();
    }
    Ok(ModelRun {
        model: HeightModel::Axisym,
        solver: "shooting".into(),
        nodes: 0,
        points,
        wall_s: t_model.elapsed().as_secs_f64(),
    })
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
    let mut out = CsvOut::new(&SIMULATED_COLUMNS);
    for r in runs {
        for p in &r.points {
            if let Some(h) = p.height_m {
                out.row(&[
                    fmt_num(Some(p.pressure_pa)),
                    fmt_num(Some(h)),
                    r.model.to_string(),
                    r.solver.clone(),
                    r.nodes.to_string(),
                    p.iterations.to_string(),
                    format!("{:.3e}", p.residual),
                    format!("{:.4}", p.wall_s),
                ]);
            }
        }
    }
    out
}
