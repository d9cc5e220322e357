//! Each point checked, then its stress, strain, modulus and their standard
//! deviations evaluated.

use super::cap::*;
use super::types::*;

/// Checks one point against the specimen.
pub fn check_point(spec: &Specimen, pt: &Point) -> Result<(), PointError> {
    let finite = |column: &'static str, value: f64| {
        if value.is_finite() {
            Ok(())
        } else {
            Err(PointError::NotFinite { column, value })
        }
    };
    finite("pressure_pa", pt.pressure_pa)?;
    finite("height_m", pt.height_m)?;
    if let Some(sd) = pt.height_std_m {
        finite("height_std_m", sd)?;
        if sd < 0.0 {
            return Err(PointError::NegativeHeightStd { value: sd });
        }
    }
    if pt.pressure_pa < 0.0 {
        return Err(PointError::NegativePressure {
            pressure_pa: pt.pressure_pa,
        });
    }
    if pt.height_m < spec.prebulge_height_m {
        return Err(PointError::BelowPrebulge {
            height_m: pt.height_m,
            prebulge_height_m: spec.prebulge_height_m,
        });
    }
    if pt.height_m == 0.0 && pt.pressure_pa > 0.0 {
        return Err(PointError::FlatUnderPressure {
            pressure_pa: pt.pressure_pa,
        });
    }
    let stretch = super::cap::stretch(spec.radius_m, spec.prebulge_height_m, pt.height_m);
    if stretch.is_nan() || stretch > super::MAX_STRETCH {
        return Err(PointError::BeyondAnyMembrane {
            height_m: pt.height_m,
            radius_m: spec.radius_m,
            stretch,
        });
    }
    Ok(())
}

pub(super) fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Values and their derivatives with respect to `H` for one valid point.
pub(super) fn evaluate(spec: &Specimen, opts: &Options, p: f64, h: f64) -> (Derived, Derived) {
    let a = spec.radius_m;
    let t = spec.thickness_m;
    let h0 = spec.prebulge_height_m;
    let (x0, x1) = (h0 / a, h / a);

    let radius = cap_radius(a, h);
    let d_radius = 0.5 * (1.0 - 1.0 / (x1 * x1));
    let s = arc_length(a, h);
    let d_s = 2.0 * arc_ratio_slope(x1);

    let g0 = arc_ratio(x0);
    let eps_eng = engineering_strain(a, h0, h);
    let lambda = 1.0 + eps_eng;
    let d_lambda = arc_ratio_slope(x1) / (a * g0);
    let (strain, d_strain) = match opts.strain {
        StrainMeasure::Engineering => (eps_eng, d_lambda),
        StrainMeasure::Log => (eps_eng.ln_1p(), d_lambda / lambda),
    };

    let sigma = pole_stress(p, radius, t);
    let d_sigma = if p == 0.0 {
        0.0
    } else {
        p / (2.0 * t) * d_radius
    };
    let (true_stress, d_true) = match opts.true_stress {
        TrueStress::Paper => (lambda * sigma, d_lambda * sigma + lambda * d_sigma),
        TrueStress::Incompressible => (
            lambda * lambda * sigma,
            2.0 * lambda * d_lambda * sigma + lambda * lambda * d_sigma,
        ),
    };
    let (sm, d_sm) = match opts.modulus_stress {
        ModulusStress::Nominal => (lambda * sigma, d_lambda * sigma + lambda * d_sigma),
        ModulusStress::Stress => (sigma, d_sigma),
        ModulusStress::True => (true_stress, d_true),
    };
    let k = match opts.modulus {
        Modulus::Biaxial => 1.0 - spec.poisson,
        Modulus::Uniaxial => 1.0,
    };
    let (modulus, d_modulus) = if strain > 0.0 {
        (
            Some(k * sm / strain),
            Some(k * (d_sm / strain - sm * d_strain / (strain * strain))),
        )
    } else {
        (None, None)
    };

    let value = Derived {
        radius_m: finite(radius),
        arc_length_m: Some(s),
        stretch: Some(lambda),
        strain: Some(strain),
        stress_pa: Some(sigma),
        true_stress_pa: Some(true_stress),
        secant_modulus_pa: modulus.and_then(finite),
    };
    let slope = Derived {
        radius_m: finite(d_radius),
        arc_length_m: Some(d_s),
        stretch: Some(d_lambda),
        strain: Some(d_strain),
        stress_pa: finite(d_sigma),
        true_stress_pa: finite(d_true),
        secant_modulus_pa: d_modulus.and_then(finite),
    };
    (value, slope)
}

/// Derivatives with respect to the height `H` (per metre) of every derived
/// quantity at one point; `None` where the value or derivative is infinite.
/// Exposed so that the propagation can be checked against finite differences.
pub fn height_derivatives(spec: &Specimen, opts: &Options, p: f64, h: f64) -> Derived {
    evaluate(spec, opts, p, h).1
}

/// The stress stage: one [`Row`] per input point, or the first refused input.
pub fn stress_strain(
    spec: &Specimen,
    opts: &Options,
    points: &[Point],
) -> Result<Vec<Row>, StressError> {
    spec.validate().map_err(StressError::Specimen)?;
    points
        .iter()
        .enumerate()
        .map(|(index, pt)| {
            check_point(spec, pt).map_err(|problem| StressError::Point { index, problem })?;
            let (value, slope) = evaluate(spec, opts, pt.pressure_pa, pt.height_m);
            let shift = pt.height_std_m.map(|sd| {
                let f = |v: Option<f64>, d: Option<f64>| match (v, d) {
                    (Some(_), Some(d)) => finite(d * sd),
                    _ => None,
                };
                Derived {
                    radius_m: f(value.radius_m, slope.radius_m),
                    arc_length_m: f(value.arc_length_m, slope.arc_length_m),
                    stretch: f(value.stretch, slope.stretch),
                    strain: f(value.strain, slope.strain),
                    stress_pa: f(value.stress_pa, slope.stress_pa),
                    true_stress_pa: f(value.true_stress_pa, slope.true_stress_pa),
                    secant_modulus_pa: f(value.secant_modulus_pa, slope.secant_modulus_pa),
                }
            });
            let std = shift.map(|s| s.map(f64::abs));
            Ok(Row { value, std, shift })
        })
        .collect()
}
