//! How sure: the uncertainty of the measured quantities carried to the
//! fitted parameters and to the heights they predict.
//!
//! # The sources
//!
//! [`Sources`] lists what a bulge test does not know exactly, as the
//! experiment file gives it: every height's own standard deviation
//! (`height_std_m` of the track stage, independent from photo to photo), the
//! pressure reading's noise (`[pressure] std_pa`, independent per reading)
//! and its gain (`[pressure] relative_std`, one factor shared by every
//! reading: a gauge's "accuracy of the reading"), the scale
//! (`[calibration] metres_per_pixel_std`: every height in the same
//! proportion), the clamp row (`[calibration] clamp_row_std_px`: every height
//! by the same offset) and the specimen's thickness and radius
//! (`[specimen] thickness_std_m`, `radius_std_m`: one value for the whole
//! test). The last four are shared: they move every point together, so
//! averaging many photos does not reduce them.
//!
//! # The method
//!
//! A fit minimises `sum_i r_i(theta)^2` with `r_i = (model_i - data_i) / w_i`
//! (weighted least squares, `w_i` the point's independent standard
//! deviation when every point has one). To first order each elementary
//! error `u_k` (a standard normal: one per point for the height, one per
//! point for the pressure noise, one per shared source) moves the residuals
//! by `S[:, k] u_k`, and the estimate by
//!
//! `theta_hat - theta = -A S u`, `A = (J^T J)^-1 J^T`,
//!
//! so its covariance is `C = (A S)(A S)^T` ("sandwich" covariance of the
//! weighted estimator under the full covariance `S S^T` of the data: the
//! shared sources are propagated through the Jacobian of the fit in them,
//! not modelled as nuisance parameters, so the estimate is the ordinary
//! weighted one and the covariance is exact to first order for it; the
//! law of propagation for correlated input quantities of JCGM 100:2008,
//! Evaluation of measurement data: Guide to the expression of uncertainty in
//! measurement, section 5.2). The matrix
//! `A S` is kept ([`ParamUncertainty::response`]): a height predicted with
//! the fitted law on the nominal specimen, `h(p; theta_hat, t, a)`, differs
//! from the true one by `(-g^T A S + M) u`, with `g = dh/dtheta` and `M` the
//! prediction's own dependence on the shared sources (a thickness that is
//! too large makes the law stiffer and the nominal specimen thicker: the two
//! cancel in the predicted height, which the band must know).
//!
//! When the points have no standard deviation, the independent errors are
//! estimated from the residuals, `s^2 = RSS / (n - p)`, and the intervals use
//! Student's t with `n - p` degrees of freedom instead of the normal
//! quantile (W. S. Gosset, "The probable error of a mean", Biometrika 6(1),
//! 1908, doi:10.1093/biomet/6.1.1).

use crate::experiment::Specimen;
use crate::mechanics::{self, Derived};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

#[cfg(test)]
mod tests;

/// The uncertainties of one test's inputs besides the heights' own (which
/// come with the heights). Zero means "exact". Standard deviations.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Sources {
    /// Noise of each pressure reading, Pa, independent between readings.
    pub pressure_std_pa: f64,
    /// Gain error of the pressure gauge, a fraction of the reading, shared by
    /// every reading.
    pub pressure_relative_std: f64,
    /// Thickness of the specimen, m.
    pub thickness_std_m: f64,
    /// Free radius of the specimen, m.
    pub radius_std_m: f64,
    /// Scale (m per pixel) as a fraction of itself: every height in
    /// proportion.
    pub scale_relative_std: f64,
    /// Height of the clamp plane in the photos, m: every height by the same
    /// offset.
    pub height_offset_std_m: f64,
    /// The scale's relative change per metre of the clamp plane's offset,
    /// 1/m, where the scale was read at the clamp plane (the opening's
    /// width there): the offset's error `d` then moves a height `h` by `d
    /// (1 + h offset_scale_per_m)`, one error in two parts, while
    /// `scale_relative_std` is the scale's error besides it. 0: independent.
    #[serde(default)]
    pub offset_scale_per_m: f64,
    /// The stress-free dome height of a slack membrane, m, when it was
    /// found from the heights (`prebulge_height_m = "fit"`): the law is
    /// then fitted on a specimen whose dome may be off by that much. The
    /// stress stage's changes use this value; the correction to the heights
    /// takes the dome height, when it is not 0, as a parameter of its
    /// covariance beside the law's, so that the fit itself gives its error
    /// and its correlation with the heights' own.
    #[serde(default)]
    pub prebulge_std_m: f64,
    /// Whether the heights are measured from the dome's apex (a reference
    /// photo of the stress-free dome) and shifted by the found dome height,
    /// so that they move with it too.
    #[serde(default)]
    pub prebulge_in_heights: bool,
}

