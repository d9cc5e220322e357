//! The whole pipeline as library stages: photos -> heights -> stress/strain
//! -> material -> simulated heights -> comparison, each a function from its
//! input to its output in memory, so that `bulge run` only chains them and
//! writes each stage's files, and the closed-loop study
//! (`examples/closed_loop.rs`) runs the same chain without writing anything.
//!
//! Conventions shared with the single-stage commands:
//!
//! * heights: [`crate::track::track`] (`bulge track`);
//! * stress/strain: [`crate::mechanics::stress_strain`] with
//!   [`crate::mechanics::Options`] (`bulge stress`);
//! * fit: the quartic secant modulus [`crate::fit::quartic::fit`] on the
//!   stress stage's `(strain, secant_modulus_pa)` (what `bulge fit
//!   --model quartic` does with `stress_strain.csv`), or a hyperelastic model
//!   on `(stretch, Cauchy stress l^2 p R / 2t)` (as `bulge fit --model NAME`);
//! * simulate: the disc of the specimen, the spring models of [`crate::sim`]
//!   solved by continuation over the pressures, and the exact axisymmetric
//!   solution [`crate::axisym::solve_pressure`] of the same material.

use std::path::Path;
#[cfg(feature = "opencv")]
use std::path::PathBuf;
use std::time::Instant;

use crate::axisym::{self, AxisymError};
#[cfg(feature = "opencv")]
use crate::experiment::Experiment;
use crate::experiment::Specimen;
use crate::fit::hyperelastic::{self, Equibiaxial, HyperFit, Kind};
use crate::fit::quartic::{self, PolyFit};
use crate::fit::{FitError, StressMeasure, inverse};
use crate::io::{CsvOut, fmt_num};
use crate::material::{Material, Model};
use crate::mechanics::{
    self, DERIVED_COLUMNS, Modulus, ModulusStress, Point, Row, STD_COLUMNS, StrainMeasure,
    StressError, TrueStress,
};
use crate::sim::DiscSolver;
use crate::sim::SimError;
use crate::sim::scene::{MeshSize, Scene};
use crate::sim::solve::{self, Solver};
use crate::sim::springs::SpringModel;
#[cfg(feature = "opencv")]
use crate::track::{self, Setup, TemplateSource, TrackError, Tracked};

/// The five stages, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Photos -> heights.
    Track,
    /// Heights -> stress/strain.
    Stress,
    /// Stress/strain -> material.
    Fit,
    /// Material -> simulated heights.
    Simulate,
    /// Tables, plots and the HTML report.
    Report,
}

impl Stage {
    /// All stages in order.
    pub const ALL: [Stage; 5] = [
        Stage::Track,
        Stage::Stress,
        Stage::Fit,
        Stage::Simulate,
        Stage::Report,
    ];

    /// The stage's name (the subcommand that does it alone).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Track => "track",
            Stage::Stress => "stress",
            Stage::Fit => "fit",
            Stage::Simulate => "simulate",
            Stage::Report => "report",
        }
    }
}

/// Why a stage refused its input or failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The tracking stage.
    #[cfg(feature = "opencv")]
    #[error(transparent)]
    Track(#[from] TrackError),
    /// The stress stage.
    #[error(transparent)]
    Stress(#[from] StressError),
    /// The fit stage.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The mass-spring solver could not be set up.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The axisymmetric reference could not be set up.
    #[error(transparent)]
    Axisym(#[from] AxisymError),
    /// A setting or an input that the stage refuses.
    #[error("{0}")]
    Input(String),
    /// Writing or drawing an output failed.
    #[error("{0}")]
    Output(String),
}

impl PipelineError {
    /// True when the user's input was refused (exit 2), false when the work
    /// failed (exit 1).
    pub fn is_bad_input(&self) -> bool {
        match self {
            #[cfg(feature = "opencv")]
            PipelineError::Track(e) => e.is_bad_input(),
            PipelineError::Stress(_) | PipelineError::Input(_) => true,
            PipelineError::Fit(e) => !matches!(e, FitError::Solver(_)),
            PipelineError::Sim(e) => matches!(
                e,
                SimError::BadParameter(_)
                    | SimError::DegenerateTriangle { .. }
                    | SimError::InvertedTriangle { .. }
                    | SimError::BadMesh(_)
            ),
            PipelineError::Axisym(e) => matches!(
                e,
                AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)
            ),
            PipelineError::Output(_) => false,
        }
    }
}

/// The model fitted by the fit stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitChoice {
    /// Tudruj et al.'s (2023) polynomial secant modulus `E(eps)` of this degree.
    Quartic(usize),
    /// An incompressible hyperelastic model fitted to the pole's Cauchy stress.
    Hyper(Kind),
}

