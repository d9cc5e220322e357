//! `bulge stress`: apex heights -> stress and strain ([`bulge::mechanics`]).
//!
//! Reads `pressure_pa,height_m` (plus any other columns, carried through in
//! input order), takes the specimen from `--experiment FILE.toml` or from
//! flags, and writes `pressure_pa,height_m,radius_m,arc_length_m,stretch,
//! strain,stress_pa,true_stress_pa,secant_modulus_pa`, followed by `*_std`
//! columns when a height uncertainty is given, and, when the experiment file
//! gives the other inputs' standard deviations, `<stem>_sources.csv` beside
//! it: how every point moves for each input's error. The outputs are built
//! in memory and written whole, or not at all when any input is refused.

use anyhow::{Context, anyhow};

use super::{Classify, Failure};
use bulge::experiment::{Experiment, Specimen};
use bulge::fit::uncertainty::Sources;
use bulge::io::OutputPlan;
use bulge::io::Table;
use bulge::mechanics::Options;
use bulge::pipeline;

mod args;
pub use args::*;

/// Runs `bulge stress`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let (spec, sources) = specimen(&args)?;
    let sources_path = args.output.with_file_name(format!(
        "{}_sources.csv",
        args.output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    ));
    let opts = Options {
        strain: args.strain,
        true_stress: args.true_stress,
        modulus: args.modulus,
        modulus_stress: args.modulus_stress,
    };
    if let Some(sd) = args.height_std_m
        && !(sd.is_finite() && sd >= 0.0)
    {
        return Err(anyhow!(
            "--height-std-m {sd}: a standard deviation must be a finite number >= 0 (in metres, e.g. 5e-5)"
        ))
        .bad_input();
    }
    let plan = OutputPlan::new()
        .input(&args.heights)
        .inputs(&args.experiment);
    super::guard(
        plan.output_as("-o", &args.output)
            .outputs((sources != Sources::default()).then_some(&sources_path)),
    )?;

    let table = Table::read(&args.heights)?;
    let both =
        "--height-std-m: drop the flag to use the column, or drop the column to use the flag";
    let tables = pipeline::stress_of_table(&spec, &opts, &table, args.height_std_m, &sources)
        .map_err(|e| match e {
            pipeline::StressTableError::Input(e) => {
                pipeline::StressTableError::Input(super::with_flags(e, &[("height_std_m", both)]))
            }
            e => e,
        })
        .map_err(Failure::of)?;
    let rows = tables.rows;
    let with_std = tables.with_std;
    let warnings = tables.warnings;
    tables
        .csv
        .write(&args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))
        .failed()?;
    if let Some(t) = tables.sources_csv {
        t.write(&sources_path)
            .with_context(|| format!("cannot write {}", sources_path.display()))
            .failed()?;
        eprintln!(
            "bulge stress: every point's change for each input's error -> {}",
            sources_path.display()
        );
    }
    eprintln!(
        "bulge stress: {} rows -> {} (strain {}, true stress {}, modulus {} on {} stress{})",
        rows,
        args.output.display(),
        opts.strain.name(),
        opts.true_stress.name(),
        opts.modulus.name(),
        opts.modulus_stress.name(),
        if with_std { ", with *_std columns" } else { "" }
    );
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The specimen from `--experiment` or from the flags, validated, and the
/// experiment's standard deviations besides the heights' (none from flags);
/// errors name the file and the line of the offending field, or the flag.
fn specimen(args: &Args) -> Result<(Specimen, Sources), Failure> {
    if let Some(path) = &args.experiment {
        // The specimen as a number (a dome height to fit is refused), its
        // bad field located to its line; then the standard deviations, checked,
        // of the whole file.
        let specimen = Experiment::read_specimen(path)?;
        let whole = Experiment::read(path)?;
        // Every key that shapes the membrane is honoured or said: the cap
        // formulas hold for a circular opening only, so through another
        // window the rows are the first guess that `bulge fit
        // --to-heights` (or `bulge run`) corrects through the window.
        if !whole.window.is_circle() {
            eprintln!(
                "warning: {}: [window] is not a circle: the spherical-cap formulas hold for a circular opening only, so these rows are a first guess of the law (radius_m as the cap's radius); correct it through the window with `bulge fit --to-heights {}` or use `bulge run`",
                path.display(),
                path.display()
            );
        }
        let sources = whole.uncertainty();
        return Ok((specimen, sources));
    }
    let missing = |flag: &str| anyhow!("{flag} is required without --experiment");
    let spec = Specimen {
        radius_m: args
            .radius_m
            .ok_or_else(|| missing("--radius-m"))
            .bad_input()?,
        thickness_m: args
            .thickness_m
            .ok_or_else(|| missing("--thickness-m"))
            .bad_input()?,
        poisson: args
            .poisson
            .ok_or_else(|| missing("--poisson"))
            .bad_input()?,
        prebulge_height_m: args.prebulge_height_m.unwrap_or(0.0),
    };
    spec.validate()
        .map_err(|m| {
            let flag = match m.field() {
                "radius_m" => "--radius-m",
                "thickness_m" => "--thickness-m",
                "poisson" => "--poisson",
                _ => "--prebulge-height-m",
            };
            anyhow!("flag {flag}: {m}")
        })
        .bad_input()?;
    Ok((spec, Sources::default()))
}
