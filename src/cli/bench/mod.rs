//! `bulge bench`: speed against error of every solver and integrator, on the
//! disc bubble (error against the exact axisymmetric solution) and on paper
//! Sudhamani & Merriliance's sheet (error against a converged static solution of the same mesh).
//! Writes `bench.csv`, `bench.md` and `bench.png` (log wall time against log
//! error, with each case's Pareto front); with `--paper003` also
//! `paper003.md`, Sudhamani & Merriliance's (2019) three experiments and the disc's pressure step
//! (see `docs/dynamics.md`).

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, anyhow};
use nalgebra::Vector3;

mod paper003;

use crate::cli::{Classify, Failure};
use bulge::experiment::Specimen;
use bulge::io::{CsvOut, fmt_num, write_atomic};
use bulge::report::plot::{Figure, Panel, Series};
use bulge::sim::dynamics::{DampingLaw, DynOptions, Dynamics, Integrator};
use bulge::sim::mesh::Mesh;
use bulge::sim::scene::DiscPredictor;
use bulge::sim::solve::{self, Options, Solver};
use bulge::sim::springs::{Membrane, SpringModel};
use paper003::SheetSetup;

/// Flags of `bulge bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder for bench.csv, bench.md and bench.png (created; files in
    /// it with those names are replaced). Default `bench`.
    #[arg(long, default_value = "bench")]
    pub out: PathBuf,
    /// Small meshes and one tolerance only: a few seconds (for tests and a
    /// first look). The default set takes one to two minutes in a release
    /// build on one core.
    #[arg(long)]
    pub quick: bool,
    /// Also reproduce Sudhamani & Merriliance's (2019) experiments (time against points, largest
    /// stable step per integrator, deformation against load) and the disc's
    /// pressure step into paper003.md. Several minutes (less with --quick).
    #[arg(long)]
    pub paper003: bool,
}

/// One measured run.
#[derive(Debug, Clone)]
struct Entry {
    case: &'static str,
    method: String,
    model: SpringModel,
    nodes: usize,
    tolerance: f64,
    wall_s: f64,
    steps: usize,
    error: Option<f64>,
    status: String,
}

const DISC_P: f64 = 5000.0;
const A: f64 = 0.0375;
const T: f64 = 0.35e-3;

fn disc_reference() -> anyhow::Result<f64> {
    let (_, mat) = paper003::bubble_disc(2);
    let spec = Specimen {
        radius_m: A,
        thickness_m: T,
        poisson: mat.poisson,
        prebulge_height_m: 0.0,
    };
    let sol =
        bulge::axisym::solve_pressure(&mat, &spec, DISC_P, &bulge::axisym::Options::default())
            .map_err(|e| anyhow!("axisymmetric reference: {e}"))?;
    Ok(sol.height_m)
}

/// A static solve of a prepared membrane from rest: (wall, iterations, result).
fn static_run(
    mem: &mut Membrane,
    mesh: &Mesh,
    solver: Solver,
    tol: f64,
    disc: bool,
    measure: &dyn Fn(&[nalgebra::Point3<f64>]) -> f64,
) -> (f64, usize, Result<f64, String>, String) {
    let mut x = mesh.nodes.clone();
    let opts = Options {
        tolerance: tol,
        ..Options::default()
    };
    let pred = DiscPredictor {
        radius_m: A,
        young_pa: 1.0e6,
        thickness_m: T,
        poisson: 0.45,
    };
    let mut ws = None;
    let t0 = Instant::now();
    let p = mem.pressure_pa;
    let predictor: &dyn solve::Predictor = if disc { &pred } else { &solve::Stay };
    let out = solve::continuation(
        mem,
        &mesh.nodes,
        &mut x,
        0.0,
        p,
        solver,
        &opts,
        predictor,
        &mut ws,
    );
    let wall = t0.elapsed().as_secs_f64();
    match out {
        Ok(s) => (wall, s.iterations, Ok(measure(&x)), "ok".into()),
        Err(e) => (wall, 0, Err(e.to_string()), String::new()),
    }
}

