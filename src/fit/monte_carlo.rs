//! The corrected law's parameters by Monte Carlo (`bulge run --samples N`):
//! synthetic tests drawn from the corrected law itself with every error
//! source ([`draw`]), each corrected again. The same draws, made from a
//! known law, give the coverage of the stated intervals (the harness
//! `fit::coverage`, feature `harness`, and its example).

use rayon::prelude::*;

use super::FitError;
use super::inverse::{self, Measured};
use super::uncertainty::Sources;
use crate::axisym;
use crate::experiment::Specimen;
use crate::material::Material;
use crate::numerics::Rng;

/// One synthetic experiment's readings and the true heights at them.
#[derive(Debug, Clone)]
pub struct Synthetic {
    /// What the fit sees.
    pub measured: Vec<Measured>,
    /// The real bubble's apex heights at the photos, m.
    pub true_heights_m: Vec<f64>,
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
        let gain = 1.0 + s.pressure_relative_std * rng.normal();
        let scale = 1.0 + s.scale_relative_std * rng.normal();
        let offset_m = s.height_offset_std_m * rng.normal();
        Shared {
            real,
            gain,
            // the scale read at the clamp plane moves with its offset
            scale: scale + s.offset_scale_per_m * offset_m,
            offset_m,
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
