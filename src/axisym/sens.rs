//! Exact derivatives of the apex height with respect to the law's
//! parameters: the forward sensitivity equations integrated along the shot.
//!
//! At a given load `pi = p a / t` the solution is the pole stretch `l0` whose
//! shot reaches the clamp with `l2(a) = 1`: `g(l0, th) = y_2(1; l0, th) = 0`.
//! The apex height over the radius is `d(1; l0, th)`. By the implicit
//! function theorem
//!
//! ```text
//! dh/dth = a (d_th - d_l0 g_th / g_l0)
//! ```
//!
//! The partial derivatives `dy(1)/dl0` and `dy(1)/dth` solve the forward
//! sensitivity equations `S' = (df/dy) S + df/dth`, started from the
//! derivatives of the pole series. They are integrated here by carrying dual
//! numbers through the same right-hand side and the same Dormand-Prince
//! steps as the state (the steps chosen by the state's error alone), which
//! is the exact derivative of the discrete shot ("internal numerical
//! differentiation", H. G. Bock, "Numerical treatment of inverse problems in
//! chemical reaction kinetics", in Modelling of Chemical Reaction Systems,
//! Springer 1981, doi:10.1007/978-3-642-68220-9_8; the dual numbers are
//! the `num-dual` crate's). The same shot gives `g_l0`, so the pole stretch
//! is found by Newton's method from a nearby start (the last solution at this
//! pressure) in two or three shots.

use nalgebra::{Const, SVector, U1};
use num_dual::{Derivative, DualNum, DualSVec64, DualStruct};

use super::law::Law;
use super::ode::{self, Settings};
use super::shoot::{Membrane, Reference};
use super::{AxisymError, Options};
use crate::experiment::Specimen;
use crate::material::Material;

/// Directions carried by the dual numbers of a gradient: the pole stretch
/// and at most `DIRS - 1` parameters of the law.
pub const DIRS: usize = 8;

/// Newton iterations on the pole stretch at most.
const NEWTON_ITERATIONS: usize = 12;

/// A Newton step below this share of the pole strain ends the iteration
/// (taken to first order, see [`newton`]).
const ACCEPT: f64 = 1e-6;

/// A state of four dual numbers packed into plain numbers for the
/// integrator: the four values first (they alone drive the step size),
/// then the derivatives.
pub(crate) trait Packed<const N: usize>: DualNum<f64> + Copy {
    /// Directions carried.
    const K: usize;
    fn pack(y: &[Self; 4]) -> [f64; N];
    fn unpack(z: &[f64; N]) -> [Self; 4];
    /// The value with derivative 1 along direction `k`.
    fn seed(v: f64, k: usize) -> Self;
    /// Derivative along direction `k`.
    fn deriv(&self, k: usize) -> f64;
}

macro_rules! packed {
    ($k:literal, $n:literal) => {
        impl Packed<$n> for DualSVec64<$k> {
            const K: usize = $k;
            fn pack(y: &[Self; 4]) -> [f64; $n] {
                let mut z = [0.0; $n];
                for (i, v) in y.iter().enumerate() {
                    z[i] = v.re;
                    let e = v.eps.clone().unwrap_generic(Const::<$k>, U1);
                    for k in 0..$k {
                        z[4 + i * $k + k] = e[k];
                    }
                }
                z
            }
            fn unpack(z: &[f64; $n]) -> [Self; 4] {
                std::array::from_fn(|i| {
                    let e = SVector::<f64, $k>::from_fn(|k, _| z[4 + i * $k + k]);
                    DualSVec64::new(z[i], Derivative::some(e))
                })
            }
            fn seed(v: f64, k: usize) -> Self {
                DualSVec64::new(
                    v,
                    Derivative::some(SVector::<f64, $k>::from_fn(
                        |j, _| {
                            if j == k { 1.0 } else { 0.0 }
                        },
                    )),
                )
            }
            fn deriv(&self, k: usize) -> f64 {
                self.eps.clone().unwrap_generic(Const::<$k>, U1)[k]
            }
        }
    };
}

packed!(1, 8);
packed!(2, 12);
packed!(3, 16);
packed!(4, 20);
packed!(6, 28);
packed!(8, 36);

