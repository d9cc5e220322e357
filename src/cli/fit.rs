//! `bulge fit`: stress/strain -> `material.toml` and its side files (see
//! `--output`), computed and drawn in memory first ([`bulge::fit::fit_material`],
//! [`bulge::report::fit_outputs`]); nothing is written when the input is refused.

use std::path::{Path, PathBuf};

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::experiment::Experiment;
use bulge::fit::data::{self, LoadOptions};
use bulge::fit::hyperelastic::Kind;
use bulge::fit::{FitError, FitModel, FitSettings, StressMeasure, fit_material, inverse};
use bulge::io::{OutputPlan, Table, write_atomic};
use bulge::material::StrainMeasure;
use bulge::mechanics::Modulus;
use bulge::report::fit_outputs::{FitPaths, fit_outputs};

/// Flags of `bulge fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input CSV: `stress_strain.csv` from `bulge stress` (recognised by its
    /// `secant_modulus_pa` column), or raw equibiaxial data with a `stretch`
    /// column and `nominal_stress_pa` or `cauchy_stress_pa` (or `stress_pa`
    /// with --stress-measure), such as data/treloar_equibiaxial.csv. Rows must
    /// be sorted by increasing stretch, without repeats.
    pub input: PathBuf,

    /// Model to fit. `quartic` fits the secant modulus against strain (what
    /// the mass-spring simulator reads); the hyperelastic models fit the
    /// equibiaxial stress against stretch; `all` compares every hyperelastic
    /// model.
    /// One of quartic, neo-hookean, mooney-rivlin, yeoh, ogden (see
    /// --ogden-terms), gent, all.
    #[arg(long, default_value = "quartic", value_parser = super::parse_fit_model)]
    pub model: FitModel,

    /// Degree N of the polynomial modulus law E(eps) (quartic only). Default
    /// 4, the paper's quartic; lower it when there are few points or the
    /// warnings report an unphysical law.
    #[arg(long, default_value_t = 4)]
    pub degree: usize,

    /// Number of Ogden terms, 1 to 3 (`--model ogden`). Default 3, Ogden's
    /// 1972 rubber model.
    #[arg(long, default_value_t = 3)]
    pub ogden_terms: usize,

    /// Poisson ratio written to material.toml (used by the mass-spring
    /// models) and, for raw data, in the biaxial secant modulus
    /// E = (1 - nu) sigma / eps. Must be in [0, 0.5). Default 0.45, the latex
    /// of Tudruj et al. (2023); use the value given to `bulge stress`.
    #[arg(long, default_value_t = 0.45)]
    pub poisson: f64,

    /// Stress measure. Raw data: what the stress column holds (inferred from
    /// `nominal_stress_pa` / `cauchy_stress_pa`; needed for `stress_pa`).
    /// `stress_strain.csv`: the measure the hyperelastic models are fitted
    /// in, built from `stress_pa` for an incompressible membrane (default
    /// cauchy). The residuals are in this measure, in Pa.
    #[arg(long, value_enum)]
    pub stress_measure: Option<StressMeasure>,

    /// Strain measure of the modulus law. `stress_strain.csv`: recognised
    /// from its `strain` column (the flag must agree); raw data: default
    /// engineering (lambda - 1).
    #[arg(long, value_enum)]
    pub strain_measure: Option<StrainMeasure>,

    /// Secant modulus convention, as in `bulge stress --modulus`: biaxial
    /// E = (1 - nu) sigma / eps (default, equibiaxial plane stress) or
    /// uniaxial E = sigma / eps. Used to build the modulus from raw data and
    /// to draw the stress that the fitted law implies.
    #[arg(long, value_enum, default_value_t = Modulus::Biaxial)]
    pub modulus: Modulus,

    /// Output material file (TOML); the other outputs are named after it
    /// (`<stem>_curve.csv`, `<stem>_residuals.csv`, `<stem>_fit.svg`,
    /// `<stem>_fit.png`, `<stem>_models.csv`).
    #[arg(short, long, default_value = "material.toml")]
    pub output: PathBuf,

    /// Correct the fitted law until the exact axisymmetric inflation of the
    /// specimen of this experiment file (its [specimen] table) reproduces the
    /// heights in the input's `pressure_pa` and `height_m` columns, which
    /// `bulge stress` writes (what `bulge run` does by default; see
    /// docs/run.md). `material.toml` then holds the corrected law, with the
    /// fitted one and the height errors before and after under
    /// [fit.refined]; the curve, residuals and plot stay those of the fit to
    /// the points. With a non-circular [window] in the experiment file the
    /// heights are those of the membrane model on that window (slower: a
    /// mesh sweep per law tried).
    #[arg(long, value_name = "EXPERIMENT")]
    pub to_heights: Option<PathBuf>,

    /// Weigh every point by its standard deviation instead of alike: in the
    /// fit to the points, each row's uncertainty carried from its height's
    /// along the law (the std and corr columns that `bulge stress
    /// --height-std-m` writes; without them the fit stays unweighted, with a
    /// warning); with --to-heights, each photo by its height's standard
    /// deviation, (h_sim - h) / sigma, instead of its relative error.
    #[arg(long)]
    pub weighted: bool,

    /// Number of points of the fitted curve in `<stem>_curve.csv` and the
    /// plot (default 200).
    #[arg(long, default_value_t = 200)]
    pub samples: usize,

    /// Do not draw the SVG and PNG plots.
    #[arg(long)]
    pub no_plot: bool,
}