impl FitChoice {
    /// Parses `quartic`, `neo-hookean`, `mooney-rivlin`, `yeoh`, `ogden-N`,
    /// `gent` (the quartic with `degree`).
    pub fn parse(s: &str, degree: usize) -> Option<FitChoice> {
        let s = s.trim();
        if s == "quartic" {
            return Some(FitChoice::Quartic(degree));
        }
        Kind::all()
            .into_iter()
            .find(|k| k.label() == s)
            .map(FitChoice::Hyper)
            .or(match s {
                "ogden" => Some(FitChoice::Hyper(Kind::Ogden(3))),
                _ => None,
            })
    }

    /// Display name.
    pub fn label(&self) -> String {
        match self {
            FitChoice::Quartic(4) => "quartic".into(),
            FitChoice::Quartic(d) => format!("polynomial E(eps) of degree {d}"),
            FitChoice::Hyper(k) => k.label(),
        }
    }
}

/// Everything `bulge run` can be told.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Tracking options.
    #[cfg(feature = "opencv")]
    pub track: track::Options,
    /// Stress and strain conventions.
    pub stress: mechanics::Options,
    /// The material model to fit.
    pub fit: FitChoice,
    /// Spring models to simulate (default TP MSS and Van Gelder).
    pub models: Vec<SpringModel>,
    /// Also solve the exact axisymmetric reference of the same material.
    pub axisym: bool,
    /// Pressures to simulate, Pa; `None`: the measured ones.
    pub pressures_pa: Option<Vec<f64>>,
    /// Mesh size of the disc; `None`: the simulate stage's default (16 rings
    /// of the 60 degree sector).
    pub mesh: Option<MeshSize>,
    /// Quasi-static solver of the mass-spring models.
    pub solver: Solver,
    /// Residual force relative to the load at which a solve stops.
    pub tolerance: f64,
    /// Correct the fitted law until the exact axisymmetric inflation
    /// reproduces the measured heights ([`crate::fit::inverse`]).
    pub refine: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            #[cfg(feature = "opencv")]
            track: track::Options::default(),
            stress: mechanics::Options::default(),
            fit: FitChoice::Quartic(4),
            models: vec![SpringModel::Tp, SpringModel::VanGelder],
            axisym: true,
            pressures_pa: None,
            mesh: None,
            solver: Solver::Newton,
            tolerance: 1e-8,
            refine: true,
        }
    }
}

/// Output of the tracking stage.
#[cfg(feature = "opencv")]
#[derive(Debug, Clone)]
pub struct Tracking {
    /// What was tracked.
    pub setup: Setup,
    /// The result per frame.
    pub tracked: Tracked,
    /// Template size `[w, h]`, px.
    pub template_size: [usize; 2],
    /// Apex position inside the template, px.
    pub apex_in_template: [f64; 2],
}

#[cfg(feature = "opencv")]
impl Tracking {
    /// `heights.csv` as `bulge track` writes it.
    pub fn csv(&self) -> CsvOut {
        self.tracked.heights_csv()
    }

    /// The measured points.
    pub fn points(&self) -> Vec<Point> {
        self.tracked
            .rows
            .iter()
            .map(|r| Point {
                pressure_pa: r.pressure_pa,
                height_m: r.height_m,
                height_std_m: Some(r.height_std_m),
            })
            .collect()
    }

    /// What to draw on frame `i` of the tracked rows.
    pub fn marks(&self, i: usize) -> track::annotate::Marks {
        let r = &self.tracked.rows[i];
        let q = r.apex_quadratic_px;
        let [tw, th] = self.template_size;
        let roi = self.setup.roi;
        track::annotate::Marks {
            roi_px: [roi[0] as f64, roi[1] as f64, roi[2] as f64, roi[3] as f64],
            template_px: [
                q[0] - self.apex_in_template[0],
                q[1] - self.apex_in_template[1],
                tw as f64,
                th as f64,
            ],
            apex_px: [r.apex_x_px, r.apex_y_px],
        }
    }

    /// Path of the photo of tracked row `i`.
    pub fn photo(&self, i: usize) -> PathBuf {
        self.setup.frames[self.tracked.rows[i].frame].path.clone()
    }
}

#[cfg(feature = "opencv")]
/// Stage 1: the photos of `exp` -> heights. `tick` is called per frame.
pub fn track_stage(
    exp: &Experiment,
    settings: &Settings,
    tick: &(dyn Fn() + Sync),
) -> Result<Tracking, PipelineError> {
    struct Tick<'a>(&'a (dyn Fn() + Sync));
    impl Observer for Tick<'_> {
        fn tick(&self) {
            (self.0)()
        }
    }
    track_stage_observed(exp, settings, &Tick(tick))
}

