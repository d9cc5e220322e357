//! The modulus law `E(stretch)` a triangle of the spring models follows:
//! a constant, the quartic secant modulus in the strain, or the equibiaxial
//! secant modulus of a hyperelastic law.

use super::super::SimError;
use crate::material::{Material, Model, StrainMeasure};

/// `E` as a function of a triangle's stretch (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum ModulusLaw {
    /// Constant, Pa.
    Constant(f64),
    /// Polynomial in the strain, clamped to its range.
    Quartic {
        /// Coefficients, Pa.
        coefficients_pa: Vec<f64>,
        /// Fitted strain range.
        range: [f64; 2],
        /// The strain the law takes.
        measure: StrainMeasure,
    },
    /// Equibiaxial secant modulus of a hyperelastic model.
    Secant {
        /// The model.
        model: Model,
        /// Poisson ratio of the springs.
        poisson: f64,
    },
}

impl ModulusLaw {
    /// The law of a material; refuses what the springs cannot take.
    pub fn from_material(m: &Material) -> Result<ModulusLaw, SimError> {
        let nu = m.poisson;
        if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
            return Err(SimError::BadParameter(format!(
                "poisson = {nu} must be in [0, 0.5): the plane-stress spring formulas divide by 1 - nu^2 and 1 - nu (rubber: 0.45 to 0.499)"
            )));
        }
        match &m.model {
            Model::Linear { young_pa } => {
                if !(young_pa.is_finite() && *young_pa > 0.0) {
                    return Err(SimError::BadParameter(format!(
                        "young_pa = {young_pa} must be a positive modulus in Pa"
                    )));
                }
                Ok(ModulusLaw::Constant(*young_pa))
            }
            Model::Quartic {
                coefficients_pa,
                strain_range,
                strain_measure,
            } => {
                if coefficients_pa.is_empty() || coefficients_pa.iter().any(|c| !c.is_finite()) {
                    return Err(SimError::BadParameter(format!(
                        "coefficients_pa = {coefficients_pa:?} must be a non-empty list of finite numbers (Pa)"
                    )));
                }
                let [lo, hi] = *strain_range;
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(SimError::BadParameter(format!(
                        "strain_range = [{lo}, {hi}] must be two finite strains, the smaller first"
                    )));
                }
                Ok(ModulusLaw::Quartic {
                    coefficients_pa: coefficients_pa.clone(),
                    range: [lo, hi],
                    measure: *strain_measure,
                })
            }
            other => {
                let e0 = other.initial_young_pa();
                if !(e0.is_finite() && e0 > 0.0) {
                    return Err(SimError::BadParameter(format!(
                        "the {} material has a small-strain modulus of {e0} Pa; it must be positive",
                        other.name()
                    )));
                }
                Ok(ModulusLaw::Secant {
                    model: other.clone(),
                    poisson: nu,
                })
            }
        }
    }

    /// True when `E` does not depend on the strain.
    pub fn is_constant(&self) -> bool {
        matches!(self, ModulusLaw::Constant(_))
    }

    /// `(strain, E)` at the equibiaxial-equivalent stretch `lambda`; the strain
    /// is the one the law was evaluated at (after clamping).
    #[inline]
    pub fn young(&self, lambda: f64) -> (f64, f64) {
        match self {
            ModulusLaw::Constant(e) => (lambda - 1.0, *e),
            ModulusLaw::Quartic {
                coefficients_pa,
                range,
                measure,
            } => {
                let eps = measure.of_stretch(lambda).clamp(range[0], range[1]);
                let mut e = 0.0;
                for c in coefficients_pa.iter().rev() {
                    e = e * eps + c;
                }
                (eps, e)
            }
            ModulusLaw::Secant { model, poisson } => {
                let h = model
                    .hyperelastic()
                    .expect("secant law of a hyperelastic model");
                let d = lambda - 1.0;
                let e = if d.abs() < 1e-5 {
                    let s = 1e-5;
                    (1.0 - poisson)
                        * (h.equibiaxial_nominal(1.0 + s) - h.equibiaxial_nominal(1.0 - s))
                        / (2.0 * s)
                } else {
                    (1.0 - poisson) * h.equibiaxial_nominal(lambda) / d
                };
                (d, e)
            }
        }
    }
}