#[allow(clippy::too_many_arguments)]
fn dynamic_run(
    mem: &mut Membrane,
    mesh: &Mesh,
    integ: Integrator,
    step_factor: f64,
    damping: DampingLaw,
    tol: f64,
    t_cap: f64,
    measure: &dyn Fn(&[nalgebra::Point3<f64>]) -> f64,
) -> (f64, usize, Result<f64, String>, String) {
    let t0 = Instant::now();
    let out = (|| -> Result<(f64, usize, bool, f64), String> {
        let mut d = Dynamics::new(mem, mesh, damping).map_err(|e| e.to_string())?;
        let est = d.estimate_step(&mesh.nodes).map_err(|e| e.to_string())?;
        let dt = step_factor * est.limit(Integrator::Verlet);
        // XPBD's projections are serial and it settles to its own (compliant,
        // under-iterated) state: at most 3000 steps
        let t_cap = if integ == Integrator::Xpbd {
            t_cap.min(3000.0 * dt)
        } else {
            t_cap
        };
        let steps = (t_cap / dt).ceil();
        let opts = DynOptions {
            integrator: integ,
            dt_s: dt,
            t_end_s: t_cap,
            damping,
            settle_tolerance: Some(tol),
            max_samples: ((steps / 20.0) as usize).clamp(10, 1_000_000),
            ..DynOptions::default()
        };
        let mut x = mesh.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let run = d
            .run(&mut x, &mut v, &opts, measure)
            .map_err(|e| e.to_string())?;
        let settled = (run.steps as f64) < steps - 0.5;
        Ok((measure(&x), run.steps * run.substeps, settled, t_cap))
    })();
    let wall = t0.elapsed().as_secs_f64();
    match out {
        Ok((v, steps, true, _)) => (wall, steps, Ok(v), "ok".into()),
        Ok((v, steps, false, t)) => (
            wall,
            steps,
            Ok(v),
            format!("not settled to the tolerance by t = {t:.3e} s (error at that time)"),
        ),
        Err(e) => (wall, 0, Err(e), String::new()),
    }
}

fn entry(
    case: &'static str,
    method: &str,
    model: SpringModel,
    nodes: usize,
    tol: f64,
    r: (f64, usize, Result<f64, String>, String),
    reference: f64,
) -> Entry {
    let (wall_s, steps, out, note) = r;
    let (error, status) = match out {
        Ok(v) => (Some(((v - reference) / reference).abs()), note),
        Err(e) => (None, e),
    };
    Entry {
        case,
        method: method.to_string(),
        model,
        nodes,
        tolerance: tol,
        wall_s,
        steps,
        error,
        status,
    }
}