/// The flags checked before any work; the settings of the fit.
fn settings(args: &Args) -> Result<FitSettings, Failure> {
    let bad = |m: String| Err(Failure::BadInput(anyhow!(m)));
    let (p, d, o, n) = (args.poisson, args.degree, args.ogden_terms, args.samples);
    let checks = [
        (
            (0.0..0.5).contains(&p),
            format!(
                "--poisson {p} is outside [0, 0.5): give the specimen's Poisson ratio (0.45 for latex, 0.5 is excluded)"
            ),
        ),
        (
            d <= 8,
            format!(
                "--degree {d} is too high: polynomial laws above degree 8 only fit the noise; use 2 to 6"
            ),
        ),
        (
            (1..=3).contains(&o),
            format!("--ogden-terms {o} is not supported: use 1, 2 or 3"),
        ),
        (
            (2..=100_000).contains(&n),
            format!(
                "--samples {n} must be in 2..=100000 (points of the drawn curve; 200 is plenty)"
            ),
        ),
    ];
    if let Some((_, m)) = checks.into_iter().find(|c| !c.0) {
        return bad(m);
    }
    let model = match args.model {
        FitModel::Hyperelastic(Kind::Ogden(_)) => {
            FitModel::Hyperelastic(Kind::Ogden(args.ogden_terms))
        }
        m => m.with_degree(args.degree),
    };
    Ok(FitSettings {
        model,
        poisson: args.poisson,
        modulus: args.modulus,
        modulus_stress: None,
        lower_degree: false,
        weighted: args.weighted,
    })
}

/// Runs `bulge fit`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let out = FitPaths::new(&args.output);
    let plan = OutputPlan::new()
        .input(&args.input)
        .inputs(&args.to_heights);
    super::guard(plan.output_as("-o", &out.material).outputs(out.sides()))?;
    let set = settings(&args)?;
    let exp = args.to_heights.as_ref();
    let specimen = exp.map(Experiment::read_specimen).transpose()?;
    let table = Table::read(&args.input)?;
    let opts = LoadOptions {
        stress_measure: args.stress_measure,
        strain_measure: args.strain_measure,
        poisson: args.poisson,
        modulus: args.modulus,
    };
    let flags = [
        ("stress measure", "--stress-measure"),
        ("strain measure", "--strain-measure"),
    ];
    let loaded = data::load(&table, &opts).map_err(|e| super::with_flags(e, &flags))?;
    let input = args.input.display().to_string();
    let mut fitted = fit_material(&loaded, &set, &input).map_err(|e| match e {
        FitError::TooFewPoints { points, .. } if matches!(set.model, FitModel::Quartic { .. }) => {
            Failure::BadInput(anyhow!(
                "{input}: {e} (with {points} points with a secant modulus, use --degree {} or less)",
                points.max(1) - 1
            ))
        }
        FitError::Solver(_) => Failure::Failed(anyhow!("{input}: {e}")),
        e => Failure::BadInput(anyhow!("{input}: {e}")),
    })?;
    let files = fit_outputs(&fitted, &loaded, &set, &input, args.samples);
    let mut summary = files.summary.clone();
    if let (Some(exp), Some(spec)) = (&args.to_heights, &specimen) {
        summary.push_str(&to_heights(
            &args.input,
            &table,
            exp,
            spec,
            &mut fitted,
            args.weighted,
        )?);
    }
    // Render everything before writing anything.
    let mut files_out = vec![
        (
            &out.material,
            bulge::io::to_toml_string(&fitted.material)
                .failed()?
                .into_bytes(),
        ),
        (&out.curve, files.curve.into_bytes()),
        (&out.residuals, files.residuals.into_bytes()),
    ];
    if let Some(m) = files.models {
        files_out.push((&out.models, m.into_bytes()));
    }
    if !args.no_plot {
        files_out.push((&out.svg, files.figure.to_svg().failed()?.into_bytes()));
        files_out.push((&out.png, files.figure.to_png().failed()?));
    }
    for (p, bytes) in &files_out {
        write_atomic(p, bytes)
            .map_err(|e| anyhow!("cannot write {}: {e}", p.display()))
            .failed()?;
    }
    print!("{summary}");
    fitted
        .warnings
        .iter()
        .for_each(|w| eprintln!("warning: {w}"));
    let names = files_out.iter().map(|f| f.0.display().to_string());
    println!("wrote {}", names.collect::<Vec<_>>().join(", "));
    Ok(())
}

/// `--to-heights`: the law corrected to the heights of `table`; the summary line.
fn to_heights(
    input: &Path,
    table: &Table,
    exp: &Path,
    specimen: &bulge::Specimen,
    fitted: &mut bulge::fit::FittedMaterial,
    weighted: bool,
) -> Result<String, Failure> {
    let Some(measured) = inverse::Measured::from_table(table)? else {
        return Err(Failure::BadInput(anyhow!(
            "{}: --to-heights needs the columns pressure_pa and height_m (bulge stress writes them); fit its stress_strain.csv",
            input.display()
        )));
    };
    // The inputs' uncertainties of the experiment file join the heights'
    // own in the covariance.
    let opts = inverse::Options {
        uncertainty: Experiment::read(exp)?.uncertainty(),
        weighted,
        ..Default::default()
    };
    let window = Experiment::read_window(exp)?;
    let r = if window.is_circle() {
        fitted.refine_to_heights(specimen, &measured, &opts)
    } else {
        let scene = bulge::sim::scene::Scene::from_window(
            specimen,
            &window,
            fitted.cap_material.clone(),
            vec![],
        );
        fitted.refine_in_scene(&scene, None, &measured, &opts)
    }
    .map_err(|err| {
        Failure::Failed(anyhow!(
            "{}: the law could not be corrected to the heights: {err}",
            input.display()
        ))
    })?;
    Ok(format!(
        "corrected to the heights of {} points on the specimen of {}: {}\n",
        measured.len(),
        exp.display(),
        r.describe()
    ))
}
