//! `bulge run`: the whole pipeline on an experiment file, with the comparison
//! report. Chains the library stages of [`bulge::pipeline`] (track,
//! stress, fit, simulate) and writes each stage's outputs whole as soon as
//! the stage is done, so that a failed stage leaves the earlier outputs and
//! a message naming the stage.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::anyhow;
use indicatif::ProgressBar;

use super::Failure;
use bulge::experiment::Experiment;
use bulge::fit::FitModel;
use bulge::io::write_atomic;
use bulge::mechanics::{Modulus, ModulusStress, StrainMeasure, TrueStress};
use bulge::pipeline::{
    self, FitOut, Observer, PipelineError, RunOptions, Settings, Stage, StressOut, Timing,
    Tracking, describe_stress,
};
use bulge::report::figures;
use bulge::report::html::{Picture, Report};
use bulge::report::plot::Figure;
use bulge::report::table;
use bulge::sim::scene::MeshSize;
use bulge::sim::solve::Solver;
use bulge::sim::springs::SpringModel;
use bulge::track::annotate;

/// Flags of `bulge run`.
///
/// Example: `bulge run data/demo/experiment.toml --out out/`
///
/// Every setting can also be given in the experiment file, in a `[run]` (or
/// `[simulate]`) table with the flag's name in snake case, e.g.
/// `models = ["tp", "van-gelder"]`, `pressures_pa = [5000, 7300]`,
/// `accuracy = 0.005`, `fit = "quartic"`, `strain = "engineering"`; a flag
/// overrides the file.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Writes into --out: heights.csv, stress_strain.csv, material.toml, simulated.csv, \
fit.svg/png, heights.svg/png, report.html, summary.md. Exit status 2 when an input is refused, 1 when a stage \
fails; the outputs of the stages before it are kept and the message names the stage."
)]
pub struct Args {
    /// The experiment file (TOML with [specimen], [photos], [calibration],
    /// [pressure], and optionally [run] / [simulate] settings). Never
    /// written to.
    pub experiment: PathBuf,

    /// Output folder (created if missing; files of the same names are
    /// replaced). Required: bulge does not guess where to write.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Spring models to simulate, comma-separated: tp, tp-paper,
    /// van-gelder, lloyd. Default tp,van-gelder (the comparison of Tudruj et
    /// al. 2023).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub models: Option<Vec<SpringModel>>,

    /// Leave out the exact axisymmetric reference of the fitted material
    /// (solved by default beside the spring models: it tells the mesh and
    /// spring-model error apart from the material-model error).
    #[arg(long)]
    pub no_axisym: bool,

    /// Keep the law as the stress/strain points give it. By default the
    /// fitted law's parameters are then corrected until the exact
    /// axisymmetric inflation reproduces the measured heights: the
    /// spherical-cap formulas assume a uniform equibiaxial strain that the
    /// real bubble does not have, which biases the law by a few per cent
    /// (docs/run.md). `refine = false` in [run] does the same.
    #[arg(long)]
    pub no_refine: bool,

    /// Pressures to simulate, Pa, comma-separated, increasing. Default: the
    /// measured pressures (so that every measured height gets a simulated one).
    #[arg(long, value_delimiter = ',')]
    pub pressures: Option<Vec<f64>>,

    /// Mesh: wanted relative height error of the disc against the
    /// mesh-converged spring model, e.g. 0.005. Default: the simulate stage's
    /// default mesh (16 rings of the 60 degree sector, 153 nodes; about
    /// 0.2 % by the simulate stage's convergence constant).
    #[arg(long, conflicts_with = "nodes")]
    pub accuracy: Option<f64>,

    /// Mesh: about this many solved nodes (instead of --accuracy).
    #[arg(long)]
    pub nodes: Option<usize>,

    /// Material model to fit: quartic (Tudruj et al.'s (2023) secant modulus E(eps),
    /// default: what the mass-spring models were designed for),
    /// neo-hookean, mooney-rivlin, yeoh, ogden-1, ogden-2, ogden-3, gent.
    #[arg(long, value_parser = parse_fit)]
    pub fit: Option<FitModel>,

    /// Degree of the polynomial E(eps) law (quartic only). Default 4; lowered
    /// automatically to (points - 1) when there are fewer points.
    #[arg(long)]
    pub degree: Option<usize>,

