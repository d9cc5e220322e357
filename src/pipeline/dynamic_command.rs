//! `bulge simulate --dynamic` in memory: each spring model, pressure and
//! integrator from rest, against the static equilibrium it should settle
//! to, for the command line and the Python package alike. Messages name
//! each setting through [`Setting`], as the front end spells it.

use std::time::Instant;

use nalgebra::{Point3, Vector3};

use crate::io::{CsvOut, fmt_num};
use crate::setting::Setting;
use crate::sim::SceneSolver;
use crate::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use crate::sim::scene::{Scene, SceneKind};
use crate::sim::springs::{HeightModel, SpringModel};

/// Largest mesh for which a dynamic run also solves the static equilibrium
/// to compare with (a Newton solve of a 1e5-node full disc takes about 10 s
/// and 0.5 GB; memory grows a little faster than the node count).
const STATIC_COMPARISON_MAX_NODES: usize = 150_000;

/// What to integrate, as the flags give it.
#[derive(Debug, Clone)]
pub struct DynamicRequest<'a> {
    /// The scene (its pressures each applied as a step at t = 0).
    pub scene: &'a Scene,
    /// The models (spring models only).
    pub models: &'a [HeightModel],
    /// The integrators.
    pub integrators: &'a [Integrator],
    /// Time step, s (default: from the mesh's stable step).
    pub dt: Option<f64>,
    /// Simulated time, s (required).
    pub t_end: Option<f64>,
    /// Fraction of critical damping (the `critical` law).
    pub damping: f64,
    /// `critical` or `sudhamani-merriliance`.
    pub damping_law: &'a str,
    /// `substep` or `refuse`.
    pub step_policy: &'a str,
    /// XPBD constraint iterations per step.
    pub xpbd_iterations: usize,
}

/// The runs' outputs and what they say.
pub struct DynamicOut {
    /// One row per run (the columns of `simulated.csv` and the run's own).
    pub csv: CsvOut,
    /// The time histories.
    pub trace: CsvOut,
    /// The terminal table, one line per run.
    pub table: Vec<String>,
    /// The mesh, and what was held.
    pub notes: Vec<String>,
    /// A mesh too coarse, a model that is not conservative.
    pub warnings: Vec<String>,
    /// Each run that stopped, with the settings that decide it.
    pub failures: Vec<String>,
}

/// Why nothing was integrated: the input refused (`bad`) or the work failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct DynamicError {
    /// The user's input, not the work.
    pub bad: bool,
    /// What is wrong, the value and the fix.
    pub message: String,
}

impl crate::Refusal for DynamicError {
    fn is_bad_input(&self) -> bool {
        self.bad
    }
}

fn refused(message: String) -> DynamicError {
    DynamicError { bad: true, message }
}

/// The settings that decide what a run's error is about.
fn keys_of(e: &DynError) -> &'static [Setting] {
    match e {
        DynError::StepTooLarge { .. } => &[Setting::Dt, Setting::StepPolicy],
        DynError::NoStableStep => &[Setting::Damping],
        DynError::BadParameter(_) => &[Setting::Dt, Setting::TEnd, Setting::Damping],
        DynError::Diverged { .. } | DynError::NewtonFailed { .. } => {
            &[Setting::Dt, Setting::Integrator]
        }
        _ => &[Setting::Dynamic],
    }
}

