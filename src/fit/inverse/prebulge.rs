//! The dome search of a slack membrane: the law corrected at each trial
//! stress-free dome height, the height with the smallest misfit kept, and
//! its deviation from the misfit's profile.

use super::*;

/// The correction with the stress-free dome height `h0` of a slack membrane
/// found beside the law (`measured` heights above the clamp plane, or, with
/// `relative`, above a reference photo of the stress-free dome, so that the
/// apex stands at `h + h0`): the law is corrected at each trial `h0` and the
/// `h0` with the smallest rms height error kept (golden sections over
/// `[0.8, 1.25]` times `start_m`, the cap formulas' estimate, below the
/// lowest measured height). The cap estimate is biased low by a few per
/// cent (the bubble is not a cap); the exact inflation of a wrong reference
/// misses the heights' shape, which the law cannot make up.
pub fn refine_with_prebulge(
    material: &Material,
    specimen: &Specimen,
    measured: &[Measured],
    opts: &Options,
    start_m: f64,
    relative: bool,
) -> Result<(Refined, f64), FitError> {
    let lowest = measured
        .iter()
        .map(|q| q.height_m)
        .fold(f64::INFINITY, f64::min);
    let top = if relative {
        f64::INFINITY
    } else {
        0.999 * lowest
    };
    let (lo, hi) = (0.8 * start_m, (1.25 * start_m).min(top));
    if !(start_m > 0.0 && lo < hi) {
        return Err(FitError::Unsupported(format!(
            "prebulge_height_m: the estimate {start_m} m leaves no range below the lowest measured height {lowest} m"
        )));
    }
    let at = |h0: f64| {
        let spec = Specimen {
            prebulge_height_m: h0,
            ..*specimen
        };
        let shifted: Vec<Measured> = measured
            .iter()
            .map(|q| Measured {
                height_m: q.height_m + if relative { h0 } else { 0.0 },
                ..*q
            })
            .collect();
        refine(material, &spec, &shifted, opts)
            .ok()
            .and_then(|r| Refined::rms(&r.after).map(|e| (e, r)))
    };
    let score = |r: &Option<(f64, Refined)>| r.as_ref().map_or(f64::INFINITY, |v| v.0);
    let found = crate::numerics::golden::golden_section(lo, hi, PREBULGE_SECTIONS, |x| {
        let r = at(x);
        (score(&r), r)
    });
    let (h0, best) = (found.x, found.value);
    let (rms0, mut r) = best.ok_or_else(|| {
        FitError::Solver(format!(
            "the law could not be corrected to the heights for any stress-free dome height near {start_m} m"
        ))
    })?;
    r.prebulge_height_m = Some(h0);
    r.prebulge_std_m = profile_std(&at, h0, rms0, measured.len(), &r, top);
    Ok((r, h0))
}

/// The standard error of the dome height `h0` found by [`refine_with_prebulge`],
/// from the profile of the misfit: with the law corrected again at each
/// height, the mean square relative error `Q(h)` (`rms0^2` at `h0`) has the
/// curvature `Q''` there, and `var(h0) = 2 s^2 / (n Q'')` with `s^2 = n rms0^2 /
/// (n - p - 1)` the points' own variance from the residuals (`p` the law's
/// parameters, one more for `h0`): the profile-likelihood curvature, which
/// carries `h0`'s correlation with the law. `Q''` by a central difference
/// of step 2 % of `h0`, shrunk to stay below `top`. `None` when a side has
/// no fit or the profile is not convex there.
pub(super) fn profile_std<F>(
    at: &F,
    h0: f64,
    rms0: f64,
    n: usize,
    r: &Refined,
    top: f64,
) -> Option<f64>
where
    F: Fn(f64) -> Option<(f64, Refined)>,
{
    let p = law_parameters(&r.material.model)?.1.len();
    if n <= p + 1 {
        return None;
    }
    // (false for NaN too)
    let step = Some((0.02 * h0).min(0.5 * (top - h0))).filter(|s| *s > 0.0)?;
    // `rms` is the root mean square relative error: Q = rms^2.
    let q = |h: f64| at(h).map(|(rms, _)| rms * rms);
    let (up, down, mid) = (q(h0 + step)?, q(h0 - step)?, rms0 * rms0);
    let curvature = Some((up + down - 2.0 * mid) / (step * step)).filter(|c| *c > 0.0)?;
    let s2 = n as f64 * mid / (n - p - 1) as f64;
    Some((2.0 * s2 / (n as f64 * curvature)).sqrt())
}

/// Golden sections of the search for the dome height (the bracket shrinks
/// to 0.618^n of 0.45 times the start: 0.1 % of it at 12).
pub(super) const PREBULGE_SECTIONS: usize = 12;
