//! The constant-strain triangle (CST) membrane: the material's whole law on
//! a triangle mesh (`--model membrane`).
//!
//! Per triangle, the reference triangle `X0, X1, X2` (flat or on a dome) is
//! given an orthonormal frame of its plane; with `G` the 2x2 matrix of its
//! edges `X1 - X0`, `X2 - X0` in that frame, the deformation gradient is
//! the 3x2 matrix `F = [x1 - x0, x2 - x0] G^-1`, constant over the
//! triangle, and `C = F^T F` the in-plane right Cauchy-Green tensor
//! (G. A. Holzapfel, *Nonlinear Solid Mechanics: A Continuum Approach for
//! Engineering*, Wiley, 2000, ISBN 0-471-82319-8). With the columns
//! `F_a = sum_n x_n B[n][a]` (`B` from `G^-1`), `C_ab = F_a . F_b`.
//! Derivation and validation: docs/theory.md section 9, docs/simulate.md.
//!
//! The element's energy is `t0 |T0| W(C)`, `W` per unit reference volume:
//!
//! * hyperelastic models: the incompressible plane-stress energy of
//!   [`crate::material::Hyperelastic::energy_of_c`] (`l3^2 = 1 / det C`);
//! * `linear`: plane-stress Hooke in the engineering strains of the
//!   principal stretches, `W = E / (2 (1 - nu^2)) (e1^2 + e2^2 + 2 nu e1
//!   e2)`, `e_i = l_i - 1`, the law the axisymmetric reference takes (see
//!   `crate::axisym::law`); with `s = l1 + l2 = sqrt(tr C + 2 sqrt(det C))`
//!   it is `E / (2 (1 - nu^2)) ((1 - nu)(tr C - 2 s + 2) + nu (s - 2)^2)`,
//!   smooth in `C`;
//! * `quartic`: Tudruj et al.'s secant law as the axisymmetric reference
//!   carries it, `P_i = E(eps_m) / (1 - nu^2) (e_i + nu e_j)` with `E` at the
//!   equibiaxial-equivalent stretch `l_m = sqrt(l1 l2) = (det C)^(1/4)`
//!   (clamped to the fitted range): the linear energy's stress with the
//!   modulus of the triangle's area stretch. It is **not** the gradient of
//!   an energy (the modulus is frozen in the stress, not integrated), so the
//!   element's stress `dW/dC := E(l_m) dW_1/dC` (`W_1` the linear energy at
//!   `E = 1`) has a tangent `E d2W_1/dC2 + dW_1/dC (x) E'(l_m) dl_m/dC` that
//!   is not symmetric where `E` varies; there is no energy
//!   ([`CstLaw::energy`] is `None`). Under equibiaxial stretch it is exactly
//!   the fitted law, as for the springs.
//!
//! Nodal forces `f_n = -t0 |T0| sum_v g_v dv/dx_n` over `v = (C11, C12,
//! C22)` with `g = dW/dv` (exact, by dual numbers), and the consistent
//! tangent `K = t0 |T0| (sum_vw H_vw dv/dx (x) dw/dx + sum_v g_v d2v/dx2)`
//! with `H = dg/dv`. The follower pressure gives each vertex `p n2 / 6`
//! (`n2 = (x1 - x0) x (x2 - x0)`, twice the area vector) and the load
//! stiffness `-d(p n2 / 6)/dx`, not symmetric per triangle (its sum is over
//! a clamped or closed surface).

use nalgebra::{Point3, SVector, Vector3};
use num_dual::{DualNum, DualSVec64};

use crate::material::{Material, Model, StrainMeasure};

/// The law of a CST membrane.
#[derive(Debug, Clone, PartialEq)]
pub enum CstLaw {
    /// An incompressible hyperelastic model.
    Hyper(Model),
    /// Plane-stress Hooke in the principal engineering strains.
    Linear {
        /// Young's modulus, Pa.
        young_pa: f64,
        /// Poisson ratio.
        nu: f64,
    },
    /// The quartic secant law at the area stretch (see the module docs).
    Quartic {
        /// `c_0 .. c_n` of `E(eps)`, Pa.
        coefficients_pa: Vec<f64>,
        /// Fitted strain range (the argument is clamped to it).
        range: [f64; 2],
        /// Strain measure.
        measure: StrainMeasure,
        /// Poisson ratio.
        nu: f64,
    },
}

