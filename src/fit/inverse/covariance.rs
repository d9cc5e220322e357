//! The corrected parameters' covariance: the law's parameters in the order
//! of the height gradients, the points' independent errors, and the
//! uncertainty propagated from the heights, the specimen and the gauge.

use super::*;

/// The law's parameters as the gradients of [`axisym::height_gradient`]
/// order them: names with units, values, and whether each is a stress
/// (scales with the thickness: all but the Ogden exponents and the Gent
/// locking parameter).
pub fn law_parameters(model: &Model) -> Option<(Vec<String>, Vec<f64>, Vec<bool>)> {
    match model {
        Model::Quartic {
            coefficients_pa, ..
        } => Some((
            (0..coefficients_pa.len())
                .map(|k| format!("c{k}_pa"))
                .collect(),
            coefficients_pa.clone(),
            vec![true; coefficients_pa.len()],
        )),
        Model::Linear { young_pa } => Some((vec!["young_pa".into()], vec![*young_pa], vec![true])),
        _ => {
            let (Params::Hyper { kind, .. }, _) = Params::of(model).ok()? else {
                return None;
            };
            let values = kind.params_of(model)?;
            let stress = (0..values.len()).map(|k| kind.is_stress(k)).collect();
            Some((kind.param_names(), values, stress))
        }
    }
}

/// `sum_k theta_k dh/dtheta_k` over the stress parameters: `t dh/dt`, and
/// `-p dh/dp` (the inflation depends on `p a / t` over the law's stresses
/// only, so scaling the thickness is scaling every stress parameter).
pub(super) fn stress_moment(theta: &[f64], stress: &[bool], g: &[f64]) -> f64 {
    (0..g.len())
        .filter(|&k| stress[k])
        .map(|k| theta[k] * g[k])
        .sum()
}

/// Per point, the standard deviation of its independent errors (the
/// height's own and the pressure noise's through `dh/dp` of the law at
/// `x`), when every point has a positive one; `None` otherwise.
pub(super) fn independent_std(problem: &Problem, x: &[f64], sources: &Sources) -> Option<Vec<f64>> {
    let sd: Option<Vec<f64>> = problem.points.iter().map(|q| q.height_std_m).collect();
    let sd = sd?;
    let m = problem.material(x);
    let (_, theta, stress) = law_parameters(&m.model)?;
    let out: Option<Vec<f64>> = (0..problem.points.len())
        .into_par_iter()
        .map(|i| {
            let q = &problem.points[i];
            let noise = if sources.pressure_std_pa > 0.0 {
                let g = problem.solve(&m, i, true)?;
                let dhdp = -stress_moment(&theta, &stress, &g.gradient) / q.pressure_pa;
                dhdp * sources.pressure_std_pa
            } else {
                0.0
            };
            let s = sd[i].hypot(noise);
            (s > 0.0 && s.is_finite()).then_some(s)
        })
        .collect();
    out
}

