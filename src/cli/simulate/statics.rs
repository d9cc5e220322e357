//! `bulge simulate` without `--dynamic`: the library's sweep of the scene
//! ([`bulge::pipeline::simulate_static`]), printed and written.

use std::path::PathBuf;

use anyhow::{Context, anyhow};

use super::{Args, build_scene, finish};
use crate::cli::{Classify, Failure};
use bulge::io::write_atomic;
use bulge::pipeline::{ModelRun, Outcome, StaticError, simulate_static};
use bulge::sim::solve::Options;
use bulge::sim::springs::HeightModel;
use bulge::sim::vtk;

/// Runs `bulge simulate` (quasi-static).
pub(super) fn run(args: Args) -> Result<(), Failure> {
    let scene = build_scene(&args).bad_input()?;
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
    let springs = args
        .model
        .iter()
        .filter(|m| **m != HeightModel::Axisym)
        .count();
    let runs = springs * args.solver.len() + usize::from(axisym);
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
    let out = simulate_static(
        &scene,
        &args.model,
        &args.solver,
        opts,
        args.profile.is_some(),
        &mut each,
        &|| pb.inc(1),
    );
    pb.finish_and_clear();
    let out = out.map_err(|e| match e {
        StaticError::Mesh(m) => Failure::BadInput(anyhow!("--accuracy or the mesh: {m}")),
        e => Failure::of(e),
    })?;
    for n in &out.notes {
        eprintln!("{n}");
    }
    for w in &out.warnings {
        eprintln!("warning {w}");
    }
    out.simulated
        .write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))
        .failed()?;
    if let (Some(path), Some(csv)) = (&args.profile, out.profile) {
        csv.write(path)
            .with_context(|| format!("writing {}", path.display()))
            .failed()?;
    }
    for (path, text) in &vtks {
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
            .failed()?;
    }
    finish(
        "  pressure_pa     height_m      model  solver  iters  residual   wall_s",
        &table(&out.runs),
        &args.output,
        &out.failures,
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
