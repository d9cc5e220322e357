//! Drucker stability of an incompressible membrane in plane stress.
//!
//! Drucker's postulate asks `d sigma : d eps > 0` for every strain
//! increment. For a membrane (`sigma_3 = 0`) with the thickness stretch
//! eliminated by incompressibility, `sigma_i = l_i dW/dl_i` and log
//! strains `eps_i = ln l_i` (i = 1, 2), this is positive definiteness of
//! the symmetric 2x2 tangent
//!
//! $$D_{ij} = \frac{\partial \sigma_i}{\partial \varepsilon_j} = \lambda_i \lambda_j W_{,ij} + \delta_{ij} \lambda_i W_{,i},$$
//!
//! evaluated with the exact Hessian of [`crate::material`]. It is
//! checked, as commercial FE codes do, in the three homogeneous modes
//! a membrane sees (equibiaxial at the pole, planar tension at the clamp,
//! uniaxial), at 200 stretches spanning the fitted range (and `l = 1`).

use crate::material::Model;
use serde::Serialize;

/// A homogeneous deformation mode `l -> (l1, l2)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// `(l, l)`.
    Equibiaxial,
    /// `(l, 1)`.
    Planar,
    /// `(l, l^-1/2)`.
    Uniaxial,
}

impl Mode {
    /// In-plane stretches of the mode at stretch `l`.
    pub fn stretches(self, l: f64) -> (f64, f64) {
        match self {
            Mode::Equibiaxial => (l, l),
            Mode::Planar => (l, 1.0),
            Mode::Uniaxial => (l, 1.0 / l.sqrt()),
        }
    }

    /// Name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Equibiaxial => "equibiaxial",
            Mode::Planar => "planar",
            Mode::Uniaxial => "uniaxial",
        }
    }
}

/// The result of a stability check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// True when `D` is positive definite at every checked point.
    pub stable: bool,
    /// Per mode, the smallest stretch where `D` is not positive definite.
    pub first_unstable: Vec<(Mode, f64)>,
    /// Stretch range checked.
    pub range: [f64; 2],
}

/// Whether the tangent `D` is positive definite at `(l1, l2)`.
pub fn is_stable_at(model: &Model, l1: f64, l2: f64) -> bool {
    let h = model.hyperelastic().expect("a hyperelastic model");
    let d = h.derivatives(l1, l2);
    let l = [l1, l2];
    let mut m = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            m[i][j] = l[i] * l[j] * d.hess[i][j] + if i == j { l[i] * d.grad[i] } else { 0.0 };
        }
    }
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    tr > 0.0 && det > 0.0 && m[0][0] > 0.0
}

/// Checks the three modes at stretches spanning `[min(1, l_min), l_max]`
/// of the data.
pub fn check(model: &Model, stretch: &[f64]) -> Report {
    let lo = stretch.iter().copied().fold(1.0f64, f64::min);
    let hi = stretch.iter().copied().fold(1.0f64, f64::max);
    let samples = 200;
    let mut first_unstable = Vec::new();
    for mode in [Mode::Equibiaxial, Mode::Planar, Mode::Uniaxial] {
        for k in 0..=samples {
            let l = lo + (hi - lo) * k as f64 / samples as f64;
            let (l1, l2) = mode.stretches(l);
            if !is_stable_at(model, l1, l2) {
                first_unstable.push((mode, l));
                break;
            }
        }
    }
    Report {
        stable: first_unstable.is_empty(),
        first_unstable,
        range: [lo, hi],
    }
}
