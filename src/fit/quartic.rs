//! Tudruj et al. (2023), section 7: the secant Young's modulus over the measured strain
//! range, approximated by a polynomial (a quartic by default),
//!
//! $$E(\varepsilon) = c_0 + c_1 \varepsilon + \dots + c_N \varepsilon^N,$$
//!
//! fitted by linear least squares to the points `(strain, secant_modulus_pa)`
//! (column scaling and the SVD).
//!
//! A modulus law is physically usable only where `E(eps) > 0` and where the
//! stress it implies, `sigma(eps) = E(eps) eps / k` (`k = 1 - nu` for the
//! biaxial modulus convention of `bulge stress`, `k = 1` for the uniaxial
//! one), increases with strain. The constant `k > 0` does not change where
//! `sigma` increases, so [`check_law`] tests `d(E eps)/d eps = E + eps E' > 0`,
//! whatever the convention. A least-squares polynomial can break both
//! conditions between and beyond the data, and often does at the ends of the
//! range where the secant modulus `stress / strain` is noisiest (small
//! strains divide by a small number).

use super::FitError;
use super::linear;
use super::stats::Stats;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// A fitted polynomial modulus law.
#[derive(Debug, Clone)]
pub struct PolyFit {
    /// `c_0 .. c_N`, Pa.
    pub coefficients_pa: Vec<f64>,
    /// Standard errors of the coefficients, Pa; `None` when there are exactly
    /// as many points as coefficients.
    pub std_errors_pa: Option<Vec<f64>>,
    /// Strain range of the data, `[min, max]`.
    pub strain_range: [f64; 2],
    /// Goodness of fit (RMSE in Pa of modulus).
    pub stats: Stats,
    /// `E_i - E(eps_i)`, Pa.
    pub residuals_pa: Vec<f64>,
    /// Condition number of the column-scaled Vandermonde matrix.
    pub condition_scaled: f64,
    /// Condition number of the unscaled Vandermonde matrix.
    pub condition_raw: f64,
    /// Where the law is unphysical inside the fitted range.
    pub warnings: Vec<LawWarning>,
    /// For a weighted fit, the weighted residuals' sum of squares per
    /// degree of freedom (about 1 when the weights' standard deviations are
    /// right and the law fits).
    pub chi2_per_dof: Option<f64>,
}

/// Evaluates `sum c_k x^k` by Horner's rule.
pub fn eval(coefficients: &[f64], x: f64) -> f64 {
    coefficients.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

/// Evaluates the derivative `sum k c_k x^(k-1)`.
pub fn eval_derivative(coefficients: &[f64], x: f64) -> f64 {
    coefficients
        .iter()
        .enumerate()
        .skip(1)
        .rev()
        .fold(0.0, |acc, (k, c)| acc * x + k as f64 * c)
}

/// Slope `d(E eps)/d eps = E + eps E'` of the implied stress `E(eps) eps`
/// of the modulus law `E = sum c_k eps^k`.
pub fn implied_stress_slope(coefficients: &[f64], eps: f64) -> f64 {
    // d/d eps of sum c_k eps^(k+1)
    coefficients
        .iter()
        .enumerate()
        .map(|(k, c)| (k + 1) as f64 * c * eps.powi(k as i32))
        .sum()
}

/// Fits `E(eps)` of the given degree to `(strain, modulus_pa)`.
///
/// The strains must be finite and strictly increasing, with at least
/// `degree + 1` points.
pub fn fit(strain: &[f64], modulus_pa: &[f64], degree: usize) -> Result<PolyFit, FitError> {
    fit_weighted(strain, modulus_pa, degree, None)
}

/// [`fit`] with every point's residual divided by its standard deviation
/// `std_pa` (positive, Pa) when given: weighted least squares. The standard
/// errors are then scaled by the weighted residuals (`chi2_per_dof`), so
/// that standard deviations known only up to a factor still give honest
/// errors.
pub fn fit_weighted(
    strain: &[f64],
    modulus_pa: &[f64],
    degree: usize,
    std_pa: Option<&[f64]>,
) -> Result<PolyFit, FitError> {
    let p = degree + 1;
    let n = strain.len();
    if n != modulus_pa.len() {
        return Err(FitError::LengthMismatch {
            x: n,
            y: modulus_pa.len(),
        });
    }
    if n < p {
        return Err(FitError::TooFewPoints {
            model: format!("polynomial of degree {degree}"),
            points: n,
            parameters: p,
        });
    }
    super::check_finite(strain)?;
    super::check_finite(modulus_pa)?;
    super::check_increasing(strain)?;
    super::check_std(n, std_pa)?;
    let w = |i: usize| std_pa.map_or(1.0, |s| 1.0 / s[i]);
    let a = DMatrix::from_fn(n, p, |i, j| strain[i].powi(j as i32) * w(i));
    let y = DVector::from_fn(n, |i, _| modulus_pa[i] * w(i));
    let sol = linear::solve(&a, &y).map_err(|e| FitError::Linear {
        model: format!("polynomial of degree {degree}"),
        source: e,
    })?;
    let coefficients_pa: Vec<f64> = sol.coefficients.iter().copied().collect();
    let residuals_pa: Vec<f64> = (0..n).map(|i| sol.residuals[i] / w(i)).collect();
    let chi2_per_dof =
        (std_pa.is_some() && n > p).then(|| sol.residuals.norm_squared() / (n - p) as f64);
    let strain_range = [strain[0], strain[n - 1]];
    let warnings = check_law(&coefficients_pa, strain_range);
    Ok(PolyFit {
        stats: Stats::new(modulus_pa, &residuals_pa, p),
        std_errors_pa: sol.std_errors.map(|s| s.iter().copied().collect()),
        coefficients_pa,
        strain_range,
        residuals_pa,
        condition_scaled: sol.condition_scaled,
        condition_raw: sol.condition_raw,
        warnings,
        chi2_per_dof,
    })
}

/// Something unphysical about a modulus law over a strain interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum LawWarning {
    /// `E(eps) <= 0` on `[from, to]`.
    NonPositiveModulus {
        /// Start of the interval (strain).
        from: f64,
        /// End of the interval (strain).
        to: f64,
    },
    /// The implied stress `E(eps) eps / k` does not increase on `[from, to]`.
    StressNotIncreasing {
        /// Start of the interval (strain).
        from: f64,
        /// End of the interval (strain).
        to: f64,
    },
}