fn run_bench(quick: bool) -> anyhow::Result<Vec<Entry>> {
    let mut out = Vec::new();
    // --- the disc bubble ---
    let href = disc_reference()?;
    let rings: &[usize] = if quick { &[3, 5] } else { &[4, 8, 16, 32] };
    let dyn_rings: &[usize] = if quick { &[3] } else { &[4, 8] };
    let tols: &[f64] = if quick { &[1e-3] } else { &[1e-3, 1e-6] };
    let pb = super::progress(0, "bench");
    let (_, mat) = paper003::bubble_disc(2);
    for &n in rings {
        let (mesh, _) = paper003::bubble_disc(n);
        let measure = |x: &[nalgebra::Point3<f64>]| x[0].z;
        for &model in &[SpringModel::Tp, SpringModel::VanGelder] {
            for solver in [Solver::Newton, Solver::Dr] {
                if solver == Solver::Dr && n > 16 {
                    continue;
                }
                for &tol in tols {
                    let mut mem = Membrane::new(&mesh, model, &mat, T, 1100.0)?;
                    mem.pressure_pa = DISC_P;
                    let r = static_run(&mut mem, &mesh, solver, tol, true, &measure);
                    out.push(entry(
                        "disc",
                        solver.name(),
                        model,
                        mesh.nodes.len(),
                        tol,
                        r,
                        href,
                    ));
                    pb.tick();
                }
            }
        }
        if !dyn_rings.contains(&n) {
            continue;
        }
        for integ in Integrator::ALL {
            let (model, factor) = match integ {
                Integrator::Xpbd => (SpringModel::VanGelder, 10.0),
                Integrator::ImplicitEuler => (SpringModel::Tp, 30.0),
                _ => (SpringModel::Tp, 0.9),
            };
            for &tol in tols {
                let mut mem = Membrane::new(&mesh, model, &mat, T, 1100.0)?;
                mem.pressure_pa = DISC_P;
                let r = dynamic_run(
                    &mut mem,
                    &mesh,
                    integ,
                    factor,
                    DampingLaw::Critical(1.0),
                    tol,
                    0.5,
                    &measure,
                );
                out.push(entry(
                    "disc",
                    integ.name(),
                    model,
                    mesh.nodes.len(),
                    tol,
                    r,
                    href,
                ));
                pb.tick();
            }
        }
    }
    // --- Sudhamani & Merriliance's (2019) sheet, loaded at the middle with 10 N/m ---
    let setup = SheetSetup::default();
    let points: &[usize] = if quick { &[60] } else { &[200, 1000] };
    let dyn_points: usize = if quick { 60 } else { 200 };
    for &np in points {
        let mesh = setup.mesh(np);
        let node = mesh.probe("middle").expect("sheet probe");
        let measure = |x: &[nalgebra::Point3<f64>]| (x[node] - mesh.nodes[node]).norm();
        let mut mem = setup.membrane(&mesh, "middle", 10.0);
        let xs = paper003::static_solution(&mut mem, &mesh, 2)?;
        let uref = measure(&xs);
        for solver in [Solver::Newton, Solver::Dr] {
            for &tol in tols {
                let mut m = setup.membrane(&mesh, "middle", 10.0);
                let r = static_run(&mut m, &mesh, solver, tol, false, &measure);
                out.push(entry(
                    "sheet",
                    solver.name(),
                    setup.model,
                    mesh.nodes.len(),
                    tol,
                    r,
                    uref,
                ));
                pb.tick();
            }
        }
        if mesh.nodes.len() > 2 * dyn_points {
            continue;
        }
        for integ in Integrator::ALL {
            let factor = match integ {
                Integrator::Xpbd => 10.0,
                Integrator::ImplicitEuler => 30.0,
                _ => 0.9,
            };
            for &tol in tols {
                let mut m = setup.membrane(&mesh, "middle", 10.0);
                let r = dynamic_run(
                    &mut m,
                    &mesh,
                    integ,
                    factor,
                    DampingLaw::Critical(1.0),
                    tol,
                    60.0,
                    &measure,
                );
                out.push(entry(
                    "sheet",
                    integ.name(),
                    setup.model,
                    mesh.nodes.len(),
                    tol,
                    r,
                    uref,
                ));
                pb.tick();
            }
        }
    }
    pb.finish_and_clear();
    Ok(out)
}

/// Indices of the entries on the Pareto front of one case (no other entry
/// is both faster and more accurate), by increasing wall time.
fn pareto(entries: &[Entry], case: &str) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..entries.len())
        .filter(|&i| {
            entries[i].case == case && entries[i].error.is_some() && entries[i].status == "ok"
        })
        .collect();
    idx.sort_by(|&a, &b| entries[a].wall_s.total_cmp(&entries[b].wall_s));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        let e = entries[i].error.expect("filtered");
        if e < best {
            best = e;
            front.push(i);
        }
    }
    front
}

fn markdown(entries: &[Entry]) -> String {
    let mut s = String::new();
    for case in ["disc", "sheet"] {
        let front = pareto(entries, case);
        let _ = writeln!(
            s,
            "\n### {}\n\n| method | model | nodes | tolerance | wall_s | steps | relative error | Pareto | status |\n|---|---|---|---|---|---|---|---|---|",
            if case == "disc" {
                "Disc bubble (a = 37.5 mm, t = 0.35 mm, E = 1 MPa, nu = 0.45, 5 kPa): error of the apex height against the axisymmetric solution"
            } else {
                "the Sudhamani & Merriliance sheet (0.1 m, E = 50 kPa, 10 N/m at the middle): error of the loaded node's displacement against Newton at 1e-10 on the same mesh"
            }
        );
        for (i, e) in entries.iter().enumerate().filter(|(_, e)| e.case == case) {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.0e} | {:.4} | {} | {} | {} | {} |",
                e.method,
                e.model.name(),
                e.nodes,
                e.tolerance,
                e.wall_s,
                e.steps,
                e.error
                    .map(|v| format!("{v:.2e}"))
                    .unwrap_or_else(|| "-".into()),
                if front.contains(&i) { "yes" } else { "" },
                e.status.replace('|', "/")
            );
        }
    }
    s
}