/// The corrected parameters' uncertainty at `x` (see
/// [`super::uncertainty`]): the exact gradients of every height give the
/// Jacobian, and, by the scaling of the inflation in `p a / t`, the
/// heights' dependence on the thickness, radius and pressure too.
pub(super) fn covariance(
    problem: &Problem,
    x: &[f64],
    sources: &Sources,
    sigma: Option<&[f64]>,
    weighted: bool,
) -> Option<ParamUncertainty> {
    let m = problem.material(x);
    let (names, theta, stress) = law_parameters(&m.model)?;
    let pts = problem.points;
    let (n, p) = (pts.len(), theta.len());
    let grads = problem.gradients(&m, p)?;
    // w_i: the residual's divisor, the point's independent standard
    // deviation (a weighted fit) or its height (the relative error).
    let w: Vec<f64> = match (sigma, weighted) {
        (Some(s), true) => s.to_vec(),
        _ => pts.iter().map(|q| q.height_m).collect(),
    };
    // A dome height found from these heights is a parameter of the fit
    // beside the law's: its column `(dh/dh0 - 1 when the heights are
    // measured from the dome) / w` joins the Jacobian.
    let dome_column: Option<Vec<f64>> = if sources.prebulge_std_m > 0.0 {
        let rel = f64::from(u8::from(sources.prebulge_in_heights));
        let slopes: Option<Vec<f64>> = pts
            .par_iter()
            .map(|q| dome_slope(&m, problem.specimen, q.pressure_pa, problem.opts))
            .collect();
        Some(slopes?.iter().zip(&w).map(|(d, w)| (d - rel) / w).collect())
    } else {
        None
    };
    let dome = usize::from(dome_column.is_some());
    let jac = DMatrix::from_fn(n, p + dome, |i, k| match &dome_column {
        Some(c) if k == p => c[i],
        _ => grads[i].gradient[k] / w[i],
    });
    let r: Vec<f64> = (0..n)
        .map(|i| (grads[i].height_m - pts[i].height_m) / w[i])
        .collect();
    let rss: f64 = r.iter().map(|v| v * v).sum();
    // chi-square of the given errors (whatever the fit's weights).
    let chi2 = match sigma {
        Some(s) => (0..n)
            .map(|i| ((grads[i].height_m - pts[i].height_m) / s[i]).powi(2))
            .sum(),
        None => rss,
    };
    let moment: Vec<f64> = grads
        .iter()
        .map(|g| stress_moment(&theta, &stress, &g.gradient))
        .collect();
    let mut cols: Vec<(SourceKind, Vec<f64>)> = Vec::new();
    let unit = |i: usize, v: f64| {
        let mut c = vec![0.0; n];
        c[i] = v;
        c
    };
    match sigma {
        Some(_) => {
            for (i, q) in pts.iter().enumerate() {
                let sd = q.height_std_m.unwrap_or(0.0);
                cols.push((SourceKind::Points, unit(i, sd / w[i])));
            }
            if sources.pressure_std_pa > 0.0 {
                for (i, q) in pts.iter().enumerate() {
                    let dhdp = -moment[i] / q.pressure_pa;
                    cols.push((
                        SourceKind::PressureNoise,
                        unit(i, dhdp * sources.pressure_std_pa / w[i]),
                    ));
                }
            }
        }
        None => {
            if n <= p + dome {
                return None;
            }
            let s = (rss / (n - p - dome) as f64).sqrt();
            for i in 0..n {
                cols.push((SourceKind::Points, unit(i, s)));
            }
        }
    }
    let spec = problem.specimen;
    type PerPoint<'a> = &'a dyn Fn(usize) -> f64;
    let shared: [(SourceKind, f64, PerPoint); 5] = [
        (
            SourceKind::Thickness,
            sources.thickness_std_m / spec.thickness_m,
            &|i| moment[i],
        ),
        (
            SourceKind::Radius,
            sources.radius_std_m / spec.radius_m,
            &|i| grads[i].height_m - moment[i],
        ),
        (
            SourceKind::PressureGain,
            sources.pressure_relative_std,
            &|i| -moment[i],
        ),
        (SourceKind::Scale, sources.scale_relative_std, &|i| {
            -pts[i].height_m
        }),
        (
            SourceKind::HeightOffset,
            sources.height_offset_std_m,
            &|i| -sources.offset_factor(pts[i].height_m),
        ),
    ];
    for (kind, size, of) in shared {
        if size > 0.0 {
            cols.push((kind, (0..n).map(|i| of(i) * size / w[i]).collect()));
        }
    }
    let s = DMatrix::from_fn(n, cols.len(), |i, j| cols[j].1[i]);
    // theta_hat - theta = -A S u (and the dome height's row last).
    let full = -uncertainty::response(&jac, &s)?;
    let response = full.rows(0, p).into_owned();
    let dome_response = (dome == 1).then(|| full.row(p).transpose());
    Some(ParamUncertainty {
        names,
        values: theta,
        response,
        dome_response,
        sources: cols.iter().map(|c| c.0).collect(),
        dof: n.saturating_sub(p + dome),
        sigma_known: sigma.is_some(),
        chi2,
        weighted: weighted && sigma.is_some(),
        readings_pa: pts.iter().map(|q| q.pressure_pa).collect(),
    })
}