/// `bulge simulate --dynamic`: every model, pressure and integrator of
/// `req` from rest; `tick` is called after each run.
pub fn simulate_dynamic(req: &DynamicRequest, tick: &dyn Fn()) -> Result<DynamicOut, DynamicError> {
    let scene = req.scene;
    let models: Vec<SpringModel> = req
        .models
        .iter()
        .map(|c| match c {
            HeightModel::Spring(m) => Ok(*m),
            HeightModel::Axisym => Err(refused(format!(
                "{} integrates the spring models; axisym is a static solution: drop it from {}",
                Setting::Dynamic,
                Setting::Model
            ))),
        })
        .collect::<Result<_, _>>()?;
    let t_end = req.t_end.ok_or_else(|| {
        refused(format!(
            "{} needs {} (the simulated time in s, e.g. 0.05)",
            Setting::Dynamic,
            Setting::TEnd
        ))
    })?;
    let damping = match req.damping_law.trim() {
        "critical" => DampingLaw::Critical(req.damping),
        "sudhamani-merriliance" => DampingLaw::SudhamaniMerriliance,
        other => {
            return Err(refused(format!(
                "{} `{other}` is not one of critical, sudhamani-merriliance",
                Setting::DampingLaw
            )));
        }
    };
    let policy = match req.step_policy.trim() {
        "substep" => StepPolicy::Substep,
        "refuse" => StepPolicy::Refuse,
        other => {
            return Err(refused(format!(
                "{} `{other}` is not one of substep, refuse",
                Setting::StepPolicy
            )));
        }
    };
    let mut mesh = scene
        .build_mesh()
        .map_err(|e| refused(format!("building the mesh: {}", crate::io::chain(&e))))?;
    let pressures = scene.pressures_to_solve();
    let mut notes = Vec::new();
    if matches!(scene.kind, SceneKind::Sheet { .. })
        && pressures.iter().all(|&p| p == 0.0)
        && scene.loads.iter().all(|l| l.force_n[2] == 0.0)
    {
        mesh.hold_in_plane();
        notes.push(
            "note: every load lies in the sheet's plane: the nodes are held in z = 0 (a flat membrane has no stiffness out of its plane)".into(),
        );
    }
    notes.push(super::describe_mesh(&mesh, scene));
    let mut warnings = Vec::new();
    for &model in &models {
        for w in crate::sim::hard::mesh_warnings(&mesh, model, &scene.material, scene.thickness_m) {
            warnings.push(format!("({}): {w}", model.name()));
        }
        if let Some(w) = crate::sim::dynamics::non_conservative_warning(model, damping) {
            warnings.push(format!(
                "({}): {w}; raise {} or use {} van-gelder or lloyd",
                model.name(),
                Setting::Damping,
                Setting::Model
            ));
        }
    }
    let mut header = super::SIMULATED_COLUMNS.to_vec();
    header.extend([
        "peak_m",
        "static_height_m",
        "overshoot",
        "settling_time_s",
        "dt_s",
        "substeps",
        "dt_limit_s",
    ]);
    let mut out = DynamicOut {
        csv: CsvOut::new(&header),
        trace: CsvOut::new(&[
            "t_s",
            "value_m",
            "kinetic_j",
            "pressure_pa",
            "model",
            "integrator",
        ]),
        table: Vec::new(),
        notes,
        warnings,
        failures: Vec::new(),
    };
    let keys = |e: &DynError| {
        keys_of(e)
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(" / ")
    };
    for &model in &models {
        let mut membrane = scene
            .membrane(&mesh, model)
            .map_err(|e| refused(e.to_string()))?;
        let measure = |x: &[Point3<f64>]| scene.measure(&mesh, x).0;
        for &p in &pressures {
            // the static answer the run should settle to: a Newton solve (a
            // sparse factorisation), skipped on the biggest meshes for its
            // memory
            let static_h = if mesh.nodes.len() > STATIC_COMPARISON_MAX_NODES {
                out.notes.push(format!(
                    "note: {} nodes: the static comparison (Newton) is skipped above {STATIC_COMPARISON_MAX_NODES} nodes",
                    mesh.nodes.len()
                ));
                None
            } else {
                SceneSolver::on_mesh(scene, mesh.clone(), model)
                    .ok()
                    .and_then(|mut s| s.solve_to(p).ok().map(|_| s.measure().0))
            };
            for &integ in req.integrators {
                membrane.pressure_pa = p;
                let mut dynm = Dynamics::new(&mut membrane, &mesh, damping)
                    .map_err(|e| refused(e.to_string()))?;
                let dt = match req.dt {
                    Some(dt) => dt,
                    None => {
                        let est = dynm.estimate_step(&mesh.nodes).map_err(|e| DynamicError {
                            bad: false,
                            message: e.to_string(),
                        })?;
                        est.safety() * est.limit(Integrator::Verlet)
                    }
                };
                let opts = DynOptions {
                    integrator: integ,
                    dt_s: dt,
                    t_end_s: t_end,
                    damping,
                    policy,
                    xpbd_iterations: req.xpbd_iterations,
                    ..DynOptions::default()
                };
                let mut x = mesh.nodes.clone();
                let mut v = vec![Vector3::zeros(); x.len()];
                let t0 = Instant::now();
                let run = dynm.run(&mut x, &mut v, &opts, &measure);
                let wall = t0.elapsed().as_secs_f64();
                tick();
                let run = match run {
                    Ok(run) => run,
                    Err(
                        e @ (DynError::BadParameter(_)
                        | DynError::StepTooLarge { .. }
                        | DynError::NoStableStep),
                    ) => {
                        return Err(refused(format!(
                            "{} / {}: {}: {e}",
                            model.name(),
                            integ.name(),
                            keys(&e)
                        )));
                    }
                    Err(e) => {
                        out.failures.push(format!(
                            "{} / {} at {p} Pa: {}: {e}",
                            model.name(),
                            integ.name(),
                            keys(&e)
                        ));
                        continue;
                    }
                };
                let h = run.last();
                let peak = run.peak();
                let (overshoot, settle) = match static_h {
                    Some(s) if s != 0.0 => (Some((peak - s) / s), Some(run.settling_time(s, 0.02))),
                    _ => (None, None),
                };
                let limit = run
                    .estimate
                    .map(|e| e.limit(integ))
                    .filter(|l| l.is_finite());
                out.csv.row(&[
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
                    out.trace.row(&[
                        fmt_num(Some(s.t_s)),
                        fmt_num(Some(s.value_m)),
                        fmt_num(Some(s.kinetic_j)),
                        fmt_num(Some(p)),
                        model.name().to_string(),
                        integ.name().to_string(),
                    ]);
                }
                out.table.push(format!(
                    "{:>10} {:>10} {:>16} {:>12.5e} {:>12.5e} {:>12} {:>9.2e} {:>8} {:>8.3}",
                    p,
                    model.name(),
                    integ.name(),
                    h,
                    peak,
                    static_h
                        .map(|s| format!("{s:.5e}"))
                        .unwrap_or_else(|| "-".into()),
                    run.h_s,
                    run.steps * run.substeps,
                    wall
                ));
            }
        }
    }
    Ok(out)
}
