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
//! parameters ([`monte_carlo`], `bulge run --samples N`).

use rayon::prelude::*;

use super::FitError;
use super::inverse::{self, Measured};
use super::uncertainty::{ParamUncertainty, SourceKind, Sources, normal_quantile};
use crate::axisym;
use crate::experiment::Specimen;
use crate::material::Material;

#[cfg(feature = "opencv")]
pub mod photos;

pub use crate::numerics::Rng;

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

/// One synthetic experiment's readings and the true heights at them.
#[derive(Debug, Clone)]
pub struct Synthetic {
    /// What the fit sees.
    pub measured: Vec<Measured>,
    /// The real bubble's apex heights at the photos, m.
    pub true_heights_m: Vec<f64>,
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

/// One experiment's errors that every reading or height shares: the real
/// specimen, the gauge's gain, the scale's factor and the clamp row's
/// offset, m.
pub(crate) struct Shared {
    pub(crate) real: Specimen,
    pub(crate) gain: f64,
    pub(crate) scale: f64,
    pub(crate) offset_m: f64,
}

impl Shared {
    /// Draws them about `nominal` (thickness, radius, gain, scale, offset,
    /// in that order from `rng`).
    pub(crate) fn draw(s: &Sources, nominal: &Specimen, rng: &mut Rng) -> Shared {
        let real = Specimen {
            thickness_m: nominal.thickness_m - s.thickness_std_m * rng.normal(),
            radius_m: nominal.radius_m - s.radius_std_m * rng.normal(),
            ..*nominal
        };
        Shared {
            real,
            gain: 1.0 + s.pressure_relative_std * rng.normal(),
            scale: 1.0 + s.scale_relative_std * rng.normal(),
            offset_m: s.height_offset_std_m * rng.normal(),
        }
    }
}

/// One test of `truth` on a real specimen drawn about `nominal`, at the
/// true pressures `pressures`, read with the errors `s` and each height's
/// own standard deviation `stds`.
pub(crate) fn draw(
    truth: &Material,
    nominal: &Specimen,
    pressures: &[f64],
    stds: &[f64],
    s: &Sources,
    rng: &mut Rng,
) -> Result<Synthetic, FitError> {
    let Shared {
        real,
        gain,
        scale,
        offset_m: offset,
    } = Shared::draw(s, nominal, rng);
    let opts = inverse::Options::default().axisym;
    let mut measured = Vec::new();
    let mut true_heights_m = Vec::new();
    for (&p, &sd) in pressures.iter().zip(stds) {
        let h = axisym::solve_pressure(truth, &real, p, &opts)
            .map_err(|e| FitError::Solver(format!("the true law at {p} Pa: {e}")))?
            .height_m;
        measured.push(Measured {
            pressure_pa: p * gain + s.pressure_std_pa * rng.normal(),
            height_m: h * scale + offset + sd * rng.normal(),
            height_std_m: Some(sd),
        });
        true_heights_m.push(h);
    }
    Ok(Synthetic {
        measured,
        true_heights_m,
    })
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

/// The corrected law's parameters by Monte Carlo (a parametric bootstrap,
/// B. Efron and R. J. Tibshirani, An Introduction to the Bootstrap, Chapman
/// & Hall 1993, chapter 6): `samples` tests drawn from the corrected law
/// itself at the measured pressures with every error source, each corrected
/// again; the spread of the parameters is their uncertainty without the
/// first-order approximation.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarlo {
    /// Parameter names.
    pub names: Vec<String>,
    /// The corrected law's values.
    pub values: Vec<f64>,
    /// Samples drawn.
    pub samples: usize,
    /// Samples whose correction failed (left out).
    pub failed: usize,
    /// Standard deviation of each parameter over the samples.
    pub std_errors: Vec<f64>,
    /// Basic bootstrap 95 % intervals `[2 v - q97.5, 2 v - q2.5]`, `q` the
    /// samples' quantiles.
    pub intervals_95: Vec<[f64; 2]>,
}

impl MonteCarlo {
    /// The `monte_carlo` table of `material.toml`.
    pub fn toml_table(&self) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert("samples".into(), (self.samples as i64).into());
        t.insert("failed".into(), (self.failed as i64).into());
        let mut params = toml::Table::new();
        for (k, name) in self.names.iter().enumerate() {
            let mut p = toml::Table::new();
            p.insert("std_error".into(), self.std_errors[k].into());
            p.insert(
                "ci95".into(),
                toml::Value::Array(vec![
                    self.intervals_95[k][0].into(),
                    self.intervals_95[k][1].into(),
                ]),
            );
            params.insert(name.clone(), p.into());
        }
        t.insert("parameters".into(), params.into());
        t
    }
}

/// Monte Carlo of `refined`, the correction of a law to `measured` on
/// `specimen` with `opts` (see [`MonteCarlo`]): the samples in parallel,
/// sample `i` seeded by `seed + i`, so the result does not depend on the
/// threads. A point without a standard deviation gets the corrected law's
/// rms relative error times its height.
pub fn monte_carlo(
    refined: &inverse::Refined,
    specimen: &Specimen,
    measured: &[Measured],
    opts: &inverse::Options,
    samples: usize,
    seed: u64,
) -> Result<MonteCarlo, FitError> {
    let law = &refined.material;
    let (names, values, _) = inverse::law_parameters(&law.model)
        .ok_or_else(|| FitError::Unsupported("the law has no parameters".into()))?;
    let rms = inverse::Refined::rms(&refined.after).unwrap_or(0.0);
    let stds: Vec<f64> = measured
        .iter()
        .map(|q| q.height_std_m.unwrap_or(rms * q.height_m))
        .collect();
    let pressures: Vec<f64> = measured.iter().map(|q| q.pressure_pa).collect();
    let fits: Vec<Option<Vec<f64>>> = (0..samples)
        .into_par_iter()
        .map(|i| {
            let mut rng = Rng::new(seed.wrapping_add(i as u64));
            let data = draw(
                law,
                specimen,
                &pressures,
                &stds,
                &opts.uncertainty,
                &mut rng,
            )
            .ok()?;
            let r = inverse::refine(law, specimen, &data.measured, opts).ok()?;
            inverse::law_parameters(&r.material.model).map(|p| p.1)
        })
        .collect();
    let ok: Vec<Vec<f64>> = fits.iter().flatten().cloned().collect();
    if ok.len() < 2 {
        return Err(FitError::Solver(format!(
            "Monte Carlo: {} of {samples} samples could be corrected",
            ok.len()
        )));
    }
    let p = values.len();
    let m = ok.len() as f64;
    let mut std_errors = Vec::with_capacity(p);
    let mut intervals_95 = Vec::with_capacity(p);
    for k in 0..p {
        let mut v: Vec<f64> = ok.iter().map(|x| x[k]).collect();
        let mean = v.iter().sum::<f64>() / m;
        std_errors.push((v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt());
        v.sort_by(f64::total_cmp);
        let q = |f: f64| {
            let pos = f * (m - 1.0);
            let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
            v[lo] + (pos - lo as f64) * (v[hi] - v[lo])
        };
        intervals_95.push([2.0 * values[k] - q(0.975), 2.0 * values[k] - q(0.025)]);
    }
    Ok(MonteCarlo {
        names,
        values,
        samples,
        failed: samples - ok.len(),
        std_errors,
        intervals_95,
    })
}
