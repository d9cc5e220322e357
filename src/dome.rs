//! The stress-free dome height of a slack membrane (`prebulge_height_m =
//! "fit"`) found from the measured heights, and the checks that keep a
//! law with negative stiffness out of a run.
//!
//! A slack coated fabric is clamped with more length than the flat disc
//! needs: it sags or domes with no stress, and the heights a gauge or a 3D
//! correlation gives are often displacements from that state. The law
//! fitted to the heights depends on the dome height `h0` assumed, so `h0`
//! is found with the law: at each trial `h0` the stress stage, the fit and
//! the correction to the heights through the exact axisymmetric inflation
//! are run, and the root mean square relative height error of the
//! corrected law is the misfit `Q(h0)`.
//!
//! Why a search can fall off a cliff: at a trial `h0` the cap formulas'
//! secant moduli can make a quartic `E(eps)` that is negative near zero
//! strain (a fabric is soft while its crimp straightens, then stiff), the
//! correction then has no equilibrium at the lowest pressure and the trial
//! fails. So (1) a quartic start whose implied stress `E(eps) eps` does not
//! rise from zero strain to the largest is replaced by a positive one (the
//! straight line through the secant moduli, [`positive_start`]) before the
//! correction; (2) a trial that fails, or whose corrected law has negative
//! stiffness anywhere from zero strain to the largest measured
//! ([`stiffness_problem`]), counts as an infinite misfit, never as an
//! abort; (3) the search first scans a grid over the whole physical range
//! of `h0`, then refines by golden sections inside the best grid point's
//! neighbours, so a failure on one side moves the bracket instead of
//! ending the search. The standard deviation of `h0` is the profile
//! likelihood's ([`crate::fit::inverse`]'s `profile_std`): the curvature of
//! `Q` at the optimum, with the points' variance from the residuals.

use crate::experiment::Specimen;
use crate::fit::FittedMaterial;
use crate::fit::data::Loaded;
use crate::fit::quartic;
use crate::material::Model;

/// `x > 0`, false for NaN.
fn positive(x: f64) -> bool {
    x > 0.0
}

/// Samples of the strain range in the stiffness check.
const STIFFNESS_SAMPLES: usize = 200;

/// Why `model` is not a physical law from zero strain to `max_strain`
/// (engineering strain of the pole, `lambda - 1`): a quartic secant modulus
/// `E(0) <= 0` or an implied stress `E(eps) eps` that falls somewhere; a
/// hyperelastic law whose equibiaxial nominal stress falls with the
/// stretch. `None` when the law stiffens or softens but always rises.
pub fn stiffness_problem(model: &Model, max_strain: f64) -> Option<String> {
    let top = max_strain.max(0.0);
    let samples = (0..STIFFNESS_SAMPLES).map(|k| top * k as f64 / (STIFFNESS_SAMPLES - 1) as f64);
    match model {
        Model::Quartic {
            coefficients_pa, ..
        } => {
            let e0 = coefficients_pa.first().copied().unwrap_or(0.0);
            if !positive(e0) {
                return Some(format!(
                    "its modulus at zero strain is {e0:.3e} Pa (not positive)"
                ));
            }
            samples
                .map(|e| (e, quartic::implied_stress_slope(coefficients_pa, e)))
                .find(|(_, s)| !positive(*s))
                .map(|(e, s)| {
                    format!("its stress falls at strain {e:.4} (tangent modulus {s:.3e} Pa)")
                })
        }
        Model::Linear { young_pa } => {
            (!positive(*young_pa)).then(|| format!("its modulus {young_pa:.3e} Pa is not positive"))
        }
        _ => {
            let h = model.hyperelastic()?;
            let mut last = 0.0;
            for (k, e) in samples.enumerate().skip(1) {
                let s = h.equibiaxial_nominal(1.0 + e);
                if !positive(s - last) {
                    let _ = k;
                    return Some(format!(
                        "its equibiaxial stress falls at strain {e:.4} ({s:.3e} Pa)"
                    ));
                }
                last = s;
            }
            None
        }
    }
}