impl Sources {
    /// How far the clamp plane's offset moves a height `height_m`, per
    /// metre of offset: `1 + h offset_scale_per_m` (the offset itself and
    /// the scale read at the plane with it).
    pub fn offset_factor(&self, height_m: f64) -> f64 {
        1.0 + height_m * self.offset_scale_per_m
    }

    /// Checks that every field is a finite, non-negative number; the error
    /// names the field.
    pub fn validate(&self) -> Result<(), crate::io::BadValue> {
        for (name, v) in [
            ("pressure_std_pa", self.pressure_std_pa),
            ("pressure_relative_std", self.pressure_relative_std),
            ("thickness_std_m", self.thickness_std_m),
            ("radius_std_m", self.radius_std_m),
            ("scale_relative_std", self.scale_relative_std),
            ("height_offset_std_m", self.height_offset_std_m),
            ("prebulge_std_m", self.prebulge_std_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(crate::io::BadValue::new(
                    name,
                    format!("{name} = {v}: a standard deviation is a finite number >= 0"),
                ));
            }
        }
        if !self.offset_scale_per_m.is_finite() {
            return Err(crate::io::BadValue::new(
                "offset_scale_per_m",
                format!(
                    "offset_scale_per_m = {}: a finite number, 1/m",
                    self.offset_scale_per_m
                ),
            ));
        }
        Ok(())
    }
}

/// What one column of [`ParamUncertainty::response`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SourceKind {
    /// The independent errors of the points (heights, or everything when
    /// estimated from the residuals), one column per point.
    Points,
    /// The independent pressure noise, one column per point.
    PressureNoise,
    /// The pressure gauge's gain.
    PressureGain,
    /// The specimen's thickness.
    Thickness,
    /// The specimen's radius.
    Radius,
    /// The scale of the photos.
    Scale,
    /// The clamp row (a common height offset).
    HeightOffset,
    /// The stress-free dome height found from the heights.
    Prebulge,
}

impl SourceKind {
    /// Name as written in output files.
    pub fn name(self) -> &'static str {
        match self {
            SourceKind::Points => "points",
            SourceKind::PressureNoise => "pressure_noise",
            SourceKind::PressureGain => "pressure_gain",
            SourceKind::Thickness => "thickness",
            SourceKind::Radius => "radius",
            SourceKind::Scale => "scale",
            SourceKind::HeightOffset => "height_offset",
            SourceKind::Prebulge => "prebulge_height",
        }
    }

    /// All kinds, in output order.
    pub const ALL: [SourceKind; 8] = [
        SourceKind::Points,
        SourceKind::PressureNoise,
        SourceKind::PressureGain,
        SourceKind::Thickness,
        SourceKind::Radius,
        SourceKind::Scale,
        SourceKind::HeightOffset,
        SourceKind::Prebulge,
    ];
}