/// Stage 1, telling `obs` of the number of frames and each frame done.
#[cfg(feature = "opencv")]
fn track_stage_observed(
    exp: &Experiment,
    settings: &Settings,
    obs: &dyn Observer,
) -> Result<Tracking, PipelineError> {
    let setup = track::setup_from_experiment(exp)?;
    obs.start(Stage::Track, setup.frames.len() as u64);
    let tracked = track::track(&setup, &settings.track, &|| obs.tick())?;
    if tracked.rows.is_empty() {
        return Err(PipelineError::Input(format!(
            "every one of the {} frames scored below the minimum score {}: nothing to measure; check the template and the region",
            setup.frames.len(),
            settings.track.min_score
        )));
    }
    let template_size = match &setup.template {
        TemplateSource::Rect(r) => [r[2] as usize, r[3] as usize],
        TemplateSource::File(p) => {
            let t = track::image::read_gray(p, None)?;
            [t.width, t.height]
        }
    };
    let apex_in_template = setup.apex_in_template.unwrap_or([
        (template_size[0] as f64 - 1.0) / 2.0,
        (template_size[1] as f64 - 1.0) / 2.0,
    ]);
    Ok(Tracking {
        setup,
        tracked,
        template_size,
        apex_in_template,
    })
}

/// Output of the stress stage.
#[derive(Debug, Clone)]
pub struct StressOut {
    /// The measured points.
    pub points: Vec<Point>,
    /// Derived quantities per point.
    pub rows: Vec<Row>,
}

/// Stage 2: heights -> stress and strain.
pub fn stress_stage(
    spec: &Specimen,
    settings: &Settings,
    points: Vec<Point>,
) -> Result<StressOut, PipelineError> {
    let rows = mechanics::stress_strain(spec, &settings.stress, &points)?;
    Ok(StressOut { points, rows })
}

impl StressOut {
    /// `stress_strain.csv` in the columns of `bulge stress` (with `frame` and
    /// `file` first when given, and the `*_std` columns).
    pub fn csv(&self, labels: Option<&[(usize, String)]>) -> CsvOut {
        let mut header: Vec<&str> = Vec::new();
        if labels.is_some() {
            header.extend(["frame", "file"]);
        }
        header.extend(["pressure_pa", "height_m"]);
        header.extend(DERIVED_COLUMNS);
        header.push("height_std_m");
        header.extend(STD_COLUMNS);
        let mut out = CsvOut::new(&header);
        for (i, (p, r)) in self.points.iter().zip(&self.rows).enumerate() {
            let mut f = Vec::new();
            if let Some(l) = labels {
                f.push(l[i].0.to_string());
                f.push(l[i].1.clone());
            }
            f.push(fmt_num(Some(p.pressure_pa)));
            f.push(fmt_num(Some(p.height_m)));
            f.extend(r.value.to_array().into_iter().map(fmt_num));
            f.push(fmt_num(p.height_std_m));
            f.extend(
                r.std
                    .unwrap_or_default()
                    .to_array()
                    .into_iter()
                    .map(fmt_num),
            );
            out.row(&f);
        }
        out
    }
}

/// The fitted law in the form the report draws.
#[derive(Debug, Clone)]
pub enum FitDetail {
    /// The polynomial modulus law.
    Quartic(PolyFit),
    /// A hyperelastic fit.
    Hyper(HyperFit),
}

/// Output of the fit stage.
#[derive(Debug, Clone)]
pub struct FitOut {
    /// The material for the simulators (`material.toml`).
    pub material: Material,
    /// The fit.
    pub detail: FitDetail,
    /// `(strain, secant modulus, its std)` of the points the quartic saw,
    /// sorted by strain.
    pub modulus_points: Vec<(f64, f64, Option<f64>)>,
    /// `(stretch, Cauchy stress)` of the points the hyperelastic models saw.
    pub stress_points: Vec<(f64, f64)>,
    /// `1 - nu` (biaxial) or 1 (uniaxial): `E = k S / eps`.
    pub modulus_factor: f64,
    /// Strain measure of the law.
    pub strain_measure: StrainMeasure,
    /// Warnings about the law (unphysical regions, ill conditioning).
    pub warnings: Vec<String>,
    /// The law as the stress/strain points gave it, before the correction
    /// to the heights (the same as `material` without it).
    pub cap_material: Material,
    /// The correction to the heights, when made.
    pub refined: Option<inverse::Refined>,
}

