//! Do the 95 % intervals hold the truth 95 % of the time? Synthetic
//! inflation tests with known errors, each fitted as `bulge run` fits
//! (the law corrected to the heights, weighted, with its covariance), and
//! the share of intervals that hold the true parameters and the true heights
//! counted.
//!
//! Each experiment draws the real specimen's thickness and radius about
//! the nominal ones, solves the true law's apex heights on it with the
//! exact axisymmetric inflation, then reads them as a bulge test does: the
//! pressures through a gauge with a gain error and reading noise, the
//! heights through a scale and a clamp row that are off, with each height's
//! own noise. The fit sees only the nominal specimen and the readings. The
//! experiments are independent and seeded by their index, so a plan gives
//! the same counts on every machine and any number of threads.
//!
//! The unit tests run a cheap plan (`src/fit/inverse/tests.rs`), the example
//! `coverage` the full one (its table in `docs/fit.md`). The same draws,
//! made from a corrected law itself, give the Monte Carlo of its
//! parameters ([`super::monte_carlo`], `bulge run --samples N`).
//!
//! A harness, not a stage: built for the tests and with the feature
//! `harness` (its examples need it).

use rayon::prelude::*;

use super::FitError;
use super::inverse;
pub use super::monte_carlo::Synthetic;
use super::monte_carlo::draw;
use super::uncertainty::{ParamUncertainty, SourceKind, Sources, normal_quantile};
use crate::experiment::Specimen;
use crate::material::Material;
use crate::numerics::Rng;

#[cfg(feature = "opencv")]
pub mod photos;

/// What to simulate.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The true law.
    pub truth: Material,
    /// The nominal specimen (the real one is drawn about it).
    pub specimen: Specimen,
    /// The true pressures of the photos, Pa.
    pub pressures_pa: Vec<f64>,
    /// Each height's own standard deviation, m.
    pub height_std_m: f64,
    /// The other errors, drawn as they say and given to the fit.
    pub sources: Sources,
    /// Experiments.
    pub experiments: usize,
    /// Seed of the first experiment (experiment `i` uses `seed + i`).
    pub seed: u64,
    /// Fit weighted by the points' standard deviations (else the relative
    /// errors, as `bulge run` does by default).
    pub weighted: bool,
}

/// Experiment `index` of `plan`.
pub fn synthetic(plan: &Plan, index: usize) -> Result<Synthetic, FitError> {
    let mut rng = Rng::new(plan.seed.wrapping_add(index as u64));
    let stds = vec![plan.height_std_m; plan.pressures_pa.len()];
    draw(
        &plan.truth,
        &plan.specimen,
        &plan.pressures_pa,
        &stds,
        &plan.sources,
        &mut rng,
    )
}

/// The counts of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// Parameter names.
    pub names: Vec<String>,
    /// Experiments fitted (with a covariance).
    pub experiments: usize,
    /// Per parameter, the experiments whose 95 % interval holds the truth.
    pub covered: Vec<usize>,
    /// The same with the intervals from the points' own errors alone (the
    /// shared ones left out): what an unweighted or naive fit would claim.
    pub covered_points_only: Vec<usize>,
    /// Photos whose true height lies in the 95 % band, and photos.
    pub band: (usize, usize),
    /// Standard error of the band's share `band.0 / band.1`, from the
    /// spread of the experiments' own shares (the heights of one
    /// experiment share its law's error, so they are not independent
    /// trials: the binomial error of `band.1` heights would be too small).
    pub band_std_error: f64,
    /// Per parameter, the mean standard error over the experiments,
    /// relative to the true value.
    pub mean_relative_std: Vec<f64>,
}

