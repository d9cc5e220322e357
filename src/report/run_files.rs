//! Every file of a run, built in memory from the stages' outputs:
//! `heights.csv`, `stress_strain.csv` (and `stress_strain_sources.csv` when
//! the experiment gives standard deviations), `material.toml`, `fit.svg`/`.png`,
//! `simulated.csv`, `heights.svg`/`.png`, `report.html` (self-contained) and
//! `summary.md`, and the table printed on the terminal. `bulge run` writes
//! them; a failed run still gives the files of the stages that finished
//! ([`stage_files`]).

use std::time::Instant;

use super::figures;
use super::html::{Picture, Report};
use super::table;
use crate::experiment::Experiment;
use crate::pipeline::{
    self, FitOut, PipelineError, RunOutput, Settings, Stage, StressOut, Timing, Tracking,
    describe_stress,
};
use crate::sim::scene::MeshSize;
use crate::track::annotate;

/// One output file: its name in the output folder, the stage that made it,
/// and its bytes.
#[derive(Debug, Clone)]
pub struct OutFile {
    /// File name, e.g. `heights.csv`.
    pub name: &'static str,
    /// The stage it belongs to.
    pub stage: Stage,
    /// Its content.
    pub bytes: Vec<u8>,
}

/// Every file of a finished run, and what to print.
#[derive(Debug, Clone)]
pub struct RunFiles {
    /// The files, in the order of the stages.
    pub files: Vec<OutFile>,
    /// The comparison table and the time per stage, for the terminal.
    pub terminal: String,
    /// The time per stage, the report's own included.
    pub timings: Vec<Timing>,
}

fn output_error(what: &str, e: impl std::fmt::Display) -> PipelineError {
    PipelineError::Output(format!("{what}: {e}"))
}

/// The files of the stages that finished: `heights.csv`, `stress_strain.csv`
/// (with the frame and file of each row), `material.toml`, `fit.svg` and
/// `fit.png`.
pub fn stage_files(
    tracking: Option<&Tracking>,
    stress: Option<&StressOut>,
    fit: Option<&FitOut>,
) -> Result<Vec<OutFile>, PipelineError> {
    let mut files = Vec::new();
    if let Some(t) = tracking {
        files.push(OutFile {
            name: "heights.csv",
            stage: Stage::Track,
            bytes: t.csv().into_bytes(),
        });
    }
    if let Some(s) = stress {
        let labels: Option<Vec<(usize, String)>> = tracking.map(|t| {
            t.tracked
                .rows
                .iter()
                .map(|r| (r.frame, r.file.clone()))
                .collect()
        });
        files.push(OutFile {
            name: "stress_strain.csv",
            stage: Stage::Stress,
            bytes: s.csv(labels.as_deref()).into_bytes(),
        });
        if let Some(t) = pipeline::shifts_csv(&s.points, &s.shifts) {
            files.push(OutFile {
                name: "stress_strain_sources.csv",
                stage: Stage::Stress,
                bytes: t.into_bytes(),
            });
        }
    }
    if let Some(f) = fit {
        let toml_text =
            crate::io::to_toml_string(&f.material).map_err(|e| output_error("material.toml", e))?;
        let fig = figures::fit(f);
        let svg = fig.to_svg().map_err(|e| output_error("fit.svg", e))?;
        let png = fig.to_png().map_err(|e| output_error("fit.png", e))?;
        files.push(OutFile {
            name: "material.toml",
            stage: Stage::Fit,
            bytes: toml_text.into_bytes(),
        });
        if let Some(sel) = &f.laws {
            files.push(OutFile {
                name: "laws.csv",
                stage: Stage::Fit,
                bytes: super::laws::laws_csv(sel).into_bytes(),
            });
        }
        files.push(OutFile {
            name: "fit.svg",
            stage: Stage::Fit,
            bytes: svg.into_bytes(),
        });
        files.push(OutFile {
            name: "fit.png",
            stage: Stage::Fit,
            bytes: png,
        });
    }
    Ok(files)
}

