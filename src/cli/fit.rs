//! `bulge fit`: stress/strain -> `material.toml`, with the fitted curve as
//! CSV and a plot (SVG and PNG) of the data, the fit and the residuals.
//!
//! Outputs, all named after `--output` (default `material.toml`):
//! `material.toml`, `material_curve.csv` (the fitted curve on a fine grid),
//! `material_residuals.csv` (data, fit and residual at every point),
//! `material_fit.svg` and `material_fit.png` (unless `--no-plot`), and with
//! `--model all` `material_models.csv` (the comparison table). Everything is
//! computed and drawn in memory first; nothing is written when the input is
//! refused.

use super::{Classify, Failure};
use anyhow::anyhow;
use bulge::fit::data::{self, LoadOptions, Loaded, Source};
use bulge::fit::hyperelastic::{self, Equibiaxial, HyperFit, Kind};
use bulge::fit::quartic::{self, PolyFit};
use bulge::fit::{FitError, StressMeasure, inverse};
use bulge::io::{CsvOut, Table, fmt_num, write_atomic};
use bulge::material::{Material, Model, StrainMeasure};
use bulge::mechanics::Modulus;
use bulge::report::plot::{Figure, LegendPosition, Panel, Series};
use std::path::{Path, PathBuf};

/// Which model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    /// Tudruj et al.'s (2023) secant modulus law E(eps) = c0 + c1 eps + ... (degree `--degree`).
    Quartic,
    /// W = C1 (I1 - 3).
    NeoHookean,
    /// W = C1 (I1 - 3) + C2 (I2 - 3).
    MooneyRivlin,
    /// W = C1 (I1 - 3) + C2 (I1 - 3)^2 + C3 (I1 - 3)^3.
    Yeoh,
    /// W = sum mu_i/alpha_i (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3), `--ogden-terms` terms.
    Ogden,
    /// W = -(mu Jm / 2) ln(1 - (I1 - 3)/Jm).
    Gent,
    /// Every hyperelastic model (Ogden with 1, 2 and 3 terms); the one with
    /// the lowest AICc among the Drucker-stable fits goes to material.toml.
    All,
}

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
    #[arg(long, value_enum, default_value_t = ModelArg::Quartic)]
    pub model: ModelArg,

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
    /// the points.
    #[arg(long, value_name = "EXPERIMENT")]
    pub to_heights: Option<PathBuf>,

    /// Number of points of the fitted curve in `<stem>_curve.csv` and the
    /// plot (default 200).
    #[arg(long, default_value_t = 200)]
    pub samples: usize,

    /// Do not draw the SVG and PNG plots.
    #[arg(long)]
    pub no_plot: bool,
}

/// Side outputs named after the material file.
struct Outputs {
    material: PathBuf,
    curve: PathBuf,
    residuals: PathBuf,
    svg: PathBuf,
    png: PathBuf,
    models: PathBuf,
}

impl Outputs {
    fn new(material: &Path) -> Self {
        let stem = material
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "material".into());
        let dir = material.parent().unwrap_or(Path::new(""));
        let f = |suffix: &str| dir.join(format!("{stem}{suffix}"));
        Self {
            material: material.to_path_buf(),
            curve: f("_curve.csv"),
            residuals: f("_residuals.csv"),
            svg: f("_fit.svg"),
            png: f("_fit.png"),
            models: f("_models.csv"),
        }
    }
}

/// Everything to write, built in memory.
struct Product {
    material: Material,
    curve: CsvOut,
    residuals: CsvOut,
    figure: Figure,
    models: Option<CsvOut>,
    summary: String,
    warnings: Vec<String>,
}

