//! `bulge simulate`: material -> simulated bubble heights with the
//! mass-spring membrane models (see `docs/simulate.md`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, anyhow};

use super::{Classify, Failure};

mod dynamic;
use bulge::experiment::Experiment;
use bulge::io::{CsvOut, fmt_num, read_toml, write_atomic};
use bulge::material::Material;
use bulge::sim::mesh::Mesh;
use bulge::sim::scene::{self, DiscPredictor, MeshSize, Scene, SceneKind};
use bulge::sim::solve::{self, Options, Predictor, Solver, Stay};
use bulge::sim::springs::SpringModel;
use bulge::sim::{SimError, vtk};

/// Flags of `bulge simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene file (TOML): `kind` = disc | sphere-segment | sheet, the geometry
    /// in metres, `pressure_pa` = [...], `[material]` (or `material = "path"`)
    /// and `[mesh]`. Format in docs/simulate.md. Or use --experiment.
    pub scene: Option<PathBuf>,
    /// Experiment file whose `[specimen]` gives the clamped disc (radius_m,
    /// thickness_m); needs --material and --pressures.
    #[arg(long, conflicts_with = "scene")]
    pub experiment: Option<PathBuf>,
    /// Material file (material.toml as `bulge fit` writes it). Required with
    /// --experiment; with a scene it replaces the scene's material.
    #[arg(long)]
    pub material: Option<PathBuf>,
    /// Pressures in Pa, comma-separated, solved in this order, each continued
    /// from the previous (e.g. 5000,7300,8940). Replaces the scene's list.
    #[arg(long)]
    pub pressures: Option<String>,
    /// Models, comma-separated, one output row each per pressure:
    /// tp (TP MSS force form, default), tp-paper (eq 11 with the eq 16
    /// switch), van-gelder (eq 1), lloyd (eq 4), axisym (the exact
    /// axisymmetric membrane solution, disc only; solver `shooting`).
    #[arg(long, default_value = "tp")]
    pub model: String,
    /// Quasi-static solvers, comma-separated: newton (sparse LU, default) or
    /// dr (dynamic relaxation with kinetic damping).
    #[arg(long, default_value = "newton")]
    pub solver: String,
    /// Output CSV: pressure_pa,height_m,model,solver,nodes,iterations,residual,wall_s
    /// (the sphere segment adds its radii).
    #[arg(short, long, default_value = "simulated.csv")]
    pub output: PathBuf,
    /// Folder for the deformed meshes as VTK (one file per model, solver and
    /// pressure), for ParaView. Default: none written.
    #[arg(long)]
    pub vtk: Option<PathBuf>,
    /// Residual force relative to the load at which a solve stops. Default 1e-8.
    #[arg(long, default_value_t = 1e-8)]
    pub tolerance: f64,
    /// Cap on iterations per pressure step (Newton iterations, default 40; or
    /// relaxation steps, default 200000).
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Mesh: target edge length in m (replaces the scene's [mesh] size).
    #[arg(long, conflicts_with_all = ["nodes", "accuracy"])]
    pub edge_length: Option<f64>,
    /// Mesh: about this many solved nodes.
    #[arg(long, conflicts_with = "accuracy")]
    pub nodes: Option<usize>,
    /// Mesh: relative height error wanted against the mesh-converged model
    /// (disc), e.g. 0.005. Default mesh when no size is given anywhere: 16
    /// rings (disc), 16 divisions (sphere segment).
    #[arg(long)]
    pub accuracy: Option<f64>,
    /// Mesh the full disc instead of the 60 degree sector with mirror planes.
    #[arg(long)]
    pub full: bool,
    /// With --model axisym: write the meridian profile at the last pressure
    /// solved (r_m,rho_m,z_m,stretch_meridional,stretch_hoop) to this CSV.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Density in kg/m^3 for the lumped masses (default: the scene's, else 1100).
    #[arg(long)]
    pub density: Option<f64>,
    /// Dynamic runs (--dynamic and its flags; see docs/dynamics.md).
    #[command(flatten)]
    pub dynamic: dynamic::DynArgs,
}