/// Why the law has no stress at a triangle's strain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawFailure {
    /// The quartic modulus `E <= 0` (or not finite) at this strain.
    Modulus {
        /// The strain.
        strain: f64,
        /// The modulus, Pa.
        young_pa: f64,
    },
    /// The stress is not finite (a collapsed triangle, or beyond Gent's
    /// locking stretch).
    Domain {
        /// Principal stretches of the triangle.
        stretches: [f64; 2],
    },
}

impl CstLaw {
    /// The law of a material (its parameters were checked by
    /// [`super::springs::ModulusLaw::from_material`]).
    pub fn from_material(m: &Material) -> CstLaw {
        match &m.model {
            Model::Linear { young_pa } => CstLaw::Linear {
                young_pa: *young_pa,
                nu: m.poisson,
            },
            Model::Quartic {
                coefficients_pa,
                strain_range,
                strain_measure,
            } => CstLaw::Quartic {
                coefficients_pa: coefficients_pa.clone(),
                range: *strain_range,
                measure: *strain_measure,
                nu: m.poisson,
            },
            other => CstLaw::Hyper(other.clone()),
        }
    }

    /// Energy per reference volume at `c = (C11, C12, C22)`, Pa; `None` for
    /// the quartic law, which has none.
    pub fn energy(&self, c: [f64; 3]) -> Option<f64> {
        match self {
            CstLaw::Hyper(m) => Some(m.hyperelastic()?.energy_of_c(c[0], c[1], c[2])),
            CstLaw::Linear { young_pa, nu } => Some(young_pa * linear_w(*nu, c[0], c[1], c[2])),
            CstLaw::Quartic { .. } => None,
        }
    }

    /// `g = dW/dc` and, when `tangent`, `H = dg/dc`.
    pub fn stress(
        &self,
        c: [f64; 3],
        tangent: bool,
    ) -> Result<([f64; 3], [[f64; 3]; 3]), LawFailure> {
        let (g, h) = match self {
            CstLaw::Hyper(m) => {
                let hy = m.hyperelastic().expect("a hyperelastic model");
                if tangent {
                    let (_, g, h) = hy.derivatives_c(c);
                    (g, h)
                } else {
                    let (_, g) = num_dual::gradient(
                        |v: SVector<DualSVec64<3>, 3>| hy.energy_of_c(v[0], v[1], v[2]),
                        &SVector::from(c),
                    );
                    ([g[0], g[1], g[2]], [[0.0; 3]; 3])
                }
            }
            CstLaw::Linear { young_pa, nu } => {
                let (g, h) = linear_derivatives(*nu, c);
                (g.map(|v| v * young_pa), h.map(|r| r.map(|v| v * young_pa)))
            }
            CstLaw::Quartic {
                coefficients_pa,
                range,
                measure,
                nu,
            } => {
                let det = c[0] * c[2] - c[1] * c[1];
                let lm = det.sqrt().sqrt();
                let raw = measure.of_stretch(lm);
                let eps = raw.clamp(range[0], range[1]);
                let (mut e, mut de) = (0.0, 0.0);
                for ck in coefficients_pa.iter().rev() {
                    de = de * eps + e;
                    e = e * eps + ck;
                }
                if !(e > 0.0 && e.is_finite()) {
                    return Err(LawFailure::Modulus {
                        strain: eps,
                        young_pa: e,
                    });
                }
                let (g1, h1) = linear_derivatives(*nu, c);
                let g = g1.map(|v| v * e);
                let mut h = h1.map(|r| r.map(|v| v * e));
                if tangent && raw == eps {
                    // dE/dc = E'(eps) deps/dlm dlm/dc, dlm/dc = lm / (4 det) ddet/dc
                    let deps = match measure {
                        StrainMeasure::Engineering => 1.0,
                        StrainMeasure::Log => 1.0 / lm,
                    };
                    let k = de * deps * lm / (4.0 * det);
                    let ddet = [c[2], -2.0 * c[1], c[0]];
                    for (i, hi) in h.iter_mut().enumerate() {
                        for (j, hij) in hi.iter_mut().enumerate() {
                            *hij += g1[i] * k * ddet[j];
                        }
                    }
                }
                (g, h)
            }
        };
        if g.iter().chain(h.iter().flatten()).all(|v| v.is_finite()) {
            Ok((g, h))
        } else {
            Err(LawFailure::Domain {
                stretches: principal_stretches(c),
            })
        }
    }
}