/// The apex height at one pressure with its derivatives.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightGradient {
    /// Apex height above the clamp plane, m.
    pub height_m: f64,
    /// Pole stretch of the solution.
    pub pole_stretch: f64,
    /// `dh/dth_k`, m per unit of parameter `k` (the law's parameters in the
    /// order of the material's: `[E]`, the coefficients of `E(eps)`, or the
    /// hyperelastic parameters as `Hyperelastic::params` lists them); empty
    /// when only the height was asked for.
    pub gradient: Vec<f64>,
    /// `dg/dl0` at the solution, `g` the clamp residual `l2(a) - 1`: its sign
    /// tells the branch (it changes sign at a limit point).
    pub slope: f64,
    /// Shots spent.
    pub shots: usize,
}

/// One shot in dual numbers: the state at the clamp, `None` when the shot
/// does not reach it.
fn shot<T: Packed<N>, const N: usize>(
    mem: &Membrane,
    th: &[T],
    l0: T,
    pi: f64,
    rtol: f64,
) -> Option<[T; 4]> {
    let ser = mem.series_with(th, l0, pi)?;
    let k = ser.k.re();
    let x0 = 1e-3 * (1.0f64).min(1.0 / k.max(1e-300));
    let delta = l0.re() - 1.0;
    let ps = k.max(1e-300);
    let mut atol = [1e300; N];
    atol[..4].copy_from_slice(&[rtol * delta, rtol * delta, rtol * ps, rtol * ps]);
    let settings = Settings {
        rtol,
        atol,
        h0: x0,
        h_min: 1e-13,
        max_steps: mem.max_steps,
        norm_dims: 4,
    };
    let out = ode::integrate(
        |x, z| {
            let y = T::unpack(z);
            mem.rhs_with(th, pi, x, &y).map(|d| T::pack(&d))
        },
        x0,
        T::pack(&ser.at(x0)),
        mem.reference.end,
        &settings,
        |_, z| 1.0 + z[1] < 0.5 || z[2].abs() > 2.0 * std::f64::consts::PI,
        &[],
        |_, _| {},
    );
    (out.stopped.is_none() && out.x >= mem.reference.end).then(|| T::unpack(&out.y))
}

/// Newton's method on the pole stretch at load `pi` from `l0`, the law's
/// parameters seeded as directions `1..` when `T` carries them.
fn newton<T: Packed<N>, const N: usize>(
    mem: &Membrane,
    pi: f64,
    mut l0: f64,
    opts: &Options,
) -> Option<(f64, [T; 4], usize)> {
    let params = mem.law.params();
    let th: Vec<T> = params
        .iter()
        .enumerate()
        .map(|(k, &p)| {
            if k + 1 < T::K {
                T::seed(p, k + 1)
            } else {
                T::from(p)
            }
        })
        .collect();
    for it in 1..=NEWTON_ITERATIONS {
        if !(l0 > 1.0 && l0 < opts.max_pole_stretch) {
            return None;
        }
        let mut y = shot::<T, N>(mem, &th, T::seed(l0, 0), pi, opts.rel_tol)?;
        let (g, g_l0) = (y[1].re(), y[1].deriv(0));
        if !(g_l0.is_finite() && g_l0 != 0.0) {
            return None;
        }
        let step = g / g_l0;
        if step.abs() <= ACCEPT * (l0 - 1.0) {
            // The last Newton step taken to first order in the state and its
            // derivatives: their error is of order step^2, about 1e-12 of
            // the pole strain (the integration's own noise is about 1e-9).
            let dy: [T; 4] = std::array::from_fn(|i| {
                let slope = T::from(y[i].deriv(0));
                y[i] - slope * step
            });
            y = dy;
            return Some((l0 - step, y, it));
        }
        // A step at most half the pole strain: Newton from a nearby start
        // needs no more, and a larger one leaves the branch.
        l0 -= step.clamp(-0.5 * (l0 - 1.0), 0.5 * (l0 - 1.0));
    }
    None
}