fn parse_list<T>(
    s: &str,
    what: &str,
    valid: &str,
    parse: impl Fn(&str) -> Option<T>,
) -> anyhow::Result<Vec<T>> {
    let mut out = Vec::new();
    for part in s.split(',') {
        out.push(parse(part).ok_or_else(|| {
            anyhow!(
                "--{what} `{}` is not one of {valid}; separate several with commas",
                part.trim()
            )
        })?);
    }
    Ok(out)
}

fn build_scene(args: &Args) -> anyhow::Result<Scene> {
    let (scene, origin) = load_scene(args)?;
    scene.validate(true).map_err(|m| anyhow!("{origin}: {m}"))?;
    Ok(scene)
}

/// Reads the scene (a scene file, or `--experiment` + `--material`), applies
/// the overriding flags, and returns it with the name of where it came from;
/// the static and dynamic paths validate it each their own way.
fn load_scene(args: &Args) -> anyhow::Result<(Scene, String)> {
    let material = match &args.material {
        Some(p) => Some(read_toml::<Material>(p)?),
        None => None,
    };
    let mut scene = if let Some(path) = &args.scene {
        let mut s = Scene::read(path)?;
        if let Some(m) = material {
            s.material = m;
        }
        s
    } else if let Some(exp) = &args.experiment {
        let e = Experiment::read(exp)?;
        let m = material.ok_or_else(|| {
            anyhow!("--experiment needs --material material.toml (the material to simulate)")
        })?;
        if (m.poisson - e.specimen.poisson).abs() > 1e-12 {
            eprintln!(
                "note: the material's poisson = {} is used; the specimen says {}",
                m.poisson, e.specimen.poisson
            );
        }
        if e.specimen.prebulge_height_m > 0.0 {
            eprintln!("note: the simulated disc starts flat; prebulge_height_m is not modelled");
        }
        if args.pressures.is_none() {
            return Err(anyhow!(
                "--experiment needs --pressures (Pa, comma-separated, e.g. 5000,7300,8940)"
            ));
        }
        Scene::from_specimen(&e.specimen, m, Vec::new())
    } else {
        return Err(anyhow!(
            "give a scene file (bulge simulate scene.toml) or --experiment FILE --material FILE --pressures P1,P2,..."
        ));
    };
    let origin = apply_overrides(&mut scene, args)?;
    Ok((scene, origin))
}

/// A model of the `--model` list.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Choice {
    Spring(SpringModel),
    Axisym,
}

/// Applies the flags that override a scene (pressures, mesh size, symmetry,
/// density) and returns the name of where the scene came from, for messages.
fn apply_overrides(scene: &mut Scene, args: &Args) -> anyhow::Result<String> {
    if let Some(p) = &args.pressures {
        scene.pressures_pa = scene::parse_pressures(p).map_err(|m| anyhow!("--pressures: {m}"))?;
    }
    if let Some(h) = args.edge_length {
        scene.mesh.size = Some(MeshSize::EdgeLength(h));
    }
    if let Some(n) = args.nodes {
        scene.mesh.size = Some(MeshSize::Nodes(n));
    }
    if let Some(a) = args.accuracy {
        scene.mesh.size = Some(MeshSize::Accuracy(a));
    }
    if args.full {
        scene.mesh.symmetry = false;
    }
    if let Some(d) = args.density {
        scene.density_kg_m3 = d;
    }
    Ok(args
        .scene
        .as_deref()
        .or(args.experiment.as_deref())
        .unwrap_or(Path::new("command line"))
        .display()
        .to_string())
}

fn parse_choice(s: &str) -> Option<Choice> {
    if s.trim() == "axisym" {
        Some(Choice::Axisym)
    } else {
        SpringModel::parse(s).map(Choice::Spring)
    }
}