/// Sorts points by their abscissa and merges exact repeats (noise can put
/// two frames at the same height or out of order; a least-squares fit does
/// not care about order, but the fit functions ask for increasing abscissae).
fn sorted_unique<T: Copy>(mut v: Vec<(f64, T)>) -> Vec<(f64, T)> {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v.dedup_by(|a, b| a.0 == b.0);
    v
}

/// Stage 3: stress/strain -> material.
pub fn fit_stage(
    spec: &Specimen,
    settings: &Settings,
    s: &StressOut,
) -> Result<FitOut, PipelineError> {
    let nu = spec.poisson;
    let k = match settings.stress.modulus {
        Modulus::Biaxial => 1.0 - nu,
        Modulus::Uniaxial => 1.0,
    };
    let strain_measure = settings.stress.strain;
    let mut warnings = Vec::new();
    let modulus_points: Vec<(f64, (f64, Option<f64>))> = sorted_unique(
        s.rows
            .iter()
            .filter_map(|r| {
                let e = r.value.strain?;
                let m = r.value.secant_modulus_pa?;
                (e > 0.0).then(|| (e, (m, r.std.and_then(|d| d.secant_modulus_pa))))
            })
            .collect(),
    );
    let modulus_points: Vec<(f64, f64, Option<f64>)> = modulus_points
        .into_iter()
        .map(|(e, (m, sd))| (e, m, sd))
        .collect();
    let stress_points: Vec<(f64, f64)> = sorted_unique(
        s.rows
            .iter()
            .filter_map(|r| {
                let l = r.value.stretch?;
                let st = r.value.stress_pa?;
                (l > 1.0).then_some((l, l * l * st))
            })
            .collect(),
    );
    let mut fit_table = toml::Table::new();
    fit_table.insert("source".into(), "stress_strain.csv of bulge run".into());
    let (model, detail) = match settings.fit {
        FitChoice::Quartic(degree) => {
            let (x, y): (Vec<f64>, Vec<f64>) = modulus_points.iter().map(|p| (p.0, p.1)).unzip();
            let f = quartic::fit(&x, &y, degree)?;
            warnings.extend(f.warnings.iter().map(|w| w.to_string()));
            if f.condition_scaled > 1e8 {
                warnings.push(format!(
                    "the scaled Vandermonde matrix has condition number {:.2e}: the coefficients are poorly determined; lower the degree",
                    f.condition_scaled
                ));
            }
            fit_table.insert("data".into(), "strain, secant_modulus_pa".into());
            fit_table.insert("points".into(), (f.stats.n as i64).into());
            fit_table.insert("degree".into(), (degree as i64).into());
            fit_table.insert(
                "modulus_convention".into(),
                settings.stress.modulus.name().into(),
            );
            fit_table.insert(
                "modulus_stress".into(),
                settings.stress.modulus_stress.name().into(),
            );
            fit_table.insert("rmse_pa".into(), f.stats.rmse.into());
            fit_table.insert("r2".into(), f.stats.r2.into());
            fit_table.insert("condition_number".into(), f.condition_scaled.into());
            let model = Model::Quartic {
                coefficients_pa: f.coefficients_pa.clone(),
                strain_range: f.strain_range,
                strain_measure,
            };
            (model, FitDetail::Quartic(f))
        }
        FitChoice::Hyper(kind) => {
            let data = Equibiaxial {
                stretch: stress_points.iter().map(|p| p.0).collect(),
                stress_pa: stress_points.iter().map(|p| p.1).collect(),
                measure: StressMeasure::Cauchy,
            };
            let f = hyperelastic::fit(kind, &data)?;
            if !f.drucker.stable {
                warnings.push(format!(
                    "{}: not Drucker-stable inside the fitted range",
                    kind.label()
                ));
            }
            fit_table.insert("data".into(), "stretch, cauchy stress l^2 p R / 2t".into());
            fit_table.insert("fitted".into(), kind.label().into());
            fit_table.insert("points".into(), (f.stats.n as i64).into());
            fit_table.insert("rmse_pa".into(), f.stats.rmse.into());
            fit_table.insert("r2".into(), f.stats.r2.into());
            fit_table.insert("drucker_stable".into(), f.drucker.stable.into());
            (f.model.clone(), FitDetail::Hyper(f))
        }
    };
    let cap_material = Material {
        model,
        poisson: nu,
        fit: None,
    };
    let mut material = cap_material.clone();
    let mut refined = None;
    if settings.refine {
        let measured: Vec<inverse::Measured> = s
            .points
            .iter()
            .filter(|p| p.pressure_pa > 0.0 && p.height_m > 0.0)
            .map(|p| inverse::Measured {
                pressure_pa: p.pressure_pa,
                height_m: p.height_m,
            })
            .collect();
        match inverse::refine(&cap_material, spec, &measured, &inverse::Options::default()) {
            Ok(r) => {
                let t = r.toml_table(&cap_material.model);
                fit_table.insert("refined".into(), t.into());
                if let Model::Quartic {
                    coefficients_pa,
                    strain_range,
                    ..
                } = &r.material.model
                {
                    warnings.extend(
                        quartic::check_law(coefficients_pa, *strain_range)
                            .iter()
                            .map(|w| format!("corrected law: {w}")),
                    );
                }
                material = r.material.clone();
                refined = Some(r);
            }
            Err(e) => warnings.push(format!(
                "the law was not corrected to the heights ({e}); the cap-method law is used"
            )),
        }
    }
    fit_table.insert(
        "warnings".into(),
        toml::Value::Array(warnings.iter().map(|w| w.clone().into()).collect()),
    );
    material.fit = Some(fit_table);
    Ok(FitOut {
        material,
        detail,
        modulus_points,
        stress_points,
        modulus_factor: k,
        strain_measure,
        warnings,
        cap_material,
        refined,
    })
}