    /// Strain measure of the stress stage (`bulge stress --strain`):
    /// engineering or log. Default engineering (closed-loop study in
    /// docs/run.md).
    #[arg(long, value_enum)]
    pub strain: Option<StrainMeasure>,

    /// True-stress convention (`bulge stress --true-stress`): paper or
    /// incompressible. Default paper. Only matters with --modulus-stress true.
    #[arg(long = "true-stress", value_enum)]
    pub true_stress: Option<TrueStress>,

    /// Secant modulus convention (`bulge stress --modulus`): biaxial
    /// (1 - nu) S / eps or uniaxial S / eps. Default biaxial.
    #[arg(long, value_enum)]
    pub modulus: Option<Modulus>,

    /// Stress S in the secant modulus (`bulge stress --modulus-stress`):
    /// nominal, engineering or true. Default nominal.
    #[arg(long = "modulus-stress", value_enum)]
    pub modulus_stress: Option<ModulusStress>,

    /// Quasi-static solver of the spring models: newton (default) or dr.
    #[arg(long, value_enum)]
    pub solver: Option<Solver>,

    /// Minimum template-match score of a frame (`bulge track --min-score`),
    /// in [-1, 1]. Default 0.5.
    #[arg(long)]
    pub min_score: Option<f64>,

    /// Leave frames below --min-score out instead of failing the track stage.
    #[arg(long)]
    pub skip_bad_frames: bool,
}

fn parse_fit(s: &str) -> Result<FitModel, String> {
    s.parse()
}

/// Flags over the experiment file's `[run]`/`[simulate]` tables over the defaults.
fn settings(args: &Args, exp: &Experiment) -> Result<Settings, Failure> {
    let file = RunOptions::from_experiment(exp).map_err(|e| Failure::BadInput(e.into()))?;
    let flags = RunOptions {
        models: args.models.clone(),
        axisym: args.no_axisym.then_some(false),
        refine: args.no_refine.then_some(false),
        pressures_pa: args.pressures.clone(),
        accuracy: args.accuracy,
        nodes: args.nodes,
        fit: args.fit,
        degree: args.degree,
        strain: args.strain,
        true_stress: args.true_stress,
        modulus: args.modulus,
        modulus_stress: args.modulus_stress,
        solver: args.solver,
        min_score: args.min_score,
        skip_bad_frames: args.skip_bad_frames.then_some(true),
    };
    flags
        .or(file)
        .settings()
        .map_err(|e| Failure::BadInput(anyhow!("{}: {e}", exp.path.display())))
}

