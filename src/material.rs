//! Materials: what `bulge fit` writes to `material.toml` and what the
//! simulators read.
//!
//! ```toml
//! model = "mooney-rivlin"   # linear | quartic | neo-hookean | mooney-rivlin | yeoh | ogden | gent
//! poisson = 0.45            # used by the mass-spring models (plane stress)
//! c1_pa = 180000.0
//! c2_pa = 18000.0
//! ```
//!
//! The hyperelastic models are incompressible. Their strain energy per unit
//! reference volume is written as a function of the two in-plane principal
//! stretches, the third eliminated with `l3 = 1 / (l1 l2)`:
//!
//! * neo-Hookean: `W = C1 (I1 - 3)`
//! * Mooney-Rivlin: `W = C1 (I1 - 3) + C2 (I2 - 3)`
//! * Yeoh: `W = C1 (I1 - 3) + C2 (I1 - 3)^2 + C3 (I1 - 3)^3`
//! * Ogden (Ogden 1972 convention): `W = sum_i mu_i / alpha_i (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3)`
//! * Gent: `W = -(mu Jm / 2) ln(1 - (I1 - 3) / Jm)`
//!
//! with `I1 = l1^2 + l2^2 + l3^2` and `I2 = l1^-2 + l2^-2 + l3^-2`. For a
//! membrane in plane stress the principal Cauchy stresses are
//! `sigma_i = l_i dW/dl_i` and the nominal (first Piola) stresses
//! `P_i = dW/dl_i`. [`Hyperelastic::derivatives`] returns `W`, its gradient and
//! its Hessian in `(l1, l2)`, computed exactly with second-order dual numbers
//! (no finite differences), for the fits and the axisymmetric shooting.

use nalgebra::SVector;
use num_dual::{Dual2SVec, DualNum};
use serde::{Deserialize, Serialize};

mod check;

pub use check::MaterialError;

/// A material file: the model with its parameters, the Poisson ratio, and the
/// statistics of the fit that produced it (if any).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// The constitutive model and its parameters.
    #[serde(flatten)]
    pub model: Model,
    /// Poisson ratio used by the plane-stress (mass-spring) models, [0, 0.5).
    pub poisson: f64,
    /// Where the material came from: the fit that produced it, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<crate::fit::Provenance>,
}

impl Material {
    /// A linear elastic material (Young's modulus, Pa; Poisson ratio).
    pub fn linear(young_pa: f64, poisson: f64) -> Material {
        Material {
            model: Model::Linear { young_pa },
            poisson,
            fit: None,
        }
    }
}

/// Which strain the quartic modulus law is a function of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum StrainMeasure {
    /// Engineering strain `lambda - 1`.
    #[default]
    Engineering,
    /// Logarithmic (Hencky) strain `ln lambda`.
    Log,
}

impl StrainMeasure {
    /// The name as settings files and the command line spell it.
    pub fn name(self) -> &'static str {
        match self {
            StrainMeasure::Engineering => "engineering",
            StrainMeasure::Log => "log",
        }
    }

    /// The strain of a stretch.
    pub fn of_stretch(self, lambda: f64) -> f64 {
        match self {
            StrainMeasure::Engineering => lambda - 1.0,
            StrainMeasure::Log => lambda.ln(),
        }
    }
}

