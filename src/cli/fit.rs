//! `bulge fit`: stress/strain -> `material.toml` and its side files (see
//! `--output`), computed and drawn in memory first
//! ([`bulge::report::fit_command`]); nothing is written when the input is
//! refused.

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::io::{OutputPlan, Table, write_atomic};
use bulge::report::fit_command::{FitChoices, FitCommandError, fit_files};
use bulge::report::fit_outputs::FitPaths;

mod args;
pub use args::*;

/// The choices the flags give.
fn choices(args: &Args) -> FitChoices {
    FitChoices {
        model: args.model,
        degree: args.degree,
        ogden_terms: args.ogden_terms,
        poisson: args.poisson,
        modulus: args.modulus,
        weighted: args.weighted,
        samples: args.samples,
        stress_measure: args.stress_measure,
        strain_measure: args.strain_measure,
    }
}

/// Runs `bulge fit`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let out = FitPaths::new(&args.output);
    let plan = OutputPlan::new()
        .input(&args.input)
        .inputs(&args.to_heights);
    super::guard(plan.output_as("-o", &out.material).outputs(out.sides()))?;
    let choices = choices(&args);
    let set = choices
        .settings()
        .map_err(|e| Failure::BadInput(anyhow!("--{} {}", e.key.replace('_', "-"), e.text)))?;
    let table = Table::read(&args.input)?;
    let flags = [
        ("stress_measure", "--stress-measure"),
        ("strain_measure", "--strain-measure"),
    ];
    let input = args.input.display().to_string();
    let fit = fit_files(&table, &input, &choices, &set, args.to_heights.as_deref()).map_err(
        |e| match e {
            FitCommandError::Input(e) => Failure::BadInput(super::with_flags(e, &flags).into()),
            e => Failure::of(e),
        },
    )?;
    let (fitted, files, summary) = (fit.material, fit.outputs, fit.summary);
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