/// A quartic start with positive stiffness from zero strain to the
/// largest, of the same degree, in place of `fitted`'s cap-method law when
/// that one has negative stiffness there (the correction to the heights
/// starts from it and would find no equilibrium at the lowest pressures).
/// The start is the least-squares straight line `E = c0 + c1 eps` through
/// the secant moduli of `data`, both coefficients kept positive (the better
/// of `c1 = 0` and `c0 -> 0` when the free line has a negative one); the
/// correction then moves every coefficient. Returns a sentence when it
/// replaced the start.
pub fn positive_start(fitted: &mut FittedMaterial, data: &Loaded) -> Option<String> {
    let Model::Quartic {
        coefficients_pa, ..
    } = &fitted.cap_material.model
    else {
        return None;
    };
    let pts: Vec<(f64, f64)> = data
        .strain
        .iter()
        .zip(&data.modulus_pa)
        .filter_map(|(&e, m)| m.filter(|m| m.is_finite() && e.is_finite()).map(|m| (e, m)))
        .collect();
    let max_strain = pts.iter().map(|p| p.0).fold(0.0, f64::max);
    let why = stiffness_problem(&fitted.cap_material.model, max_strain)?;
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let ssr = |c0: f64, c1: f64| -> f64 { pts.iter().map(|p| (c0 + c1 * p.0 - p.1).powi(2)).sum() };
    let (mut c0, mut c1) = if sxx > 0.0 {
        (my - sxy / sxx * mx, sxy / sxx)
    } else {
        (my, 0.0)
    };
    if !(c0 > 0.0 && c1 >= 0.0) {
        let flat = (my.max(0.0), 0.0);
        let sxx0: f64 = pts.iter().map(|p| p.0 * p.0).sum();
        let through = (
            0.0,
            (pts.iter().map(|p| p.0 * p.1).sum::<f64>() / sxx0).max(0.0),
        );
        (c0, c1) = if ssr(flat.0, flat.1) <= ssr(through.0, through.1) {
            flat
        } else {
            through
        };
    }
    // A positive modulus at zero strain: a hundredth of the largest
    // modulus of the line at least.
    let top = c0 + c1 * max_strain;
    c0 = c0.max(0.01 * top);
    if !(c0 > 0.0 && c0.is_finite() && c1.is_finite()) {
        return None;
    }
    let mut coefficients = vec![0.0; coefficients_pa.len()];
    coefficients[0] = c0;
    if coefficients.len() > 1 {
        coefficients[1] = c1;
    }
    let mut start = fitted.cap_material.clone();
    if let Model::Quartic {
        coefficients_pa, ..
    } = &mut start.model
    {
        *coefficients_pa = coefficients;
    }
    fitted.cap_material = start;
    Some(format!(
        "the cap-method law was not physical ({why}): the correction to the heights started from the straight line E = {c0:.3e} Pa + {c1:.3e} Pa x strain through the secant moduli"
    ))
}

/// The largest strain of `data` in the measure `model` takes: the strain
/// column for a quartic (its own measure), the stretch less one for the
/// others.
pub fn top_strain(model: &Model, data: &Loaded) -> f64 {
    match model {
        Model::Quartic { .. } => data.strain.iter().copied().fold(0.0, f64::max),
        _ => data
            .equibiaxial
            .stretch
            .iter()
            .map(|l| l - 1.0)
            .fold(0.0, f64::max),
    }
}

/// The largest pole strain (`lambda - 1`) of `points` on the dome of
/// `spec`, from the cap formulas (the range the stiffness check covers).
pub fn max_strain(spec: &Specimen, heights_m: &[f64]) -> f64 {
    let a = spec.radius_m;
    let s0 = crate::mechanics::arc_length(a, spec.prebulge_height_m);
    heights_m
        .iter()
        .map(|&h| crate::mechanics::arc_length(a, h) / s0 - 1.0)
        .fold(0.0, f64::max)
}