/// Runs `bulge fit`.
pub fn run(args: Args) -> Result<(), Failure> {
    if !(0.0..0.5).contains(&args.poisson) {
        return Err(Failure::BadInput(anyhow!(
            "--poisson {} is outside [0, 0.5): give the specimen's Poisson ratio (0.45 for latex, 0.5 is excluded)",
            args.poisson
        )));
    }
    if args.degree > 8 {
        return Err(Failure::BadInput(anyhow!(
            "--degree {} is too high: polynomial laws above degree 8 only fit the noise; use 2 to 6",
            args.degree
        )));
    }
    if !(1..=3).contains(&args.ogden_terms) {
        return Err(Failure::BadInput(anyhow!(
            "--ogden-terms {} is not supported: use 1, 2 or 3",
            args.ogden_terms
        )));
    }
    if args.samples < 2 {
        return Err(Failure::BadInput(anyhow!(
            "--samples {} must be at least 2",
            args.samples
        )));
    }
    let table = Table::read(&args.input)?;
    let opts = LoadOptions {
        stress_measure: args.stress_measure,
        strain_measure: args.strain_measure,
        poisson: args.poisson,
        modulus: args.modulus,
    };
    let loaded = data::load(&table, &opts)?;
    // `bulge stress` writes the uncertainty of `secant_modulus_pa` as
    // `secant_modulus_std_pa` (unit last); drawn as error bars.
    let mod_std = match table.optional_numbers("secant_modulus_std_pa")? {
        Some(v) => Some(v),
        None => table.optional_numbers("secant_modulus_pa_std")?,
    };
    let product = match args.model {
        ModelArg::Quartic => quartic_product(&args, &loaded, mod_std)?,
        ModelArg::All => all_product(&args, &loaded)?,
        m => {
            let kind = match m {
                ModelArg::NeoHookean => Kind::NeoHookean,
                ModelArg::MooneyRivlin => Kind::MooneyRivlin,
                ModelArg::Yeoh => Kind::Yeoh,
                ModelArg::Ogden => Kind::Ogden(args.ogden_terms),
                _ => Kind::Gent,
            };
            let fit = hyperelastic::fit(kind, &loaded.equibiaxial)
                .map_err(|e| classify(&args.input, e))?;
            hyper_product(&args, &loaded, vec![fit], 0)
        }
    };
    let mut product = product;
    if let Some(exp) = &args.to_heights {
        to_heights(&args.input, &table, exp, &mut product)?;
    }
    // Render everything before writing anything.
    let toml_text = toml::to_string(&product.material).failed()?;
    let (svg, do_png) = if args.no_plot {
        (None, false)
    } else {
        (Some(product.figure.to_svg().failed()?), true)
    };
    let out = Outputs::new(&args.output);
    let write = |p: &Path, b: &[u8]| {
        write_atomic(p, b).map_err(|e| anyhow!("cannot write {}: {e}", p.display()))
    };
    write(&out.material, toml_text.as_bytes()).failed()?;
    write(&out.curve, &product.curve.into_bytes()).failed()?;
    write(&out.residuals, &product.residuals.into_bytes()).failed()?;
    if let Some(m) = product.models {
        write(&out.models, &m.into_bytes()).failed()?;
    }
    if let Some(svg) = svg {
        write(&out.svg, svg.as_bytes()).failed()?;
    }
    if do_png {
        product.figure.write_png(&out.png).failed()?;
    }
    print!("{}", product.summary);
    for w in &product.warnings {
        eprintln!("warning: {w}");
    }
    let mut written = vec![&out.material, &out.curve, &out.residuals];
    if args.model == ModelArg::All {
        written.push(&out.models);
    }
    if !args.no_plot {
        written.push(&out.svg);
        written.push(&out.png);
    }
    println!(
        "wrote {}",
        written
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

/// `--to-heights`: corrects `product.material` to the heights of `table`
/// (the input `input`) on the specimen of the experiment file `exp`.
fn to_heights(
    input: &Path,
    table: &Table,
    exp: &Path,
    product: &mut Product,
) -> Result<(), Failure> {
    let e = bulge::experiment::Experiment::read(exp)?;
    let (Some(p), Some(h)) = (
        table.optional_numbers("pressure_pa")?,
        table.optional_numbers("height_m")?,
    ) else {
        return Err(Failure::BadInput(anyhow!(
            "{}: --to-heights needs the columns pressure_pa and height_m (bulge stress writes them); fit its stress_strain.csv",
            input.display()
        )));
    };
    let measured: Vec<inverse::Measured> = p
        .iter()
        .zip(&h)
        .filter_map(|(p, h)| match (p, h) {
            (Some(p), Some(h)) if *p > 0.0 && *h > 0.0 => Some(inverse::Measured {
                pressure_pa: *p,
                height_m: *h,
            }),
            _ => None,
        })
        .collect();
    let r = inverse::refine(
        &product.material,
        &e.specimen,
        &measured,
        &Default::default(),
    )
    .map_err(|err| {
        Failure::Failed(anyhow!(
            "{}: the law could not be corrected to the heights: {err}",
            input.display()
        ))
    })?;
    let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.2} %", 100.0 * v));
    product.summary.push_str(&format!(
        "corrected to the heights of {} points on the specimen of {}: rms height error {} -> {} ({} iterations, {} axisymmetric solves)\n",
        measured.len(),
        exp.display(),
        pct(inverse::Refined::rms(&r.before)),
        pct(inverse::Refined::rms(&r.after)),
        r.iterations,
        r.solves
    ));
    let table = r.toml_table(&product.material.model);
    if let Some(ft) = product.material.fit.as_mut() {
        ft.insert("refined".into(), table.into());
    }
    product.material.model = r.material.model;
    Ok(())
}

/// Input problems are the user's (exit 2); solver failures are ours (exit 1).
fn classify(input: &Path, e: FitError) -> Failure {
    let msg = anyhow!("{}: {e}", input.display());
    match e {
        FitError::Solver(_) => Failure::Failed(msg),
        _ => Failure::BadInput(msg),
    }
}

/// Stress display unit for data of magnitude `max`.
fn stress_unit(max: f64) -> (f64, &'static str) {
    if max >= 1e5 {
        (1e-6, "MPa")
    } else {
        (1e-3, "kPa")
    }
}

fn stretch_of_strain(m: StrainMeasure, e: f64) -> f64 {
    match m {
        StrainMeasure::Engineering => 1.0 + e,
        StrainMeasure::Log => e.exp(),
    }
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

fn source_table(args: &Args, loaded: &Loaded) -> toml::Table {
    let mut t = toml::Table::new();
    t.insert("source".into(), args.input.display().to_string().into());
    t.insert(
        "input_kind".into(),
        match loaded.source {
            Source::StressStage => "stress_strain.csv of bulge stress",
            Source::Raw => "raw equibiaxial stretch and stress",
        }
        .into(),
    );
    t
}

fn quartic_product(
    args: &Args,
    loaded: &Loaded,
    mod_std: Option<Vec<Option<f64>>>,
) -> Result<Product, Failure> {
    let (strain, modulus) = loaded.modulus_points();
    let fit: PolyFit = quartic::fit(&strain, &modulus, args.degree).map_err(|e| match e {
        FitError::TooFewPoints { points, .. } => Failure::BadInput(anyhow!(
            "{}: {e} (with {points} points with a secant modulus, use --degree {} or less)",
            args.input.display(),
            points.max(1) - 1
        )),
        e => classify(&args.input, e),
    })?;
    let k = args.modulus.factor(args.poisson);
    let sm = loaded.strain_measure;
    let mut warnings: Vec<String> = fit.warnings.iter().map(|w| w.to_string()).collect();
    if fit.condition_scaled > 1e8 {
        warnings.push(format!(
            "the scaled Vandermonde matrix has condition number {:.2e}: the coefficients are poorly determined; lower --degree",
            fit.condition_scaled
        ));
    }
    let skipped = loaded.modulus_pa.iter().filter(|m| m.is_none()).count();

    let mut ft = source_table(args, loaded);
    ft.insert("data".into(), "strain, secant_modulus_pa".into());
    ft.insert("points".into(), (fit.stats.n as i64).into());
    ft.insert("points_skipped_zero_strain".into(), (skipped as i64).into());
    ft.insert("degree".into(), (args.degree as i64).into());
    ft.insert("modulus_convention".into(), args.modulus.name().into());
    ft.insert("rmse_pa".into(), fit.stats.rmse.into());
    ft.insert("r2".into(), fit.stats.r2.into());
    ft.insert("aic".into(), fit.stats.aic.into());
    ft.insert("condition_number".into(), fit.condition_scaled.into());
    ft.insert("condition_number_unscaled".into(), fit.condition_raw.into());
    if let Some(se) = &fit.std_errors_pa {
        ft.insert(
            "std_errors_pa".into(),
            toml::Value::Array(se.iter().map(|v| (*v).into()).collect()),
        );
    }
    ft.insert(
        "warnings".into(),
        toml::Value::Array(warnings.iter().map(|w| w.clone().into()).collect()),
    );
    let material = Material {
        model: Model::Quartic {
            coefficients_pa: fit.coefficients_pa.clone(),
            strain_range: fit.strain_range,
            strain_measure: sm,
        },
        poisson: args.poisson,
        fit: Some(ft),
    };

    // Curve on a grid; the stress the law implies is E eps / k.
    let [lo, hi] = fit.strain_range;
    let xs = grid(lo, hi, args.samples);
    let mut curve = CsvOut::new(&["stretch", "strain", "modulus_pa", "implied_stress_pa"]);
    let mut e_line = Vec::new();
    let mut s_line = Vec::new();
    for &e in &xs {
        let m = quartic::eval(&fit.coefficients_pa, e);
        let s = m * e / k;
        curve.row(&[
            fmt_num(Some(stretch_of_strain(sm, e))),
            fmt_num(Some(e)),
            fmt_num(Some(m)),
            fmt_num(Some(s)),
        ]);
        e_line.push((e, m));
        s_line.push((e, s));
    }
    let mut residuals = CsvOut::new(&[
        "line",
        "strain",
        "modulus_pa",
        "fit_modulus_pa",
        "residual_pa",
    ]);
    let used: Vec<usize> = (0..loaded.strain.len())
        .filter(|&i| loaded.modulus_pa[i].is_some())
        .collect();
    for (j, &i) in used.iter().enumerate() {
        residuals.row(&[
            loaded.lines[i].to_string(),
            fmt_num(Some(strain[j])),
            fmt_num(Some(modulus[j])),
            fmt_num(Some(modulus[j] - fit.residuals_pa[j])),
            fmt_num(Some(fit.residuals_pa[j])),
        ]);
    }

    // Plot: modulus, implied stress, residuals.
    let emax = modulus.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (f, unit) = stress_unit(emax);
    let smax = strain
        .iter()
        .zip(&modulus)
        .fold(0.0f64, |m, (e, v)| m.max((v * e / k).abs()));
    let (fs, sunit) = stress_unit(smax);
    let sc = |pts: &[(f64, f64)], f: f64| pts.iter().map(|&(x, y)| (x, y * f)).collect::<Vec<_>>();
    let data_pts: Vec<(f64, f64)> = strain.iter().zip(&modulus).map(|(&e, &m)| (e, m)).collect();
    let mut data_series = Series::scatter("secant modulus (data)", sc(&data_pts, f));
    if let Some(std) = mod_std {
        let errs: Vec<f64> = used
            .iter()
            .map(|&i| std[i].unwrap_or(f64::NAN) * f)
            .collect();
        data_series = data_series.with_errors(errs);
    }
    let strain_label = format!("{} strain (-)", sm.name());
    let p1 = Panel::new(&strain_label, format!("secant modulus E ({unit})"))
        .with(data_series)
        .with(Series::line(
            format!("E(eps), degree {}", args.degree),
            sc(&e_line, f),
        ))
        .legend(LegendPosition::UpperRight)
        .weight(2.0);
    let stress_pts: Vec<(f64, f64)> = strain
        .iter()
        .zip(&modulus)
        .map(|(&e, &m)| (e, m * e / k))
        .collect();
    let p2 = Panel::new(
        &strain_label,
        format!(
            "stress E eps / {} ({sunit})",
            if k == 1.0 {
                "1".to_string()
            } else {
                format!("(1 - {})", args.poisson)
            }
        ),
    )
    .with(Series::scatter("data", sc(&stress_pts, fs)))
    .with(Series::line("implied by the law", sc(&s_line, fs)))
    .weight(2.0);
    let res_pts: Vec<(f64, f64)> = strain
        .iter()
        .zip(&fit.residuals_pa)
        .map(|(&e, &r)| (e, r * f))
        .collect();
    let p3 = Panel::new(&strain_label, format!("residual ({unit})"))
        .with(Series::scatter("", res_pts).color(2))
        .zero_line()
        .weight(1.2);
    let figure = Figure::new(
        format!(
            "Secant modulus law, degree {} ({})",
            args.degree,
            file_name(&args.input)
        ),
        vec![p1, p2, p3],
    )
    .size(900, 1000);

    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} points ({} skipped at zero strain), {} strain, {} modulus\n",
        args.input.display(),
        fit.stats.n,
        skipped,
        sm.name(),
        args.modulus.name()
    ));
    s.push_str(&format!(
        "E(eps) = sum c_k eps^k, degree {}, strain range [{:.6}, {:.6}]\n",
        args.degree, lo, hi
    ));
    for (i, c) in fit.coefficients_pa.iter().enumerate() {
        let se = fit
            .std_errors_pa
            .as_ref()
            .map(|s| format!(" +- {:.4e}", s[i]))
            .unwrap_or_default();
        s.push_str(&format!("  c{i} = {c:.6e} Pa{se}\n"));
    }
    s.push_str(&format!(
        "RMSE {:.4e} Pa, R^2 {:.6}, AIC {:.3}, condition number {:.3e} (scaled; {:.3e} unscaled)\n",
        fit.stats.rmse, fit.stats.r2, fit.stats.aic, fit.condition_scaled, fit.condition_raw
    ));
    Ok(Product {
        material,
        curve,
        residuals,
        figure,
        models: None,
        summary: s,
        warnings,
    })
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

