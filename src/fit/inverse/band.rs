//! The band of heights a corrected law predicts: each pressure's apex
//! height with its standard deviation by the delta method, the dome
//! height's slope included.

use super::*;

/// `dh/dh0`: the apex height's change at pressure `p` per metre of the
/// stress-free dome height, the law held (central differences of step
/// `1e-4 a`, forward from a flat disc).
pub(super) fn dome_slope(
    m: &Material,
    spec: &Specimen,
    p: f64,
    opts: &axisym::Options,
) -> Option<f64> {
    let step = 1e-4 * spec.radius_m;
    let at = |h0: f64| {
        let s = Specimen {
            prebulge_height_m: h0,
            ..*spec
        };
        axisym::solve_pressure(m, &s, p, opts)
            .ok()
            .map(|s| s.height_m)
    };
    let h0 = spec.prebulge_height_m;
    if h0 >= step {
        Some((at(h0 + step)? - at(h0 - step)?) / (2.0 * step))
    } else {
        Some((at(h0 + step)? - at(h0)?) / step)
    }
}

/// One pressure of [`band`]: the law's apex height there and its standard
/// deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandPoint {
    /// Pressure (a reading), Pa.
    pub pressure_pa: f64,
    /// Apex height of the law on the nominal specimen, m.
    pub height_m: f64,
    /// Standard deviation of the true bubble's apex height at this reading
    /// about `height_m`, m: the parameters' uncertainty through the exact
    /// gradient (the delta method), with the nominal specimen's and the
    /// gauge's own errors (correlated with the parameters' through the fit)
    /// and the reading's noise (correlated too when it is one of the
    /// readings the law was fitted to: the fit followed it).
    pub std_m: f64,
    /// Standard deviation of `height_m` minus a height measured at this
    /// reading, the measured height's own independent error left out: as
    /// `std_m`, with the scale and clamp-row errors that the measured height
    /// shares with those the law was fitted to.
    pub diff_std_m: f64,
}

/// The heights of `material` (a law whose uncertainty is `unc`) on
/// `specimen` at `pressures`, with their standard deviations (see
/// [`BandPoint`]); `None` where the inflation has no equilibrium.
pub fn band(
    material: &Material,
    specimen: &Specimen,
    unc: &ParamUncertainty,
    sources: &Sources,
    pressures: &[f64],
    opts: &axisym::Options,
) -> Vec<Option<BandPoint>> {
    let Some((_, theta, stress)) = law_parameters(&material.model) else {
        return vec![None; pressures.len()];
    };
    pressures
        .par_iter()
        .map(|&p| {
            let cold = axisym::solve_pressure(material, specimen, p, opts).ok()?;
            let g = axisym::height_gradient(material, specimen, p, cold.pole_stretch, true, opts)
                .ok()?;
            let mom = stress_moment(&theta, &stress, &g.gradient);
            let m = [
                (
                    SourceKind::Thickness,
                    mom * sources.thickness_std_m / specimen.thickness_m,
                ),
                (
                    SourceKind::Radius,
                    (g.height_m - mom) * sources.radius_std_m / specimen.radius_m,
                ),
                (
                    SourceKind::PressureGain,
                    -mom * sources.pressure_relative_std,
                ),
            ];
            // The reading's noise moves the law's height at it by dh/dp
            // per Pa. At a reading the law was fitted to, the same noise
            // moved the fit: one column, not independent errors.
            let reading = -mom / p * sources.pressure_std_pa;
            let own = unc
                .readings_pa
                .iter()
                .position(|&r| r == p)
                .and_then(|i| unc.column(SourceKind::PressureNoise, i));
            let measured = [
                (SourceKind::Scale, -g.height_m * sources.scale_relative_std),
                (
                    SourceKind::HeightOffset,
                    -sources.height_offset_std_m * sources.offset_factor(g.height_m),
                ),
            ];
            let all: Vec<_> = m.iter().chain(&measured).copied().collect();
            // A dome height fitted beside the law moves the prediction by
            // dh/dh0 per metre of its error; a height measured from the dome
            // and shifted by it moves with it.
            let slope = match unc.dome_response {
                Some(_) => dome_slope(material, specimen, p, opts)?,
                None => 0.0,
            };
            let shifted = f64::from(u8::from(sources.prebulge_in_heights));
            let (std_m, diff_std_m) = match own {
                Some(j) => (
                    unc.prediction_std_with(&g.gradient, slope, &m, &[(j, reading)]),
                    unc.prediction_std_with(&g.gradient, slope - shifted, &all, &[(j, reading)]),
                ),
                None => (
                    unc.prediction_std_with(&g.gradient, slope, &m, &[])
                        .hypot(reading),
                    unc.prediction_std_with(&g.gradient, slope - shifted, &all, &[])
                        .hypot(reading),
                ),
            };
            Some(BandPoint {
                pressure_pa: p,
                height_m: g.height_m,
                std_m,
                diff_std_m,
            })
        })
        .collect()
}