/// The fitted parameters with their uncertainty (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamUncertainty {
    /// Parameter names with units, in the order of the law's parameters.
    pub names: Vec<String>,
    /// The values.
    pub values: Vec<f64>,
    /// `theta_hat - theta` per unit of each elementary source, `-A S` (p
    /// rows, one column per source), so that the covariance is `R R^T`.
    pub response: DMatrix<f64>,
    /// The response of a stress-free dome height fitted beside the law
    /// (its row of `-A S`, a column per source), when it was: the law's
    /// predictions on the found dome share its error.
    pub dome_response: Option<DVector<f64>>,
    /// What each column of `response` is.
    pub sources: Vec<SourceKind>,
    /// Residual degrees of freedom `n - p`.
    pub dof: usize,
    /// Whether the points' independent errors were given (normal quantile)
    /// or estimated from the residuals (Student's t).
    pub sigma_known: bool,
    /// `sum ((model_i - data_i) / sigma_i)^2` at the minimum with the
    /// given errors `sigma_i` (chi-square with about `dof` degrees of
    /// freedom when the model holds), or the residual sum of squares
    /// without them.
    pub chi2: f64,
    /// Whether the fit was weighted by the given errors (else by the
    /// relative errors).
    pub weighted: bool,
    /// The pressure readings of the points, Pa, in the order of their
    /// columns (empty when unknown).
    pub readings_pa: Vec<f64>,
}

impl ParamUncertainty {
    /// The covariance matrix of the parameters.
    pub fn covariance(&self) -> DMatrix<f64> {
        &self.response * self.response.transpose()
    }

    /// Standard errors (square roots of the covariance's diagonal).
    pub fn std_errors(&self) -> Vec<f64> {
        (0..self.names.len())
            .map(|k| self.response.row(k).norm())
            .collect()
    }

    /// The factor between a standard error and a 95 % half-interval: the
    /// normal quantile 1.96 with given errors, Student's t with `dof`
    /// degrees of freedom with estimated ones.
    pub fn coverage_factor(&self) -> f64 {
        if self.sigma_known {
            normal_quantile(0.975)
        } else {
            student_t_quantile(0.975, self.dof.max(1) as f64)
        }
    }

    /// The 95 % intervals `[value - k se, value + k se]`.
    pub fn intervals_95(&self) -> Vec<[f64; 2]> {
        let k = self.coverage_factor();
        self.values
            .iter()
            .zip(self.std_errors())
            .map(|(v, s)| [v - k * s, v + k * s])
            .collect()
    }