impl FitOut {
    /// One line on the fit: the model, points, R^2, RMSE, and the correction
    /// to the heights when made.
    pub fn summary(&self, choice: &FitChoice) -> String {
        let what = match &self.detail {
            FitDetail::Quartic(q) => format!(
                "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                choice.label(),
                q.stats.n,
                q.stats.r2,
                q.stats.rmse
            ),
            FitDetail::Hyper(h) => format!(
                "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                h.kind.label(),
                h.stats.n,
                h.stats.r2,
                h.stats.rmse
            ),
        };
        match &self.refined {
            Some(r) => {
                let pct = |e: &[Option<f64>]| {
                    inverse::Refined::rms(e)
                        .map_or("-".to_string(), |v| format!("{:.2} %", 100.0 * v))
                };
                format!(
                    "{what}; corrected to the heights: rms height error {} -> {} ({} iterations, {} axisymmetric solves)",
                    pct(&r.before),
                    pct(&r.after),
                    r.iterations,
                    r.solves
                )
            }
            None => what,
        }
    }
}

/// One simulated pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct SimPoint {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m; `None` when no equilibrium was found.
    pub height_m: Option<f64>,
    /// Newton iterations / relaxation steps / shots.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Time of this pressure, s.
    pub wall_s: f64,
    /// Why there is no height.
    pub note: Option<String>,
}

/// The heights of one model at every pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelRun {
    /// `tp`, `van-gelder`, ..., or `axisym`.
    pub model: String,
    /// `newton`, `dr` or `shooting`.
    pub solver: String,
    /// Solved nodes (0 for the axisymmetric reference).
    pub nodes: usize,
    /// One per pressure.
    pub points: Vec<SimPoint>,
    /// Total time, s.
    pub wall_s: f64,
}

/// The pressures to simulate: the given list, or the distinct positive
/// measured pressures in increasing order.
pub fn pressures(settings: &Settings, points: &[Point]) -> Vec<f64> {
    if let Some(p) = &settings.pressures_pa {
        return p.clone();
    }
    let mut p: Vec<f64> = points
        .iter()
        .map(|p| p.pressure_pa)
        .filter(|&p| p > 0.0)
        .collect();
    p.sort_by(f64::total_cmp);
    p.dedup();
    p
}