/// The dome found by [`search`].
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Height of the reference state's apex above the clamp plane, m: added
    /// to heights measured from the reference (0 for heights above the
    /// clamp plane).
    pub reference_m: f64,
    /// The stress-free dome height `h0` (`prebulge_height_m`), m.
    pub h0_m: f64,
    /// Standard deviation of `h0` from the profile of the misfit, when the
    /// profile is convex there and the heights determine `h0`
    /// (`h0_determined`); `None` otherwise, never a number with a false
    /// deviation.
    pub h0_std_m: Option<f64>,
    /// The 95 % profile-likelihood interval of `h0`, m: the lowest and
    /// highest trial dome whose misfit lies within the chi-square quantile
    /// of one degree of freedom of the best (`n (Q - Q_best) / s^2 <=
    /// 3.84`), when the points' variance `s^2` can be estimated.
    pub h0_interval_m: Option<(f64, f64)>,
    /// Whether the heights determine `h0`: false when the 95 % interval
    /// reaches an end of the physical range (a flat dome `z`, or the lowest
    /// measured height `z + d1`), so the profile of the misfit does not
    /// rise on that side within the range the search may try.
    pub h0_determined: bool,
    /// The corrected law's rms relative height error at the optimum.
    pub rms: f64,
    /// Trials run, and how many failed or gave a law with negative
    /// stiffness (counted as an infinite misfit).
    pub trials: usize,
    /// Of them, the failed ones.
    pub failed: usize,
}

/// Grid of the search: the stress-free dome height as a fraction of the
/// lowest measured height above the reference (`h0 = z + f d1`).
const F_GRID: [f64; 6] = [0.0, 0.25, 0.5, 0.75, 0.9, 1.0];
/// The reference apex height `z`, as a fraction of the radius.
const Z_GRID: [f64; 5] = [0.0, 0.05, 0.1, 0.2, 0.3];
/// Golden sections per coordinate after the grid.
const SECTIONS: usize = 8;
/// The chi-square quantile of one degree of freedom at 95 %.
const CHI2_1_95: f64 = 3.841;

/// The profile interval of `h0` over the trials `seen` (`(h0, f, rms)`,
/// `f` the fraction of the lowest height, 0 and 1 the ends of the
/// physical range): the lowest and highest `h0` whose misfit satisfies
/// `n (Q - Q_best) / s^2 <= level` (`Q = rms^2`), with whether it is
/// closed (no such trial at an end of the range).
pub fn profile_interval(
    seen: &[(f64, f64, f64)],
    best: (f64, f64),
    n: usize,
    s2: f64,
    level: f64,
) -> ((f64, f64), bool) {
    let (h0, qbest) = best;
    let within: Vec<&(f64, f64, f64)> = seen
        .iter()
        .filter(|(_, _, v)| n as f64 * (v * v - qbest * qbest) <= level * s2)
        .collect();
    let lo = within.iter().map(|t| t.0).fold(h0, f64::min);
    let hi = within.iter().map(|t| t.0).fold(h0, f64::max);
    let open = within.iter().any(|t| t.1 <= 0.0 || t.1 >= 1.0);
    ((lo, hi), !open)
}

/// Why the dome search found no dome height.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SearchError {
    /// The lowest height given, m.
    #[error("the lowest measured height is {0} m: the dome search needs positive heights")]
    NotPositive(f64),
    /// Every trial failed; how many there were.
    #[error(
        "no trial dome height gave a law with positive stiffness that reproduces the heights ({0} trials)"
    )]
    NoTrial(usize),
}