/// Rows of the exact axisymmetric solution at the scene's pressures.
fn run_axisym(
    scene: &Scene,
    header_len: usize,
    csv: &mut CsvOut,
    table: &mut Vec<String>,
    failures: &mut Vec<String>,
    profile: Option<&Path>,
    pb: &indicatif::ProgressBar,
) -> Result<Option<CsvOut>, Failure> {
    use bulge::axisym::{self, AxisymError};
    let SceneKind::Disc { radius_m } = scene.kind else {
        return Err(Failure::BadInput(anyhow!(
            "--model axisym solves the clamped disc only; this scene is a {}",
            scene.kind.name()
        )));
    };
    let specimen = bulge::experiment::Specimen {
        radius_m,
        thickness_m: scene.thickness_m,
        poisson: scene.material.poisson,
        prebulge_height_m: 0.0,
    };
    let opts = axisym::Options::default();
    let mut last = None;
    for &p in &scene.pressures_pa {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(&scene.material, &specimen, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        pb.inc(1);
        match out {
            Ok(sol) => {
                let mut row = vec![
                    fmt_num(Some(p)),
                    fmt_num(Some(sol.height_m)),
                    "axisym".to_string(),
                    "shooting".to_string(),
                    opts.n_profile.to_string(),
                    sol.iterations.to_string(),
                    format!("{:.3e}", sol.residual),
                    format!("{wall:.4}"),
                ];
                row.resize(header_len, String::new());
                csv.row(&row);
                table.push(format!(
                    "{:>10} {:>12.6e} {:>10} {:>7} {:>6} {:>9.2e} {:>8.3}",
                    p, sol.height_m, "axisym", "shoot", sol.iterations, sol.residual, wall
                ));
                last = Some(sol);
            }
            Err(
                e @ (AxisymError::Specimen(_)
                | AxisymError::Material(_)
                | AxisymError::Options(_)
                | AxisymError::Pressure(_)),
            ) => return Err(Failure::BadInput(anyhow!("axisym at {p} Pa: {e}"))),
            Err(e) => {
                failures.push(format!("axisym: {e}"));
                break;
            }
        }
    }
    Ok(match (profile, last) {
        (Some(_), Some(sol)) => Some(axisym::profile_csv(&sol)),
        _ => None,
    })
}

fn describe(mesh: &Mesh, scene: &Scene) -> String {
    let q = mesh.quality();
    let part = match (scene.kind, mesh.symmetry_copies) {
        (SceneKind::Disc { .. }, 6) => " (60 degree sector with mirror planes)",
        (SceneKind::SphereSegment { .. }, _) => " (octant with three symmetry planes)",
        _ => "",
    };
    format!(
        "mesh: {} nodes, {} triangles{part}; angles {:.1}-{:.1} deg, non-acute {:.2} %, edges {:.3e}-{:.3e} m",
        mesh.nodes.len(),
        q.triangles,
        q.min_angle_deg,
        q.max_angle_deg,
        100.0 * q.non_acute_share,
        q.edge_range_m[0],
        q.edge_range_m[1]
    )
}

/// Runs `bulge simulate`.
pub fn run(args: Args) -> Result<(), Failure> {
    if args.dynamic.dynamic {
        return dynamic::run(args);
    }
    let scene = build_scene(&args).bad_input()?;
    let choices = parse_list(
        &args.model,
        "model",
        "tp, tp-paper, van-gelder, lloyd, axisym",
        parse_choice,
    )
    .bad_input()?;
    let models: Vec<SpringModel> = choices
        .iter()
        .filter_map(|c| match c {
            Choice::Spring(m) => Some(*m),
            Choice::Axisym => None,
        })
        .collect();
    let axisym = choices.contains(&Choice::Axisym);
    if args.profile.is_some() && !axisym {
        return Err(Failure::BadInput(anyhow!(
            "--profile writes the axisym meridian: add axisym to --model"
        )));
    }
    let solvers = parse_list(&args.solver, "solver", "newton, dr", Solver::parse).bad_input()?;
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
    let mesh = scene
        .build_mesh_for(&models)
        .context("building the mesh")
        .bad_input()?;
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
    let runs = models.len() * solvers.len() + usize::from(axisym);
    let pb = super::progress((runs * scene.pressures_pa.len()) as u64, "simulate");
    let mut profile_out = None;
    if axisym {
        profile_out = run_axisym(
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
        for &solver in &solvers {
            let mut membrane = scene
                .membrane(&mesh, model)
                .map_err(|e| anyhow!("{e}"))
                .bad_input()?;
            let predictor: Box<dyn Predictor> = match scene.kind {
                SceneKind::Disc { radius_m } => Box::new(DiscPredictor {
                    radius_m,
                    young_pa: membrane.law.young(1.0).1,
                    thickness_m: scene.thickness_m,
                    poisson: scene.material.poisson,
                }),
                _ => Box::new(Stay),
            };
            let mut x = mesh.nodes.clone();
            let mut ws = None;
            let mut p_prev = 0.0;
            for (ip, &p) in scene.pressures_pa.iter().enumerate() {
                let t0 = Instant::now();
                let out = solve::continuation(
                    &mut membrane,
                    &mesh.nodes,
                    &mut x,
                    p_prev,
                    p,
                    solver,
                    &opts,
                    predictor.as_ref(),
                    &mut ws,
                );
                let wall = t0.elapsed().as_secs_f64();
                pb.inc(1);
                match out {
                    Ok(stats) => {
                        let (h, extra) = scene.measure(&mesh, &x);
                        let mut row = vec![
                            fmt_num(Some(p)),
                            fmt_num(Some(h)),
                            model.name().to_string(),
                            solver.name().to_string(),
                            mesh.nodes.len().to_string(),
                            stats.iterations.to_string(),
                            format!("{:.3e}", stats.residual),
                            format!("{wall:.4}"),
                        ];
                        row.extend(extra.iter().map(|v| fmt_num(Some(*v))));
                        csv.row(&row);
                        table.push(format!(
                            "{:>10} {:>12.6e} {:>10} {:>7} {:>6} {:>9.2e} {:>8.3}",
                            p,
                            h,
                            model.name(),
                            solver.name(),
                            stats.iterations,
                            stats.residual,
                            wall
                        ));
                        if let Some(dir) = &args.vtk {
                            let name = format!("{}_{}_{:03}.vtk", model.name(), solver.name(), ip);
                            let title =
                                format!("bulge {} {} {} Pa", model.name(), solver.name(), p);
                            vtks.push((
                                dir.join(name),
                                vtk::polydata(&mesh, &x, &membrane.triangle_stretch(&x), &title),
                            ));
                        }
                        p_prev = p;
                    }
                    Err(e @ SimError::NonPositiveModulus { .. }) => {
                        pb.finish_and_clear();
                        return Err(Failure::BadInput(anyhow!(
                            "{} / {} at {p} Pa: {e}",
                            model.name(),
                            solver.name()
                        )));
                    }
                    Err(e) => {
                        let mut msg = format!("{} / {}: {e}", model.name(), solver.name());
                        // dyn: the disc's limit pressure from the axisymmetric solution
                        if let SceneKind::Disc { radius_m } = scene.kind
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
                        pb.inc((scene.pressures_pa.len() - ip - 1) as u64);
                        break;
                    }
                }
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

/// Prints the result table and where it was written; fails naming every
/// failure and where the finished part (`kept`) is.
fn finish(
    header: &str,
    table: &[String],
    output: &std::path::Path,
    failures: &[String],
    kept: &str,
) -> Result<(), Failure> {
    println!("{header}");
    for line in table {
        println!("{line}");
    }
    println!("wrote {}", output.display());
    if !failures.is_empty() {
        return Err(Failure::Failed(anyhow!(
            "{}; {kept} are in {}",
            failures.join("; "),
            output.display()
        )));
    }
    Ok(())
}