    /// Standard error of each parameter from one kind of source alone.
    pub fn std_errors_from(&self, kind: SourceKind) -> Vec<f64> {
        (0..self.names.len())
            .map(|k| {
                self.sources
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| **s == kind)
                    .map(|(j, _)| self.response[(k, j)].powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect()
    }

    /// With given errors, a warning when the weighted residuals are too
    /// large for them: `chi2` above its 99.9 % point with `dof` degrees of
    /// freedom (Wilson-Hilferty's cube-root normal approximation, E. B.
    /// Wilson and M. M. Hilferty, "The distribution of chi-square", PNAS
    /// 17(12), 1931, doi:10.1073/pnas.17.12.684). The law then misses the
    /// heights by more than their errors, and the intervals (from the
    /// errors) are too narrow by about `sqrt(chi2 / dof)`.
    pub fn misfit_warning(&self) -> Option<String> {
        if !self.sigma_known || self.dof == 0 {
            return None;
        }
        let k = self.dof as f64;
        let c = 2.0 / (9.0 * k);
        let bound = k * (1.0 - c + normal_quantile(0.999) * c.sqrt()).powi(3);
        (self.chi2 > bound).then(|| {
            format!(
                "the corrected law misses the heights by more than their standard deviations (chi2 / dof = {:.3} with {} degrees of freedom, above its 99.9 % point {:.3}): the model's own misfit dominates, and the parameters' intervals, from the given errors, are too narrow by about a factor {:.1}",
                self.chi2 / k,
                self.dof,
                bound / k,
                (self.chi2 / k).sqrt()
            )
        })
    }

    /// Correlation matrix of the parameters.
    pub fn correlation(&self) -> DMatrix<f64> {
        let c = self.covariance();
        let s = self.std_errors();
        DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| {
            let d = s[i] * s[j];
            if d > 0.0 { c[(i, j)] / d } else { 0.0 }
        })
    }

    /// Standard deviation of a prediction `f(theta_hat)` with gradient `g`
    /// in the parameters whose own dependence on the sources is `m`
    /// (`(kind, value per unit source)`, shared sources only).
    pub fn prediction_std(&self, g: &[f64], m: &[(SourceKind, f64)]) -> f64 {
        self.prediction_std_with(g, 0.0, m, &[])
    }

    /// [`Self::prediction_std`] for a prediction that also moves by `dome`
    /// per metre of the error of a dome height fitted beside the law
    /// ([`Self::dome_response`]; nothing without one), and with its own
    /// dependence on single columns of the response: `(column, value per
    /// unit source)` (see [`Self::column`]).
    pub fn prediction_std_with(
        &self,
        g: &[f64],
        dome: f64,
        m: &[(SourceKind, f64)],
        columns: &[(usize, f64)],
    ) -> f64 {
        let gv = DVector::from_column_slice(g);
        let mut row = gv.transpose() * &self.response;
        if let Some(d) = &self.dome_response {
            row += d.transpose() * dome;
        }
        for &(kind, v) in m {
            if let Some(j) = self.sources.iter().position(|s| *s == kind) {
                row[j] += v;
            }
        }
        for &(j, v) in columns {
            row[j] += v;
        }
        row.norm()
    }

    /// The column of the response of the `k`-th source of `kind` (for the
    /// per-point kinds, point `k`'s).
    pub fn column(&self, kind: SourceKind, k: usize) -> Option<usize> {
        self.sources
            .iter()
            .enumerate()
            .filter(|(_, s)| **s == kind)
            .nth(k)
            .map(|(j, _)| j)
    }

    /// The `[...uncertainty]` table of `material.toml`: per parameter its
    /// value, standard error, 95 % interval and the standard error from each
    /// source; the covariance and the method.
    pub fn toml_table(&self) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert(
            "method".into(),
            format!(
                "first-order propagation: least squares of {}, covariance (A S)(A S)^T with A the fit's pseudo-inverse \
                 and S the residuals' response to every source, shared ones included",
                if self.weighted {
                    "(model - data) / sigma, sigma the point's standard deviation"
                } else {
                    "model / data - 1"
                }
            )
            .into(),
        );
        t.insert(
            "errors".into(),
            if self.sigma_known {
                "given (heights, pressures, calibration, specimen)"
            } else {
                "the points' independent errors estimated from the residuals"
            }
            .into(),
        );
        t.insert("coverage_factor".into(), self.coverage_factor().into());
        t.insert("dof".into(), (self.dof as i64).into());
        if self.sigma_known && self.dof > 0 {
            t.insert("chi2_per_dof".into(), (self.chi2 / self.dof as f64).into());
        }
        let se = self.std_errors();
        let ci = self.intervals_95();
        let mut params = toml::Table::new();
        for (k, name) in self.names.iter().enumerate() {
            let mut p = toml::Table::new();
            p.insert("value".into(), self.values[k].into());
            p.insert("std_error".into(), se[k].into());
            p.insert(
                "ci95".into(),
                toml::Value::Array(vec![ci[k][0].into(), ci[k][1].into()]),
            );
            for kind in SourceKind::ALL {
                if self.sources.contains(&kind) {
                    p.insert(
                        format!("std_from_{}", kind.name()),
                        self.std_errors_from(kind)[k].into(),
                    );
                }
            }
            params.insert(name.clone(), p.into());
        }
        t.insert("parameters".into(), params.into());
        let c = self.covariance();
        t.insert(
            "covariance".into(),
            toml::Value::Array(
                (0..c.nrows())
                    .map(|i| toml::Value::Array((0..c.ncols()).map(|j| c[(i, j)].into()).collect()))
                    .collect(),
            ),
        );
        t
    }
}