fn plot(entries: &[Entry]) -> Figure {
    let methods = [
        "newton",
        "dr",
        "explicit-euler",
        "symplectic-euler",
        "verlet",
        "implicit-euler",
        "xpbd",
    ];
    let mut panels = Vec::new();
    for case in ["disc", "sheet"] {
        let mut panel =
            Panel::new("log10 wall time (s)", "log10 relative error").titled(if case == "disc" {
                "disc bubble against the axisymmetric solution"
            } else {
                "the Sudhamani & Merriliance sheet against the converged static solution"
            });
        for (k, m) in methods.iter().enumerate() {
            let pts: Vec<(f64, f64)> = entries
                .iter()
                .filter(|e| e.case == case && e.method == *m)
                .filter_map(|e| {
                    e.error
                        .map(|err| (e.wall_s.max(1e-6).log10(), err.max(1e-16).log10()))
                })
                .collect();
            if !pts.is_empty() {
                panel = panel.with(Series::scatter(*m, pts).color(k));
            }
        }
        let front: Vec<(f64, f64)> = pareto(entries, case)
            .into_iter()
            .map(|i| {
                let e = &entries[i];
                (
                    e.wall_s.max(1e-6).log10(),
                    e.error.expect("front").max(1e-16).log10(),
                )
            })
            .collect();
        if !front.is_empty() {
            panel = panel.with(Series::line("Pareto front", front).dashed().color(7));
        }
        panels.push(panel);
    }
    Figure::new("bulge bench: speed against error", panels).size(900, 1100)
}

/// Runs `bulge bench`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out, "--out")?;
    if args.out.exists() && !args.out.is_dir() {
        return Err(Failure::BadInput(anyhow!(
            "--out {} is a file; give a folder (it is created if missing)",
            args.out.display()
        )));
    }
    let entries = run_bench(args.quick).failed()?;
    let mut csv = CsvOut::new(&[
        "case",
        "method",
        "model",
        "nodes",
        "tolerance",
        "wall_s",
        "steps",
        "relative_error",
        "pareto",
        "status",
    ]);
    let fronts: Vec<usize> = ["disc", "sheet"]
        .iter()
        .flat_map(|c| pareto(&entries, c))
        .collect();
    for (i, e) in entries.iter().enumerate() {
        csv.row(&[
            e.case.to_string(),
            e.method.clone(),
            e.model.name().to_string(),
            e.nodes.to_string(),
            format!("{:e}", e.tolerance),
            format!("{:.6}", e.wall_s),
            e.steps.to_string(),
            fmt_num(e.error),
            (fronts.contains(&i) as u8).to_string(),
            e.status.clone(),
        ]);
    }
    let md = markdown(&entries);
    let fig = plot(&entries);
    let paper = if args.paper003 {
        Some(paper003_tables(args.quick).failed()?)
    } else {
        None
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))
        .failed()?;
    csv.write(&args.out.join("bench.csv"))
        .context("writing bench.csv")
        .failed()?;
    write_atomic(&args.out.join("bench.md"), md.as_bytes())
        .context("writing bench.md")
        .failed()?;
    fig.write_png(&args.out.join("bench.png"))
        .map_err(|e| anyhow!("{e}"))
        .failed()?;
    if let Some(p) = &paper {
        write_atomic(&args.out.join("paper003.md"), p.as_bytes())
            .context("writing paper003.md")
            .failed()?;
    }
    println!("{md}");
    if let Some(p) = &paper {
        println!("{p}");
    }
    println!(
        "wrote {}/bench.csv, bench.md, bench.png{}",
        args.out.display(),
        if paper.is_some() { ", paper003.md" } else { "" }
    );
    Ok(())
}