/// Finds the stress-free dome `h0` and, for heights measured from a
/// reference state (`relative`), the reference's apex height `z` above the
/// clamp plane, from the heights `points` (see the module documentation).
///
/// A slack membrane's reference is not its stress-free dome: the fabric
/// hangs slack below the dome its length makes taut, so the apex stands at
/// `d + z` (`d` the measured displacement) and the law's strain is measured
/// from a dome `h0` between `z` and `z + d1` (`d1` the lowest displacement:
/// the first pressure stage takes up the slack; the point can not be
/// compressed). For heights above the clamp plane `z = 0` and `h0` lies
/// between 0 and the lowest height. `misfit(z, h0)` is the corrected law's
/// rms relative height error, `None` on failure or a non-physical law.
/// `n` points and `p` law parameters give the standard deviation of `h0`:
/// `var = 2 s^2 / (n Q'')` with `Q = rms^2`, `Q''` its curvature along `h0`
/// (by central differences of 2 % of `h0`) and `s^2 = n rms^2 / (n - p - k)`
/// the points' variance from the residuals, `k` the dome's own parameters
/// (2 with a reference, else 1).
pub fn search<F>(
    radius_m: f64,
    lowest_m: f64,
    relative: bool,
    (n, p): (usize, usize),
    misfit: F,
) -> Result<Found, SearchError>
where
    F: Fn(f64, f64) -> Option<f64> + Sync,
{
    use std::sync::atomic::{AtomicUsize, Ordering};
    if !positive(lowest_m) {
        return Err(SearchError::NotPositive(lowest_m));
    }
    let (trials, failed) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let seen = std::sync::Mutex::new(Vec::<(f64, f64, f64)>::new());
    let q = |z: f64, f: f64| -> f64 {
        trials.fetch_add(1, Ordering::Relaxed);
        match misfit(z, z + f * lowest_m) {
            Some(v) if v.is_finite() => {
                seen.lock().expect("trials").push((z + f * lowest_m, f, v));
                v
            }
            _ => {
                failed.fetch_add(1, Ordering::Relaxed);
                f64::INFINITY
            }
        }
    };
    let zs: Vec<f64> = if relative {
        Z_GRID.iter().map(|k| k * radius_m).collect()
    } else {
        vec![0.0]
    };
    let grid: Vec<(f64, f64)> = zs
        .iter()
        .flat_map(|&z| F_GRID.iter().map(move |&f| (z, f)))
        .collect();
    let scores: Vec<f64> = {
        use rayon::prelude::*;
        grid.par_iter().map(|&(z, f)| q(z, f)).collect()
    };
    let best = (0..grid.len())
        .filter(|&i| scores[i].is_finite())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
        .ok_or(SearchError::NoTrial(grid.len()))?;
    let (mut z, mut f) = grid[best];
    let mut qbest = scores[best];
    // golden sections on f between the grid neighbours, then on z
    let neighbours = |v: f64, list: &[f64]| -> (f64, f64) {
        let i = list.iter().position(|x| *x == v).unwrap_or(0);
        (list[i.saturating_sub(1)], list[(i + 1).min(list.len() - 1)])
    };
    // the best of a golden-section search and the grid point it started at
    let golden = |lo: f64, hi: f64, g: &dyn Fn(f64) -> f64, x0: f64, q0: f64| -> (f64, f64) {
        let b = crate::numerics::golden::golden_section(lo, hi, SECTIONS, |x| (g(x), ()));
        if b.score < q0 {
            (b.x, b.score)
        } else {
            (x0, q0)
        }
    };
    let (flo, fhi) = neighbours(f, &F_GRID);
    (f, qbest) = golden(flo, fhi, &|x| q(z, x), f, qbest);
    if relative {
        let (zlo, zhi) = neighbours(z / radius_m, &Z_GRID);
        let (zz, qq) = golden(zlo * radius_m, zhi * radius_m, &|x| q(x, f), z, qbest);
        (z, qbest) = (zz, qq);
    }
    let h0 = z + f * lowest_m;
    // the profile of the misfit along h0 (z held)
    let step = 0.02 * lowest_m.max(h0);
    let qh = |h: f64| -> f64 { q(z, (h - z) / lowest_m) };
    let (up, down) = (qh(h0 + step), qh(h0 - step));
    let curv = (up * up + down * down - 2.0 * qbest * qbest) / (step * step);
    let k = if relative { 2 } else { 1 };
    let s2 = (n > p + k).then(|| n as f64 * qbest * qbest / (n - p - k) as f64);
    let h0_std = s2.and_then(|s2| {
        let local = (curv.is_finite() && curv > 0.0).then(|| (2.0 * s2 / (n as f64 * curv)).sqrt());
        // Every trial dome whose misfit is within one unit of chi^2 of the
        // best (n (Q - Q_best) / s^2 <= 1, the profile likelihood's one
        // standard deviation): with a reference and a flexible law the
        // misfit has a valley along which the law makes up for the dome,
        // and its extent, not the curvature across it, is the uncertainty.
        let within: Vec<f64> = seen
            .lock()
            .expect("trials")
            .iter()
            .filter(|(_, _, v)| n as f64 * (v * v - qbest * qbest) <= s2)
            .map(|(h, _, _)| *h)
            .collect();
        let lo = within.iter().copied().fold(h0, f64::min);
        let hi = within.iter().copied().fold(h0, f64::max);
        let half = 0.5 * (hi - lo);
        match local {
            Some(l) => Some(l.max(half)),
            None => (half > 0.0).then_some(half),
        }
    });
    let interval = s2.map(|s2| {
        let seen = seen.lock().expect("trials");
        profile_interval(&seen, (h0, qbest), n, s2, CHI2_1_95)
    });
    // An optimum with the reference apex at the top of its range (0.3 a, a
    // bound of the search, not of the physics) lies in a valley that runs on
    // past it: the heights do not determine the dome there either.
    let z_at_top = relative && z >= Z_GRID[Z_GRID.len() - 1] * radius_m * (1.0 - 1e-9);
    let h0_determined = !z_at_top && interval.is_some_and(|(_, closed)| closed);
    Ok(Found {
        reference_m: z,
        h0_m: h0,
        h0_std_m: h0_std.filter(|_| h0_determined),
        h0_interval_m: interval.map(|(i, _)| i),
        h0_determined,
        rms: qbest,
        trials: trials.load(Ordering::Relaxed),
        failed: failed.load(Ordering::Relaxed),
    })
}

