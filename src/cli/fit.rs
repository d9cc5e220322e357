//! `bulge fit`: stress/strain -> `material.toml` and its side files (see
//! `--output`), computed and drawn in memory first ([`bulge::fit::fit_material`],
//! [`bulge::report::fit_outputs`]); nothing is written when the input is refused.

use std::path::Path;

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::experiment::Experiment;
use bulge::fit::data::{self, LoadOptions};
use bulge::fit::hyperelastic::Kind;
use bulge::fit::{FitError, FitModel, FitSettings, fit_material, inverse};
use bulge::io::{OutputPlan, Table, write_atomic};
use bulge::report::fit_outputs::{FitPaths, fit_outputs};

mod args;
pub use args::*;

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
        ("stress_measure", "--stress-measure"),
        ("strain_measure", "--strain-measure"),
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