/// Stage 4: the material on the specimen's disc at `pressures`, per model.
/// A pressure without equilibrium (above a limit point, a modulus law that
/// fails) ends that model's run with a note; the stage itself fails only
/// when a model cannot be set up.
pub fn simulate_stage(
    spec: &Specimen,
    settings: &Settings,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<Vec<ModelRun>, PipelineError> {
    crate::sim::scene::validate_pressures(pressures)
        .map_err(|m| PipelineError::Input(format!("pressures to simulate: {m}")))?;
    if pressures.windows(2).any(|w| w[1] <= w[0]) {
        return Err(PipelineError::Input(format!(
            "pressures to simulate {pressures:?}: give them in increasing order (each is continued from the previous)"
        )));
    }
    let mut scene = Scene::from_specimen(spec, material.clone(), pressures.to_vec());
    scene.mesh.size = settings.mesh;
    scene.validate(true).map_err(PipelineError::Input)?;
    let mesh = scene.build_mesh()?;
    let opts = solve::Options {
        tolerance: settings.tolerance,
        ..solve::Options::default()
    };
    opts.validate()?;
    let mut runs = Vec::new();
    for &model in &settings.models {
        let t_model = Instant::now();
        let mut disc =
            DiscSolver::on_mesh(&scene, mesh.clone(), model)?.with_solver(settings.solver, opts)?;
        let mut points = Vec::new();
        let mut stopped: Option<String> = None;
        for &p in pressures {
            if let Some(why) = &stopped {
                points.push(SimPoint {
                    pressure_pa: p,
                    height_m: None,
                    iterations: 0,
                    residual: f64::NAN,
                    wall_s: 0.0,
                    note: Some(why.clone()),
                });
                tick();
                continue;
            }
            let t0 = Instant::now();
            let out = disc.solve_to(p);
            let wall = t0.elapsed().as_secs_f64();
            match out {
                Ok(st) => points.push(SimPoint {
                    pressure_pa: p,
                    height_m: Some(disc.apex_height_m()),
                    iterations: st.iterations,
                    residual: st.residual,
                    wall_s: wall,
                    note: None,
                }),
                Err(e) => {
                    let why = format!("{} at {p} Pa: {e}", model.name());
                    points.push(SimPoint {
                        pressure_pa: p,
                        height_m: None,
                        iterations: 0,
                        residual: f64::NAN,
                        wall_s: wall,
                        note: Some(why.clone()),
                    });
                    stopped = Some(format!(
                        "not solved: {} stopped at a lower pressure",
                        model.name()
                    ));
                }
            }
            tick();
        }
        runs.push(ModelRun {
            model: model.name().to_string(),
            solver: settings.solver.name().to_string(),
            nodes: mesh.nodes.len(),
            points,
            wall_s: t_model.elapsed().as_secs_f64(),
        });
    }
    if settings.axisym {
        runs.push(axisym_run(spec, material, pressures, tick)?);
    }
    Ok(runs)
}

/// The exact axisymmetric reference of `material` at `pressures`.
pub fn axisym_run(
    spec: &Specimen,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<ModelRun, PipelineError> {
    let t_model = Instant::now();
    let opts = axisym::Options {
        n_profile: 2,
        ..axisym::Options::default()
    };
    let mut points = Vec::new();
    for &p in pressures {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(material, spec, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        points.push(match out {
            Ok(s) => SimPoint {
                pressure_pa: p,
                height_m: Some(s.height_m),
                iterations: s.iterations,
                residual: s.residual,
                wall_s: wall,
                note: None,
            },
            Err(
                e @ (AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)),
            ) => return Err(e.into()),
            Err(e) => SimPoint {
                pressure_pa: p,
                height_m: None,
                iterations: 0,
                residual: f64::NAN,
                wall_s: wall,
                note: Some(format!("axisym at {p} Pa: {e}")),
            },
        });
        tick();
    }
    Ok(ModelRun {
        model: "axisym".into(),
        solver: "shooting".into(),
        nodes: 0,
        points,
        wall_s: t_model.elapsed().as_secs_f64(),
    })
}

/// The columns every simulated-heights file starts with (`bulge simulate`,
/// `bulge simulate --dynamic`, `simulated.csv` of `bulge run`).
pub const SIMULATED_COLUMNS: [&str; 8] = [
    "pressure_pa",
    "height_m",
    "model",
    "solver",
    "nodes",
    "iterations",
    "residual",
    "wall_s",
];

/// `simulated.csv`: [`SIMULATED_COLUMNS`], solved pressures only (as
/// `bulge simulate`).
pub fn simulated_csv(runs: &[ModelRun]) -> CsvOut {
    let mut out = CsvOut::new(&SIMULATED_COLUMNS);
    for r in runs {
        for p in &r.points {
            if let Some(h) = p.height_m {
                out.row(&[
                    fmt_num(Some(p.pressure_pa)),
                    fmt_num(Some(h)),
                    r.model.clone(),
                    r.solver.clone(),
                    r.nodes.to_string(),
                    p.iterations.to_string(),
                    format!("{:.3e}", p.residual),
                    format!("{:.4}", p.wall_s),
                ]);
            }
        }
    }
    out
}

/// One row of the comparison table (Tudruj et al. (2023), Table 3 layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Measured height, m (mean over frames at this pressure), if measured.
    pub measured_m: Option<f64>,
    /// Its standard deviation, m.
    pub measured_std_m: Option<f64>,
    /// Simulated height per model (order of the runs), m.
    pub simulated_m: Vec<Option<f64>>,
}

impl Comparison {
    /// Relative error `(simulated - measured) / measured` per model.
    pub fn rel_errors(&self) -> Vec<Option<f64>> {
        self.simulated_m
            .iter()
            .map(|s| match (s, self.measured_m) {
                (Some(s), Some(m)) if m != 0.0 => Some((s - m) / m),
                _ => None,
            })
            .collect()
    }
}

/// The comparison table: one row per simulated pressure.
pub fn compare(points: &[Point], runs: &[ModelRun], pressures: &[f64]) -> Vec<Comparison> {
    pressures
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let same: Vec<&Point> = points.iter().filter(|q| q.pressure_pa == p).collect();
            let n = same.len() as f64;
            let measured_m =
                (!same.is_empty()).then(|| same.iter().map(|q| q.height_m).sum::<f64>() / n);
            let measured_std_m = if same.is_empty() {
                None
            } else {
                let v: Option<Vec<f64>> = same.iter().map(|q| q.height_std_m).collect();
                v.map(|v| (v.iter().map(|s| s * s).sum::<f64>()).sqrt() / n)
            };
            Comparison {
                pressure_pa: p,
                measured_m,
                measured_std_m,
                simulated_m: runs
                    .iter()
                    .map(|r| r.points.get(i).and_then(|q| q.height_m))
                    .collect(),
            }
        })
        .collect()
}