/// The settings as key/value pairs for the report.
fn settings_table(s: &Settings, exp: &Experiment, pressures: &[f64]) -> Vec<(String, String)> {
    let mesh = match s.mesh {
        None => "default: 16 rings of the 60 degree sector".to_string(),
        Some(MeshSize::Accuracy(a)) => format!("accuracy {a} (relative height error)"),
        Some(MeshSize::Nodes(n)) => format!("about {n} nodes"),
        Some(MeshSize::EdgeLength(h)) => format!("edge length {h} m"),
    };
    vec![
        ("experiment".into(), exp.path.display().to_string()),
        (
            "track".into(),
            format!(
                "refine {}, min score {}, skip bad frames {}",
                s.track.refine.name(),
                s.track.min_score,
                s.track.skip_bad_frames
            ),
        ),
        ("stress".into(), describe_stress(&s.stress)),
        (
            "fit".into(),
            format!(
                "{}{}",
                s.fit.label(),
                if s.refine {
                    ", corrected to the measured heights through the axisymmetric solution"
                } else {
                    ", as the stress/strain points give it (--no-refine)"
                }
            ),
        ),
        (
            "simulate".into(),
            format!(
                "models {}{}, solver {}, tolerance {:e}",
                s.models
                    .iter()
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", "),
                if s.axisym {
                    " + axisym (exact reference)"
                } else {
                    ""
                },
                s.solver.name(),
                s.tolerance
            ),
        ),
        ("mesh".into(), mesh),
        (
            "pressures simulated (Pa)".into(),
            format!(
                "{} {}",
                if s.pressures_pa.is_some() {
                    "given:"
                } else {
                    "the measured ones:"
                },
                pressures
                    .iter()
                    .map(|p| format!("{p:.1}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    ]
}

/// A failed stage: the message names it and says where the earlier outputs are.
fn stage_failure(stage: Stage, out: &Path, e: PipelineError) -> Failure {
    let bad = e.is_bad_input();
    let msg = anyhow!(
        "stage `{}` {}: {e} (the outputs of the earlier stages are kept in {})",
        stage.name(),
        if bad { "refused its input" } else { "failed" },
        out.display()
    );
    if bad {
        Failure::BadInput(msg)
    } else {
        Failure::Failed(msg)
    }
}

fn write(stage: Stage, out: &Path, file: &str, bytes: &[u8]) -> Result<PathBuf, Failure> {
    let p = out.join(file);
    write_atomic(&p, bytes).map_err(|e| {
        stage_failure(
            stage,
            out,
            PipelineError::Output(format!("cannot write {}: {e}", p.display())),
        )
    })?;
    Ok(p)
}

/// Writes a figure as SVG and PNG; returns the PNG bytes.
fn write_figure(stage: Stage, out: &Path, stem: &str, fig: &Figure) -> Result<Vec<u8>, Failure> {
    let err = |e: String| stage_failure(stage, out, PipelineError::Output(e));
    let svg = fig.to_svg().map_err(|e| err(format!("{stem}.svg: {e}")))?;
    write(stage, out, &format!("{stem}.svg"), svg.as_bytes())?;
    let png = out.join(format!("{stem}.png"));
    fig.write_png(&png).map_err(|e| err(e.to_string()))?;
    std::fs::read(&png).map_err(|e| err(format!("cannot read back {}: {e}", png.display())))
}

/// Inputs are never written to: refuse an output folder that holds the
/// experiment file or the photos.
fn refuse_input_folder(exp: &Experiment, out: &Path) -> Result<(), Failure> {
    let Ok(o) = out.canonicalize() else {
        return Ok(());
    };
    let mut inputs = vec![exp.base_dir.clone()];
    if let Some(p) = &exp.photos {
        inputs.push(exp.resolve(&p.dir));
    }
    for i in inputs {
        if i.canonicalize().is_ok_and(|i| i == o) {
            return Err(Failure::BadInput(anyhow!(
                "--out {} is the folder of the experiment's inputs: choose another folder (inputs are never overwritten)",
                out.display()
            )));
        }
    }
    Ok(())
}

/// Progress bars and one line per stage on stderr.
struct Console {
    out: PathBuf,
    bar: Mutex<Option<ProgressBar>>,
}

impl Observer for Console {
    fn start(&self, stage: Stage, steps: u64) {
        let mut bar = self.bar.lock().expect("progress bar");
        if let Some(b) = bar.take() {
            b.finish_and_clear();
        }
        if steps > 0 {
            *bar = Some(super::progress(steps, stage.name()));
        }
    }

    fn tick(&self) {
        if let Some(b) = self.bar.lock().expect("progress bar").as_ref() {
            b.inc(1);
        }
    }

    fn note(&self, stage: Stage, message: &str) {
        if stage == Stage::Track || stage == Stage::Fit && message.starts_with("only ") {
            eprintln!("         {message}");
        }
    }

    fn done(&self, t: &Timing) {
        if let Some(b) = self.bar.lock().expect("progress bar").take() {
            b.finish_and_clear();
        }
        let files = match t.stage {
            Stage::Track => "heights.csv",
            Stage::Stress => "stress_strain.csv",
            Stage::Fit => "material.toml, fit.svg, fit.png",
            Stage::Simulate => "simulated.csv",
            Stage::Report => "heights.svg, heights.png, report.html, summary.md",
        };
        let step = Stage::ALL.iter().position(|s| *s == t.stage).unwrap_or(0) + 1;
        eprintln!("[{step}/5] {:<8} {} -> {files}", t.stage.name(), t.what);
        let _ = &self.out;
    }
}

/// The files of the stages that finished, written whole.
struct StageFiles {
    heights: Option<Vec<u8>>,
    stress: Option<Vec<u8>>,
    fit: Option<(String, Figure)>,
}

impl StageFiles {
    fn of(tracking: Option<&Tracking>, stress: Option<&StressOut>, fit: Option<&FitOut>) -> Self {
        let labels: Option<Vec<(usize, String)>> = tracking.map(|t| {
            t.tracked
                .rows
                .iter()
                .map(|r| (r.frame, r.file.clone()))
                .collect()
        });
        StageFiles {
            heights: tracking.map(|t| t.csv().into_bytes()),
            stress: stress.map(|s| s.csv(labels.as_deref()).into_bytes()),
            fit: fit.and_then(|f| Some((toml::to_string(&f.material).ok()?, figures::fit(f)))),
        }
    }

    /// Writes what there is; returns the PNG of the fit.
    fn write(self, out: &Path) -> Result<Vec<u8>, Failure> {
        if let Some(h) = self.heights {
            write(Stage::Track, out, "heights.csv", &h)?;
        }
        if let Some(s) = self.stress {
            write(Stage::Stress, out, "stress_strain.csv", &s)?;
        }
        let mut png = Vec::new();
        if let Some((toml_text, fig)) = self.fit {
            let svg = fig.to_svg().map_err(|e| {
                stage_failure(
                    Stage::Fit,
                    out,
                    PipelineError::Output(format!("fit.svg: {e}")),
                )
            })?;
            write(Stage::Fit, out, "material.toml", toml_text.as_bytes())?;
            write(Stage::Fit, out, "fit.svg", svg.as_bytes())?;
            let p = out.join("fit.png");
            fig.write_png(&p).map_err(|e| {
                stage_failure(Stage::Fit, out, PipelineError::Output(e.to_string()))
            })?;
            png = std::fs::read(&p).unwrap_or_default();
        }
        Ok(png)
    }
}

/// Runs `bulge run`.
pub fn run(args: Args) -> Result<(), Failure> {
    let exp = Experiment::read(&args.experiment)?;
    let s = settings(&args, &exp)?;
    refuse_input_folder(&exp, &args.out)?;
    let out = args.out.as_path();
    std::fs::create_dir_all(out)
        .map_err(|e| Failure::Failed(anyhow!("cannot create {}: {e}", out.display())))?;
    let spec = exp.specimen;
    let console = Console {
        out: out.to_path_buf(),
        bar: Mutex::new(None),
    };
    let o = match pipeline::run_observed(&exp, &s, &console) {
        Ok(o) => o,
        Err(e) => {
            if let Some(b) = console.bar.lock().expect("progress bar").take() {
                b.finish_and_clear();
            }
            let p = &e.partial;
            StageFiles::of(p.tracking.as_ref(), p.stress.as_ref(), p.fit.as_ref()).write(out)?;
            return Err(stage_failure(e.stage, out, e.error));
        }
    };
    let fit_png = StageFiles::of(Some(&o.tracking), Some(&o.stress), Some(&o.fit)).write(out)?;
    write(
        Stage::Simulate,
        out,
        "simulated.csv",
        &pipeline::simulated_csv(&o.runs).into_bytes(),
    )?;
    for w in &o.fit.warnings {
        eprintln!("         warning: {w}");
    }
    let notes: Vec<String> = o
        .notes
        .iter()
        .filter_map(|n| n.strip_prefix("simulate: ").map(str::to_string))
        .collect();
    for n in &notes {
        eprintln!("         note: {n}");
    }
    let material_toml = toml::to_string(&o.fit.material).map_err(|e| {
        stage_failure(
            Stage::Fit,
            out,
            PipelineError::Output(format!("material.toml: {e}")),
        )
    })?;
    let (tracking, stress, fit, runs, rows, pressures) = (
        &o.tracking,
        &o.stress,
        &o.fit,
        &o.runs,
        &o.comparison,
        &o.pressures_pa,
    );
    let mut timings = o.timings.clone();

    // 5. report
    let t = Instant::now();
    let hfig = figures::heights(&stress.points, runs, rows);
    let heights_png = write_figure(Stage::Report, out, "heights", &hfig)?;
    let nrows = tracking.tracked.rows.len();
    let mut picks = vec![0, nrows / 2, nrows - 1];
    picks.dedup();
    let mut photos = Vec::new();
    for i in picks {
        let r = &tracking.tracked.rows[i];
        let png = annotate::annotated_png(&tracking.photo(i), &tracking.marks(i), 640)
            .map_err(|e| stage_failure(Stage::Report, out, e.into()))?;
        photos.push(Picture {
            caption: format!(
                "frame {} ({}): {:.1} Pa, apex height {:.3} mm, match score {:.3}",
                r.frame,
                r.file,
                r.pressure_pa,
                r.height_m * 1e3,
                r.score
            ),
            png,
        });
    }
    let secs = t.elapsed().as_secs_f64();
    timings.push(Timing {
        stage: Stage::Report,
        seconds: secs,
        what: format!(
            "2 figures, {} annotated photos, report.html, summary.md",
            photos.len()
        ),
    });
    let mut experiment = vec![
        ("file".to_string(), exp.path.display().to_string()),
        ("free radius a".into(), format!("{} m", spec.radius_m)),
        ("thickness t".into(), format!("{} m", spec.thickness_m)),
        ("Poisson ratio".into(), format!("{}", spec.poisson)),
        (
            "pre-bulge height h0".into(),
            format!("{} m", spec.prebulge_height_m),
        ),
        (
            "photos".into(),
            format!(
                "{} tracked of {} ({}x{} px)",
                nrows,
                tracking.setup.frames.len(),
                tracking.tracked.image_size[0],
                tracking.tracked.image_size[1]
            ),
        ),
        (
            "metres per pixel".into(),
            format!("{:.6e}", tracking.setup.calibration.metres_per_pixel),
        ),
    ];
    if let (Some(lo), Some(hi)) = (
        stress.points.iter().map(|p| p.pressure_pa).reduce(f64::min),
        stress.points.iter().map(|p| p.pressure_pa).reduce(f64::max),
    ) {
        experiment.push(("pressure range".into(), format!("{lo:.1} to {hi:.1} Pa")));
    }
    let mut all_notes: Vec<String> = fit.warnings.iter().map(|w| format!("fit: {w}")).collect();
    all_notes.extend(
        notes
            .iter()
            .filter(|n| !n.starts_with("not solved"))
            .cloned(),
    );
    let report = Report {
        title: exp.path.display().to_string(),
        experiment,
        photos,
        heights: Some(Picture {
            caption: "Measured apex height (points, one standard deviation) and each model (lines; the axisymmetric reference dashed); below, the relative error.".into(),
            png: heights_png,
        }),
        fit: Some(Picture {
            caption: "The fitted material: stress against strain, the secant modulus E(eps), and the residuals.".into(),
            png: fit_png,
        }),
        material_toml: material_toml.clone(),
        rows: rows.clone(),
        runs: runs.clone(),
        settings: settings_table(&s, &exp, pressures),
        timings: timings.clone(),
        notes: all_notes.clone(),
    };
    let html = report.to_html();
    let mut md = format!(
        "# bulge run: {}\n\n## Measured against simulated apex heights\n\n",
        exp.path.display()
    );
    md.push_str(&table::markdown(rows, runs));
    md.push_str("\nRelative error = simulated / measured - 1.\n\n## Material\n\n```toml\n");
    md.push_str(&material_toml);
    md.push_str("```\n\n## Settings\n\n");
    for (k, v) in settings_table(&s, &exp, pressures) {
        md.push_str(&format!("- {k}: {v}\n"));
    }
    md.push_str("\n## Time per stage\n\n");
    md.push_str(&table::timings_markdown(&timings));
    if !all_notes.is_empty() {
        md.push_str("\n## Notes\n\n");
        for n in &all_notes {
            md.push_str(&format!("- {n}\n"));
        }
    }
    write(Stage::Report, out, "report.html", html.as_bytes())?;
    write(Stage::Report, out, "summary.md", md.as_bytes())?;
    eprintln!(
        "[5/5] {:<8} heights.svg, heights.png, report.html, summary.md",
        Stage::Report.name()
    );

    println!("\nMeasured against simulated apex heights (error = simulated / measured - 1):\n");
    print!("{}", table::terminal(rows, runs));
    println!("\nTime per stage:");
    print!("{}", table::timings_terminal(&timings));
    println!("\nwrote {}", out.join("report.html").display());
    Ok(())
}
