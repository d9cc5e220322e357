//! The law the heights call for: every law `bulge run` knows is fitted to
//! the stress/strain points, corrected to the measured heights through the
//! exact axisymmetric inflation ([`super::inverse`]), and ranked on the
//! heights.
//!
//! Per law: the chi-square of the corrected heights against their stated
//! standard deviations, `chi2 = sum ((h_sim - h) / sigma)^2`, with `n - k`
//! degrees of freedom (`k` the law's parameters), its p-value, and the
//! information criteria of the heights, `AICc = chi2 + 2k + 2k(k+1)/(n-k-1)`
//! and `BIC = chi2 + k ln n` (with known errors, `-2 ln L = chi2` up to a
//! constant; K. P. Burnham and D. R. Anderson, "Model selection and
//! multimodel inference", 2nd ed., Springer 2002,
//! doi:10.1007/b97636). The chi-square distribution's tail is taken with
//! Wilson and Hilferty's cube-root normal approximation (E. B. Wilson and
//! M. M. Hilferty, "The distribution of chi-square", PNAS 17(12), 1931,
//! doi:10.1073/pnas.17.12.684), good to about 0.01 in p for 3 or more
//! degrees of freedom.
//!
//! A law is *consistent* when its chi-square is below the 95 % point of
//! the chi-square distribution with its degrees of freedom: a right law
//! fails this 5 % of the time. A law whose equibiaxial stress does not
//! increase with the stretch somewhere over the measured range (negative
//! tangent stiffness: a pressure-controlled inflation snaps through there)
//! is warned about and never chosen; for the polynomial secant modulus this
//! is [`super::quartic::check_law`] (`E <= 0` or `d(E eps)/d eps <= 0`).
//!
//! The rule: among the laws with positive stiffness, the consistent law
//! with the fewest parameters (ties: the lower chi-square); when none is
//! consistent, the lowest AICc, its misfit said, among the laws the spring
//! models can follow when there are any ([`LawRow::springs_follow`]: the
//! spring models take a hyperelastic law's equibiaxial secant modulus,
//! whose heights can differ from the law's own by more than the law's own
//! misfit, as for a Mooney-Rivlin law with `C1 < 0`). Without a stated standard
//! deviation for every height there is no chi-square: the laws are then
//! ranked by the AICc of the relative height errors,
//! `n ln(RSS / n) + 2k + 2k(k+1)/(n-k-1)`, and none is called consistent.

use rayon::prelude::*;

use super::data::Loaded;
use super::hyperelastic::Kind;
use super::material_fit::{FitModel, FitSettings, FittedMaterial, fit_material};
use super::uncertainty::normal_quantile;
use super::{FitError, inverse, quartic};
use crate::experiment::Specimen;
use crate::material::{Material, Model};

/// The laws compared: the polynomial secant modulus of `degree` (the
/// quartic of the paper), the same polynomial with fewer terms (down to
/// degree 2: a short series may determine no more than three, and AICc's
/// small-sample term `2k(k+1)/(n-k-1)` would otherwise judge the polynomial
/// by its largest form only), and every hyperelastic law.
pub fn candidates(degree: usize) -> Vec<FitModel> {
    let mut v = vec![FitModel::Quartic { degree }];
    v.extend((2..degree).rev().map(|d| FitModel::Quartic { degree: d }));
    v.extend(Kind::all().into_iter().map(FitModel::Hyperelastic));
    v
}

/// Parameters of a law.
pub fn n_params(model: &FitModel) -> usize {
    match model {
        FitModel::Quartic { degree } => degree + 1,
        FitModel::Hyperelastic(k) => k.n_params(),
        FitModel::AllHyperelastic | FitModel::Auto => 0,
    }
}

