//! `bulge simulate` without `--dynamic`: each spring model and quasi-static
//! solver swept over the scene's pressures ([`bulge::sim::SceneSolver`]).

use std::path::PathBuf;

use anyhow::{Context, anyhow};

use super::{Args, build_scene, describe, finish};
use crate::cli::{Classify, Failure};
use bulge::io::{CsvOut, fmt_num, write_atomic};
use bulge::sim::disc::mesh_for_accuracy;
use bulge::sim::scene::{MeshSize, SceneKind};
use bulge::sim::solve::Options;
use bulge::sim::springs::{HeightModel, SpringModel};
use bulge::sim::{SceneSolver, SimError, vtk};

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
    let mesh = match (scene.mesh.size, scene.kind) {
        (Some(MeshSize::Accuracy(a)), SceneKind::Disc { .. }) if !models.is_empty() => {
            let s = mesh_for_accuracy(
                &scene,
                &models,
                args.solver[0],
                opts,
                a,
                scene.mesh.max_nodes,
            )
            .context("--accuracy")
            .bad_input()?;
            eprintln!(
                "mesh sized for --accuracy {a}: {} rings, estimated relative height error {:.2e} (Richardson: {} against {} rings)",
                s.rings, s.estimated_error, s.rings, s.coarse_rings
            );
            s.mesh
        }
        _ => scene
            .build_mesh_for(&models)
            .context("building the mesh")
            .bad_input()?,
    };
    eprintln!("{}", describe(&mesh, &scene));
    for &model in &models {
        for w in bulge::sim::hard::mesh_warnings(&mesh, model, &scene.material, scene.thickness_m) {
            eprintln!("warning ({}): {w}", model.name());
        }
    }

    let mut header: Vec<&str> = bulge::pipeline::SIMULATED_COLUMNS.to_vec();
    header.extend(scene.extra_columns());
    let mut csv = CsvOut::new(&header);
    let mut vtks: Vec<(PathBuf, String)> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    let mut table = Vec::new();
    let runs = models.len() * args.solver.len() + usize::from(axisym);
    let pressures = scene.pressures_to_solve();
    let n_p = pressures.len();
    let pb = crate::cli::progress((runs * n_p) as u64, "simulate");
    let mut profile_out = None;
    if axisym {
        profile_out = super::axisym::run_axisym(
            &scene,
            header.len(),
            &mut csv,
            &mut table,
            &mut failures,
            args.profile.as_deref(),
            &pb,
        )?;
    }
    for &model in &models {
        for &solver in &args.solver {
            let mut s = SceneSolver::on_mesh(&scene, mesh.clone(), model)
                .and_then(|s| s.with_solver(solver, opts))
                .map_err(|e| anyhow!("{e}"))
                .bad_input()?;
            let (m, sv) = (model.name(), solver.name());
            let mut at_floor: Vec<(f64, f64)> = Vec::new();
            let swept = s.sweep(&pressures, |s, q| {
                pb.inc(1);
                if q.stats.residual > opts.tolerance {
                    at_floor.push((q.pressure_pa, q.stats.residual));
                }
                // Newton found the dome turned inside out, or none, on a
                // slack dome: the equilibrium is dynamic relaxation's.
                let sv = if q.stats.relaxed { "dr" } else { sv };
                let mut row = vec![
                    fmt_num(Some(q.pressure_pa)),
                    fmt_num(Some(q.height_m)),
                    m.to_string(),
                    sv.to_string(),
                    mesh.nodes.len().to_string(),
                    q.stats.iterations.to_string(),
                    format!("{:.3e}", q.stats.residual),
                    format!("{:.4}", q.wall_s),
                ];
                row.extend(q.extra.iter().map(|v| fmt_num(Some(*v))));
                csv.row(&row);
                table.push(format!(
                    "{:>10} {:>12.6e} {:>10} {:>7} {:>6} {:>9.2e} {:>8.3}",
                    q.pressure_pa,
                    q.height_m,
                    m,
                    sv,
                    q.stats.iterations,
                    q.stats.residual,
                    q.wall_s
                ));
                if let Some(dir) = &args.vtk {
                    let x = s.positions();
                    let name = format!("{m}_{sv}_{:03}.vtk", q.index);
                    let title = format!("bulge {m} {sv} {} Pa", q.pressure_pa);
                    let stretch = s.membrane().triangle_stretch(x);
                    vtks.push((dir.join(name), vtk::polydata(&mesh, x, &stretch, &title)));
                }
            });
            if !at_floor.is_empty() {
                let worst = at_floor.iter().fold(0.0_f64, |a, r| a.max(r.1));
                let ps: Vec<String> = at_floor.iter().map(|r| r.0.to_string()).collect();
                pb.suspend(|| {
                    eprintln!(
                        "warning ({m} / {sv}): at {} Pa the residual (largest {worst:.2e} of the load) stopped above --tolerance {:e}, at the round-off floor of double precision here (the membrane's internal forces dwarf the pressure's); those heights carry a relative error of about that size",
                        ps.join(", "),
                        opts.tolerance
                    )
                });
            }
            if let Err((_, stop)) = swept {
                let p = stop.pressure_pa;
                if let e @ SimError::NonPositiveModulus { .. } = &stop.error {
                    pb.finish_and_clear();
                    return Err(Failure::BadInput(anyhow!("{m} / {sv} at {p} Pa: {e}")));
                }
                let mut msg = format!("{m} / {sv}: {}", stop.error);
                // the disc's limit pressure from the axisymmetric solution
                if let SceneKind::Disc { radius_m, .. } = scene.kind
                    && let Some(note) = bulge::sim::hard::limit_note(
                        &scene.material,
                        radius_m,
                        scene.thickness_m,
                        p,
                    )
                {
                    msg.push_str(&format!(" ({note})"));
                }
                failures.push(msg);
                pb.inc((n_p - stop.index) as u64);
            }
        }
    }
    pb.finish_and_clear();
    csv.write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))
        .failed()?;
    if let (Some(path), Some(prof)) = (&args.profile, profile_out) {
        prof.write(path)
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
        &table,
        &args.output,
        &failures,
        "the rows solved before",
    )
}