fn label_column(k: &Kind) -> String {
    k.label().replace('-', "_")
}

fn all_product(args: &Args, loaded: &Loaded) -> Result<Product, Failure> {
    let mut fits = Vec::new();
    let mut skipped = Vec::new();
    for kind in Kind::all() {
        match hyperelastic::fit(kind, &loaded.equibiaxial) {
            Ok(f) => fits.push(f),
            Err(e @ FitError::TooFewPoints { .. }) => {
                skipped.push(format!("{}: {e}", kind.label()))
            }
            Err(FitError::Solver(e)) => {
                skipped.push(format!("{}: solver failed: {e}", kind.label()))
            }
            Err(e) => return Err(classify(&args.input, e)),
        }
    }
    if fits.is_empty() {
        return Err(Failure::BadInput(anyhow!(
            "{}: no model could be fitted: {}",
            args.input.display(),
            skipped.join("; ")
        )));
    }
    // Lowest AICc among Drucker-stable fits, else overall. A model with
    // n <= k + 1 has no AICc (it can interpolate the data): it ranks after
    // every model that has one, by AIC among its kind.
    let score = |f: &HyperFit| match f.stats.aicc {
        Some(a) => (0, a),
        None => (1, f.stats.aic),
    };
    let pick = |stable_only: bool| {
        fits.iter()
            .enumerate()
            .filter(|(_, f)| !stable_only || f.drucker.stable)
            .min_by(|a, b| {
                let (sa, sb) = (score(a.1), score(b.1));
                sa.0.cmp(&sb.0).then(sa.1.total_cmp(&sb.1))
            })
            .map(|(i, _)| i)
    };
    let best = pick(true)
        .or_else(|| pick(false))
        .expect("at least one fit");
    let mut p = hyper_product(args, loaded, fits, best);
    for s in skipped {
        p.warnings.push(format!("skipped {s}"));
    }
    Ok(p)
}