/// Principal stretches of `C`, larger first.
pub fn principal_stretches(c: [f64; 3]) -> [f64; 2] {
    let m = 0.5 * (c[0] + c[2]);
    let d = (0.25 * (c[0] - c[2]) * (c[0] - c[2]) + c[1] * c[1]).sqrt();
    [(m + d).max(0.0).sqrt(), (m - d).max(0.0).sqrt()]
}

/// The linear plane-stress energy at `E = 1` (see the module docs).
fn linear_w<T: DualNum<f64> + Copy>(nu: f64, c11: T, c12: T, c22: T) -> T {
    let tr = c11 + c22;
    let det = c11 * c22 - c12 * c12;
    let s = (tr + det.sqrt() * 2.0).sqrt();
    ((tr - s * 2.0 + 2.0) * (1.0 - nu) + (s - 2.0) * (s - 2.0) * nu) * (0.5 / (1.0 - nu * nu))
}

fn linear_derivatives(nu: f64, c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let (_, g, h) = num_dual::hessian(
        |v: SVector<num_dual::Dual2SVec64<3>, 3>| linear_w(nu, v[0], v[1], v[2]),
        &SVector::from(c),
    );
    (
        [g[0], g[1], g[2]],
        std::array::from_fn(|i| std::array::from_fn(|j| h[(i, j)])),
    )
}

/// Rest data of one triangle.
#[derive(Debug, Clone, Copy)]
pub struct CstRest {
    /// `F_a = sum_n x_n b[n][a]`.
    b: [[f64; 2]; 3],
    /// `t0 |T0|`, m^3.
    volume: f64,
}

impl CstRest {
    /// The rest data of the reference triangle `p` (non-degenerate) of
    /// thickness `t`.
    pub fn new(p: &[Point3<f64>; 3], t: f64) -> CstRest {
        let (d1, d2) = (p[1] - p[0], p[2] - p[0]);
        let n = d1.cross(&d2);
        let e1 = d1.normalize();
        let e2 = n.normalize().cross(&e1);
        // G = [[g11, g12], [g21, g22]], columns the edges in the frame
        let (g11, g21, g12, g22) = (d1.norm(), 0.0, d2.dot(&e1), d2.dot(&e2));
        let det = g11 * g22 - g12 * g21;
        let gi = [[g22 / det, -g12 / det], [-g21 / det, g11 / det]];
        let b1 = gi[0];
        let b2 = gi[1];
        CstRest {
            b: [[-(b1[0] + b2[0]), -(b1[1] + b2[1])], b1, b2],
            volume: t * n.norm() / 2.0,
        }
    }

    /// The columns of `F` and `c = (C11, C12, C22)` at positions `p`.
    fn strain(&self, p: &[Point3<f64>; 3]) -> ([Vector3<f64>; 2], [f64; 3]) {
        let f: [Vector3<f64>; 2] = std::array::from_fn(|a| {
            p[0].coords * self.b[0][a] + p[1].coords * self.b[1][a] + p[2].coords * self.b[2][a]
        });
        (f, [f[0].dot(&f[0]), f[0].dot(&f[1]), f[1].dot(&f[1])])
    }

    /// `dv/dx_n` for `v = C11, C12, C22`.
    fn dc(&self, f: &[Vector3<f64>; 2], n: usize) -> [Vector3<f64>; 3] {
        let b = self.b[n];
        [
            f[0] * (2.0 * b[0]),
            f[1] * b[0] + f[0] * b[1],
            f[1] * (2.0 * b[1]),
        ]
    }

    /// Elastic energy of the triangle at `p`, J (`None` for the quartic law).
    pub fn energy(&self, law: &CstLaw, p: &[Point3<f64>; 3]) -> Option<f64> {
        let (_, c) = self.strain(p);
        law.energy(c).map(|w| w * self.volume)
    }