/// Every file of the finished run `o` of `exp` with `s`.
pub fn run_files(exp: &Experiment, s: &Settings, o: &RunOutput) -> Result<RunFiles, PipelineError> {
    let t = Instant::now();
    let mut files = stage_files(o.tracking.as_ref(), Some(&o.stress), Some(&o.fit))?;
    let fit_png = files
        .iter()
        .find(|f| f.name == "fit.png")
        .map(|f| f.bytes.clone())
        .unwrap_or_default();
    files.push(OutFile {
        name: "simulated.csv",
        stage: Stage::Simulate,
        bytes: pipeline::simulated_csv(&o.runs).into_bytes(),
    });
    let (tracking, stress, fit, runs, rows, pressures) = (
        &o.tracking,
        &o.stress,
        &o.fit,
        &o.runs,
        &o.comparison,
        &o.pressures_pa,
    );
    let spec = &o.specimen;
    let hfig = figures::heights(&stress.points, runs, rows, o.band.as_deref());
    let heights_svg = hfig.to_svg().map_err(|e| output_error("heights.svg", e))?;
    let heights_png = hfig.to_png().map_err(|e| output_error("heights.png", e))?;
    let mut photos = Vec::new();
    if let Some(tracking) = tracking {
        let nrows = tracking.tracked.rows.len();
        let mut picks = vec![0, nrows / 2, nrows.saturating_sub(1)];
        picks.dedup();
        for i in picks {
            let r = &tracking.tracked.rows[i];
            let png = annotate::annotated_frame_png(tracking.frame(i), &tracking.marks(i), 640)?;
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
    }
    let mut timings = o.timings.clone();
    timings.push(Timing {
        stage: Stage::Report,
        seconds: t.elapsed().as_secs_f64(),
        what: format!(
            "2 figures, {} annotated photos, report.html, summary.md",
            photos.len()
        ),
        files: true,
    });
    let mut experiment = vec![
        ("file".to_string(), exp.path.display().to_string()),
        ("free radius a".into(), format!("{} m", spec.radius_m)),
        ("thickness t".into(), format!("{} m", spec.thickness_m)),
        ("Poisson ratio".into(), format!("{}", spec.poisson)),
        (
            "pre-bulge height h0".into(),
            if exp.prebulge_fit {
                format!("{} m (found from the heights)", spec.prebulge_height_m)
            } else {
                format!("{} m", spec.prebulge_height_m)
            },
        ),
    ];
    match tracking {
        Some(tracking) => {
            experiment.push((
                "photos".into(),
                format!(
                    "{} tracked of {} ({}x{} px)",
                    tracking.tracked.rows.len(),
                    tracking.setup.frames.len(),
                    tracking.tracked.image_size[0],
                    tracking.tracked.image_size[1]
                ),
            ));
            experiment.push((
                "metres per pixel".into(),
                format!("{:.6e}", tracking.setup.calibration.metres_per_pixel),
            ));
        }
        None => {
            let h = exp.heights.as_ref();
            experiment.push((
                "heights".into(),
                format!(
                    "{} measured ({}, {})",
                    stress.points.len(),
                    h.map_or(String::new(), |h| h.csv.display().to_string()),
                    if h.is_some_and(|h| h.origin == crate::experiment::HeightsOrigin::Reference) {
                        "above the stress-free reference state"
                    } else {
                        "above the clamp plane"
                    }
                ),
            ));
        }
    }
    if let (Some(lo), Some(hi)) = (
        stress.points.iter().map(|p| p.pressure_pa).reduce(f64::min),
        stress.points.iter().map(|p| p.pressure_pa).reduce(f64::max),
    ) {
        experiment.push(("pressure range".into(), format!("{lo:.1} to {hi:.1} Pa")));
    }
    let mut notes: Vec<String> = fit.warnings.iter().map(|w| format!("fit: {w}")).collect();
    notes.extend(o.notes.iter().filter_map(|n| match n.stage {
        Stage::Simulate => Some(n.text.clone()),
        Stage::Stress => Some(n.to_string()),
        _ => None,
    }));
    let material_toml = String::from_utf8_lossy(
        &files
            .iter()
            .find(|f| f.name == "material.toml")
            .map(|f| f.bytes.clone())
            .unwrap_or_default(),
    )
    .into_owned();
    let settings = settings_table(s, exp, pressures);
    let report = Report {
        title: exp.path.display().to_string(),
        experiment,
        photos,
        heights: Some(Picture {
            caption: if o.band.is_some() {
                "Measured apex height (points, one standard deviation) and each model (lines; the axisymmetric reference dashed), with the corrected law's 95 % band (dashed pair); below, the relative error and the band's half-width."
            } else {
                "Measured apex height (points, one standard deviation) and each model (lines; the axisymmetric reference dashed); below, the relative error."
            }
            .into(),
            png: heights_png.clone(),
        }),
        fit: Some(Picture {
            caption: "The fitted material: stress against strain, the secant modulus E(eps), and the residuals.".into(),
            png: fit_png,
        }),
        material_toml: material_toml.clone(),
        verdicts: verdict_lines(o),
        laws: laws_section(o),
        rows: rows.clone(),
        runs: runs.clone(),
        settings: settings.clone(),
        timings: timings.clone(),
        notes: notes.clone(),
    };
    let html = report.to_html();
    let mut md = format!(
        "# bulge run: {}\n\n## Measured against simulated apex heights\n\n",
        exp.path.display()
    );
    md.push_str(&table::markdown(rows, runs));
    md.push_str("\nRelative error = simulated / measured - 1.\n\n");
    if !o.verdicts.is_empty() {
        md.push_str("## Within the uncertainty?\n\n");
        for (model, v) in verdict_lines(o) {
            md.push_str(&format!("- {model}: {v}\n"));
        }
        md.push('\n');
    }
    if let Some((why, lines)) = laws_section(o) {
        md.push_str("## The law the heights call for\n\n");
        md.push_str(&format!("{why}\n\n"));
        for (law, v) in lines {
            md.push_str(&format!("- {law}: {v}\n"));
        }
        md.push_str("\nEvery law in laws.csv (chi-square of the heights against their standard deviations, AICc, BIC).\n\n");
    }
    md.push_str("## Material\n\n```toml\n");
    md.push_str(&material_toml);
    md.push_str("```\n\n## Settings\n\n");
    for (k, v) in &settings {
        md.push_str(&format!("- {k}: {v}\n"));
    }
    md.push_str("\n## Time per stage\n\n");
    md.push_str(&table::timings_markdown(&timings));
    if !notes.is_empty() {
        md.push_str("\n## Notes\n\n");
        for n in &notes {
            md.push_str(&format!("- {n}\n"));
        }
    }
    for (name, bytes) in [
        ("heights.svg", heights_svg.into_bytes()),
        ("heights.png", heights_png),
        ("report.html", html.into_bytes()),
        ("summary.md", md.into_bytes()),
    ] {
        files.push(OutFile {
            name,
            stage: Stage::Report,
            bytes,
        });
    }
    let mut terminal = String::from(
        "\nMeasured against simulated apex heights (error = simulated / measured - 1):\n\n",
    );
    terminal.push_str(&table::terminal(rows, runs));
    if !o.verdicts.is_empty() {
        terminal.push_str("\nWithin the uncertainty (measured and law's 95 % band):\n");
        for (model, v) in verdict_lines(o) {
            terminal.push_str(&format!("  {model}: {v}\n"));
        }
    }
    if let Some((why, lines)) = laws_section(o) {
        terminal.push_str(&format!("\nThe law the heights call for: {why}\n"));
        for (law, v) in lines {
            terminal.push_str(&format!("  {law}: {v}\n"));
        }
    }
    terminal.push_str("\nTime per stage:\n");
    terminal.push_str(&table::timings_terminal(&timings));
    Ok(RunFiles {
        files,
        terminal,
        timings,
    })
}

/// Per model, its verdict against the measured heights; then the paper's
/// chain (the quartic through TP MSS and the axisymmetric solution) when
/// another law was chosen.
fn verdict_lines(o: &RunOutput) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = o
        .verdicts
        .iter()
        .map(|v| (v.model.to_string(), v.describe()))
        .collect();
    if let Some(p) = &o.paper_chain {
        out.extend(p.verdicts.iter().map(|v| {
            (
                format!("{} ({}, the paper's chain)", v.model, p.law),
                v.describe(),
            )
        }));
    }
    out
}

/// Why the law was chosen and every law's line, when the run chose it.
fn laws_section(o: &RunOutput) -> Option<(String, Vec<(String, String)>)> {
    let sel = o.fit.laws.as_ref()?;
    Some((
        format!("chosen {}", sel.reason),
        super::laws::laws_lines(sel),
    ))
}

/// The settings of a run as key/value pairs for the report.
pub fn settings_table(s: &Settings, exp: &Experiment, pressures: &[f64]) -> Vec<(String, String)> {
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
                "{}{}{}{}",
                s.fit.label(),
                if s.refine {
                    ", corrected to the measured heights through the axisymmetric solution"
                } else {
                    ", as the stress/strain points give it (refine = false)"
                },
                if s.refine && s.weighted {
                    ", weighted by the heights' standard deviations"
                } else {
                    ""
                },
                if s.refine && s.samples > 0 {
                    format!(", Monte Carlo of {} samples", s.samples)
                } else {
                    String::new()
                }
            ),
        ),
        (
            "simulate".into(),
            format!(
                "models {}{}, solver {}, tolerance {:e}",
                if s.models.is_empty() {
                    "none".to_string()
                } else {
                    s.models
                        .iter()
                        .map(|m| m.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                },
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