/// How one point of the stress stage moves for a one-standard-deviation
/// error of each input that is not known exactly: its height
/// ([`SourceKind::Points`], from `height_std_m`), its pressure reading's
/// noise, and the shared sources of `sources` (the gauge's gain, the
/// thickness, the radius, the scale, the clamp row, a dome height found
/// from the heights), each a signed change
/// of every derived value ([`mechanics::Derived`]; a value the point does
/// not have stays `None`). Only the sources with a standard deviation are
/// listed. To first order the covariance of two values `q` and `r` of
/// points `i` and `j` is the sum over the sources `k` that both move of
/// `dq_ik dr_jk`: a point's own sources (height, pressure noise) belong to
/// it alone, the shared ones to every point.
///
/// The changes are first-order: the height's by the exact derivatives of
/// the cap formulas, the pressure's exactly (every stress is proportional to
/// the pressure, no strain depends on it), the thickness's and radius's by
/// central differences of step `1e-6` of the value.
pub fn point_shifts(
    spec: &Specimen,
    opts: &mechanics::Options,
    pt: &mechanics::Point,
    sources: &Sources,
) -> Result<Vec<(SourceKind, Derived)>, mechanics::StressError> {
    type Values = Result<Derived, mechanics::StressError>;
    let at = |spec: &Specimen, pt: mechanics::Point| -> Values {
        let pt = mechanics::Point {
            height_std_m: None,
            ..pt
        };
        Ok(mechanics::stress_strain(spec, opts, &[pt])?[0].value)
    };
    let base = at(spec, *pt)?;
    // `(a - b) f` value by value, where both are present.
    let diff = |a: &Derived, b: &Derived, f: f64| -> Derived {
        let d = |x: Option<f64>, y: Option<f64>| Some((x? - y?) * f).filter(|v| v.is_finite());
        Derived {
            radius_m: d(a.radius_m, b.radius_m),
            arc_length_m: d(a.arc_length_m, b.arc_length_m),
            stretch: d(a.stretch, b.stretch),
            strain: d(a.strain, b.strain),
            stress_pa: d(a.stress_pa, b.stress_pa),
            true_stress_pa: d(a.true_stress_pa, b.true_stress_pa),
            secant_modulus_pa: d(a.secant_modulus_pa, b.secant_modulus_pa),
        }
    };
    // The height's exact slope times `dh`, where the point has the value.
    let slope = mechanics::height_derivatives(spec, opts, pt.pressure_pa, pt.height_m);
    let along_height = |dh: f64| diff(&slope.map(|v| v * dh), &base.map(|_| 0.0), 1.0);
    // `sd` times the slope in a quantity that `moved(d)` moves by `d`:
    // central differences of step `h`, forward when `-h` would leave its
    // range.
    let numeric = |sd: f64, h: f64, forward: bool, moved: &dyn Fn(f64) -> Values| {
        let (lo, width) = if forward { (0.0, h) } else { (-h, 2.0 * h) };
        Ok::<_, mechanics::StressError>(diff(&moved(lo + width)?, &moved(lo)?, sd / width))
    };
    let mut out = Vec::new();
    if let Some(sd) = pt.height_std_m.filter(|&v| v > 0.0) {
        out.push((SourceKind::Points, along_height(sd)));
    }
    // Linear in the pressure: a change of dp moves every stress by exactly
    // the values at p + dp minus those at p.
    for (kind, dp) in [
        (SourceKind::PressureNoise, sources.pressure_std_pa),
        (
            SourceKind::PressureGain,
            pt.pressure_pa * sources.pressure_relative_std,
        ),
    ] {
        if dp > 0.0 {
            let p = mechanics::Point {
                pressure_pa: pt.pressure_pa + dp,
                ..*pt
            };
            out.push((kind, diff(&at(spec, p)?, &base, 1.0)));
        }
    }
    // The specimen's dimensions, one field at a time.
    type Field = fn(&mut Specimen) -> &mut f64;
    let dimensions: [(SourceKind, f64, Field); 2] = [
        (SourceKind::Thickness, sources.thickness_std_m, |s| {
            &mut s.thickness_m
        }),
        (SourceKind::Radius, sources.radius_std_m, |s| {
            &mut s.radius_m
        }),
    ];
    for (kind, sd, field) in dimensions {
        if sd > 0.0 {
            let x = *field(&mut spec.to_owned());
            let moved = |d: f64| {
                let mut s = *spec;
                *field(&mut s) = x + d;
                at(&s, *pt)
            };
            out.push((kind, numeric(sd, 1e-6 * x, false, &moved)?));
        }
    }
    if sources.scale_relative_std > 0.0 {
        let d = along_height(pt.height_m * sources.scale_relative_std);
        out.push((SourceKind::Scale, d));
    }
    if sources.height_offset_std_m > 0.0 {
        let k = sources.offset_factor(pt.height_m);
        out.push((
            SourceKind::HeightOffset,
            along_height(sources.height_offset_std_m * k),
        ));
    }
    if sources.prebulge_std_m > 0.0 {
        // The dome height, and with it the height when it is measured from
        // the dome's apex; forward from a flat disc.
        let (h0, h) = (spec.prebulge_height_m, 1e-6 * spec.radius_m);
        let rel = f64::from(u8::from(sources.prebulge_in_heights));
        let moved = |d: f64| {
            let s = Specimen {
                prebulge_height_m: h0 + d,
                ..*spec
            };
            let p = mechanics::Point {
                height_m: pt.height_m + rel * d,
                ..*pt
            };
            at(&s, p)
        };
        let d = numeric(sources.prebulge_std_m, h, h0 < h, &moved)?;
        out.push((SourceKind::Prebulge, d));
    }
    Ok(out)
}