impl std::fmt::Display for LawWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LawWarning::NonPositiveModulus { from, to } => write!(
                f,
                "E(eps) <= 0 for strain in [{from:.6}, {to:.6}]: the law is unphysical there"
            ),
            LawWarning::StressNotIncreasing { from, to } => write!(
                f,
                "the implied stress E(eps)*eps does not increase for strain in [{from:.6}, {to:.6}] \
                 (softening: a pressure-controlled simulation can snap through there)"
            ),
        }
    }
}

/// Number of sample intervals used by [`check_law`].
const CHECK_SAMPLES: usize = 2000;

/// Intervals of `range` where `E <= 0` or `d(E eps)/d eps <= 0`, sampled on
/// a uniform grid of `CHECK_SAMPLES` intervals (a quartic has at most four
/// sign changes, so the grid resolves each one to `range / 2000`).
pub fn check_law(coefficients: &[f64], range: [f64; 2]) -> Vec<LawWarning> {
    let [lo, hi] = range;
    let grid: Vec<f64> = (0..=CHECK_SAMPLES)
        .map(|i| lo + (hi - lo) * i as f64 / CHECK_SAMPLES as f64)
        .collect();
    let mut out = Vec::new();
    let runs = |bad: &dyn Fn(f64) -> bool| -> Vec<(f64, f64)> {
        let mut runs = Vec::new();
        let mut start: Option<f64> = None;
        let mut last = lo;
        for &x in &grid {
            if bad(x) {
                start.get_or_insert(x);
                last = x;
            } else if let Some(s) = start.take() {
                runs.push((s, last));
            }
        }
        if let Some(s) = start {
            runs.push((s, last));
        }
        runs
    };
    for (from, to) in runs(&|x| eval(coefficients, x) <= 0.0) {
        out.push(LawWarning::NonPositiveModulus { from, to });
    }
    for (from, to) in runs(&|x| implied_stress_slope(coefficients, x) <= 0.0) {
        out.push(LawWarning::StressNotIncreasing { from, to });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn horner_and_derivative() {
        let c = [1.0, -2.0, 0.5, 3.0];
        let x: f64 = 0.7;
        assert_abs_diff_eq!(
            eval(&c, x),
            1.0 - 2.0 * x + 0.5 * x * x + 3.0 * x.powi(3),
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            eval_derivative(&c, x),
            -2.0 + x + 9.0 * x * x,
            epsilon = 1e-14
        );
    }

    /// Exact quartic data (latex-like: 1.2 MPa at rest, softening then
    /// stiffening) over strains 0.01 ... 1.5: recovered to 1e-9 relative.
    #[test]
    fn exact_quartic_recovered() {
        let c = [1.2e6, -1.5e6, 1.1e6, -2.0e5, 4.0e4];
        let strain: Vec<f64> = (0..40).map(|i| 0.01 + 1.49 * i as f64 / 39.0).collect();
        let e: Vec<f64> = strain.iter().map(|&x| eval(&c, x)).collect();
        let f = fit(&strain, &e, 4).unwrap();
        for (got, want) in f.coefficients_pa.iter().zip(c) {
            assert!(((got - want) / want).abs() < 1e-9, "{got} vs {want}");
        }
        assert!(f.stats.rmse < 1e-9 * 1.2e6);
    }

    #[test]
    fn other_degrees_recovered() {
        let strain: Vec<f64> = (0..12).map(|i| 0.05 * (i + 1) as f64).collect();
        for c in [
            vec![2.0e6],
            vec![2.0e6, -3.0e5],
            vec![1.0e6, 2.0e5, 3.0e5, -1.0e5, 2.0e4, 5.0e3],
        ] {
            let e: Vec<f64> = strain.iter().map(|&x| eval(&c, x)).collect();
            let f = fit(&strain, &e, c.len() - 1).unwrap();
            for (got, want) in f.coefficients_pa.iter().zip(&c) {
                assert!(((got - want) / want).abs() < 1e-9, "{got} vs {want}");
            }
        }
    }

    #[test]
    fn unphysical_laws_are_flagged() {
        // E = 1 - eps: positive on [0, 1), stress eps - eps^2 peaks at 0.5.
        let w = check_law(&[1.0, -1.0], [0.0, 2.0]);
        let mut nonpos = None;
        let mut soft = None;
        for x in &w {
            match *x {
                LawWarning::NonPositiveModulus { from, to } => nonpos = Some((from, to)),
                LawWarning::StressNotIncreasing { from, to } => soft = Some((from, to)),
            }
        }
        let (a, b) = nonpos.expect("E <= 0 flagged");
        assert!((a - 1.0).abs() <= 1e-3 && b == 2.0, "{a} {b}");
        let (a, b) = soft.expect("softening flagged");
        assert!((a - 0.5).abs() <= 1e-3 && b == 2.0, "{a} {b}");
        assert!(check_law(&[1.0, 1.0], [0.0, 2.0]).is_empty());
    }

    #[test]
    fn bad_inputs_refused() {
        assert!(matches!(
            fit(&[0.1, 0.2, 0.3], &[1.0, 2.0, 3.0], 4),
            Err(FitError::TooFewPoints {
                points: 3,
                parameters: 5,
                ..
            })
        ));
        assert!(matches!(
            fit(&[0.1, 0.2, 0.2, 0.3, 0.4], &[1.0; 5], 1),
            Err(FitError::NotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            fit(&[0.1, 0.3, 0.2, 0.4], &[1.0; 4], 1),
            Err(FitError::NotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            fit(&[0.1, 0.2, 0.3], &[1.0, f64::NAN, 3.0], 1),
            Err(FitError::NonFinite { index: 1, .. })
        ));
    }

    /// Noisy data: the coefficients equal the exact least-squares solution
    /// computed outside bulge (fixtures/fit/make_noisy_quartic.py, rational
    /// arithmetic), for degrees 2, 3 and 4.
    #[test]
    fn noisy_quartic_matches_independent_solution() {
        use crate::io::Table;
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/fit");
        let data = Table::read(dir.join("noisy_quartic.csv")).unwrap();
        let strain = data.numbers("strain").unwrap();
        let modulus = data.numbers("secant_modulus_pa").unwrap();
        let want = Table::read(dir.join("noisy_quartic_expected.csv")).unwrap();
        let deg = want.numbers("degree").unwrap();
        let k = want.numbers("k").unwrap();
        let c = want.numbers("coefficient_pa").unwrap();
        for degree in [2usize, 3, 4] {
            let f = fit(&strain, &modulus, degree).unwrap();
            let expected: Vec<f64> = (0..deg.len())
                .filter(|&i| deg[i] as usize == degree)
                .map(|i| (k[i] as usize, c[i]))
                .map(|(_, c)| c)
                .collect();
            assert_eq!(expected.len(), degree + 1);
            let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (got, want) in f.coefficients_pa.iter().zip(&expected) {
                // Conditioning of the scaled Vandermonde matrix is ~1e3:
                // agreement to 1e-9 of the largest coefficient is ~1e4 ulp.
                assert!(
                    (got - want).abs() <= 1e-9 * scale,
                    "degree {degree}: {got} vs {want}"
                );
            }
        }
    }
}
