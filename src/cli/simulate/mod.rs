//! `bulge simulate`: material -> simulated bubble heights with the
//! mass-spring membrane models (see `docs/simulate.md`).

use std::path::PathBuf;

use anyhow::anyhow;

use super::Failure;
use bulge::io::OutputPlan;

mod dynamic;
mod scene;
mod statics;

use scene::build_scene;

use bulge::sim::solve::Solver;
use bulge::sim::springs::HeightModel;
use std::str::FromStr;

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
    #[arg(long, value_delimiter = ',', value_parser = parse_pressure)]
    pub pressures: Option<Vec<f64>>,
    /// Models, comma-separated, one output row each per pressure:
    /// tp (TP MSS force form, default), tp-paper (eq 11 with the eq 16
    /// switch), van-gelder (eq 1), lloyd (eq 4), membrane (constant-strain
    /// triangles carrying the material's whole strain energy), axisym (the
    /// exact axisymmetric membrane solution, disc only; solver `shooting`).
    #[arg(long, default_value = "tp", value_delimiter = ',', value_parser = HeightModel::from_str)]
    pub model: Vec<HeightModel>,
    /// Quasi-static solvers, comma-separated: newton (sparse LU, default) or
    /// dr (dynamic relaxation with kinetic damping).
    #[arg(long, default_value = "newton", value_enum, value_delimiter = ',')]
    pub solver: Vec<Solver>,
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
    /// Largest mesh, nodes (default 300000, about 10 GB for Newton): bigger
    /// meshes are refused before they are built.
    #[arg(long)]
    pub max_nodes: Option<usize>,
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

fn parse_pressure(s: &str) -> anyhow::Result<f64> {
    s.trim()
        .parse()
        .map_err(|_| anyhow!("`{}` is not a pressure in Pa", s.trim()))
}

/// Runs `bulge simulate`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let inputs = [&args.scene, &args.material, &args.experiment];
    let mut plan = OutputPlan::new().inputs(inputs.into_iter().flatten());
    plan = plan.output_as("-o", &args.output);
    for (p, flag) in [
        (&args.vtk, "--vtk"),
        (&args.profile, "--profile"),
        (&args.dynamic.trace, "--trace"),
    ] {
        if let Some(p) = p {
            plan = plan.output_as(flag, p);
        }
    }
    super::guard(plan)?;
    if let Some(v) = &args.vtk {
        super::output_folder(v, "--vtk")?;
    }
    for (p, flag) in [
        (&args.profile, "--profile"),
        (&args.dynamic.trace, "--trace"),
    ] {
        if let Some(p) = p {
            super::output_file(p, flag)?;
        }
    }
    if args.dynamic.dynamic {
        dynamic::run(args)
    } else {
        statics::run(args)
    }
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