/// `A S` for the whitened Jacobian `j` (n x p) and the residuals' response
/// `s` (n x m) to the elementary sources: `(J^T J)^-1 J^T S` through the
/// SVD of `J` (never the normal equations). `None` when `J` is rank
/// deficient (some parameter not determined by the data).
pub fn response(j: &DMatrix<f64>, s: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let p = j.ncols();
    // Column scaling first: the parameters' units differ by orders of
    // magnitude.
    let scale: Vec<f64> = j
        .column_iter()
        .map(|c| {
            let n = c.norm();
            if n > 0.0 { n } else { 1.0 }
        })
        .collect();
    let mut js = j.clone();
    for (k, mut c) in js.column_iter_mut().enumerate() {
        c /= scale[k];
    }
    let svd = js.svd(true, true);
    let sv = &svd.singular_values;
    let determined = sv.min() > 1e-12 * sv.max(); // false for NaN too
    if sv.len() < p || !determined {
        return None;
    }
    let u = svd.u.as_ref()?;
    let vt = svd.v_t.as_ref()?;
    let uts = u.transpose() * s;
    let mut w = uts;
    for k in 0..p {
        let f = 1.0 / sv[k];
        w.row_mut(k).scale_mut(f);
    }
    let mut a = vt.transpose() * w;
    for (k, s) in scale.iter().enumerate() {
        a.row_mut(k).scale_mut(1.0 / s);
    }
    Some(a)
}

