//! The flags of `bulge fit` and their help.

use bulge::fit::{FitModel, StressMeasure};
use bulge::material::StrainMeasure;
use bulge::mechanics::Modulus;
use std::path::PathBuf;

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
    #[arg(long, default_value = "quartic", value_parser = super::super::parse_fit_model)]
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