/// The dome search of a run ([`search`] with the run's own stress stage,
/// fit and correction to the heights at each trial): the dome found and a
/// sentence on it for the run's notes.
pub fn stage(
    spec: &Specimen,
    settings: &crate::pipeline::Settings,
    points: &[crate::mechanics::Point],
    relative: bool,
) -> Result<(Found, String), crate::pipeline::PipelineError> {
    use crate::pipeline::{PipelineError, fit_stage, shift, stress_stage};
    let lowest = points
        .iter()
        .map(|p| p.height_m)
        .filter(|h| *h > 0.0)
        .fold(f64::INFINITY, f64::min);
    let n = points.iter().filter(|p| p.height_m > 0.0).count();
    // Each trial fits one law: with the law still to be chosen, the
    // paper's quartic (the most flexible over a slack fabric's first
    // stages); no Monte Carlo inside the search.
    let searched = crate::pipeline::Settings {
        fit: match settings.fit {
            crate::fit::FitModel::Auto => crate::fit::FitModel::Quartic { degree: 4 },
            f => f,
        },
        samples: 0,
        ..settings.clone()
    };
    let settings = &searched;
    let p = match settings.fit {
        crate::fit::FitModel::Quartic { degree } => degree + 1,
        _ => 3,
    };
    let misfit = |z: f64, h0: f64| -> Option<f64> {
        let at = Specimen {
            prebulge_height_m: h0,
            ..*spec
        };
        let pts = shift(points.to_vec(), relative, z);
        let heights: Vec<f64> = pts.iter().map(|p| p.height_m).collect();
        let stress = stress_stage(&at, settings, pts).ok()?;
        let fit = fit_stage(&at, settings, &stress).ok()?;
        let rms = crate::fit::inverse::Refined::rms(&fit.refined.as_ref()?.after)?;
        stiffness_problem(&fit.material.model, max_strain(&at, &heights))
            .is_none()
            .then_some(rms)
    };
    let found = search(spec.radius_m, lowest, relative, (n, p), misfit).map_err(|m| {
        PipelineError::Input(format!(
            "prebulge_height_m = \"fit\": {m}; give prebulge_height_m as a number"
        ))
    })?;
    let pm = found
        .h0_std_m
        .map_or_else(String::new, |s| format!(" +- {s:.1e}"));
    let interval = found.h0_interval_m.map_or_else(String::new, |(lo, hi)| {
        format!(" (95 % profile interval {lo:.4e} to {hi:.4e} m)")
    });
    let undetermined = if found.h0_determined {
        String::new()
    } else {
        "; the heights do not determine the dome height: the misfit stays within the 95 % chi-square level up to an end of its physical range, so the value is one of many that fit as well (a measured reference dome given as prebulge_height_m, or a first pressure stage low enough to catch the slack being taken up, would determine it)".to_string()
    };
    let reference = if relative {
        format!(
            ", the reference state's apex {:.4e} m above the clamp plane (added to the heights)",
            found.reference_m
        )
    } else {
        String::new()
    };
    let what = format!(
        "prebulge_height_m = {:.4e}{pm} m{interval} found from the heights{reference}: the law corrected to the heights at each trial dome, rms height error {:.2} % at the best ({} trials, {} failed or not physical, counted as misfits){undetermined}",
        found.h0_m,
        100.0 * found.rms,
        found.trials,
        found.failed
    );
    Ok((found, what))
}