/// The standard normal quantile `Phi^-1(p)`, `0 < p < 1` (Wichura's
/// algorithm AS 241, "The percentage points of the normal distribution",
/// Applied Statistics 37(3), 1988, doi:10.2307/2347330; relative accuracy
/// about 1e-16). The coefficients as printed.
#[allow(clippy::excessive_precision)]
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180625 - q * q;
        return q
            * (((((((2509.0809287301227 * r + 33430.575583588128) * r + 67265.7709270087) * r
                + 45921.95393154987)
                * r
                + 13731.693765509461)
                * r
                + 1971.5909503065513)
                * r
                + 133.14166789178438)
                * r
                + 3.3871328727963665)
            / (((((((5226.495278852545 * r + 28729.085735721943) * r + 39307.89580009271) * r
                + 21213.794301586597)
                * r
                + 5394.196021424751)
                * r
                + 687.1870074920579)
                * r
                + 42.31333070160091)
                * r
                + 1.0);
    }
    let r0 = if q < 0.0 { p } else { 1.0 - p };
    let mut r = (-r0.ln()).sqrt();
    let v = if r <= 5.0 {
        r -= 1.6;
        (((((((7.745450142783414e-4 * r + 0.022723844989269184) * r + 0.2417807251774506) * r
            + 1.2704582524523684)
            * r
            + 3.6478483247632045)
            * r
            + 5.769497221460691)
            * r
            + 4.630337846156546)
            * r
            + 1.4234371107496835)
            / (((((((1.0507500716444169e-9 * r + 5.475938084995345e-4) * r
                + 0.015198666563616457)
                * r
                + 0.14810397642748008)
                * r
                + 0.6897673349851)
                * r
                + 1.6763848301838038)
                * r
                + 2.053191626637759)
                * r
                + 1.0)
    } else {
        r -= 5.0;
        (((((((2.0103343992922881e-7 * r + 2.7115555687434876e-5) * r + 0.0012426609473880784)
            * r
            + 0.026532189526576124)
            * r
            + 0.2965605718285049)
            * r
            + 1.7848265399172913)
            * r
            + 5.463784911164114)
            * r
            + 6.657904643501103)
            / (((((((2.0442631033899397e-15 * r + 1.421511758316446e-7) * r
                + 1.8463183175100548e-5)
                * r
                + 7.868691311456133e-4)
                * r
                + 0.014875361290850615)
                * r
                + 0.1369298809227358)
                * r
                + 0.599832206555888)
                * r
                + 1.0)
    };
    if q < 0.0 { -v } else { v }
}

/// `ln Gamma(x)`, x > 0 (Lanczos, g = 7, n = 9; relative accuracy ~1e-15).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let mut a = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised incomplete beta function `I_x(a, b)` by its continued
/// fraction (modified Lentz), the symmetry `I_x(a, b) = 1 - I_{1-x}(b, a)`
/// used where the fraction converges slowly.
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(1.0 - x, b, a);
    }
    let tiny = 1e-300;
    let mut c = 1.0;
    let mut d = 1.0 - (a + b) * x / (a + 1.0);
    if d.abs() < tiny {
        d = tiny;
    }
    d = 1.0 / d;
    let mut f = d;
    for m in 1..500 {
        let m = m as f64;
        for num in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 + num * d;
            if d.abs() < tiny {
                d = tiny;
            }
            c = 1.0 + num / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            f *= c * d;
        }
        if (c * d - 1.0).abs() < 1e-15 {
            break;
        }
    }
    front * f / a
}

/// Student's t distribution function with `dof` degrees of freedom.
pub fn student_t_cdf(t: f64, dof: f64) -> f64 {
    let x = dof / (dof + t * t);
    let tail = 0.5 * incomplete_beta(x, 0.5 * dof, 0.5);
    if t > 0.0 { 1.0 - tail } else { tail }
}

/// Student's t quantile, `0 < p < 1`, `dof > 0`: bisection then Newton-free
/// refinement on [`student_t_cdf`] (to 1e-12).
pub fn student_t_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && dof > 0.0) {
        return f64::NAN;
    }
    if p < 0.5 {
        return -student_t_quantile(1.0 - p, dof);
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while student_t_cdf(hi, dof) < p {
        hi *= 2.0;
        if hi > 1e12 {
            return f64::INFINITY;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_t_cdf(mid, dof) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}