/// Sudhamani & Merriliance's (2019) three experiments and the disc pressure step, as Markdown.
#[allow(clippy::approx_constant)] // Sudhamani & Merriliance (2019) Table 2.2.1 reports 3.14 s
fn paper003_tables(quick: bool) -> anyhow::Result<String> {
    let setup = SheetSetup::default();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Sheet: {} m square, t = {} m, E = {} Pa, nu = {}, rho = {} kg/m^3, {} springs, damping {:?} of each spring's critical value; in-plane load along -y, force per unit thickness.\n",
        setup.side_m,
        setup.thickness_m,
        setup.young_pa,
        setup.poisson,
        setup.density_kg_m3,
        setup.model.name(),
        setup.damping
    );
    // Table 2.2.1
    let points: &[usize] = if quick {
        &[60, 120]
    } else {
        &[200, 500, 1000, 2000, 4000]
    };
    // Sudhamani & Merriliance (2019) Table 2.2.1 as published (3.14 s is a time, not pi).
    #[allow(clippy::approx_constant)]
    let paper_time = [
        (200, 0.5, 0.3),
        (500, 1.7, 1.2),
        (1000, 2.78, 2.0),
        (2000, 3.14, 2.67),
        (4000, 3.96, 3.12),
    ];
    let t_end = 1.0;
    let rows = paper003::time_table(
        &setup,
        points,
        &[
            Integrator::ExplicitEuler,
            Integrator::Verlet,
            Integrator::ImplicitEuler,
        ],
        10.0,
        t_end,
    )?;
    let _ = writeln!(
        s,
        "#### Computation time against points (Sudhamani & Merriliance 2019, Table 2.2.1)\n\n{t_end} s simulated, 10 N/m at the middle, from rest; step 0.9 of Verlet's estimated limit for every integrator (explicit Euler sub-steps to 0.9 of its own). One core.\n\n| points (published) | published Euler s | published Verlet s | points | dt_s | explicit Euler s (sub-steps) | Verlet s | implicit Euler s | u(t_end) / u_static, Verlet |\n|---|---|---|---|---|---|---|---|---|"
    );
    let mut pts: Vec<usize> = rows.iter().map(|r| r.points).collect();
    pts.dedup();
    for (k, &np) in pts.iter().enumerate() {
        // Sudhamani & Merriliance's sizes only beside the full set (the quick one is smaller).
        let paper = if quick {
            None
        } else {
            paper_time.get(k).copied()
        };
        let get = |i: Integrator| rows.iter().find(|r| r.points == np && r.integrator == i);
        let (ee, vv) = (
            get(Integrator::ExplicitEuler).expect("explicit Euler row"),
            get(Integrator::Verlet).expect("Verlet row"),
        );
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.3e} | {:.3} ({}) | {:.3} | {} | {:.3} |",
            paper.map(|p| p.0.to_string()).unwrap_or_default(),
            paper.map(|p| p.1.to_string()).unwrap_or_default(),
            paper.map(|p| p.2.to_string()).unwrap_or_default(),
            np,
            vv.dt_s,
            ee.wall_s,
            ee.substeps,
            vv.wall_s,
            get(Integrator::ImplicitEuler)
                .map(|r| format!("{:.3}", r.wall_s))
                .unwrap_or_else(|| "-".into()),
            vv.displacement_m / vv.static_m
        );
    }
    // Table 2.2.2
    let np = if quick { 120 } else { 1000 };
    let rows = paper003::step_table(
        &setup,
        np,
        10.0,
        if quick { 600 } else { 1500 },
        &Integrator::ALL,
    )?;
    let paper_step = |i: Integrator| match i {
        Integrator::ExplicitEuler => "0.5",
        Integrator::ImplicitEuler => "49.0",
        Integrator::Verlet => "11.5",
        _ => "-",
    };
    let _ = writeln!(
        s,
        "\n#### Largest stable step (Sudhamani & Merriliance 2019, Table 2.2.2)\n\n{} points, at the static equilibrium under 10 N/m; stiffest mode {:.1} rad/s (power iteration; Gershgorin bound {:.1}), its damping ratio {:.3}. Measured: bisection to 1 %, a velocity along the stiffest mode integrated for the stated steps, stable when the kinetic energy has not grown.\n\n| integrator | published step ms | estimate ms | measured ms | measured / estimate |\n|---|---|---|---|---|",
        np, rows[0].omega[0], rows[0].omega[2], rows[0].omega[1]
    );
    for r in &rows {
        let est = if r.estimate_s.is_finite() {
            format!("{:.4}", r.estimate_s * 1e3)
        } else {
            "none (unconditionally stable)".into()
        };
        let meas = match r.measured_s {
            Some(m) => format!("{:.4}", m * 1e3),
            None => format!("stable up to {:.1}", r.tried_s * 1e3),
        };
        let ratio = match r.measured_s {
            Some(m) if r.estimate_s.is_finite() => format!("{:.3}", m / r.estimate_s),
            _ => "-".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            r.integrator.name(),
            paper_step(r.integrator),
            est,
            meas,
            ratio
        );
    }
    // Table 2.2.3
    let loads = [0.0, 2.0, 4.0, 6.0, 8.0, 10.0];
    let paper_def = [
        (0.0, 0.0),
        (1.583356, 1.298453),
        (3.248017, 1.972952),
        (4.183456, 2.7839),
        (9.492629, 6.93582),
        (12.423452, 8.1674),
    ];
    let np = if quick { 120 } else { 1000 };
    let t3 = 2.0;
    let _ = writeln!(
        s,
        "\n#### Deformation against load (Sudhamani & Merriliance 2019, Table 2.2.3)\n\n{np} points; displacement of the loaded node; \"error\" = |u(t = {t3} s) - u_static| after {t3} s from rest at 0.9 of Verlet's step limit.\n"
    );
    for at in ["middle", "corner"] {
        let rows = paper003::load_table(
            &setup,
            np,
            at,
            &loads,
            &[
                Integrator::ExplicitEuler,
                Integrator::Verlet,
                Integrator::ImplicitEuler,
            ],
            t3,
        )?;
        let _ = writeln!(
            s,
            "Load at the {at}:\n\n| N/m | published Euler mm | published Verlet mm | static u mm | explicit Euler error mm | Verlet error mm | implicit Euler error mm |\n|---|---|---|---|---|---|---|"
        );
        for (r, p) in rows.iter().zip(paper_def) {
            let err = |k: usize| (r.dynamic_m[k].1 - r.static_m).abs() * 1e3;
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
                r.q_n_m,
                p.0,
                p.1,
                r.static_m * 1e3,
                err(0),
                err(1),
                err(2)
            );
        }
        let _ = writeln!(s);
    }
    // Disc pressure step
    let rings = if quick { 4 } else { 8 };
    let hs = paper003::disc_static(rings, SpringModel::Tp, DISC_P)?;
    let href = disc_reference()?;
    let _ = writeln!(
        s,
        "#### Sudden pressure step on the disc\n\n{DISC_P} Pa applied at t = 0 on the flat bubble disc (a = 37.5 mm, t = 0.35 mm, E = 1 MPa, nu = 0.45, rho = 1100 kg/m^3, tp, 60 degree sector of {rings} rings); static height (Newton) {:.5e} m, axisymmetric {:.5e} m. Settling: last time outside 2 % of the static height.\n\n| integrator | damping | dt_s | peak m | overshoot | settling s | final m | final / static | steps | wall s |\n|---|---|---|---|---|---|---|---|---|---|",
        hs, href
    );
    let (mesh, mat) = paper003::bubble_disc(rings);
    let vl = {
        let mut mem = Membrane::new(&mesh, SpringModel::Tp, &mat, T, 1100.0)?;
        mem.pressure_pa = DISC_P;
        let d = Dynamics::new(&mut mem, &mesh, DampingLaw::Critical(1.0))?;
        d.estimate_step(&mesh.nodes)?.limit(Integrator::Verlet)
    };
    for (integ, z, f) in [
        (Integrator::Verlet, 0.1, 0.9),
        (Integrator::Verlet, 1.0, 0.9),
        (Integrator::SymplecticEuler, 1.0, 0.9),
        (Integrator::ExplicitEuler, 1.0, 0.9),
        (Integrator::ImplicitEuler, 1.0, 0.9),
        (Integrator::ImplicitEuler, 1.0, 10.0),
    ] {
        let r = paper003::pressure_step(
            rings,
            SpringModel::Tp,
            DISC_P,
            integ,
            f * vl,
            0.1,
            DampingLaw::Critical(z),
            hs,
        )?;
        let _ = writeln!(
            s,
            "| {} | {z} | {:.3e} | {:.5e} | {:.3} | {:.4} | {:.5e} | {:.5} | {} | {:.3} |",
            integ.name(),
            r.dt_s,
            r.peak_m,
            r.overshoot,
            r.settling_s,
            r.final_m,
            r.final_m / hs,
            r.steps,
            r.wall_s
        );
    }
    Ok(s)
}
