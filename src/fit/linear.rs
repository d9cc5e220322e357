//! Linear least squares by column scaling and the singular value
//! decomposition (never the normal equations).
//!
//! For `min |A c - y|`, each column of `A` is divided by its Euclidean norm
//! `s_j` (equilibration: for a Vandermonde matrix of strains the columns span
//! many orders of magnitude), the scaled matrix is decomposed `A S^-1 = U Sigma V^T`
//! and `c = S^-1 V Sigma^-1 U^T y`. The decomposition also gives the condition
//! number `sigma_max / sigma_min` and, with `s^2 = RSS / (n - p)`, the
//! covariance of the coefficients `s^2 S^-1 V Sigma^-2 V^T S^-1`
//! (standard errors on its diagonal).

use nalgebra::{DMatrix, DVector};

/// A linear least-squares solution with its diagnostics.
#[derive(Debug, Clone)]
pub struct LinearFit {
    /// The coefficients `c`.
    pub coefficients: DVector<f64>,
    /// `y - A c`.
    pub residuals: DVector<f64>,
    /// Standard errors of the coefficients; `None` without residual degrees
    /// of freedom (`n == p`).
    pub std_errors: Option<DVector<f64>>,
    /// Condition number of the column-scaled matrix (the one that governs
    /// the accuracy of this solution).
    pub condition_scaled: f64,
    /// Condition number of the unscaled matrix, for comparison.
    pub condition_raw: f64,
}

/// Why a linear least-squares problem has no unique solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum LinearError {
    /// More unknowns than equations.
    #[error("{rows} equations for {cols} unknowns")]
    Underdetermined {
        /// Equations.
        rows: usize,
        /// Unknowns.
        cols: usize,
    },
    /// The columns are linearly dependent to working precision.
    #[error("the columns are linearly dependent (scaled condition number {condition:.3e})")]
    RankDeficient {
        /// Scaled condition number.
        condition: f64,
    },
}

/// Relative threshold on `sigma_min / sigma_max` below which the scaled
/// matrix counts as rank deficient.
const RANK_TOL: f64 = 1e-13;

/// Solves `min |A c - y|` as described in the module docs.
pub fn solve(a: &DMatrix<f64>, y: &DVector<f64>) -> Result<LinearFit, LinearError> {
    let (n, p) = a.shape();
    if n < p || p == 0 {
        return Err(LinearError::Underdetermined { rows: n, cols: p });
    }
    let scale: Vec<f64> = a
        .column_iter()
        .map(|c| {
            let s = c.norm();
            if s > 0.0 { s } else { 1.0 }
        })
        .collect();
    let mut scaled = a.clone();
    for (j, mut col) in scaled.column_iter_mut().enumerate() {
        col /= scale[j];
    }
    let svd = scaled.svd(true, true);
    let sv = &svd.singular_values;
    let smax = sv.max();
    let smin = sv.min();
    let condition_scaled = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    let full_rank = smin > RANK_TOL * smax; // false for NaN too
    if !full_rank {
        return Err(LinearError::RankDeficient {
            condition: condition_scaled,
        });
    }
    let u = svd.u.as_ref().expect("SVD computed with U");
    let vt = svd.v_t.as_ref().expect("SVD computed with V^T");
    let uty = u.transpose() * y;
    let w = DVector::from_iterator(p, (0..p).map(|k| uty[k] / sv[k]));
    let mut c = vt.transpose() * w;
    for j in 0..p {
        c[j] /= scale[j];
    }
    let residuals = y - a * &c;
    let std_errors = (n > p).then(|| {
        let s2 = residuals.norm_squared() / (n - p) as f64;
        DVector::from_iterator(
            p,
            (0..p).map(|j| {
                let var: f64 = (0..p).map(|k| (vt[(k, j)] / sv[k]).powi(2)).sum();
                (s2 * var).sqrt() / scale[j]
            }),
        )
    });
    let raw = a.clone().singular_values();
    let condition_raw = if raw.min() > 0.0 {
        raw.max() / raw.min()
    } else {
        f64::INFINITY
    };
    Ok(LinearFit {
        coefficients: c,
        residuals,
        std_errors,
        condition_scaled,
        condition_raw,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    /// y = 1 + 2 x on three points with residuals (0.1, -0.2, 0.1): the
    /// residuals are orthogonal to both columns, so the solution is exact and
    /// the standard errors follow from (X^T X)^-1 by hand.
    #[test]
    fn straight_line_by_hand() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0]);
        let y = DVector::from_vec(vec![1.1, 2.8, 5.1]);
        let f = solve(&a, &y).unwrap();
        assert_abs_diff_eq!(f.coefficients[0], 1.0, epsilon = 1e-14);
        assert_abs_diff_eq!(f.coefficients[1], 2.0, epsilon = 1e-14);
        // s^2 = 0.06 / 1; (X^T X)^-1 = [[5/6, -1/2], [-1/2, 1/2]].
        let se = f.std_errors.unwrap();
        assert_abs_diff_eq!(se[0], (0.06f64 * 5.0 / 6.0).sqrt(), epsilon = 1e-14);
        assert_abs_diff_eq!(se[1], (0.06f64 * 0.5).sqrt(), epsilon = 1e-14);
    }

    #[test]
    fn dependent_columns_and_too_few_rows_are_refused() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 2.0, 2.0, 4.0, 3.0, 6.0]);
        let y = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        assert!(matches!(
            solve(&a, &y),
            Err(LinearError::RankDeficient { .. })
        ));
        let a = DMatrix::from_row_slice(1, 2, &[1.0, 2.0]);
        let y = DVector::from_vec(vec![1.0]);
        assert!(matches!(
            solve(&a, &y),
            Err(LinearError::Underdetermined { .. })
        ));
    }
}
