//! The flags of `bulge run` (shared with `bulge study`) and their help.

use bulge::fit::FitModel;
use bulge::mechanics::{Modulus, ModulusStress, StrainMeasure, TrueStress};
use bulge::pipeline::RunOptions;
use bulge::sim::solve::Solver;
use bulge::sim::springs::SpringModel;
use std::path::PathBuf;

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

    /// The run's settings (each also a key of the experiment's [run] table).
    #[command(flatten)]
    pub flags: RunFlags,
}

/// The settings flags of `bulge run` (and `bulge study`): each overrides
/// the same key of a `[run]` table.
#[derive(Debug, Clone, clap::Args)]
pub struct RunFlags {
    /// Membrane models to simulate, comma-separated: tp, tp-paper,
    /// van-gelder, lloyd (mass-spring), membrane (constant-strain triangles
    /// with the material's whole law). Default tp,van-gelder (the
    /// comparison of Tudruj et al. 2023).
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

    /// Weigh each photo in the correction to the heights by its height's
    /// standard deviation (height_std_m and [pressure] std_pa), (h_sim - h) /
    /// sigma, instead of its relative error h_sim / h - 1 (the default, which
    /// weighs every photo alike; docs/fit.md, "Uncertainty"), and each point
    /// of the fit to the stress/strain points by its uncertainty carried
    /// from its height's. The parameters' covariance carries the given
    /// errors either way. `weighted = true` in [run] does the same.
    #[arg(long)]
    pub weighted: bool,

    /// Monte Carlo of the corrected parameters: N tests drawn from the
    /// corrected law with every error source (height_std_m, [pressure],
    /// [calibration], [specimen] standard deviations), each corrected again,
    /// in parallel and seeded (the same N gives the same result); their
    /// spread is written beside the first-order covariance in material.toml
    /// ([fit.refined.uncertainty.monte_carlo]). Costs N corrections.
    /// `samples = N` in [run] does the same.
    #[arg(long, value_name = "N")]
    pub samples: Option<usize>,

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
    #[arg(long, value_parser = super::super::parse_fit_model)]
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

    /// The largest --samples taken (default 10000: each sample is one
    /// correction of the law, 0.1-0.5 s). `max_samples = N` in [run] does
    /// the same.
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
}

impl RunFlags {
    /// The flags as run options (what they leave out is `None`).
    pub fn options(&self) -> RunOptions {
        RunOptions {
            models: self.models.clone(),
            axisym: self.no_axisym.then_some(false),
            refine: self.no_refine.then_some(false),
            weighted: self.weighted.then_some(true),
            samples: self.samples,
            pressures_pa: self.pressures.clone(),
            accuracy: self.accuracy,
            nodes: self.nodes,
            fit: self.fit,
            degree: self.degree,
            strain: self.strain,
            true_stress: self.true_stress,
            modulus: self.modulus,
            modulus_stress: self.modulus_stress,
            solver: self.solver,
            min_score: self.min_score,
            skip_bad_frames: self.skip_bad_frames.then_some(true),
            max_samples: self.max_samples,
        }
    }
}