/// One law, fitted and corrected to the heights.
#[derive(Debug, Clone)]
pub struct LawRow {
    /// The law.
    pub model: FitModel,
    /// Its parameters.
    pub params: usize,
    /// The fit and its correction, when both succeeded.
    pub fitted: Option<FittedMaterial>,
    /// Why there is none.
    pub error: Option<String>,
    /// Heights compared.
    pub n: usize,
    /// `sum ((h_sim - h) / sigma)^2` (with every height's sigma given).
    pub chi2: Option<f64>,
    /// `n - k`.
    pub dof: usize,
    /// The probability of a chi-square at least this large when the law
    /// holds.
    pub p_value: Option<f64>,
    /// The 95 % point of the chi-square with `dof` degrees of freedom.
    pub chi2_95: Option<f64>,
    /// AICc of the heights (see the module docs).
    pub aicc: Option<f64>,
    /// BIC of the heights.
    pub bic: Option<f64>,
    /// Root-mean-square of `h_sim / h - 1`.
    pub rms_rel: Option<f64>,
    /// Largest `|h_sim - h| / sigma`.
    pub max_z: Option<f64>,
    /// Where the law's stiffness is not positive over the measured range.
    pub negative_stiffness: Vec<String>,
    /// For a hyperelastic law: the root-mean-square of `h_springs / h_law -
    /// 1` over the measured pressures, where `h_law` are the law's exact
    /// heights and `h_springs` those of the law the spring models take from
    /// it, its equibiaxial secant modulus (see [`springs_equivalent`]);
    /// `None` for the polynomial laws, which the springs take as they are.
    pub springs_rms_rel: Option<f64>,
}

impl LawRow {
    /// Whether the law's chi-square is below its 95 % point.
    pub fn consistent(&self) -> bool {
        matches!((self.chi2, self.chi2_95), (Some(c), Some(b)) if c <= b)
    }

    /// Whether the law may be chosen: fitted, corrected, scored, positive
    /// stiffness.
    pub fn eligible(&self) -> bool {
        self.error.is_none() && self.negative_stiffness.is_empty() && self.aicc.is_some()
    }

    /// Whether the spring models can follow the law: a polynomial law they
    /// take as it is; a hyperelastic law when its springs' heights differ
    /// from its own by no more than its own misfit to the measured ones
    /// ([`LawRow::springs_rms_rel`] at most [`LawRow::rms_rel`]).
    pub fn springs_follow(&self) -> bool {
        match self.model {
            FitModel::Quartic { .. } => true,
            _ => matches!((self.springs_rms_rel, self.rms_rel), (Some(d), Some(r)) if d <= r),
        }
    }

    /// "consistent", "misses (chi2/dof 41.2, p < 1e-6)", "negative
    /// stiffness: ...", "not fitted: ...".
    pub fn verdict(&self) -> String {
        if let Some(e) = &self.error {
            return format!("not fitted: {e}");
        }
        let fit = match (self.chi2, self.p_value) {
            (Some(c), Some(p)) if self.dof > 0 => {
                let p = if p < 1e-6 {
                    "p < 1e-6".to_string()
                } else {
                    format!("p = {p:.3}")
                };
                if self.consistent() {
                    format!("consistent (chi2/dof {:.2}, {p})", c / self.dof as f64)
                } else {
                    format!(
                        "misses the heights (chi2/dof {:.2}, {p})",
                        c / self.dof as f64
                    )
                }
            }
            (Some(_), _) => "no degrees of freedom left to test it".into(),
            _ => "no stated uncertainty of the heights: ranked by AICc only".into(),
        };
        let fit = match (self.springs_follow(), self.springs_rms_rel) {
            (false, Some(d)) if d.is_finite() => format!(
                "{fit}; the spring models' version of it (its equibiaxial secant modulus) gives heights {:.2} % rms from its own",
                100.0 * d
            ),
            (false, _) if self.rms_rel.is_some() => format!(
                "{fit}; the spring models' version of it (its equibiaxial secant modulus) has no equilibrium at some measured pressure"
            ),
            _ => fit,
        };
        if self.negative_stiffness.is_empty() {
            fit
        } else {
            format!(
                "{fit}; negative stiffness, never chosen: {}",
                self.negative_stiffness.join("; ")
            )
        }
    }
}

/// Every law's row and the one carried forward.
#[derive(Debug, Clone)]
pub struct Selection {
    /// One row per law of [`candidates`].
    pub rows: Vec<LawRow>,
    /// Index of the chosen law in `rows`.
    pub chosen: usize,
    /// Whether every height had a stated standard deviation (else no
    /// chi-square).
    pub sigma_known: bool,
    /// Why it was chosen.
    pub reason: String,
}

impl Selection {
    /// The chosen row.
    pub fn chosen_row(&self) -> &LawRow {
        &self.rows[self.chosen]
    }
}

