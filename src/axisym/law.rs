//! Membrane laws as nominal stresses of the two principal stretches.
//!
//! The shooting equations need, for every material, the two *nominal membrane
//! stresses* `P1(l1, l2)`, `P2(l1, l2)` (force per unit **reference** length
//! divided by the initial thickness `t`, Pa) and their four derivatives. The
//! Cauchy tensions (force per unit deformed length) are `T1 = t P1 / l2`,
//! `T2 = t P2 / l1`.
//!
//! * Hyperelastic, incompressible: `P_i = dW/dl_i` (the thickness is
//!   eliminated in `W`, see [`crate::material`]), derivatives from the exact
//!   Hessian. Check: the Cauchy stress is `sigma_1 = l1 W1`, the current
//!   thickness `t l3 = t / (l1 l2)`, so `T1 = sigma_1 t l3 = t W1 / l2`.
//! * `linear`: `P_i = E/(1 - nu^2) (e_i + nu e_j)`, `e = l - 1`: plane-stress
//!   Hooke's law in engineering strains, written per unit reference length with
//!   the initial thickness — the same thing a spring lattice computes, whose
//!   forces are spring constants (set from the reference geometry) times
//!   extensions. It is hyperelastic with
//!   `W = E/(2(1 - nu^2)) (e1^2 + e2^2 + 2 nu e1 e2)`; compressible: the
//!   thickness is not tracked, it is inside the tensions.
//! * `quartic`: the same with the secant modulus `E(eps)` of Tudruj et al. (2023),
//!   `P_i = E(eps_m)/(1 - nu^2) (e_i + nu e_j)`. The modulus is taken exactly
//!   as the mass-spring solver takes it per triangle (`crate::sim`), so that
//!   the two compare like for like: at the **equibiaxial-equivalent stretch**
//!   `lambda_m = sqrt(l1 l2)` (the square root of the area stretch), in the
//!   material's strain measure (`eps_m = lambda_m - 1`, or `ln lambda_m`, the
//!   mean log strain), **clamped to the fitted `strain_range`** (outside it
//!   the law is held at its end value). Under equibiaxial stretch (the bubble
//!   pole, where the stress stage's cap formulas and the fit live) `eps_m` is
//!   the strain of the fit, so the fitted law is reproduced exactly there.

use num_dual::DualNum;

use crate::material::{Hyperelastic, Material, Model, StrainMeasure};

/// Nominal stresses and their derivatives at one pair of stretches, of any
/// dual number type `T` (`f64` for the plain solve).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stress<T = f64> {
    /// `P1, P2`, Pa.
    pub p: [T; 2],
    /// `dp[i][j] = dP_i / dl_j`, Pa.
    pub dp: [[T; 2]; 2],
}

/// The form of a law; its parameters are [`Law::params`].
#[derive(Debug, Clone)]
enum Form<'a> {
    /// Incompressible hyperelastic energy.
    Hyper(Hyperelastic<'a>),
    /// Linear plane stress, `P_i = E/(1 - nu^2) (e_i + nu e_j)`; parameter `[E]`.
    Linear {
        /// Poisson ratio.
        nu: f64,
    },
    /// Secant modulus polynomial at the equibiaxial-equivalent strain;
    /// parameters `[c_0, c_1, ..]` of `E(eps)`, Pa.
    Quartic {
        /// Poisson ratio.
        nu: f64,
        /// Strain measure the polynomial takes.
        measure: StrainMeasure,
        /// Strain range the argument is clamped to.
        range: [f64; 2],
    },
}

/// A material reduced to what the membrane equations need: a form and its
/// parameters.
#[derive(Debug, Clone)]
pub struct Law<'a> {
    form: Form<'a>,
    params: Vec<f64>,
}

