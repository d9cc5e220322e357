//! `bulge simulate --dynamic`: time integration of a scene under a load step
//! ([`bulge::pipeline::simulate_dynamic`]; see `docs/dynamics.md`).

use std::path::PathBuf;

use anyhow::Context;

use super::{Args, build_scene, finish};
use crate::cli::{Classify, Failure};
use bulge::io::write_atomic;
use bulge::pipeline::{DynamicRequest, simulate_dynamic};
use bulge::sim::dynamics::Integrator;

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
    let req = DynamicRequest {
        scene: &scene,
        models: &args.model,
        integrators: &d.integrator,
        dt: d.dt,
        t_end: d.t_end,
        damping: d.damping,
        damping_law: &d.damping_law,
        step_policy: &d.step_policy,
        xpbd_iterations: d.xpbd_iterations,
    };
    let runs = args.model.len() * d.integrator.len() * scene.pressures_to_solve().len();
    let pb = crate::cli::progress(runs as u64, "dynamic");
    let out = simulate_dynamic(&req, &|| pb.inc(1));
    pb.finish_and_clear();
    let out = out.map_err(Failure::of)?;
    for n in &out.notes {
        eprintln!("{n}");
    }
    for w in &out.warnings {
        eprintln!("warning {w}");
    }
    out.csv
        .write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))
        .failed()?;
    if let Some(t) = &d.trace {
        write_atomic(t, &out.trace.into_bytes())
            .with_context(|| format!("writing {}", t.display()))
            .failed()?;
    }
    finish(
        "  pressure_pa    model       integrator      final_m       peak_m     static_m       dt_s    steps   wall_s",
        &out.table,
        &args.output,
        &out.failures,
        "the runs that finished",
    )
}