/// The chi-square distribution's upper tail `P(X >= x)` with `k` degrees of
/// freedom (Wilson-Hilferty).
pub fn chi2_upper_tail(x: f64, k: usize) -> f64 {
    if k == 0 {
        return f64::NAN;
    }
    let k = k as f64;
    let c = 2.0 / (9.0 * k);
    let z = ((x.max(0.0) / k).cbrt() - (1.0 - c)) / c.sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The `q` point of the chi-square distribution with `k` degrees of freedom
/// (Wilson-Hilferty).
pub fn chi2_quantile(q: f64, k: usize) -> f64 {
    let k = k as f64;
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + normal_quantile(q) * c.sqrt()).powi(3)
}

/// The complementary error function, Chebyshev fit `erfcc` of W. H. Press,
/// S. A. Teukolsky, W. T. Vetterling and B. P. Flannery, "Numerical Recipes
/// in C", 2nd ed., Cambridge University Press 1992, section 6.2
/// (fractional error below 1.2e-7 everywhere).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Where a law's stiffness is not positive over the strain range of the
/// data: the quartic's [`quartic::check_law`] over its fitted range; for a
/// hyperelastic law, where the equibiaxial Cauchy stress does not increase
/// with the stretch on `[1, max_stretch]` (sampled on 400 intervals).
pub fn stiffness_warnings(model: &Model, max_stretch: f64) -> Vec<String> {
    if let Model::Quartic {
        coefficients_pa,
        strain_range,
        ..
    } = model
    {
        return quartic::check_law(coefficients_pa, *strain_range)
            .iter()
            .map(|w| w.to_string())
            .collect();
    }
    let Some(h) = model.hyperelastic() else {
        return vec![];
    };
    let n = 400;
    let hi = max_stretch.max(1.0);
    let at = |i: usize| 1.0 + (hi - 1.0) * i as f64 / n as f64;
    let mut bad: Option<(f64, f64)> = None;
    let mut last = h.equibiaxial_cauchy(1.0);
    for i in 1..=n {
        let l = at(i);
        let s = h.equibiaxial_cauchy(l);
        // (a NaN stress counts as not increasing)
        if s.partial_cmp(&last) != Some(std::cmp::Ordering::Greater) {
            let b = bad.get_or_insert((at(i - 1), l));
            b.1 = l;
        }
        last = s;
    }
    bad.map(|(a, b)| {
        vec![format!(
            "the equibiaxial stress does not increase for stretch in [{a:.4}, {b:.4}] (negative tangent stiffness: a pressure-controlled inflation snaps through there)"
        )]
    })
    .unwrap_or_default()
}

/// The law the spring models take from a hyperelastic `material`: its
/// equibiaxial secant modulus `E(eps) = (1 - nu) P(1 + eps) / eps` (`P` the
/// equibiaxial nominal stress), as a polynomial of degree 6 in the
/// engineering strain fitted on `[0, max_stretch - 1]`. Its exact
/// axisymmetric heights are what TP MSS converges to; they equal the law's
/// own only where the membrane is stretched equally in both directions
/// (the pole), so a law whose response off the equibiaxial line is unlike
/// its response on it (a Mooney-Rivlin law with `C1 < 0`, say) gives the
/// spring models other heights. `None` for a law that is not hyperelastic.
pub fn springs_equivalent(material: &Material, max_stretch: f64) -> Option<Material> {
    let h = material.model.hyperelastic()?;
    let top = (max_stretch - 1.0).max(1e-3);
    let nu = material.poisson;
    let n = 60;
    let (strain, modulus): (Vec<f64>, Vec<f64>) = (1..=n)
        .map(|i| {
            let e = top * i as f64 / n as f64;
            (e, (1.0 - nu) * h.equibiaxial_nominal(1.0 + e) / e)
        })
        .unzip();
    // Least squares in the scaled strain eps / top (well conditioned over
    // any range), then back to powers of eps.
    let p = 7;
    let a = nalgebra::DMatrix::from_fn(n, p, |i, j| (strain[i] / top).powi(j as i32));
    let y = nalgebra::DVector::from_column_slice(&modulus);
    let b = a.svd(true, true).solve(&y, 1e-13).ok()?;
    let coefficients_pa: Vec<f64> = (0..p).map(|j| b[j] / top.powi(j as i32)).collect();
    if coefficients_pa.iter().any(|c| !c.is_finite()) {
        return None;
    }
    Some(Material {
        model: Model::Quartic {
            coefficients_pa,
            strain_range: [0.0, top],
            strain_measure: crate::material::StrainMeasure::Engineering,
        },
        poisson: nu,
        fit: None,
    })
}