/// Constitutive models with their parameters (SI units, Pa). Keys that the
/// model does not take are refused; [`Material::read`] also names the nearest
/// valid key and checks the parameters ([`Model::validate`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Model {
    /// Linear elastic, Young's modulus in Pa.
    Linear {
        /// Young's modulus, Pa.
        young_pa: f64,
    },
    /// Tudruj et al.'s (2023) secant modulus law `E(eps) = sum_k c_k eps^k`.
    Quartic {
        /// `c_0 .. c_n`, Pa.
        coefficients_pa: Vec<f64>,
        /// Strain range the law was fitted over, `[min, max]`.
        strain_range: [f64; 2],
        /// The strain the law takes (default engineering).
        #[serde(default)]
        strain_measure: StrainMeasure,
    },
    /// `W = C1 (I1 - 3)`; shear modulus `mu = 2 C1`.
    NeoHookean {
        /// C1, Pa.
        c1_pa: f64,
    },
    /// `W = C1 (I1 - 3) + C2 (I2 - 3)`.
    MooneyRivlin {
        /// C1, Pa.
        c1_pa: f64,
        /// C2, Pa.
        c2_pa: f64,
    },
    /// `W = C1 (I1 - 3) + C2 (I1 - 3)^2 + C3 (I1 - 3)^3`.
    Yeoh {
        /// C1, Pa.
        c1_pa: f64,
        /// C2, Pa.
        c2_pa: f64,
        /// C3, Pa.
        c3_pa: f64,
    },
    /// `W = sum mu_i / alpha_i (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3)`.
    Ogden {
        /// mu_i, Pa.
        mu_pa: Vec<f64>,
        /// alpha_i, dimensionless.
        alpha: Vec<f64>,
    },
    /// `W = -(mu Jm / 2) ln(1 - (I1 - 3) / Jm)`.
    Gent {
        /// Shear modulus mu, Pa.
        mu_pa: f64,
        /// Locking parameter Jm (max of I1 - 3).
        jm: f64,
    },
}

impl Model {
    /// The model's name as written in `material.toml`.
    pub fn name(&self) -> &'static str {
        match self {
            Model::Linear { .. } => "linear",
            Model::Quartic { .. } => "quartic",
            Model::NeoHookean { .. } => "neo-hookean",
            Model::MooneyRivlin { .. } => "mooney-rivlin",
            Model::Yeoh { .. } => "yeoh",
            Model::Ogden { .. } => "ogden",
            Model::Gent { .. } => "gent",
        }
    }

    /// The hyperelastic energy of this model, if it is one.
    pub fn hyperelastic(&self) -> Option<Hyperelastic<'_>> {
        match self {
            Model::Linear { .. } | Model::Quartic { .. } => None,
            _ => Some(Hyperelastic(self)),
        }
    }

    /// Small-strain Young's modulus (incompressible models: `E = 3 mu`).
    pub fn initial_young_pa(&self) -> f64 {
        match self {
            Model::Linear { young_pa } => *young_pa,
            Model::Quartic {
                coefficients_pa, ..
            } => coefficients_pa.first().copied().unwrap_or(0.0),
            Model::NeoHookean { c1_pa } => 6.0 * c1_pa,
            Model::MooneyRivlin { c1_pa, c2_pa } => 6.0 * (c1_pa + c2_pa),
            Model::Yeoh { c1_pa, .. } => 6.0 * c1_pa,
            Model::Ogden { mu_pa, alpha } => {
                1.5 * mu_pa.iter().zip(alpha).map(|(m, a)| m * a).sum::<f64>()
            }
            Model::Gent { mu_pa, .. } => 3.0 * mu_pa,
        }
    }
}

/// A hyperelastic model viewed as an energy of the two in-plane stretches.
#[derive(Debug, Clone, Copy)]
pub struct Hyperelastic<'a>(&'a Model);

/// `W`, its gradient and Hessian at `(l1, l2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyDerivatives {
    /// Strain energy per reference volume, Pa.
    pub w: f64,
    /// `dW/dl1`, `dW/dl2`, Pa (the nominal stresses).
    pub grad: [f64; 2],
    /// Second derivatives, Pa.
    pub hess: [[f64; 2]; 2],
}