    /// Nodal forces of the triangle (elastic and pressure `pressure_pa`).
    #[inline]
    pub fn forces(
        &self,
        law: &CstLaw,
        pressure_pa: f64,
        p: &[Point3<f64>; 3],
    ) -> Result<[Vector3<f64>; 3], LawFailure> {
        let (f, c) = self.strain(p);
        let (g, _) = law.stress(c, false)?;
        let n2 = (p[1] - p[0]).cross(&(p[2] - p[0])) * (pressure_pa / 6.0);
        Ok(std::array::from_fn(|n| {
            let d = self.dc(&f, n);
            n2 - (d[0] * g[0] + d[1] * g[1] + d[2] * g[2]) * self.volume
        }))
    }

    /// The triangle's stiffness `-df/dx` (9x9 over its vertices'
    /// coordinates): material, geometric and pressure-load parts.
    pub fn stiffness(
        &self,
        law: &CstLaw,
        pressure_pa: f64,
        p: &[Point3<f64>; 3],
    ) -> Result<[[f64; 9]; 9], LawFailure> {
        let (f, c) = self.strain(p);
        let (g, h) = law.stress(c, true)?;
        let d: [[Vector3<f64>; 3]; 3] = std::array::from_fn(|n| self.dc(&f, n));
        let v = self.volume;
        let mut k = [[0.0; 9]; 9];
        for n in 0..3 {
            // sum_w H_vw dw/dx_n, per v
            for m in 0..3 {
                let (bn, bm) = (self.b[n], self.b[m]);
                let geo = 2.0 * g[0] * bn[0] * bm[0]
                    + g[1] * (bn[0] * bm[1] + bn[1] * bm[0])
                    + 2.0 * g[2] * bn[1] * bm[1];
                for r in 0..3 {
                    for s in 0..3 {
                        let mut mat = 0.0;
                        for (a, ha) in h.iter().enumerate() {
                            for (b, hab) in ha.iter().enumerate() {
                                mat += hab * d[n][a][r] * d[m][b][s];
                            }
                        }
                        k[3 * n + r][3 * m + s] = v * (mat + if r == s { geo } else { 0.0 });
                    }
                }
            }
        }
        if pressure_pa != 0.0 {
            // f_n = p/6 n2 for each n; dn2/dx1 = -[e2]x, dn2/dx2 = [e1]x
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let cross = |a: Vector3<f64>| [[0.0, -a.z, a.y], [a.z, 0.0, -a.x], [-a.y, a.x, 0.0]];
            let (c1, c2) = (cross(-e2), cross(e1));
            let q = pressure_pa / 6.0;
            for n in 0..3 {
                for r in 0..3 {
                    for s in 0..3 {
                        let d1 = c1[r][s];
                        let d2 = c2[r][s];
                        k[3 * n + r][3 + s] -= q * d1;
                        k[3 * n + r][6 + s] -= q * d2;
                        k[3 * n + r][s] += q * (d1 + d2);
                    }
                }
            }
        }
        Ok(k)
    }