/// The height and its gradient from the state at the clamp (see the module
/// documentation).
fn gradient_of<T: DualNum<f64> + Copy + Packed<N>, const N: usize>(
    y: &[T; 4],
    n: usize,
    a: f64,
    l0: f64,
    shots: usize,
) -> HeightGradient {
    let (g_l0, d_l0) = (y[1].deriv(0), y[3].deriv(0));
    HeightGradient {
        height_m: a * y[3].re(),
        pole_stretch: l0,
        gradient: (1..=n)
            .map(|k| a * (y[3].deriv(k) - d_l0 * y[1].deriv(k) / g_l0))
            .collect(),
        slope: g_l0,
        shots,
    }
}

/// The apex height at `pressure_pa` and its derivatives with respect to the
/// law's parameters, by Newton's method on the pole stretch from `l0_start`
/// (a solution at a nearby pressure or law; [`super::solve_pressure`] gives
/// one). `gradient` asks for the derivatives (the law may have at most
/// [`DIRS`]` - 1` parameters); without it only the height is found, more
/// cheaply. Fails when Newton does not converge from that start (no
/// equilibrium nearby, or a start too far off): the caller then solves
/// from scratch.
pub fn height_gradient(
    material: &Material,
    specimen: &Specimen,
    pressure_pa: f64,
    l0_start: f64,
    gradient: bool,
    opts: &Options,
) -> Result<HeightGradient, AxisymError> {
    specimen.validate().map_err(AxisymError::Specimen)?;
    opts.validate()?;
    let mem = Membrane {
        law: Law::new(material)?,
        max_steps: opts.max_steps,
        reference: Reference::of(specimen),
    };
    let n = mem.law.params().len();
    if gradient && n + 1 > DIRS {
        return Err(AxisymError::Options(format!(
            "the {} law has {n} parameters; the exact gradient carries at most {}",
            material.model.name(),
            DIRS - 1
        )));
    }
    let pi = pressure_pa * specimen.radius_m / specimen.thickness_m;
    let fail = || {
        AxisymError::NoConvergence(format!(
            "Newton on the pole stretch from {l0_start} did not converge at {pressure_pa} Pa"
        ))
    };
    let a = specimen.radius_m;
    if gradient {
        // As few directions as the law has parameters (plus the pole
        // stretch): the cost of a shot grows with them.
        macro_rules! with {
            ($k:literal, $n:literal) => {
                newton::<DualSVec64<$k>, $n>(&mem, pi, l0_start, opts)
                    .map(|(l0, y, shots)| gradient_of(&y, n, a, l0, shots))
            };
        }
        let found = match n + 1 {
            2 => with!(2, 12),
            3 => with!(3, 16),
            4 => with!(4, 20),
            5 | 6 => with!(6, 28),
            _ => with!(8, 36),
        };
        found.ok_or_else(fail)
    } else {
        let (l0, y, shots) =
            newton::<DualSVec64<1>, 8>(&mem, pi, l0_start, opts).ok_or_else(fail)?;
        Ok(HeightGradient {
            height_m: a * y[3].re(),
            pole_stretch: l0,
            gradient: Vec::new(),
            slope: y[1].deriv(0),
            shots,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Model, StrainMeasure};

    fn specimen() -> Specimen {
        Specimen::latex()
    }

    /// One of every model `bulge fit` writes, with the parameters set out
    /// in the order of the gradient.
    fn laws() -> Vec<(Material, f64)> {
        let m = |model| Material {
            model,
            poisson: 0.45,
            fit: None,
        };
        vec![
            (m(Model::Linear { young_pa: 1.0e6 }), 5000.0),
            (
                m(Model::Quartic {
                    coefficients_pa: vec![1.2e6, -1.5e6, 2.0e6, 1.0e6, -0.5e6],
                    strain_range: [0.0, 0.5],
                    strain_measure: StrainMeasure::Engineering,
                }),
                5000.0,
            ),
            (
                m(Model::Quartic {
                    coefficients_pa: vec![1.2e6, -1.0e6, 1.5e6],
                    strain_range: [0.0, 0.4],
                    strain_measure: StrainMeasure::Log,
                }),
                5000.0,
            ),
            (m(Model::NeoHookean { c1_pa: 0.2e6 }), 3000.0),
            (
                m(Model::MooneyRivlin {
                    c1_pa: 0.18e6,
                    c2_pa: 0.02e6,
                }),
                3000.0,
            ),
            (
                m(Model::Yeoh {
                    c1_pa: 0.18e6,
                    c2_pa: -2.0e3,
                    c3_pa: 50.0,
                }),
                3000.0,
            ),
            (
                m(Model::Ogden {
                    mu_pa: vec![0.4e6, 1.0e3, -6.0e3],
                    alpha: vec![1.3, 5.0, -2.0],
                }),
                3000.0,
            ),
            (
                m(Model::Gent {
                    mu_pa: 0.35e6,
                    jm: 80.0,
                }),
                3000.0,
            ),
        ]
    }

    /// The material with parameter `k` (in the gradient's order) moved by `h`.
    fn moved(m: &Material, k: usize, h: f64) -> Material {
        let mut m = m.clone();
        match &mut m.model {
            Model::Linear { young_pa } => *young_pa += h,
            Model::Quartic {
                coefficients_pa, ..
            } => coefficients_pa[k] += h,
            Model::NeoHookean { c1_pa } => *c1_pa += h,
            Model::MooneyRivlin { c1_pa, c2_pa } => *[c1_pa, c2_pa][k] += h,
            Model::Yeoh {
                c1_pa,
                c2_pa,
                c3_pa,
            } => *[c1_pa, c2_pa, c3_pa][k] += h,
            Model::Ogden { mu_pa, alpha } => {
                let n = mu_pa.len();
                if k < n {
                    mu_pa[k] += h
                } else {
                    alpha[k - n] += h
                }
            }
            Model::Gent { mu_pa, jm } => *[mu_pa, jm][k] += h,
        }
        m
    }

    /// On every material model, the exact height and its gradient agree with
    /// the plain solve and with central differences of plain solves (to
    /// 2e-8 of the derivative; the differences themselves are good to about
    /// that).
    #[test]
    fn gradient_matches_central_differences_on_every_model() {
        let opts = Options {
            n_profile: 2,
            ..Options::default()
        };
        for (m, p) in laws() {
            let sp = specimen();
            let plain = super::super::solve_pressure(&m, &sp, p, &opts).unwrap();
            // A start 2 % off in pole strain.
            let start = 1.0 + 1.02 * (plain.pole_stretch - 1.0);
            let g = height_gradient(&m, &sp, p, start, true, &opts).unwrap();
            assert!(
                (g.height_m / plain.height_m - 1.0).abs() < 1e-8,
                "{}: height {} against {}",
                m.model.name(),
                g.height_m,
                plain.height_m
            );
            let theta = Law::new(&m).unwrap().params().to_vec();
            for (k, th) in theta.iter().enumerate() {
                let h = 1e-4 * th.abs().max(1e-3);
                let hp = super::super::solve_pressure(&moved(&m, k, h), &sp, p, &opts)
                    .unwrap()
                    .height_m;
                let hm = super::super::solve_pressure(&moved(&m, k, -h), &sp, p, &opts)
                    .unwrap()
                    .height_m;
                let fd = (hp - hm) / (2.0 * h);
                // Compared on the scale of a relative change of the parameter.
                let (exact, fd_s) = (g.gradient[k] * th.abs(), fd * th.abs());
                let tol = 1e-9 * plain.height_m + 1e-6 * exact.abs();
                assert!(
                    (exact - fd_s).abs() < tol,
                    "{} parameter {k}: exact {exact:.6e}, central differences {fd_s:.6e} (m per relative change)",
                    m.model.name()
                );
            }
            // The height alone, more cheaply.
            let h = height_gradient(&m, &sp, p, start, false, &opts).unwrap();
            assert!((h.height_m / plain.height_m - 1.0).abs() < 1e-8);
            assert!(h.gradient.is_empty() && h.slope.signum() == g.slope.signum());
        }
    }

    /// Past the limit point there is no equilibrium: Newton says so instead
    /// of returning a height.
    #[test]
    fn newton_fails_past_the_limit_point() {
        let m = Material {
            model: Model::NeoHookean { c1_pa: 0.1e6 },
            poisson: 0.45,
            fit: None,
        };
        let opts = Options::default();
        assert!(height_gradient(&m, &specimen(), 50_000.0, 1.3, true, &opts).is_err());
    }
}
