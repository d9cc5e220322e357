//! The dynamic runs of `bulge simulate --dynamic`: each model, pressure and
//! integrator from rest, against the static equilibrium it should settle to.

use std::time::Instant;

use anyhow::anyhow;
use nalgebra::{Point3, Vector3};

use crate::cli::{Classify, Failure};
use bulge::io::{CsvOut, fmt_num};
use bulge::sim::SceneSolver;
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use bulge::sim::mesh::Mesh;
use bulge::sim::scene::Scene;
use bulge::sim::springs::SpringModel;

/// Largest mesh for which `--dynamic` also solves the static equilibrium to
/// compare with (a Newton solve of a 1e5-node full disc takes about 10 s and
/// 0.5 GB; memory grows a little faster than the node count).
const STATIC_COMPARISON_MAX_NODES: usize = 150_000;

/// What to run.
pub(super) struct Plan<'a> {
    pub scene: &'a Scene,
    pub mesh: &'a Mesh,
    pub models: &'a [SpringModel],
    pub integrators: &'a [Integrator],
    pub pressures: &'a [f64],
    pub damping: DampingLaw,
    pub policy: StepPolicy,
    pub dt: Option<f64>,
    pub t_end: f64,
    pub xpbd_iterations: usize,
}

/// The runs' outputs: the summary CSV, the time histories, the table
/// printed, and the failures.
pub(super) struct Done {
    pub csv: CsvOut,
    pub trace: CsvOut,
    pub table: Vec<String>,
    pub failures: Vec<String>,
}

/// Runs every model, pressure and integrator of `pl`.
pub(super) fn run(pl: &Plan) -> Result<Done, Failure> {
    let Plan {
        scene,
        mesh,
        models,
        integrators,
        pressures,
        damping,
        policy,
        t_end,
        ..
    } = *pl;
    let mut header = bulge::pipeline::SIMULATED_COLUMNS.to_vec();
    header.extend([
        "peak_m",
        "static_height_m",
        "overshoot",
        "settling_time_s",
        "dt_s",
        "substeps",
        "dt_limit_s",
    ]);
    let mut csv = CsvOut::new(&header);
    let mut trace = CsvOut::new(&[
        "t_s",
        "value_m",
        "kinetic_j",
        "pressure_pa",
        "model",
        "integrator",
    ]);
    let mut table = Vec::new();
    let mut failures = Vec::new();
    let pb = crate::cli::progress(
        (models.len() * integrators.len() * pressures.len()) as u64,
        "dynamic",
    );
    for &model in models {
        let mut membrane = scene
            .membrane(mesh, model)
            .map_err(|e| anyhow!("{e}"))
            .bad_input()?;
        let measure = |x: &[Point3<f64>]| scene.measure(mesh, x).0;
        for &p in pressures {
            // the static answer the run should settle to
            // the static comparison is a Newton solve (a sparse factorisation):
            // skipped on the biggest meshes, for its memory
            let static_h = if mesh.nodes.len() > STATIC_COMPARISON_MAX_NODES {
                eprintln!(
                    "note: {} nodes: the static comparison (Newton) is skipped above {STATIC_COMPARISON_MAX_NODES} nodes",
                    mesh.nodes.len()
                );
                None
            } else {
                SceneSolver::on_mesh(scene, mesh.clone(), model)
                    .ok()
                    .and_then(|mut s| s.solve_to(p).ok().map(|_| s.measure().0))
            };
            for &integ in integrators {
                membrane.pressure_pa = p;
                let mut dynm = Dynamics::new(&mut membrane, mesh, damping)
                    .map_err(|e| anyhow!("{e}"))
                    .bad_input()?;
                let dt = match pl.dt {
                    Some(dt) => dt,
                    None => {
                        let est = dynm
                            .estimate_step(&mesh.nodes)
                            .map_err(|e| anyhow!("{e}"))
                            .failed()?;
                        est.safety() * est.limit(Integrator::Verlet)
                    }
                };
                let opts = DynOptions {
                    integrator: integ,
                    dt_s: dt,
                    t_end_s: t_end,
                    damping,
                    policy,
                    xpbd_iterations: pl.xpbd_iterations,
                    ..DynOptions::default()
                };
                let mut x = mesh.nodes.clone();
                let mut v = vec![Vector3::zeros(); x.len()];
                let t0 = Instant::now();
                let out = dynm.run(&mut x, &mut v, &opts, &measure);
                let wall = t0.elapsed().as_secs_f64();
                pb.inc(1);
                match out {
                    Ok(run) => {
                        let h = run.last();
                        let peak = run.peak();
                        let (overshoot, settle) = match static_h {
                            Some(s) if s != 0.0 => {
                                (Some((peak - s) / s), Some(run.settling_time(s, 0.02)))
                            }
                            _ => (None, None),
                        };
                        let limit = run
                            .estimate
                            .map(|e| e.limit(integ))
                            .filter(|l| l.is_finite());
                        csv.row(&[
                            fmt_num(Some(p)),
                            fmt_num(Some(h)),
                            model.name().to_string(),
                            integ.name().to_string(),
                            mesh.nodes.len().to_string(),
                            (run.steps * run.substeps).to_string(),
                            format!("{:.3e}", run.residual),
                            format!("{wall:.4}"),
                            fmt_num(Some(peak)),
                            fmt_num(static_h),
                            fmt_num(overshoot),
                            fmt_num(settle),
                            fmt_num(Some(run.h_s)),
                            run.substeps.to_string(),
                            fmt_num(limit),
                        ]);
                        for s in &run.samples {
                            trace.row(&[
                                fmt_num(Some(s.t_s)),
                                fmt_num(Some(s.value_m)),
                                fmt_num(Some(s.kinetic_j)),
                                fmt_num(Some(p)),
                                model.name().to_string(),
                                integ.name().to_string(),
                            ]);
                        }
                        table.push(format!(
                            "{:>10} {:>10} {:>16} {:>12.5e} {:>12.5e} {:>12} {:>9.2e} {:>8} {:>8.3}",
                            p,
                            model.name(),
                            integ.name(),
                            h,
                            peak,
                            static_h.map(|s| format!("{s:.5e}")).unwrap_or_else(|| "-".into()),
                            run.h_s,
                            run.steps * run.substeps,
                            wall
                        ));
                    }
                    Err(
                        e @ (DynError::BadParameter(_)
                        | DynError::StepTooLarge { .. }
                        | DynError::NoStableStep),
                    ) => {
                        pb.finish_and_clear();
                        return Err(Failure::BadInput(anyhow!(
                            "{} / {}: {}: {e}",
                            model.name(),
                            integ.name(),
                            flags_of(&e)
                        )));
                    }
                    Err(e) => failures.push(format!(
                        "{} / {} at {p} Pa: {}: {e}",
                        model.name(),
                        integ.name(),
                        flags_of(&e)
                    )),
                }
            }
        }
    }
    pb.finish_and_clear();
    Ok(Done {
        csv,
        trace,
        table,
        failures,
    })
}

/// The flags that set what a dynamic run's error is about.
fn flags_of(e: &DynError) -> &'static str {
    match e {
        DynError::StepTooLarge { .. } => "--dt / --step-policy",
        DynError::NoStableStep => "--damping",
        DynError::BadParameter(_) => "--dt / --t-end / --damping",
        DynError::Diverged { .. } | DynError::NewtonFailed { .. } => "--dt / --integrator",
        _ => "--dynamic",
    }
}