impl Hyperelastic<'_> {
    /// Energy and derivatives at in-plane stretches `(l1, l2)`, both > 0.
    pub fn derivatives(&self, l1: f64, l2: f64) -> EnergyDerivatives {
        let (w, g, h) = self.hessian(|k| self.param(k), l1, l2);
        EnergyDerivatives {
            w,
            grad: g,
            hess: h,
        }
    }

    /// As [`Hyperelastic::derivatives`], with the parameters `th` (in the
    /// order of [`Hyperelastic::params`]) and the stretches of any dual
    /// number type: the derivatives of `W`, `P_i` and `dP_i/dl_j` with
    /// respect to whatever `th`, `l1` and `l2` carry come out exactly
    /// (forward-mode automatic differentiation).
    pub fn derivatives_with<T: DualNum<f64> + Copy>(
        &self,
        th: &[T],
        l1: T,
        l2: T,
    ) -> (T, [T; 2], [[T; 2]; 2]) {
        self.hessian(|k| th[k], l1, l2)
    }

    /// `W`, its gradient and Hessian in the stretches, parameter `k` being
    /// `th(k)` (no allocation: this runs at every step of the shooting and
    /// at every point of a fit).
    fn hessian<T: DualNum<f64> + Copy>(
        &self,
        th: impl Fn(usize) -> T,
        l1: T,
        l2: T,
    ) -> (T, [T; 2], [[T; 2]; 2]) {
        let (w, g, h) = num_dual::hessian(
            |v: SVector<Dual2SVec<T, f64, 2>, 2>| {
                self.energy(|k| Dual2SVec::from_re(th(k)), v[0], v[1])
            },
            &SVector::from([l1, l2]),
        );
        (
            w,
            [g[0], g[1]],
            [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]],
        )
    }

    /// The model's parameters in a fixed order: `[c1]`, `[c1, c2]`,
    /// `[c1, c2, c3]`, `[mu_1.., alpha_1..]`, `[mu, jm]`.
    pub fn params(&self) -> Vec<f64> {
        let n = match self.0 {
            Model::Ogden { mu_pa, .. } => 2 * mu_pa.len(),
            Model::NeoHookean { .. } => 1,
            Model::MooneyRivlin { .. } | Model::Gent { .. } => 2,
            _ => 3,
        };
        (0..n).map(|k| self.param(k)).collect()
    }

    /// Parameter `k` in the order of [`Hyperelastic::params`].
    fn param(&self, k: usize) -> f64 {
        match self.0 {
            Model::NeoHookean { c1_pa } => [*c1_pa][k],
            Model::MooneyRivlin { c1_pa, c2_pa } => [*c1_pa, *c2_pa][k],
            Model::Yeoh {
                c1_pa,
                c2_pa,
                c3_pa,
            } => [*c1_pa, *c2_pa, *c3_pa][k],
            Model::Ogden { mu_pa, alpha } => {
                if k < mu_pa.len() {
                    mu_pa[k]
                } else {
                    alpha[k - mu_pa.len()]
                }
            }
            Model::Gent { mu_pa, jm } => [*mu_pa, *jm][k],
            Model::Linear { .. } | Model::Quartic { .. } => {
                unreachable!("Hyperelastic is only built for hyperelastic models")
            }
        }
    }

    /// Strain energy only, Pa.
    pub fn w(&self, l1: f64, l2: f64) -> f64 {
        self.energy(|k| self.param(k), l1, l2)
    }

    /// Equibiaxial nominal stress `P = dW/dl1 (l, l)`, Pa.
    pub fn equibiaxial_nominal(&self, l: f64) -> f64 {
        self.derivatives(l, l).grad[0]
    }

    /// Equibiaxial Cauchy stress `sigma = l dW/dl1 (l, l)`, Pa.
    pub fn equibiaxial_cauchy(&self, l: f64) -> f64 {
        l * self.equibiaxial_nominal(l)
    }

    /// `W` of the in-plane right Cauchy-Green tensor `C = [[c11, c12], [c12,
    /// c22]]` (principal values `l1^2`, `l2^2`), incompressible plane stress:
    /// `l3^2 = 1 / det C`, `I1 = tr C + 1 / det C`, `I2 = det C + tr C / det C`
    /// (Holzapfel, *Nonlinear Solid Mechanics*, 2000). Equal to
    /// [`Hyperelastic::w`] at the principal stretches, and smooth in `C`
    /// even where `l1 = l2`: Ogden's `l1^a + l2^a` is taken as a symmetric
    /// function of the two eigenvalues `m +- d / 2` of `C`, by its even
    /// Taylor series in `d^2 = (c11 - c22)^2 + 4 c12^2` where `d^2 < 4e-4
    /// m^2` (four terms; error below 1e-12 of the Hessian), so its dual-number
    /// derivatives stay finite at the equibiaxial state.
    pub fn energy_of_c<T: DualNum<f64> + Copy>(&self, c11: T, c12: T, c22: T) -> T {
        self.energy_c(|k| T::from(self.param(k)), c11, c12, c22)
    }

    /// `W`, its gradient and Hessian in `(c11, c12, c22)` (the off-diagonal
    /// `c12` counted once: `dW/dc12 = 2 dW/dC_12` of the symmetric tensor),
    /// exact by second-order dual numbers.
    pub fn derivatives_c(&self, c: [f64; 3]) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        let (w, g, h) = num_dual::hessian(
            |v: SVector<num_dual::Dual2SVec<f64, f64, 3>, 3>| {
                self.energy_c(
                    |k| num_dual::Dual2SVec::from_re(self.param(k)),
                    v[0],
                    v[1],
                    v[2],
                )
            },
            &SVector::from(c),
        );
        (
            w,
            [g[0], g[1], g[2]],
            std::array::from_fn(|i| std::array::from_fn(|j| h[(i, j)])),
        )
    }

    fn energy_c<T: DualNum<f64> + Copy>(
        &self,
        th: impl Fn(usize) -> T,
        c11: T,
        c12: T,
        c22: T,
    ) -> T {
        let tr = c11 + c22;
        let det = c11 * c22 - c12 * c12;
        let l3sq = det.recip();
        let i1 = || tr + l3sq - 3.0;
        match self.0 {
            Model::NeoHookean { .. } => i1() * th(0),
            Model::MooneyRivlin { .. } => {
                let i2 = det + tr * l3sq - 3.0;
                i1() * th(0) + i2 * th(1)
            }
            Model::Yeoh { .. } => {
                let j = i1();
                j * th(0) + j * j * th(1) + j * j * j * th(2)
            }
            Model::Ogden { mu_pa, .. } => {
                let n = mu_pa.len();
                let m = tr * 0.5;
                let dsq = (c11 - c22) * (c11 - c22) + c12 * c12 * 4.0;
                let ln_m = m.ln();
                let mut w = T::from(0.0);
                for k in 0..n {
                    let (mu, a) = (th(k), th(n + k));
                    let h = a * 0.5; // l^a = (l^2)^(a/2)
                    let pair = if dsq.re() < 4e-4 * m.re() * m.re() {
                        // 2 sum_j f^(2j)(m) (d^2/4)^j / (2j)!, f(x) = x^h
                        let q = dsq * 0.25;
                        let mut sum = T::from(0.0);
                        let mut coef = T::from(1.0); // h (h-1) ... (h-2j+1)
                        let mut qj = T::from(1.0);
                        let mut fact = 1.0;
                        for j in 0..4 {
                            let pw = ((h - (2 * j) as f64) * ln_m).exp();
                            sum += coef * pw * qj / fact;
                            coef = coef * (h - (2 * j) as f64) * (h - (2 * j + 1) as f64);
                            qj *= q;
                            fact *= ((2 * j + 1) * (2 * j + 2)) as f64;
                        }
                        sum * 2.0
                    } else {
                        let d = dsq.sqrt();
                        let pw = |x: T| (h * x.ln()).exp();
                        pw(m + d * 0.5) + pw(m - d * 0.5)
                    };
                    let l3a = (-h * det.ln()).exp();
                    w += (pair + l3a - 3.0) * mu / a;
                }
                w
            }
            Model::Gent { .. } => {
                let (mu, jm) = (th(0), th(1));
                -(T::from(1.0) - i1() / jm).ln() * mu * jm * 0.5
            }
            Model::Linear { .. } | Model::Quartic { .. } => {
                unreachable!("Hyperelastic is only built for hyperelastic models")
            }
        }
    }

    /// `W(l1, l2)` with the parameters `th` (see [`Hyperelastic::params`]),
    /// incompressible: `l3 = 1 / (l1 l2)`.
    fn energy<T: DualNum<f64> + Copy>(&self, th: impl Fn(usize) -> T, l1: T, l2: T) -> T {
        let l3 = (l1 * l2).recip();
        let i1 = || l1 * l1 + l2 * l2 + l3 * l3 - 3.0;
        match self.0 {
            Model::NeoHookean { .. } => i1() * th(0),
            Model::MooneyRivlin { .. } => {
                let i2 = (l1 * l1).recip() + (l2 * l2).recip() + (l3 * l3).recip() - 3.0;
                i1() * th(0) + i2 * th(1)
            }
            Model::Yeoh { .. } => {
                let j = i1();
                j * th(0) + j * j * th(1) + j * j * j * th(2)
            }
            Model::Ogden { mu_pa, .. } => {
                let n = mu_pa.len();
                let mut w = T::from(0.0);
                for k in 0..n {
                    let (m, a) = (th(k), th(n + k));
                    let pow = |l: T| (a * l.ln()).exp();
                    w += (pow(l1) + pow(l2) + pow(l3) - 3.0) * m / a;
                }
                w
            }
            Model::Gent { .. } => {
                let (mu, jm) = (th(0), th(1));
                -(T::from(1.0) - i1() / jm).ln() * mu * jm * 0.5
            }
            Model::Linear { .. } | Model::Quartic { .. } => {
                unreachable!("Hyperelastic is only built for hyperelastic models")
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// One of each hyperelastic model, with rubber-like parameters (shared
    /// by the material and axisymmetric tests).
    pub(crate) fn models() -> Vec<Model> {
        vec![
            Model::NeoHookean { c1_pa: 2.0e5 },
            Model::MooneyRivlin {
                c1_pa: 1.8e5,
                c2_pa: 2.0e4,
            },
            Model::Yeoh {
                c1_pa: 1.8e5,
                c2_pa: -2.0e3,
                c3_pa: 50.0,
            },
            Model::Ogden {
                mu_pa: vec![6.3e5, 1.2e3, -1.0e4],
                alpha: vec![1.3, 5.0, -2.0],
            },
            Model::Gent {
                mu_pa: 3.5e5,
                jm: 80.0,
            },
        ]
    }

    /// Gradient and Hessian against central differences of W.
    #[test]
    fn derivatives_match_finite_differences() {
        for m in models() {
            let h = m.hyperelastic().unwrap();
            for &(l1, l2) in &[(1.0, 1.0), (1.3, 1.1), (2.2, 1.7), (0.9, 1.4)] {
                let d = h.derivatives(l1, l2);
                let e = 1e-5;
                let g1 = (h.w(l1 + e, l2) - h.w(l1 - e, l2)) / (2.0 * e);
                let g2 = (h.w(l1, l2 + e) - h.w(l1, l2 - e)) / (2.0 * e);
                let scale = d.grad[0].abs().max(d.grad[1].abs()).max(1e3);
                assert!((d.grad[0] - g1).abs() < 1e-6 * scale, "{m:?} {l1} {l2}");
                assert!((d.grad[1] - g2).abs() < 1e-6 * scale, "{m:?} {l1} {l2}");
                let gd = |a: f64, b: f64| h.derivatives(a, b).grad;
                let h11 = (gd(l1 + e, l2)[0] - gd(l1 - e, l2)[0]) / (2.0 * e);
                let h12 = (gd(l1, l2 + e)[0] - gd(l1, l2 - e)[0]) / (2.0 * e);
                let h22 = (gd(l1, l2 + e)[1] - gd(l1, l2 - e)[1]) / (2.0 * e);
                let hs = d.hess[0][0].abs().max(d.hess[1][1].abs()).max(1e3);
                assert!((d.hess[0][0] - h11).abs() < 1e-5 * hs, "{m:?}");
                assert!((d.hess[0][1] - h12).abs() < 1e-5 * hs, "{m:?}");
                assert!((d.hess[1][0] - h12).abs() < 1e-5 * hs, "{m:?}");
                assert!((d.hess[1][1] - h22).abs() < 1e-5 * hs, "{m:?}");
            }
        }
    }

    /// `W(C)` equals `W(l1, l2)` at the principal stretches of `C`, for
    /// rotated, unequal and equal stretches; its gradient and Hessian in `C`
    /// match central differences of `W(C)`, also at and near `l1 = l2`
    /// (where Ogden's series takes over).
    #[test]
    fn energy_of_c_matches_stretches_and_differences() {
        for m in models() {
            let h = m.hyperelastic().unwrap();
            for &(l1, l2, th) in &[
                (1.0, 1.0, 0.0),
                (1.3, 1.1, 0.4),
                (2.2, 1.7, 1.1),
                (0.9, 1.4, -0.3),
                (1.5, 1.5, 0.2),
                (1.5, 1.5 + 1e-4, 0.7),
                (1.5, 1.52, 0.7),
            ] {
                let (c, s) = (f64::cos(th), f64::sin(th));
                let (a, b) = (l1 * l1, l2 * l2);
                let cc = [
                    a * c * c + b * s * s,
                    (a - b) * c * s,
                    a * s * s + b * c * c,
                ];
                let (w, g, hh) = h.derivatives_c(cc);
                let want = h.w(l1, l2);
                assert!(
                    (w - want).abs() < 1e-9 * want.abs().max(1.0),
                    "{m:?} {l1} {l2}: {w} vs {want}"
                );
                let e = 1e-6;
                let wc = |v: [f64; 3]| h.energy_of_c(v[0], v[1], v[2]);
                let gc = |v: [f64; 3]| h.derivatives_c(v).1;
                let scale = g.iter().fold(1e3_f64, |acc, v| acc.max(v.abs()));
                let hscale = hh.iter().flatten().fold(1e3_f64, |acc, v| acc.max(v.abs()));
                for i in 0..3 {
                    let (mut p, mut q) = (cc, cc);
                    p[i] += e;
                    q[i] -= e;
                    let fd = (wc(p) - wc(q)) / (2.0 * e);
                    assert!(
                        (g[i] - fd).abs() < 1e-6 * scale,
                        "{m:?} grad {i}: {} vs {fd}",
                        g[i]
                    );
                    let (gp, gq) = (gc(p), gc(q));
                    for j in 0..3 {
                        let fd = (gp[j] - gq[j]) / (2.0 * e);
                        assert!(
                            (hh[j][i] - fd).abs() < 1e-5 * hscale,
                            "{m:?} ({l1}, {l2}) hess {j}{i}: {} vs {fd}",
                            hh[j][i]
                        );
                    }
                }
            }
        }
    }

    /// Closed form: neo-Hookean equibiaxial nominal stress 2 C1 (l - l^-5).
    #[test]
    fn neo_hookean_equibiaxial_closed_form() {
        let m = Model::NeoHookean { c1_pa: 1.0e5 };
        let h = m.hyperelastic().unwrap();
        for l in [1.0_f64, 1.2, 2.0, 3.5] {
            let want = 2.0e5 * (l - l.powi(-5));
            assert!((h.equibiaxial_nominal(l) - want).abs() < 1e-9 * want.abs().max(1.0));
        }
    }

    /// Every model's small-strain Young's modulus equals the slope of its
    /// equibiaxial stress: d sigma / d eps = E / (1 - nu) = 2 E at nu = 1/2.
    #[test]
    fn initial_modulus_matches_equibiaxial_slope() {
        for m in models() {
            let h = m.hyperelastic().unwrap();
            let e = 1e-6;
            let slope = (h.equibiaxial_cauchy(1.0 + e) - h.equibiaxial_cauchy(1.0 - e)) / (2.0 * e);
            let want = 2.0 * m.initial_young_pa();
            assert!(
                (slope - want).abs() < 1e-5 * want,
                "{m:?}: {slope} vs {want}"
            );
        }
    }

    #[test]
    fn toml_round_trip() {
        let text = "model = \"ogden\"\npoisson = 0.45\nmu_pa = [630000.0, 1200.0, -10000.0]\nalpha = [1.3, 5.0, -2.0]\n";
        let m: Material = toml::from_str(text).unwrap();
        assert_eq!(m.model.name(), "ogden");
        let back: Material = toml::from_str(&toml::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        let q: Material = toml::from_str(
            "model = \"quartic\"\npoisson = 0.45\ncoefficients_pa = [1e6, 0, 0, 0, 0]\nstrain_range = [0, 0.5]\n",
        )
        .unwrap();
        assert!(matches!(
            q.model,
            Model::Quartic {
                strain_measure: StrainMeasure::Engineering,
                ..
            }
        ));
        let l: Material =
            toml::from_str("model = \"linear\"\npoisson = 0.3\nyoung_pa = 1000000\n").unwrap();
        assert_eq!(l.model.initial_young_pa(), 1.0e6);
    }
}