/// A one-line description of the stress conventions.
pub fn describe_stress(o: &mechanics::Options) -> String {
    format!(
        "strain {}, modulus {} = {}{} / strain, true stress {}",
        o.strain.name(),
        o.modulus.name(),
        if o.modulus == Modulus::Biaxial {
            "(1 - nu) "
        } else {
            ""
        },
        match o.modulus_stress {
            ModulusStress::Nominal => "lambda pR/2t (nominal)".to_string(),
            ModulusStress::Stress => "pR/2t (eq 18)".to_string(),
            ModulusStress::True => match o.true_stress {
                TrueStress::Paper => "lambda pR/2t (eq 25)".to_string(),
                TrueStress::Incompressible => "lambda^2 pR/2t (incompressible)".to_string(),
            },
        },
        o.true_stress.name()
    )
}

/// File name for messages.
pub fn display(p: &Path) -> String {
    p.display().to_string()
}

/// Time spent in one stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// The stage.
    pub stage: Stage,
    /// Wall time, s.
    pub seconds: f64,
    /// What it did, e.g. `12 photos, 41.3 photos/s`.
    pub what: String,
}

/// What a run tells its caller while it works (progress bars, logs). Every
/// method does nothing by default; `()` is the observer that ignores all.
pub trait Observer: Sync {
    /// `stage` starts; it will call [`Observer::tick`] about `steps` times.
    fn start(&self, _stage: Stage, _steps: u64) {}
    /// One step of the current stage is done (may be called from worker
    /// threads).
    fn tick(&self) {}
    /// A remark on the current stage (a frame left out, a degree lowered).
    fn note(&self, _stage: Stage, _message: &str) {}
    /// `stage` is done.
    fn done(&self, _timing: &Timing) {}
}

impl Observer for () {}

/// Every stage's output of a whole run ([`run`]).
#[cfg(feature = "opencv")]
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// Photos -> heights.
    pub tracking: Tracking,
    /// Heights -> stress and strain.
    pub stress: StressOut,
    /// Stress/strain -> material.
    pub fit: FitOut,
    /// The pressures simulated, Pa.
    pub pressures_pa: Vec<f64>,
    /// Simulated heights, one run per model (the axisymmetric reference last).
    pub runs: Vec<ModelRun>,
    /// Measured against simulated heights, one row per simulated pressure.
    pub comparison: Vec<Comparison>,
    /// Time per stage (track, stress, fit, simulate).
    pub timings: Vec<Timing>,
    /// Remarks made along the way (frames left out, a lowered degree, the
    /// simulator's notes), each prefixed with its stage.
    pub notes: Vec<String>,
}

/// The outputs of the stages that finished before a run stopped.
#[cfg(feature = "opencv")]
#[derive(Debug, Clone, Default)]
pub struct Partial {
    /// The tracking stage's output, when it finished.
    pub tracking: Option<Tracking>,
    /// The stress stage's output, when it finished.
    pub stress: Option<StressOut>,
    /// The fit stage's output, when it finished.
    pub fit: Option<FitOut>,
}

/// A run that stopped: the stage, why, and what the earlier stages made.
#[cfg(feature = "opencv")]
#[derive(Debug, thiserror::Error)]
#[error("stage `{}` {}: {error}", .stage.name(), if .error.is_bad_input() { "refused its input" } else { "failed" })]
pub struct RunError {
    /// The stage that stopped.
    pub stage: Stage,
    /// Why.
    pub error: PipelineError,
    /// The outputs of the stages before it.
    pub partial: Box<Partial>,
}

/// The whole pipeline on an experiment: photos -> heights -> stress/strain
/// -> material -> simulated heights -> comparison, in memory (nothing is
/// written). See [`run_observed`] for progress and remarks.
#[cfg(feature = "opencv")]
pub fn run(exp: &Experiment, settings: &Settings) -> Result<RunOutput, RunError> {
    run_observed(exp, settings, &())
}