/// Runs `plan`: every experiment fitted from `start` (experiments in
/// parallel).
pub fn run(plan: &Plan, start: &Material) -> Result<Coverage, FitError> {
    let (names, theta, _) = inverse::law_parameters(&plan.truth.model)
        .ok_or_else(|| FitError::Unsupported("the true law has no parameters".into()))?;
    let opts = inverse::Options {
        uncertainty: plan.sources,
        weighted: plan.weighted,
        ..inverse::Options::default()
    };
    let one = |i: usize| -> Result<Option<Judged>, FitError> {
        let data = synthetic(plan, i)?;
        let r = inverse::refine(start, &plan.specimen, &data.measured, &opts)?;
        let Some(u) = r.uncertainty.as_ref() else {
            return Ok(None);
        };
        let readings: Vec<f64> = data.measured.iter().map(|q| q.pressure_pa).collect();
        let b = inverse::band(
            &r.material,
            &plan.specimen,
            u,
            &plan.sources,
            &readings,
            &opts.axisym,
        );
        let pairs: Vec<_> = b.into_iter().zip(data.true_heights_m).collect();
        Ok(Some(Judged::new(u, &theta, &pairs)))
    };
    let all: Vec<Result<Option<Judged>, FitError>> =
        (0..plan.experiments).into_par_iter().map(one).collect();
    let mut judged = Vec::with_capacity(all.len());
    for r in all {
        judged.extend(r?);
    }
    Ok(Coverage::tally(names, &judged))
}

/// One experiment's verdicts: whether each parameter's 95 % interval holds
/// the truth (with every source, and with the points' own errors alone),
/// the true heights inside the 95 % band, and each parameter's standard
/// error relative to its true value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Judged {
    inside: Vec<bool>,
    naive: Vec<bool>,
    hit: usize,
    heights: usize,
    rel: Vec<f64>,
}

impl Judged {
    /// Judges the intervals of `u` against the true parameters `theta`, and
    /// each band point against the true height at its reading (`None`: no
    /// band there, not counted).
    pub(crate) fn new(
        u: &ParamUncertainty,
        theta: &[f64],
        band: &[(Option<inverse::BandPoint>, f64)],
    ) -> Judged {
        let k = u.coverage_factor();
        let se = u.std_errors();
        let pts = u.std_errors_from(SourceKind::Points);
        let z = normal_quantile(0.975);
        let (mut hit, mut heights) = (0, 0);
        for (bp, h) in band {
            if let Some(bp) = bp {
                heights += 1;
                hit += usize::from((bp.height_m - h).abs() <= z * bp.std_m);
            }
        }
        Judged {
            inside: (0..theta.len())
                .map(|j| (u.values[j] - theta[j]).abs() <= k * se[j])
                .collect(),
            naive: (0..theta.len())
                .map(|j| (u.values[j] - theta[j]).abs() <= k * pts[j])
                .collect(),
            hit,
            heights,
            rel: (0..theta.len()).map(|j| se[j] / theta[j].abs()).collect(),
        }
    }
}

impl Coverage {
    /// The counts over the experiments judged.
    pub(crate) fn tally(names: Vec<String>, judged: &[Judged]) -> Coverage {
        let p = names.len();
        let mut out = Coverage {
            names,
            experiments: judged.len(),
            covered: vec![0; p],
            covered_points_only: vec![0; p],
            band: (0, 0),
            band_std_error: 0.0,
            mean_relative_std: vec![0.0; p],
        };
        for j in judged {
            for k in 0..p {
                out.covered[k] += usize::from(j.inside[k]);
                out.covered_points_only[k] += usize::from(j.naive[k]);
                out.mean_relative_std[k] += j.rel[k];
            }
            out.band.0 += j.hit;
            out.band.1 += j.heights;
        }
        for v in &mut out.mean_relative_std {
            *v /= out.experiments.max(1) as f64;
        }
        // The ratio estimator's standard error over clusters (W. G.
        // Cochran, Sampling Techniques, 3rd ed., Wiley 1977, section 6.4).
        let e = judged.len() as f64;
        if e > 1.0 && out.band.1 > 0 {
            let share = out.band.0 as f64 / out.band.1 as f64;
            let mean_n = out.band.1 as f64 / e;
            let ss: f64 = judged
                .iter()
                .map(|j| (j.hit as f64 - share * j.heights as f64).powi(2))
                .sum();
            out.band_std_error = (ss / (e * (e - 1.0))).sqrt() / mean_n;
        }
        out
    }
}