impl<'a> Law<'a> {
    /// Builds the law of a material, checking its parameters.
    pub fn new(material: &'a Material) -> Result<Self, super::AxisymError> {
        let nu = material.poisson;
        let needs_nu = matches!(material.model, Model::Linear { .. } | Model::Quartic { .. });
        if needs_nu && !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
            return Err(super::AxisymError::Material(format!(
                "poisson = {nu} must be in [0, 0.5) for the {} material (plane stress)",
                material.model.name()
            )));
        }
        let law = match &material.model {
            Model::Linear { young_pa } => {
                if !(young_pa.is_finite() && *young_pa > 0.0) {
                    return Err(super::AxisymError::Material(format!(
                        "young_pa = {young_pa} must be a positive modulus in Pa"
                    )));
                }
                Law {
                    form: Form::Linear { nu },
                    params: vec![*young_pa],
                }
            }
            Model::Quartic {
                coefficients_pa,
                strain_measure,
                strain_range,
            } => {
                let [lo, hi] = *strain_range;
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(super::AxisymError::Material(format!(
                        "strain_range = [{lo}, {hi}] must be two finite strains, the smaller first"
                    )));
                }
                if coefficients_pa.is_empty() || coefficients_pa.iter().any(|c| !c.is_finite()) {
                    return Err(super::AxisymError::Material(format!(
                        "coefficients_pa = {coefficients_pa:?} must be a non-empty list of finite numbers (Pa)"
                    )));
                }
                if coefficients_pa[0] <= 0.0 {
                    return Err(super::AxisymError::Material(format!(
                        "coefficients_pa[0] = {} is the modulus at zero strain and must be positive",
                        coefficients_pa[0]
                    )));
                }
                Law {
                    form: Form::Quartic {
                        nu,
                        measure: *strain_measure,
                        range: [lo, hi],
                    },
                    params: coefficients_pa.clone(),
                }
            }
            m => {
                let h = m.hyperelastic().ok_or_else(|| {
                    super::AxisymError::Material(format!("{} is not hyperelastic", m.name()))
                })?;
                let d = h.derivatives(1.0, 1.0);
                let biaxial = d.hess[0][0] + d.hess[0][1];
                if !(biaxial.is_finite() && biaxial > 0.0) {
                    return Err(super::AxisymError::Material(format!(
                        "the {} parameters give a non-positive initial stiffness ({biaxial} Pa): check their signs",
                        m.name()
                    )));
                }
                Law {
                    form: Form::Hyper(h),
                    params: h.params(),
                }
            }
        };
        Ok(law)
    }

    /// The law's parameters: `[E]` (linear), the coefficients of `E(eps)`
    /// (quartic), or [`Hyperelastic::params`].
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// Nominal stresses and derivatives; `None` outside the law's domain
    /// (non-positive stretch, non-finite values, or a quartic modulus `E <= 0`).
    #[inline]
    pub fn stress(&self, l1: f64, l2: f64) -> Option<Stress> {
        self.stress_with(&self.params, l1, l2)
    }

    /// As [`Law::stress`] with the parameters `th` (in the order of
    /// [`Law::params`]) and the stretches of any dual number type: the
    /// derivatives of the stresses with respect to what `th`, `l1` and `l2`
    /// carry come out exactly.
    #[inline]
    pub fn stress_with<T: DualNum<f64> + Copy>(&self, th: &[T], l1: T, l2: T) -> Option<Stress<T>> {
        if !(l1.re() > 0.0 && l2.re() > 0.0) {
            return None;
        }
        let s = match &self.form {
            Form::Hyper(h) => {
                let (_, grad, hess) = h.derivatives_with(th, l1, l2);
                Stress { p: grad, dp: hess }
            }
            Form::Linear { nu } => {
                let c = th[0] / (1.0 - nu * nu);
                let (e1, e2) = (l1 - 1.0, l2 - 1.0);
                Stress {
                    p: [c * (e1 + e2 * *nu), c * (e2 + e1 * *nu)],
                    dp: [[c, c * *nu], [c * *nu, c]],
                }
            }
            Form::Quartic { nu, measure, range } => {
                let (m, m1, m2) = mean_strain(*measure, *range, l1, l2);
                // Horner for E(m)/(1 - nu^2) and its slope.
                let (mut e, mut de) = (T::from(0.0), T::from(0.0));
                for ck in th.iter().rev() {
                    de = de * m + e;
                    e = e * m + *ck;
                }
                let k = 1.0 / (1.0 - nu * nu);
                let (e, de) = (e * k, de * k);
                if e.re() <= 0.0 {
                    return None;
                }
                let (e1, e2) = (l1 - 1.0, l2 - 1.0);
                let (f1, f2) = (e1 + e2 * *nu, e2 + e1 * *nu);
                Stress {
                    p: [e * f1, e * f2],
                    dp: [
                        [de * m1 * f1 + e, de * m2 * f1 + e * *nu],
                        [de * m1 * f2 + e * *nu, de * m2 * f2 + e],
                    ],
                }
            }
        };
        let ok =
            s.p.iter()
                .chain(s.dp.iter().flatten())
                .all(|v| v.re().is_finite());
        ok.then_some(s)
    }

    /// Quartic modulus `E(eps_m)` at the mean strain of `(l1, l2)`, Pa; `None`
    /// for the other laws. Used to name the strain in an error.
    pub fn quartic_modulus(&self, l1: f64, l2: f64) -> Option<(f64, f64)> {
        match &self.form {
            Form::Quartic { measure, range, .. } => {
                let (m, _, _) = mean_strain(*measure, *range, l1, l2);
                let e = self.params.iter().rev().fold(0.0, |acc, ck| acc * m + ck);
                Some((m, e))
            }
            _ => None,
        }
    }

    /// Equibiaxial small-strain stiffness `dP1/dl1 + dP1/dl2` at `l = 1`, Pa
    /// (`E / (1 - nu)`; `4 mu` = `2 E` for the incompressible models).
    pub fn biaxial_modulus(&self) -> f64 {
        self.stress(1.0, 1.0)
            .map(|s| s.dp[0][0] + s.dp[0][1])
            .unwrap_or(f64::NAN)
    }
}