fn hyper_product(args: &Args, loaded: &Loaded, fits: Vec<HyperFit>, best: usize) -> Product {
    let data: &Equibiaxial = &loaded.equibiaxial;
    let measure = data.measure.name();
    let chosen = &fits[best];
    let mut warnings = Vec::new();
    for f in &fits {
        if !f.drucker.stable {
            let at: Vec<String> = f
                .drucker
                .first_unstable
                .iter()
                .map(|(m, l)| format!("{} from stretch {l:.3}", m.name()))
                .collect();
            warnings.push(format!(
                "{}: not Drucker-stable inside the fitted range ({})",
                f.kind.label(),
                at.join(", ")
            ));
        }
        if f.stats.n > f.kind.n_params() && f.params.iter().any(|p| p.std_error.is_none()) {
            warnings.push(format!(
                "{}: the Jacobian is singular at the optimum, so some parameters are not determined by these data \
                 (no standard errors); a model with fewer parameters fits as well",
                f.kind.label()
            ));
        }
    }

    let mut ft = source_table(args, loaded);
    ft.insert(
        "data".into(),
        format!("stretch, {}", loaded.stress_column).into(),
    );
    ft.insert("stress_measure".into(), measure.into());
    ft.insert("fitted".into(), chosen.kind.label().into());
    ft.insert("points".into(), (chosen.stats.n as i64).into());
    ft.insert("rmse_pa".into(), chosen.stats.rmse.into());
    ft.insert("r2".into(), chosen.stats.r2.into());
    ft.insert("aic".into(), chosen.stats.aic.into());
    if let Some(a) = chosen.stats.aicc {
        ft.insert("aicc".into(), a.into());
    }
    let mut se = toml::Table::new();
    for p in &chosen.params {
        if let Some(e) = p.std_error {
            se.insert(p.name.clone(), e.into());
        }
    }
    ft.insert("std_errors".into(), se.into());
    ft.insert("drucker_stable".into(), chosen.drucker.stable.into());
    ft.insert(
        "drucker_stretch_range".into(),
        toml::Value::Array(chosen.drucker.range.iter().map(|v| (*v).into()).collect()),
    );
    ft.insert("starts".into(), (chosen.starts as i64).into());
    if fits.len() > 1 {
        ft.insert(
            "selected_by".into(),
            "lowest AICc among the Drucker-stable fits".into(),
        );
    }
    ft.insert(
        "warnings".into(),
        toml::Value::Array(warnings.iter().map(|w| w.clone().into()).collect()),
    );
    let material = Material {
        model: chosen.model.clone(),
        poisson: args.poisson,
        fit: Some(ft),
    };

    // Curve on a grid from min(1, l_min) to l_max.
    let lo = data.stretch.iter().copied().fold(1.0f64, f64::min);
    let hi = data.stretch[data.stretch.len() - 1];
    let ls = grid(lo, hi, args.samples);
    let curve = if fits.len() == 1 {
        let h = chosen.model.hyperelastic().expect("hyperelastic");
        let mut c = CsvOut::new(&["stretch", "nominal_stress_pa", "cauchy_stress_pa"]);
        for &l in &ls {
            c.row(&[
                fmt_num(Some(l)),
                fmt_num(Some(h.equibiaxial_nominal(l) + 0.0)),
                fmt_num(Some(h.equibiaxial_cauchy(l) + 0.0)),
            ]);
        }
        c
    } else {
        let mut header = vec!["stretch".to_string()];
        header.extend(
            fits.iter()
                .map(|f| format!("{}_{measure}_stress_pa", label_column(&f.kind))),
        );
        let mut c = CsvOut::new(&header);
        for &l in &ls {
            let mut row = vec![fmt_num(Some(l))];
            row.extend(
                fits.iter()
                    .map(|f| fmt_num(Some(data.predict(&f.model, l) + 0.0))),
            );
            c.row(&row);
        }
        c
    };
    let mut header = vec![
        "line".to_string(),
        "stretch".into(),
        format!("{measure}_stress_pa"),
    ];
    for f in &fits {
        header.push(format!("{}_residual_pa", label_column(&f.kind)));
    }
    let mut residuals = CsvOut::new(&header);
    for i in 0..data.stretch.len() {
        let mut row = vec![
            loaded.lines[i].to_string(),
            fmt_num(Some(data.stretch[i])),
            fmt_num(Some(data.stress_pa[i])),
        ];
        row.extend(fits.iter().map(|f| fmt_num(Some(f.residuals_pa[i]))));
        residuals.row(&row);
    }

    // Comparison table.
    let models = (fits.len() > 1).then(|| {
        let mut c = CsvOut::new(&[
            "model",
            "parameters",
            "points",
            "rmse_pa",
            "r2",
            "aic",
            "aicc",
            "drucker_stable",
            "selected",
            "values",
        ]);
        for (i, f) in fits.iter().enumerate() {
            c.row(&[
                f.kind.label(),
                f.kind.n_params().to_string(),
                f.stats.n.to_string(),
                fmt_num(Some(f.stats.rmse)),
                fmt_num(Some(f.stats.r2)),
                fmt_num(Some(f.stats.aic)),
                fmt_num(f.stats.aicc),
                f.drucker.stable.to_string(),
                (i == best).to_string(),
                f.params
                    .iter()
                    .map(|p| format!("{}={}", p.name, p.value))
                    .collect::<Vec<_>>()
                    .join(" "),
            ]);
        }
        c
    });

    // Plot.
    let smax = data.stress_pa.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (f, unit) = stress_unit(smax);
    let rmax = fits
        .iter()
        .flat_map(|f| f.residuals_pa.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (fr, runit) = stress_unit(rmax * 10.0);
    let pts: Vec<(f64, f64)> = data
        .stretch
        .iter()
        .zip(&data.stress_pa)
        .map(|(&l, &s)| (l, s * f))
        .collect();
    let mut p1 = Panel::new(
        "equibiaxial stretch (-)",
        format!("{measure} stress ({unit})"),
    )
    .with(Series::scatter("data", pts).color(0))
    .weight(2.0);
    let mut p2 = Panel::new(
        "equibiaxial stretch (-)",
        format!("residual, data - model ({runit})"),
    )
    .zero_line();
    for (k, fit) in fits.iter().enumerate() {
        let line: Vec<(f64, f64)> = ls
            .iter()
            .map(|&l| (l, data.predict(&fit.model, l) * f))
            .collect();
        let name = format!(
            "{} (RMSE {:.3} {unit})",
            fit.kind.label(),
            fit.stats.rmse * f
        );
        p1 = p1.with(Series::line(name, line).color(k + 1));
        let res: Vec<(f64, f64)> = data
            .stretch
            .iter()
            .zip(&fit.residuals_pa)
            .map(|(&l, &r)| (l, r * fr))
            .collect();
        p2 = p2.with(
            Series::scatter(
                if fits.len() > 1 {
                    String::new()
                } else {
                    fit.kind.label()
                },
                res,
            )
            .color(k + 1),
        );
    }
    let title = if fits.len() == 1 {
        format!(
            "{} fit, equibiaxial ({})",
            chosen.kind.label(),
            file_name(&args.input)
        )
    } else {
        format!(
            "Hyperelastic models, equibiaxial ({})",
            file_name(&args.input)
        )
    };
    let figure = Figure::new(title, vec![p1, p2]).size(900, 800);

    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} points, fitted in {measure} stress ({})\n",
        args.input.display(),
        data.stretch.len(),
        loaded.stress_column
    ));
    if fits.len() > 1 {
        s.push_str(&format!(
            "{:<14} {:>2} {:>12} {:>9} {:>9} {:>9} {:>8}\n",
            "model", "k", "RMSE (Pa)", "R^2", "AIC", "AICc", "Drucker"
        ));
        for (i, f) in fits.iter().enumerate() {
            s.push_str(&format!(
                "{:<14} {:>2} {:>12.1} {:>9.6} {:>9.2} {:>9} {:>8}{}\n",
                f.kind.label(),
                f.kind.n_params(),
                f.stats.rmse,
                f.stats.r2,
                f.stats.aic,
                f.stats
                    .aicc
                    .map(|a| format!("{a:.2}"))
                    .unwrap_or_else(|| "-".into()),
                if f.drucker.stable {
                    "stable"
                } else {
                    "UNSTABLE"
                },
                if i == best {
                    "  <- selected (lowest AICc, stable)"
                } else {
                    ""
                }
            ));
        }
    }
    s.push_str(&format!("{}:\n", chosen.kind.label()));
    for p in &chosen.params {
        let se = p
            .std_error
            .map(|e| format!(" +- {e:.4e}"))
            .unwrap_or_default();
        s.push_str(&format!("  {} = {:.6e}{se}\n", p.name, p.value));
    }
    s.push_str(&format!(
        "RMSE {:.4e} Pa, R^2 {:.6}, AIC {:.3}, Drucker-stable over stretch [{:.3}, {:.3}]: {} ({} starts, {} LM iterations)\n",
        chosen.stats.rmse,
        chosen.stats.r2,
        chosen.stats.aic,
        chosen.drucker.range[0],
        chosen.drucker.range[1],
        if chosen.drucker.stable { "yes" } else { "no" },
        chosen.starts,
        chosen.iterations
    ));
    Product {
        material,
        curve,
        residuals,
        figure,
        models,
        summary: s,
        warnings,
    }
}