    /// Principal stretches of the triangle at `p`.
    pub fn stretches(&self, p: &[Point3<f64>; 3]) -> [f64; 2] {
        principal_stretches(self.strain(p).1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One of every law the fit writes (and linear).
    pub(crate) fn laws() -> Vec<CstLaw> {
        let mut v: Vec<CstLaw> = crate::material::tests::models()
            .into_iter()
            .map(CstLaw::Hyper)
            .collect();
        v.push(CstLaw::Linear {
            young_pa: 1.2e6,
            nu: 0.45,
        });
        for measure in [StrainMeasure::Engineering, StrainMeasure::Log] {
            v.push(CstLaw::Quartic {
                coefficients_pa: vec![1.0e6, -1.5e6, 2.0e6, 0.5e6, -0.2e6],
                range: [0.0, 1.5],
                measure,
                nu: 0.45,
            });
        }
        v
    }

    fn rest() -> [Point3<f64>; 3] {
        // a general triangle off the coordinate planes (a dome's)
        [
            Point3::new(0.01, 0.02, 0.003),
            Point3::new(0.031, 0.018, 0.001),
            Point3::new(0.017, 0.039, 0.006),
        ]
    }

    fn deformed(s: f64) -> [Point3<f64>; 3] {
        let r = rest();
        [
            Point3::new(0.012, 0.019, 0.009),
            r[1] + Vector3::new(0.006 * s, -0.002, 0.004),
            r[2] + Vector3::new(-0.001, 0.005 * s, 0.008),
        ]
    }

    /// At rest there is no elastic force; the energy is 0 for the laws
    /// that have one.
    #[test]
    fn rest_is_stress_free() {
        let p = rest();
        let e = CstRest::new(&p, 1e-3);
        for law in laws() {
            let f = e.forces(&law, 0.0, &p).unwrap();
            for v in f {
                assert!(v.norm() < 1e-9, "{law:?}: {v}");
            }
            if let Some(w) = e.energy(&law, &p) {
                assert!(w.abs() < 1e-15, "{law:?}: {w}");
            }
        }
    }

    /// Forces are minus the gradient of the energy (central differences),
    /// for every law with an energy, at three deformations.
    #[test]
    fn forces_are_energy_gradients() {
        let e = CstRest::new(&rest(), 1e-3);
        for law in laws() {
            for s in [0.6, 1.0, 2.0] {
                let p = deformed(s);
                let Some(_) = e.energy(&law, &p) else {
                    continue;
                };
                let f = e.forces(&law, 0.0, &p).unwrap();
                let scale = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
                assert!(scale > 0.0);
                for n in 0..3 {
                    for c in 0..3 {
                        let h = 1e-7;
                        let (mut pp, mut pm) = (p, p);
                        pp[n][c] += h;
                        pm[n][c] -= h;
                        let du = (e.energy(&law, &pp).unwrap() - e.energy(&law, &pm).unwrap())
                            / (2.0 * h);
                        assert!(
                            (f[n][c] + du).abs() < 1e-6 * scale,
                            "{law:?} s {s} node {n} dir {c}: {} vs {}",
                            f[n][c],
                            -du
                        );
                    }
                }
            }
        }
    }

    /// The tangent is minus the derivative of the forces (central
    /// differences), for every law, with and without pressure.
    #[test]
    fn tangent_is_the_force_derivative() {
        let e = CstRest::new(&rest(), 1e-3);
        for law in laws() {
            for (s, pressure) in [(0.6, 0.0), (1.0, 3.0e4), (2.0, -1.0e4)] {
                let p = deformed(s);
                let k = e.stiffness(&law, pressure, &p).unwrap();
                let scale = k.iter().flatten().fold(0.0_f64, |a, v| a.max(v.abs()));
                for col in 0..9 {
                    let h = 1e-7;
                    let (mut pp, mut pm) = (p, p);
                    pp[col / 3][col % 3] += h;
                    pm[col / 3][col % 3] -= h;
                    let fp = e.forces(&law, pressure, &pp).unwrap();
                    let fm = e.forces(&law, pressure, &pm).unwrap();
                    for row in 0..9 {
                        let fd = -(fp[row / 3][row % 3] - fm[row / 3][row % 3]) / (2.0 * h);
                        assert!(
                            (k[row][col] - fd).abs() < 1e-6 * scale,
                            "{law:?} s {s} p {pressure}: K[{row}][{col}] {} vs {fd}",
                            k[row][col]
                        );
                    }
                }
            }
        }
    }

    /// Pure shear of a right triangle (x stretched by `l`, y held, the
    /// thickness free): the x force on the moved vertex is `-t |T0| dW/dl`
    /// with the neo-Hookean `W = C1 (l^2 + 1 + l^-2 - 3)`, i.e. `2 C1 (l -
    /// l^-3) t / 2` (closed form).
    #[test]
    fn pure_shear_stress_of_neo_hookean() {
        let c1 = 2.0e5;
        let law = CstLaw::Hyper(Model::NeoHookean { c1_pa: c1 });
        let p0 = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let t = 1e-3;
        let e = CstRest::new(&p0, t);
        for l in [1.1, 1.5, 2.5] {
            let p = [p0[0], Point3::new(l, 0.0, 0.0), p0[2]];
            let f = e.forces(&law, 0.0, &p).unwrap();
            // the x force on vertex 1 is the stress on half the unit edge:
            // P t * (edge length 1) / 2 ... by virtual work f1x = -V dW/dl
            let want = 2.0 * c1 * (l - l.powi(-3)) * t * 0.5;
            assert!(
                (-f[1].x - want).abs() < 1e-9 * want,
                "l {l}: {} vs {want}",
                -f[1].x
            );
        }
    }
}
