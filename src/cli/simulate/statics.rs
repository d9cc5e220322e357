//! `bulge simulate` without `--dynamic`: the scene's mesh and the library's
//! sweep ([`bulge::pipeline::simulate_scene`]), printed and written.

use std::path::PathBuf;

use anyhow::{Context, anyhow};

use super::{Args, build_scene, describe, finish};
use crate::cli::{Classify, Failure};
use bulge::io::write_atomic;
use bulge::pipeline::{
    ModelRun, Outcome, PipelineError, SceneRequest, scene_mesh, simulate_scene, simulated_csv_with,
};
use bulge::sim::scene::MeshSize;
use bulge::sim::solve::Options;
use bulge::sim::springs::{HeightModel, SpringModel};
use bulge::sim::{SimError, vtk};

/// Runs `bulge simulate` (quasi-static).
pub(super) fn run(args: Args) -> Result<(), Failure> {
    let scene = build_scene(&args).bad_input()?;
    let models: Vec<SpringModel> = args
        .model
        .iter()
        .filter_map(|c| match c {
            HeightModel::Spring(m) => Some(*m),
            HeightModel::Axisym => None,
        })
        .collect();
    let axisym = args.model.contains(&HeightModel::Axisym);
    if args.profile.is_some() && !axisym {
        return Err(Failure::BadInput(anyhow!(
            "--profile writes the axisym meridian: add axisym to --model"
        )));
    }
    let mut opts = Options {
        tolerance: args.tolerance,
        ..Options::default()
    };
    if let Some(n) = args.max_iterations {
        opts.newton_iterations = n;
        opts.dr_steps = n;
    }
    opts.validate()
        .map_err(|e| anyhow!("--tolerance / --max-iterations: {e}"))
        .bad_input()?;
    let (mesh, sizing) = scene_mesh(&scene, &models, args.solver[0], opts)
        .map_err(|e| anyhow!("{e}"))
        .context("--accuracy or the mesh")
        .bad_input()?;
    if let (Some(s), Some(MeshSize::Accuracy(a))) = (sizing, scene.mesh.size) {
        eprintln!(
            "mesh sized for --accuracy {a}: {} rings, estimated relative height error {:.2e} (Richardson: {} against {} rings)",
            s.rings, s.estimated_error, s.rings, s.coarse_rings
        );
    }
    eprintln!("{}", describe(&mesh, &scene));
    for &model in &models {
        for w in bulge::sim::hard::mesh_warnings(&mesh, model, &scene.material, scene.thickness_m) {
            eprintln!("warning ({}): {w}", model.name());
        }
    }

    let request = SceneRequest {
        models,
        solvers: args.solver.clone(),
        axisym,
        profile: args.profile.is_some(),
        options: opts,
    };
    let runs = request.models.len() * request.solvers.len() + usize::from(axisym);
    let pb = crate::cli::progress((runs * scene.pressures_to_solve().len()) as u64, "simulate");
    let mut vtks: Vec<(PathBuf, String)> = Vec::new();
    let mut each = |s: &bulge::sim::SceneSolver, q: &bulge::sim::SweepPoint| {
        if let Some(dir) = &args.vtk {
            let (m, sv) = (s.model().name(), s.solver().name());
            let x = s.positions();
            let name = format!("{m}_{sv}_{:03}.vtk", q.index);
            let title = format!("bulge {m} {sv} {} Pa", q.pressure_pa);
            let stretch = s.membrane().triangle_stretch(x);
            vtks.push((dir.join(name), vtk::polydata(s.mesh(), x, &stretch, &title)));
        }
    };
    let out = simulate_scene(&scene, &mesh, &request, &mut each, &|| pb.inc(1));
    pb.finish_and_clear();
    let out = out.map_err(Failure::of::<PipelineError>)?;
    // a material whose modulus is not positive at a strain the sweep reached
    // is the user's material file, not a failure of the solver
    for r in &out.runs {
        if let Some(e @ SimError::NonPositiveModulus { .. }) = &r.stop
            && let Some(p) = r.points.iter().find(|p| p.outcome == Outcome::Failed)
        {
            return Err(Failure::BadInput(anyhow!(
                "{} / {} at {} Pa: {e}",
                r.model,
                r.solver,
                p.pressure_pa
            )));
        }
    }
    for r in &out.runs {
        at_floor_warning(r, opts.tolerance);
    }
    simulated_csv_with(&out.runs, &scene.extra_columns())
        .write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))
        .failed()?;
    if let (Some(path), Some(sol)) = (&args.profile, &out.axisym_last) {
        bulge::axisym::profile_csv(sol)
            .write(path)
            .with_context(|| format!("writing {}", path.display()))
            .failed()?;
    }
    for (path, text) in &vtks {
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
            .failed()?;
    }
    let failures: Vec<String> = out
        .runs
        .iter()
        .flat_map(|r| r.failures().map(|n| format!("{n} ({})", r.solver)))
        .collect();
    finish(
        "  pressure_pa     height_m      model  solver  iters  residual   wall_s",
        &table(&out.runs),
        &args.output,
        &failures,
        "the rows solved before",
    )
}

/// The terminal table: one line per pressure with a height.
fn table(runs: &[ModelRun]) -> Vec<String> {
    let mut lines = Vec::new();
    for r in runs {
        for p in r.points.iter().filter(|p| p.outcome.has_height()) {
            let solver = match (r.model, p.outcome) {
                (HeightModel::Axisym, _) => "shoot",
                (_, Outcome::Relaxed) => "dr",
                _ => r.solver.as_str(),
            };
            lines.push(format!(
                "{:>10} {:>12.6e} {:>10} {:>7} {:>6} {:>9.2e} {:>8.3}",
                p.pressure_pa,
                p.height_m.unwrap_or(f64::NAN),
                r.model.to_string(),
                solver,
                p.iterations,
                p.residual,
                p.wall_s
            ));
        }
    }
    lines
}

/// One warning per run for the pressures whose residual stopped above
/// `--tolerance` at the round-off floor ([`Outcome::AtFloor`]).
fn at_floor_warning(run: &ModelRun, tolerance: f64) {
    let at_floor: Vec<_> = run
        .points
        .iter()
        .filter(|p| p.outcome == Outcome::AtFloor)
        .collect();
    if at_floor.is_empty() {
        return;
    }
    let worst = at_floor.iter().fold(0.0_f64, |a, p| a.max(p.residual));
    let ps: Vec<String> = at_floor.iter().map(|p| p.pressure_pa.to_string()).collect();
    eprintln!(
        "warning ({} / {}): at {} Pa the residual (largest {worst:.2e} of the load) stopped above --tolerance {tolerance:e}, at the round-off floor of double precision here (the membrane's internal forces dwarf the pressure's); those heights carry a relative error of about that size",
        run.model,
        run.solver,
        ps.join(", ")
    );
}
