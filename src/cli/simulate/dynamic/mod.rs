//! `bulge simulate --dynamic`: time integration of a scene under a load step
//! (see `docs/dynamics.md`).

use std::path::PathBuf;

use anyhow::{Context, anyhow};

mod runs;

use super::{Args, build_scene, describe, finish};
use crate::cli::{Classify, Failure};
use bulge::io::write_atomic;
use bulge::sim::dynamics::{DampingLaw, Integrator, StepPolicy};
use bulge::sim::scene::SceneKind;
use bulge::sim::springs::{HeightModel, SpringModel};

/// Flags of the dynamic runs (used with --dynamic).
#[derive(Debug, Clone, clap::Args)]
pub struct DynArgs {
    /// Integrate in time instead of solving for equilibrium: each pressure of
    /// the list (and the scene's nodal loads) is applied as a step at t = 0 on
    /// the membrane at rest, from rest, one run per pressure and integrator.
    #[arg(long)]
    pub dynamic: bool,
    /// Integrators (with --dynamic), comma-separated: explicit-euler,
    /// symplectic-euler, verlet (position Verlet, the dashpots split off symmetrically:
    /// second order with damping; default),
    /// implicit-euler (Newton + sparse LU), xpbd (needs van-gelder or lloyd
    /// and a linear material).
    #[arg(long, default_value = "verlet", value_enum, value_delimiter = ',')]
    pub integrator: Vec<Integrator>,
    /// Time step in s. Default: 0.9 of Verlet's stable step estimated for the
    /// mesh at rest (0.5 without damping: Verlet's nonlinear resonances lie
    /// below its limit and the stiffest frequency rises as the membrane
    /// inflates). An explicit integrator given a larger step sub-steps (or
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
    /// Damping law: critical (a fraction of critical, default) or sudhamani-merriliance
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

/// Runs `bulge simulate --dynamic`.
pub fn run(args: Args) -> Result<(), Failure> {
    let d = args.dynamic.clone();
    let scene = build_scene(&args).bad_input()?;
    let models: Vec<SpringModel> = args
        .model
        .iter()
        .map(|c| match c {
            HeightModel::Spring(m) => Ok(*m),
            HeightModel::Axisym => Err(anyhow!(
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
        "sudhamani-merriliance" => DampingLaw::SudhamaniMerriliance,
        other => {
            return Err(Failure::BadInput(anyhow!(
                "--damping-law `{other}` is not one of critical, sudhamani-merriliance"
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
    let pressures = scene.pressures_to_solve();
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
        if let Some(w) = bulge::sim::dynamics::non_conservative_warning(model, damping) {
            eprintln!(
                "warning ({}): {w}; raise --damping or use --model van-gelder or lloyd",
                model.name()
            );
        }
    }

    let plan = runs::Plan {
        scene: &scene,
        mesh: &mesh,
        models: &models,
        integrators: &integrators,
        pressures: &pressures,
        damping,
        policy,
        dt: d.dt,
        t_end,
        xpbd_iterations: d.xpbd_iterations,
    };
    let runs::Done {
        csv,
        trace,
        table,
        failures,
    } = runs::run(&plan)?;
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
