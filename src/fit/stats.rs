//! Goodness of fit: RMSE, R^2 and the information criteria used to compare
//! models with different numbers of parameters.
//!
//! With `n` points, `k` fitted parameters and residual sum of squares `RSS`
//! (Gaussian errors of unknown variance, the variance profiled out):
//!
//! * `RMSE = sqrt(RSS / n)`
//! * `R^2 = 1 - RSS / sum (y_i - mean y)^2`
//! * `AIC = n ln(RSS / n) + 2 k` (Akaike 1974; only differences between models
//!   fitted to the same data mean anything)
//! * `AICc = AIC + 2 k (k + 1) / (n - k - 1)` (Hurvich & Tsai 1989), the
//!   small-sample correction that matters for Treloar's 17 points and the
//!   6-parameter Ogden model; undefined when `n <= k + 1`.

use serde::Serialize;

/// Goodness-of-fit figures of one fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Number of data points.
    pub n: usize,
    /// Number of fitted parameters.
    pub k: usize,
    /// Residual sum of squares, in the squared unit of the data.
    pub rss: f64,
    /// Root-mean-square residual, unit of the data.
    pub rmse: f64,
    /// Coefficient of determination.
    pub r2: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Small-sample corrected AIC; `None` when `n <= k + 1`.
    pub aicc: Option<f64>,
}

impl Stats {
    /// Figures from the data and the residuals `y_i - f(x_i)`.
    pub fn new(y: &[f64], residuals: &[f64], k: usize) -> Self {
        let n = y.len();
        let rss: f64 = residuals.iter().map(|r| r * r).sum();
        let mean = y.iter().sum::<f64>() / n as f64;
        let tss: f64 = y.iter().map(|v| (v - mean) * (v - mean)).sum();
        let nf = n as f64;
        let kf = k as f64;
        // A perfect fit has RSS = 0 and AIC = -inf; floor RSS at the
        // round-off level of the data so that the figure stays finite.
        let floor = (f64::EPSILON * y.iter().fold(0.0f64, |m, v| m.max(v.abs()))).powi(2) * nf;
        let aic = nf * (rss.max(floor).max(f64::MIN_POSITIVE) / nf).ln() + 2.0 * kf;
        let aicc = (n > k + 1).then(|| aic + 2.0 * kf * (kf + 1.0) / (nf - kf - 1.0));
        Self {
            n,
            k,
            rss,
            rmse: (rss / nf).sqrt(),
            r2: if tss > 0.0 { 1.0 - rss / tss } else { f64::NAN },
            aic,
            aicc,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn figures_by_hand() {
        // y = 1, 2, 3; residuals 0.1, -0.2, 0.1; mean 2, TSS 2, RSS 0.06.
        let s = Stats::new(&[1.0, 2.0, 3.0], &[0.1, -0.2, 0.1], 1);
        assert_abs_diff_eq!(s.rss, 0.06, epsilon = 1e-15);
        assert_abs_diff_eq!(s.rmse, (0.02f64).sqrt(), epsilon = 1e-15);
        assert_abs_diff_eq!(s.r2, 0.97, epsilon = 1e-14);
        assert_abs_diff_eq!(s.aic, 3.0 * (0.02f64).ln() + 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(s.aicc.unwrap(), s.aic + 4.0, epsilon = 1e-12);
        assert!(Stats::new(&[1.0, 2.0], &[0.0, 0.0], 1).aicc.is_none());
    }
}