/// [`LawRow::springs_rms_rel`] of a fitted law.
fn springs_deviation(
    material: &Material,
    specimen: &Specimen,
    measured: &[inverse::Measured],
    opts: &inverse::Options,
    max_stretch: f64,
) -> Option<f64> {
    let eq = springs_equivalent(material, max_stretch)?;
    let own = inverse::height_errors(material, specimen, measured, opts).ok()?;
    let springs = inverse::height_errors(&eq, specimen, measured, opts).ok()?;
    // A point where the law has an equilibrium and its springs' law has
    // none (past its limit point): the springs cannot follow it at all.
    let mut d = Vec::new();
    for (a, b) in own.iter().zip(&springs) {
        match (a, b) {
            (Some(a), Some(b)) => d.push((1.0 + b) / (1.0 + a) - 1.0),
            (Some(_), None) => return Some(f64::INFINITY),
            (None, _) => {}
        }
    }
    if d.is_empty() {
        return None;
    }
    Some((d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt())
}

/// Scores a corrected law on the measured heights (see the module docs).
fn score(row: &mut LawRow, r: &inverse::Refined, measured: &[inverse::Measured]) {
    let n = measured.len();
    let k = row.params;
    row.n = n;
    row.dof = n.saturating_sub(k);
    row.rms_rel = inverse::Refined::rms(&r.after);
    let Some(after): Option<Vec<f64>> = r.after.iter().copied().collect() else {
        row.error = Some("the corrected law has no equilibrium at some measured pressure".into());
        return;
    };
    let (nf, kf) = (n as f64, k as f64);
    let small = if n > k + 1 {
        2.0 * kf * (kf + 1.0) / (nf - kf - 1.0)
    } else {
        f64::INFINITY
    };
    let sd: Option<Vec<f64>> = measured
        .iter()
        .map(|m| m.height_std_m.filter(|s| *s > 0.0))
        .collect();
    match sd {
        Some(sd) => {
            let z: Vec<f64> = after
                .iter()
                .zip(measured)
                .zip(&sd)
                .map(|((e, m), s)| e * m.height_m / s)
                .collect();
            let chi2: f64 = z.iter().map(|v| v * v).sum();
            row.chi2 = Some(chi2);
            row.max_z = Some(z.iter().map(|v| v.abs()).fold(0.0, f64::max));
            if row.dof > 0 {
                row.p_value = Some(chi2_upper_tail(chi2, row.dof));
                row.chi2_95 = Some(chi2_quantile(0.95, row.dof));
            }
            row.aicc = Some(chi2 + 2.0 * kf + small);
            row.bic = Some(chi2 + kf * nf.ln());
        }
        None => {
            let rss: f64 = after
                .iter()
                .map(|e| e * e)
                .sum::<f64>()
                .max(f64::MIN_POSITIVE);
            let base = nf * (rss / nf).ln();
            row.aicc = Some(base + 2.0 * kf + small);
            row.bic = Some(base + kf * nf.ln());
        }
    }
}

/// Fits every law of [`candidates`] to `data` (with `settings`, its model
/// replaced), corrects each to `measured` on `specimen` with `opts`, scores
/// them and chooses (see the module docs). Fails only when no law could be
/// fitted and corrected.
pub fn select(
    data: &Loaded,
    settings: &FitSettings,
    specimen: &Specimen,
    measured: &[inverse::Measured],
    opts: &inverse::Options,
    source: &str,
) -> Result<Selection, FitError> {
    let degree = match settings.model {
        FitModel::Quartic { degree } => degree,
        _ => 4,
    };
    let max_stretch = data
        .equibiaxial
        .stretch
        .iter()
        .copied()
        .fold(1.0f64, f64::max);
    let sigma_known = !measured.is_empty()
        && measured
            .iter()
            .all(|m| m.height_std_m.is_some_and(|s| s > 0.0));
    // The laws are independent: corrected side by side.
    let rows: Vec<LawRow> = candidates(degree)
        .into_par_iter()
        .map(|model| {
            let mut row = LawRow {
                model,
                params: n_params(&model),
                fitted: None,
                error: None,
                n: measured.len(),
                chi2: None,
                dof: 0,
                p_value: None,
                chi2_95: None,
                aicc: None,
                bic: None,
                rms_rel: None,
                max_z: None,
                negative_stiffness: vec![],
                springs_rms_rel: None,
            };
            let s = FitSettings { model, ..*settings };
            let fitted = fit_material(data, &s, source).and_then(|mut f| {
                f.refine_to_heights(specimen, measured, opts)?;
                Ok(f)
            });
            match fitted {
                Ok(mut f) => {
                    row.model = f.model;
                    row.params = n_params(&f.model);
                    if let Some(r) = f.refined.clone() {
                        score(&mut row, &r, measured);
                    }
                    row.negative_stiffness = stiffness_warnings(&f.material.model, max_stretch);
                    row.springs_rms_rel =
                        springs_deviation(&f.material, specimen, measured, opts, max_stretch);
                    for w in &row.negative_stiffness {
                        let w = format!("negative stiffness: {w}");
                        if !f.warnings.contains(&w) {
                            f.warn(w);
                        }
                    }
                    row.fitted = Some(f);
                }
                Err(e) => row.error = Some(e.to_string()),
            }
            row
        })
        .collect();
    choose(rows, sigma_known)
}

/// The rule of the module docs on scored rows.
pub fn choose(rows: Vec<LawRow>, sigma_known: bool) -> Result<Selection, FitError> {
    let eligible: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].eligible()).collect();
    let consistent = eligible
        .iter()
        .copied()
        .filter(|&i| rows[i].consistent())
        .min_by(|&a, &b| {
            rows[a].params.cmp(&rows[b].params).then(
                rows[a]
                    .chi2
                    .unwrap_or(f64::INFINITY)
                    .total_cmp(&rows[b].chi2.unwrap_or(f64::INFINITY)),
            )
        });
    // Without a consistent law, the lowest AICc among the laws the spring
    // models can follow, else among all.
    let lowest_ic = |among: &mut dyn Iterator<Item = usize>| {
        among.min_by(|&a, &b| {
            rows[a]
                .aicc
                .unwrap_or(f64::INFINITY)
                .total_cmp(&rows[b].aicc.unwrap_or(f64::INFINITY))
        })
    };
    let followed = lowest_ic(
        &mut eligible
            .iter()
            .copied()
            .filter(|&i| rows[i].springs_follow()),
    );
    let best_ic = followed.or_else(|| lowest_ic(&mut eligible.iter().copied()));
    let (chosen, reason) = match (consistent, best_ic) {
        (Some(i), _) => {
            let r = &rows[i];
            (
                i,
                format!(
                    "{}: the law with the fewest parameters ({}) whose exact axisymmetric heights are consistent with the measured ones (chi2 {:.1} with {} degrees of freedom, below its 95 % point {:.1})",
                    r.model.label(),
                    r.params,
                    r.chi2.unwrap_or(f64::NAN),
                    r.dof,
                    r.chi2_95.unwrap_or(f64::NAN)
                ),
            )
        }
        (None, Some(i)) => {
            let r = &rows[i];
            let misfit = match (r.chi2, r.chi2_95) {
                (Some(c), Some(b)) => format!(
                    "it misses the heights: chi2 {c:.1} with {} degrees of freedom, above its 95 % point {b:.1}, rms height error {:.2} %",
                    r.dof,
                    100.0 * r.rms_rel.unwrap_or(f64::NAN)
                ),
                _ if !sigma_known => format!(
                    "the heights have no stated standard deviation, so no law can be tested; rms height error {:.2} %",
                    100.0 * r.rms_rel.unwrap_or(f64::NAN)
                ),
                _ => "no degrees of freedom are left to test it".into(),
            };
            (
                i,
                format!(
                    "{}: no law is consistent with the heights; the lowest AICc ({:.1}) among the laws with positive stiffness{}, and {misfit}",
                    r.model.label(),
                    r.aicc.unwrap_or(f64::NAN),
                    if followed.is_some() {
                        " that the spring models can follow"
                    } else {
                        " (the spring models follow none of them within its misfit)"
                    }
                ),
            )
        }
        (None, None) => {
            let why = rows
                .iter()
                .map(|r| format!("{}: {}", r.model.label(), r.verdict()))
                .collect::<Vec<_>>()
                .join("; ");
            return Err(FitError::Unsupported(format!(
                "no law could be fitted, corrected to the heights and kept positive in stiffness ({why}); force one with {} (a law's name)",
                crate::setting::Setting::Fit
            )));
        }
    };
    Ok(Selection {
        rows,
        chosen,
        sigma_known,
        reason,
    })
}

/// The material of a row, when it was fitted.
pub fn material_of(row: &LawRow) -> Option<&Material> {
    row.fitted.as_ref().map(|f| &f.material)
}

#[cfg(test)]
mod tests;
