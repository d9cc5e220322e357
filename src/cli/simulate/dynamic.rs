//! `bulge simulate --dynamic`: time integration of a scene under a load step
//! (see `docs/dynamics.md`).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, anyhow};
use nalgebra::{Point3, Vector3};

use super::super::{Classify, Failure};
use super::{Args, Choice, describe, finish};
use bulge::io::{CsvOut, fmt_num, write_atomic};
use bulge::sim::dynamics::{DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use bulge::sim::scene::{DiscPredictor, Scene, SceneKind};
use bulge::sim::solve::{self, Options, Predictor, Solver, Stay};
use bulge::sim::springs::SpringModel;

/// Largest mesh for which `--dynamic` also solves the static equilibrium to
/// compare with (a 1e5-node Newton solve took 6 min and 3.3 GB).
const STATIC_COMPARISON_MAX_NODES: usize = 20_000;

/// Flags of the dynamic runs (used with --dynamic).
#[derive(Debug, Clone, clap::Args)]
pub struct DynArgs {
    /// Integrate in time instead of solving for equilibrium: each pressure of
    /// the list (and the scene's nodal loads) is applied as a step at t = 0 on
    /// the membrane at rest, from rest, one run per pressure and integrator.
    #[arg(long)]
    pub dynamic: bool,
    /// Integrators (with --dynamic), comma-separated: explicit-euler,
    /// symplectic-euler, verlet (Sudhamani & Merriliance's position Verlet, default),
    /// implicit-euler (Newton + sparse LU), xpbd (needs van-gelder or lloyd
    /// and a linear material).
    #[arg(long, default_value = "verlet", value_enum, value_delimiter = ',')]
    pub integrator: Vec<Integrator>,
    /// Time step in s. Default: 0.9 of Verlet's stable step estimated for the
    /// mesh at rest. An explicit integrator given a larger step sub-steps (or
    /// refuses, see --step-policy).
    #[arg(long)]
    pub dt: Option<f64>,
    /// Simulated time in s (required with --dynamic).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Damping as a fraction of each spring's critical damping
    /// 2 sqrt(k m_red). Default 0.1.
    #[arg(long, default_value_t = bulge::sim::dynamics::DEFAULT_DAMPING)]
    pub damping: f64,
    /// Damping law: critical (a fraction of critical, default) or paper003
    /// (Sudhamani & Merriliance's d = sqrt(k (m_i + m_j)) / l0, which has an extra 1/length and
    /// depends on the mesh; --damping is then ignored).
    #[arg(long, default_value = "critical")]
    pub damping_law: String,
    /// What an explicit integrator does with a --dt above its stable step:
    /// substep (default: split each step) or refuse (stop with the limit in
    /// the message).
    #[arg(long, default_value = "substep")]
    pub step_policy: String,
    /// XPBD constraint iterations per step. Default 20.
    #[arg(long, default_value_t = 20)]
    pub xpbd_iterations: usize,
    /// Time-history CSV (t_s,value_m,kinetic_j,pressure_pa,model,integrator),
    /// value_m being the apex height (disc) or the loaded node's displacement
    /// (sheet). Default: none written.
    #[arg(long)]
    pub trace: Option<PathBuf>,
}

fn build_scene(args: &Args) -> anyhow::Result<Scene> {
    let (scene, origin) = super::load_scene(args)?;
    // a sheet may be loaded by its nodal loads alone
    let need_p = !matches!(scene.kind, SceneKind::Sheet { .. }) || scene.loads.is_empty();
    scene
        .validate(need_p)
        .map_err(|m| anyhow!("{origin}: {m}"))?;
    Ok(scene)
}

/// Runs `bulge simulate --dynamic`.
pub fn run(args: Args) -> Result<(), Failure> {
    let d = args.dynamic.clone();
    let scene = build_scene(&args).bad_input()?;
    let models: Vec<SpringModel> = args
        .model
        .iter()
        .map(|c| match c {
            Choice::Spring(m) => Ok(*m),
            Choice::Axisym => Err(anyhow!(
                "--dynamic integrates the spring models; axisym is a static solution: drop it from --model"
            )),
        })
        .collect::<anyhow::Result<_>>()
        .bad_input()?;
    let integrators = d.integrator.clone();
    let t_end = d
        .t_end
        .ok_or_else(|| anyhow!("--dynamic needs --t-end (the simulated time in s, e.g. 0.05)"))
        .bad_input()?;
    let damping = match d.damping_law.trim() {
        "critical" => DampingLaw::Critical(d.damping),
        "paper003" => DampingLaw::Paper003,
        other => {
            return Err(Failure::BadInput(anyhow!(
                "--damping-law `{other}` is not one of critical, paper003"
            )));
        }
    };
    let policy = match d.step_policy.trim() {
        "substep" => StepPolicy::Substep,
        "refuse" => StepPolicy::Refuse,
        other => {
            return Err(Failure::BadInput(anyhow!(
                "--step-policy `{other}` is not one of substep, refuse"
            )));
        }
    };
    let mut mesh = scene
        .build_mesh()
        .context("building the mesh")
        .bad_input()?;
    let pressures: Vec<f64> = if scene.pressures_pa.is_empty() {
        vec![0.0]
    } else {
        scene.pressures_pa.clone()
    };
    if matches!(scene.kind, SceneKind::Sheet { .. })
        && pressures.iter().all(|&p| p == 0.0)
        && scene.loads.iter().all(|l| l.force_n[2] == 0.0)
    {
        mesh.hold_in_plane();
        eprintln!(
            "note: every load lies in the sheet's plane: the nodes are held in z = 0 (a flat membrane has no stiffness out of its plane)"
        );
    }
    eprintln!("{}", describe(&mesh, &scene));
    for &model in &models {
        for w in bulge::sim::hard::mesh_warnings(&mesh, model, &scene.material, scene.thickness_m) {
            eprintln!("warning ({}): {w}", model.name());
        }
    }

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
    let pb = super::super::progress(
        (models.len() * integrators.len() * pressures.len()) as u64,
        "dynamic",
    );
    for &model in &models {
        let mut membrane = scene
            .membrane(&mesh, model)
            .map_err(|e| anyhow!("{e}"))
            .bad_input()?;
        let measure = |x: &[Point3<f64>]| scene.measure(&mesh, x).0;
        for &p in &pressures {
            // the static answer the run should settle to
            // the static comparison is a Newton solve (sparse LU): skipped on
            // big meshes, where it costs far more than the dynamic run
            let static_h = if mesh.nodes.len() > STATIC_COMPARISON_MAX_NODES {
                eprintln!(
                    "note: {} nodes: the static comparison (Newton) is skipped above {STATIC_COMPARISON_MAX_NODES} nodes",
                    mesh.nodes.len()
                );
                None
            } else {
                let mut m2 = membrane.clone();
                let mut x = mesh.nodes.clone();
                let pred: Box<dyn Predictor> = match scene.kind {
                    SceneKind::Disc { radius_m } => Box::new(DiscPredictor {
                        radius_m,
                        young_pa: m2.law.young(1.0).1,
                        thickness_m: scene.thickness_m,
                        poisson: scene.material.poisson,
                    }),
                    _ => Box::new(Stay),
                };
                let mut ws = None;
                let opts = Options::default();
                let ok = if p > 0.0 {
                    solve::continuation(
                        &mut m2,
                        &mesh.nodes,
                        &mut x,
                        0.0,
                        p,
                        Solver::Newton,
                        &opts,
                        pred.as_ref(),
                        &mut ws,
                    )
                    .is_ok()
                } else {
                    solve::newton(&mut m2, &mut x, 0.0, &opts).is_ok()
                };
                if ok { Some(measure(&x)) } else { None }
            };
            for &integ in &integrators {
                membrane.pressure_pa = p;
                let mut dynm = Dynamics::new(&mut membrane, &mesh, damping)
                    .map_err(|e| anyhow!("{e}"))
                    .bad_input()?;
                let dt = match d.dt {
                    Some(dt) => dt,
                    None => {
                        let est = dynm
                            .estimate_step(&mesh.nodes)
                            .map_err(|e| anyhow!("{e}"))
                            .failed()?;
                        0.9 * est.limit(Integrator::Verlet)
                    }
                };
                let opts = DynOptions {
                    integrator: integ,
                    dt_s: dt,
                    t_end_s: t_end,
                    damping,
                    policy,
                    xpbd_iterations: d.xpbd_iterations,
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
                            "{} / {}: {e}",
                            model.name(),
                            integ.name()
                        )));
                    }
                    Err(e) => failures.push(format!(
                        "{} / {} at {p} Pa: {e}",
                        model.name(),
                        integ.name()
                    )),
                }
            }
        }
    }
    pb.finish_and_clear();
    csv.write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))
        .failed()?;
    if let Some(t) = &d.trace {
        write_atomic(t, &trace.into_bytes())
            .with_context(|| format!("writing {}", t.display()))
            .failed()?;
    }
    finish(
        "  pressure_pa    model       integrator      final_m       peak_m     static_m       dt_s    steps   wall_s",
        &table,
        &args.output,
        &failures,
        "the runs that finished",
    )
}