/// The quartic's argument: the strain of `sqrt(l1 l2)`, clamped to the
/// fitted range, with its derivatives in `l1`, `l2` (zero where clamped).
#[inline]
fn mean_strain<T: DualNum<f64> + Copy>(
    measure: StrainMeasure,
    range: [f64; 2],
    l1: T,
    l2: T,
) -> (T, T, T) {
    let lm = (l1 * l2).sqrt();
    let (m, m1, m2) = match measure {
        StrainMeasure::Engineering => (lm - 1.0, lm * 0.5 / l1, lm * 0.5 / l2),
        StrainMeasure::Log => ((l1 * l2).ln() * 0.5, l1.recip() * 0.5, l2.recip() * 0.5),
    };
    let zero = T::from(0.0);
    if m.re() < range[0] {
        (T::from(range[0]), zero, zero)
    } else if m.re() > range[1] {
        (T::from(range[1]), zero, zero)
    } else {
        (m, m1, m2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat(model: Model, poisson: f64) -> Material {
        Material {
            model,
            poisson,
            fit: None,
        }
    }

    fn laws() -> Vec<Material> {
        vec![
            mat(Model::NeoHookean { c1_pa: 2.0e5 }, 0.5),
            mat(Model::Linear { young_pa: 1.0e6 }, 0.3),
            mat(
                Model::Quartic {
                    coefficients_pa: vec![1.2e6, -2.0e6, 3.0e6, -1.0e6, 2.0e5],
                    strain_range: [-0.5, 1.0],
                    strain_measure: StrainMeasure::Engineering,
                },
                0.45,
            ),
            mat(
                Model::Quartic {
                    coefficients_pa: vec![1.2e6, -2.0e6, 3.0e6, -1.0e6, 2.0e5],
                    strain_range: [-0.5, 1.0],
                    strain_measure: StrainMeasure::Log,
                },
                0.45,
            ),
        ]
    }

    /// The derivatives of every law against central differences of its
    /// stresses.
    #[test]
    fn derivatives_match_finite_differences() {
        for m in laws() {
            let law = Law::new(&m).unwrap();
            for &(l1, l2) in &[(1.0, 1.0), (1.05, 1.2), (1.4, 1.1), (0.97, 1.3)] {
                let s = law.stress(l1, l2).unwrap();
                let e = 1e-6;
                let d1p = law.stress(l1 + e, l2).unwrap().p;
                let d1m = law.stress(l1 - e, l2).unwrap().p;
                let d2p = law.stress(l1, l2 + e).unwrap().p;
                let d2m = law.stress(l1, l2 - e).unwrap().p;
                let scale = s.dp[0][0].abs();
                for i in 0..2 {
                    let fd1 = (d1p[i] - d1m[i]) / (2.0 * e);
                    let fd2 = (d2p[i] - d2m[i]) / (2.0 * e);
                    assert!((s.dp[i][0] - fd1).abs() < 1e-6 * scale, "{m:?} {l1} {l2}");
                    assert!((s.dp[i][1] - fd2).abs() < 1e-6 * scale, "{m:?} {l1} {l2}");
                }
            }
        }
    }

    /// The biaxial modulus is `E/(1 - nu)`, for the incompressible
    /// neo-Hookean `2E = 12 C1`.
    #[test]
    fn biaxial_modulus_closed_form() {
        let l = laws();
        assert!((Law::new(&l[0]).unwrap().biaxial_modulus() - 12.0 * 2.0e5).abs() < 1e-6);
        assert!((Law::new(&l[1]).unwrap().biaxial_modulus() - 1.0e6 / 0.7).abs() < 1e-6);
        assert!((Law::new(&l[2]).unwrap().biaxial_modulus() - 1.2e6 / 0.55).abs() < 1e-6);
    }

    /// Equibiaxial quartic stress is the fitted law: `P = E(eps) eps / (1 - nu)`.
    #[test]
    fn quartic_equibiaxial_is_the_fitted_law() {
        let m = &laws()[2];
        let Model::Quartic {
            coefficients_pa, ..
        } = &m.model
        else {
            unreachable!()
        };
        let law = Law::new(m).unwrap();
        for eps in [0.01f64, 0.2, 0.6] {
            let e: f64 = coefficients_pa
                .iter()
                .enumerate()
                .map(|(k, c)| c * eps.powi(k as i32))
                .sum();
            let want = e * eps / (1.0 - 0.45);
            let got = law.stress(1.0 + eps, 1.0 + eps).unwrap().p[0];
            assert!((got - want).abs() < 1e-9 * want, "{got} {want}");
        }
    }

    #[test]
    fn refuses_bad_parameters() {
        assert!(Law::new(&mat(Model::Linear { young_pa: -1.0 }, 0.3)).is_err());
        assert!(Law::new(&mat(Model::Linear { young_pa: 1.0 }, 0.5)).is_err());
        assert!(Law::new(&mat(Model::NeoHookean { c1_pa: -1.0 }, 0.5)).is_err());
        let q = mat(
            Model::Quartic {
                coefficients_pa: vec![1.0e6, -4.0e6],
                strain_range: [0.0, 0.5],
                strain_measure: StrainMeasure::Engineering,
            },
            0.45,
        );
        let law = Law::new(&q).unwrap();
        // E(eps) = 1e6 - 4e6 eps <= 0 from eps = 0.25 on.
        assert!(law.stress(1.2, 1.2).is_some());
        assert!(law.stress(1.3, 1.3).is_none());
        // Held at the end of the fitted range beyond it: E(0.2) = 2e5 Pa.
        let held = mat(
            Model::Quartic {
                coefficients_pa: vec![1.0e6, -4.0e6],
                strain_range: [0.0, 0.2],
                strain_measure: StrainMeasure::Engineering,
            },
            0.45,
        );
        let law = Law::new(&held).unwrap();
        let s = law.stress(1.5, 1.5).unwrap();
        assert!((s.p[0] - 2.0e5 * 0.5 / (1.0 - 0.45)).abs() < 1e-6);
        assert!((s.dp[0][0] - 2.0e5 / (1.0 - 0.45 * 0.45)).abs() < 1e-6);
    }

    /// The quartic's modulus is evaluated at the strain of sqrt(l1 l2), as
    /// the mass-spring triangles do.
    #[test]
    fn quartic_modulus_at_area_stretch() {
        let q = mat(
            Model::Quartic {
                coefficients_pa: vec![1.0e6, 2.0e6],
                strain_range: [0.0, 1.0],
                strain_measure: StrainMeasure::Engineering,
            },
            0.3,
        );
        let law = Law::new(&q).unwrap();
        let (eps, e) = law.quartic_modulus(1.44, 1.0).unwrap();
        assert!((eps - 0.2).abs() < 1e-12);
        assert!((e - 1.4e6).abs() < 1e-6);
    }
}