/// [`run`], telling `obs` of each stage's start, steps, remarks and end.
#[cfg(feature = "opencv")]
pub fn run_observed(
    exp: &Experiment,
    settings: &Settings,
    obs: &dyn Observer,
) -> Result<RunOutput, RunError> {
    let mut partial = Partial::default();
    let fail = |stage: Stage, error: PipelineError, partial: &Partial| RunError {
        stage,
        error,
        partial: Box::new(partial.clone()),
    };
    let spec = &exp.specimen;
    let mut timings = Vec::new();
    let mut notes = Vec::new();
    let mut note = |stage: Stage, m: String| {
        obs.note(stage, &m);
        notes.push(format!("{}: {m}", stage.name()));
    };
    let mut finish = |stage: Stage, t: Instant, what: String| {
        let timing = Timing {
            stage,
            seconds: t.elapsed().as_secs_f64(),
            what,
        };
        obs.done(&timing);
        timings.push(timing);
    };

    // 1. track
    let t = Instant::now();
    let tracking =
        track_stage_observed(exp, settings, obs).map_err(|e| fail(Stage::Track, e, &partial))?;
    let secs = t.elapsed().as_secs_f64();
    let n = tracking.tracked.rows.len();
    for sk in &tracking.tracked.skipped {
        note(
            Stage::Track,
            format!(
                "skipped frame {} ({}): score {:.3}",
                sk.frame, sk.file, sk.score
            ),
        );
    }
    finish(
        Stage::Track,
        t,
        format!(
            "{n} of {} photos ({}x{} px), {:.1} photos/s",
            tracking.setup.frames.len(),
            tracking.tracked.image_size[0],
            tracking.tracked.image_size[1],
            n as f64 / secs.max(1e-9)
        ),
    );
    partial.tracking = Some(tracking.clone());

    // 2. stress
    let t = Instant::now();
    obs.start(Stage::Stress, 0);
    let stress = stress_stage(spec, settings, tracking.points())
        .map_err(|e| fail(Stage::Stress, e, &partial))?;
    finish(
        Stage::Stress,
        t,
        format!(
            "{} points, {}",
            stress.rows.len(),
            describe_stress(&settings.stress)
        ),
    );
    partial.stress = Some(stress.clone());

    // 3. fit
    let t = Instant::now();
    obs.start(Stage::Fit, 0);
    let mut fit_settings = settings.clone();
    if let FitChoice::Quartic(d) = settings.fit {
        let n_points = stress
            .rows
            .iter()
            .filter(|r| r.value.secant_modulus_pa.is_some())
            .count();
        if n_points >= 2 && n_points <= d {
            fit_settings.fit = FitChoice::Quartic(n_points - 1);
            note(
                Stage::Fit,
                format!(
                    "only {n_points} points with a secant modulus: degree lowered from {d} to {}",
                    n_points - 1
                ),
            );
        }
    }
    let fit = fit_stage(spec, &fit_settings, &stress).map_err(|e| fail(Stage::Fit, e, &partial))?;
    let what = fit.summary(&fit_settings.fit);
    finish(Stage::Fit, t, what);
    partial.fit = Some(fit.clone());

    // 4. simulate
    let t = Instant::now();
    let pressures_pa = pressures(settings, &stress.points);
    let n_runs = settings.models.len() + usize::from(settings.axisym);
    obs.start(Stage::Simulate, (n_runs * pressures_pa.len()) as u64);
    let runs = simulate_stage(spec, settings, &fit.material, &pressures_pa, &|| obs.tick())
        .map_err(|e| fail(Stage::Simulate, e, &partial))?;
    let what = runs
        .iter()
        .map(|r| {
            let solved = r.points.iter().filter(|p| p.height_m.is_some()).count();
            let nodes = if r.nodes > 0 {
                format!(", {} nodes", r.nodes)
            } else {
                String::new()
            };
            format!(
                "{} {}/{} in {:.3} s{nodes}",
                r.model,
                solved,
                r.points.len(),
                r.wall_s
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    finish(
        Stage::Simulate,
        t,
        format!("{} pressures: {what}", pressures_pa.len()),
    );
    for n in runs
        .iter()
        .flat_map(|r| r.points.iter().filter_map(|p| p.note.clone()))
        .filter(|n| !n.starts_with("not solved"))
    {
        note(Stage::Simulate, n);
    }
    let comparison = compare(&stress.points, &runs, &pressures_pa);
    Ok(RunOutput {
        tracking,
        stress,
        fit,
        pressures_pa,
        runs,
        comparison,
        timings,
        notes,
    })
}
