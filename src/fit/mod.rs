//! Stress/strain -> material: the quartic secant modulus of Tudruj et al. (2023)
//! (section 7) and the incompressible hyperelastic models that rubber users
//! fit in practice.
//!
//! * [`quartic`]: `E(eps) = c0 + c1 eps + ... + cN eps^N` by linear least
//!   squares (column scaling and the SVD), with R^2, RMSE, the
//!   condition number, standard errors and warnings where the law is
//!   unphysical;
//! * [`hyperelastic`]: neo-Hookean, Mooney-Rivlin, Yeoh, Ogden (1-3 terms) and
//!   Gent fitted to equibiaxial stress by Levenberg-Marquardt (an
//!   argmin solver) from one or many starting points, with a Drucker
//!   stability check and AIC for comparing models ([`stats`]);
//! * [`inverse`]: the law corrected until the exact axisymmetric inflation
//!   reproduces the measured heights (the cap method's bias removed), with
//!   the corrected parameters' covariance and the heights' band;
//! * [`uncertainty`]: the inputs' uncertainties (heights, pressure gauge,
//!   calibration, specimen) carried to the parameters, first order;
//!   [`coverage`]: synthetic tests with known errors that check it, and the
//!   Monte Carlo of a correction; [`study`]: a material across specimens;
//! * [`data`]: which columns of which file feed which fit, validated with
//!   errors that name the file, line and value.
//!
//! Every entry point is a pure function from data to a fit; `bulge fit`
//! (`src/cli/fit.rs`) reads the files and writes the outputs.

#[cfg(any(test, feature = "harness"))]
pub mod coverage;
pub mod data;
pub mod hyperelastic;
pub mod inverse;
pub(crate) mod linear;
pub(crate) mod lm;
pub mod material_fit;
pub mod monte_carlo;
pub mod quartic;
pub mod select;
pub mod stats;
pub mod study;
pub mod uncertainty;
#[cfg(test)]
mod weighted_tests;

pub use material_fit::{
    DegreeLowered, FitDetail, FitModel, FitSettings, FittedMaterial, Provenance, RefinedRecord,
    UnknownFitModel, fit_material,
};

use serde::{Deserialize, Serialize};

/// Which stress a column of equibiaxial data holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum StressMeasure {
    /// First Piola stress: force per unit reference (undeformed) area.
    Nominal,
    /// Cauchy (true) stress: force per unit current area.
    Cauchy,
}

impl StressMeasure {
    /// Name as written in files (`nominal`, `cauchy`).
    pub fn name(self) -> &'static str {
        match self {
            StressMeasure::Nominal => "nominal",
            StressMeasure::Cauchy => "cauchy",
        }
    }
}

/// Why a fit was refused or failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Fewer points than parameters.
    #[error(
        "{points} data points cannot determine the {parameters} parameters of {model}: supply at least {parameters} points or choose a model with fewer parameters"
    )]
    TooFewPoints {
        /// The model.
        model: String,
        /// Points given.
        points: usize,
        /// Parameters to fit.
        parameters: usize,
    },
    /// x and y of different lengths.
    #[error("{x} abscissae but {y} ordinates")]
    LengthMismatch {
        /// Number of x values.
        x: usize,
        /// Number of y values.
        y: usize,
    },
    /// A NaN or infinite value.
    #[error("value {value} at point {index} is not finite")]
    NonFinite {
        /// 0-based index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The abscissa does not increase strictly.
    #[error(
        "point {index} ({value}) does not exceed the previous one ({previous}): abscissae must be strictly increasing without duplicates"
    )]
    NotIncreasing {
        /// 0-based index of the offending point.
        index: usize,
        /// Its value.
        value: f64,
        /// The previous value.
        previous: f64,
    },
    /// A stretch <= 0.
    #[error("stretch {value} at point {index} is not positive")]
    NonPositiveStretch {
        /// 0-based index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Every stress is zero.
    #[error("every stress is zero: there is nothing to fit")]
    ZeroStress,
    /// The linear least-squares problem has no unique solution.
    #[error("{model}: {source}")]
    Linear {
        /// The model.
        model: String,
        /// Why.
        source: linear::LinearError,
    },
    /// A request outside what is implemented.
    #[error("{0}")]
    Unsupported(String),
    /// The nonlinear solver failed.
    #[error("solver failed: {0}")]
    Solver(String),
}

impl crate::Refusal for FitError {
    /// Every fit error is bad input but the solver's failure on valid data.
    fn is_bad_input(&self) -> bool {
        !matches!(self, FitError::Solver(_))
    }
}

/// Refuses NaN and infinities.
pub(crate) fn check_finite(v: &[f64]) -> Result<(), FitError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(FitError::NonFinite {
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// Refuses the standard deviations of a weighted fit of `n` points that
/// are not `n` finite positive numbers (none: an unweighted fit).
pub(crate) fn check_std(n: usize, std_pa: Option<&[f64]>) -> Result<(), FitError> {
    let Some(s) = std_pa else {
        return Ok(());
    };
    if s.len() != n {
        return Err(FitError::LengthMismatch { x: n, y: s.len() });
    }
    check_finite(s)?;
    match s.iter().find(|&&v| v <= 0.0) {
        Some(v) => Err(FitError::Unsupported(format!(
            "a point's standard deviation is {v} Pa: a weighted fit needs positive ones"
        ))),
        None => Ok(()),
    }
}

/// Refuses abscissae that are not strictly increasing.
pub(crate) fn check_increasing(v: &[f64]) -> Result<(), FitError> {
    for i in 1..v.len() {
        if v[i] <= v[i - 1] {
            return Err(FitError::NotIncreasing {
                index: i,
                value: v[i],
                previous: v[i - 1],
            });
        }
    }
    Ok(())
}
