//! The stable step of the explicit integrators: estimated by power iteration
//! and measured by bisection.
//!
//! [`Dynamics::estimate_step`] finds the stiffest mode of `M^-1 K` by power
//! iteration (matrix-free: `K v` from central differences of the forces, at
//! most 300 iterations), its damping ratio `zeta` (Rayleigh quotient of the
//! dashpots on that mode), and the most damped mode of `M^-1 C`. For a mode
//! `x'' + 2 zeta w x' + w^2 x = 0` the amplification matrices give:
//! * explicit Euler: `|1 + h lambda| < 1`, i.e. `h < 2 zeta / w` for
//!   `zeta < 1` (no stable step at all without damping), `h < 2 / (w (zeta +
//!   sqrt(zeta^2 - 1)))` above;
//! * symplectic Euler (the damping evaluated at the step's start velocity):
//!   `det = 1 - 2 zeta w h`, `trace = 2 - (w h)^2 - 2 zeta w h`, stable for
//!   `h < (2 / w) (sqrt(1 + zeta^2) - zeta)` (the classical `2 / w` undamped);
//! * position Verlet with the dashpots split off symmetrically: the step is
//!   `D V D` with `V` the undamped drift-kick-drift (`det V = 1`, `trace V =
//!   2 - (w h)^2`) and `D = diag(1, r)` half a step of damping by the midpoint
//!   rule, `r = 1 - a + a^2 / 2`, `a = zeta w h`. Then `det = r^2`, `trace =
//!   (1 + r^2)(1 - (w h)^2 / 2)`, and the step is stable for `w h <= 2` and
//!   `|r| <= 1`, i.e. `h <= min(2 / w, 4 / c)` with `c = 2 zeta w` the largest
//!   damping rate of `M^-1 C`;
//! * implicit Euler and XPBD: no step limit (they are unconditionally stable;
//!   their error grows with the step instead).
//!
//! [`measure_step_limit`] measures the limit instead: it integrates a
//! velocity along the stiffest mode and bisects on the step.

use nalgebra::{Point3, Vector3};

use super::{DynError, DynOptions, Dynamics, Integrator, StepPolicy};
use crate::sim::mesh::Constraint;

/// The stiffest and the most damped modes at a state, and the step limits
/// they set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepEstimate {
    /// Largest angular frequency `sqrt(lambda_max(M^-1 K))`, rad/s.
    pub omega_max: f64,
    /// Damping ratio of that mode.
    pub zeta: f64,
    /// Largest eigenvalue of `M^-1 C`, 1/s (twice `zeta w` of the most damped mode).
    pub damping_rate: f64,
    /// Gershgorin upper bound of `omega_max` (row sums of the triangle stiffnesses), rad/s.
    pub omega_gershgorin: f64,
    /// Power iterations used.
    pub iterations: usize,
}

impl StepEstimate {
    /// The share of [`StepEstimate::limit`] a run steps at:
    /// [`super::STEP_SAFETY`] when the stiffest mode is damped,
    /// [`super::STEP_SAFETY_UNDAMPED`] below a damping ratio of
    /// [`super::UNDAMPED_ZETA`].
    pub fn safety(&self) -> f64 {
        if self.zeta < super::UNDAMPED_ZETA {
            super::STEP_SAFETY_UNDAMPED
        } else {
            super::STEP_SAFETY
        }
    }

    /// The share of [`StepEstimate::limit`] above which a running step is
    /// split again when the step is re-estimated along the run: a margin
    /// above [`StepEstimate::safety`], so that a frequency that rises by a
    /// few per cent does not halve the step, and every change of step (which
    /// breaks Verlet's conservation of a modified energy) is rare. Without
    /// damping it stays below Verlet's resonance at `h w = sqrt(2)`.
    pub fn resplit(&self) -> f64 {
        if self.zeta < super::UNDAMPED_ZETA {
            super::STEP_RESPLIT_UNDAMPED
        } else {
            super::STEP_RESPLIT
        }
    }

    /// The stable step limit of an integrator, s (infinite for the implicit
    /// ones; 0 for explicit Euler without damping).
    pub fn limit(&self, integrator: Integrator) -> f64 {
        // `limit_of(x)`: `x / rate`, infinite when the rate is not positive
        let limit_of = |x: f64, rate: f64| if rate > 0.0 { x / rate } else { f64::INFINITY };
        let by_mode = |w: f64, z: f64| -> f64 {
            if w.is_nan() || w <= 0.0 {
                return f64::INFINITY;
            }
            if integrator == Integrator::ExplicitEuler {
                if z < 1.0 {
                    2.0 * z / w
                } else {
                    2.0 / (w * (z + (z * z - 1.0).sqrt()))
                }
            } else {
                2.0 / w * ((1.0 + z * z).sqrt() - z)
            }
        };
        match integrator {
            Integrator::ImplicitEuler | Integrator::Xpbd => f64::INFINITY,
            Integrator::Verlet => {
                limit_of(2.0, self.omega_max).min(limit_of(4.0, self.damping_rate))
            }
            Integrator::ExplicitEuler | Integrator::SymplecticEuler => {
                let stiff = by_mode(self.omega_max, self.zeta);
                // the most damped mode: its rate c = 2 zeta w; with w <=
                // omega_max its limit is at least that of w = omega_max with
                // the same c
                let damped = if self.damping_rate > 0.0 && self.omega_max > 0.0 {
                    by_mode(self.omega_max, self.damping_rate / (2.0 * self.omega_max))
                } else {
                    f64::INFINITY
                };
                stiff.min(damped)
            }
        }
    }
}

impl Dynamics<'_> {
    /// The stiffest mode at `x` by power iteration on `M^-1/2 K M^-1/2`
    /// (`K v` by central differences of the forces): its eigenvalue
    /// `omega^2`, the iterations taken and the unit mode `u` (mass-scaled).
    fn stiffest(
        &self,
        x: &[Point3<f64>],
        start: Option<&[Vector3<f64>]>,
    ) -> Result<(f64, usize, Vec<Vector3<f64>>), DynError> {
        let n = x.len();
        let m = &self.membrane;
        let sqm: Vec<f64> = m.masses.iter().map(|&mi| mi.sqrt()).collect();
        // the last mode when re-estimating along a run (it converges in a
        // few iterations), else a deterministic pseudo-random start vector
        let warm = start.is_some_and(|s| s.len() == n);
        let mut u: Vec<Vector3<f64>> = match start {
            Some(s) if warm => s.to_vec(),
            _ => (0..n)
                .map(|i| {
                    Vector3::new(
                        pseudo_random(i, 1),
                        pseudo_random(i, 2),
                        pseudo_random(i, 3),
                    )
                })
                .collect(),
        };
        let (min_it, window) = if warm { (6, 3) } else { (30, 10) };
        m.project(&mut u);
        normalise(&mut u);
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        let mut fp = vec![Vector3::zeros(); n];
        let mut fm = vec![Vector3::zeros(); n];
        let mut w = vec![Vector3::zeros(); n];
        let eps = 1e-7 * self.size_m;
        let mut lambda = 0.0;
        let mut iterations = 0;
        let mut history = Vec::new();
        for it in 0..300 {
            iterations = it + 1;
            // v = M^-1/2 u, K v by central differences, w = M^-1/2 K v
            let vmax = (0..n)
                .map(|i| (u[i] / sqm[i].max(f64::MIN_POSITIVE)).norm())
                .fold(0.0, f64::max);
            if vmax.is_nan() || vmax <= 0.0 {
                break;
            }
            let s = eps / vmax;
            for i in 0..n {
                let dv = u[i] * (s / sqm[i].max(f64::MIN_POSITIVE));
                xp[i] = x[i] + dv;
                xm[i] = x[i] - dv;
            }
            self.forces(&xp, &mut fp)?;
            self.forces(&xm, &mut fm)?;
            for i in 0..n {
                w[i] = -(fp[i] - fm[i]) / (2.0 * s) / sqm[i].max(f64::MIN_POSITIVE);
            }
            m.project(&mut w);
            lambda = (0..n).map(|i| u[i].dot(&w[i])).sum::<f64>();
            u.copy_from_slice(&w);
            if normalise(&mut u) == 0.0 {
                break;
            }
            history.push(lambda);
            if it >= min_it {
                let old = history[it - window];
                if (lambda - old).abs() <= 1e-4 * lambda.abs() {
                    break;
                }
            }
        }
        Ok((lambda, iterations, u))
    }

    /// Power-iteration estimate of the stiffest and the most damped modes at
    /// positions `x` (see the module docs).
    pub fn estimate_step(&self, x: &[Point3<f64>]) -> Result<StepEstimate, DynError> {
        self.estimate_step_from(x, None).map(|(e, _)| e)
    }

    /// [`Dynamics::estimate_step`] with the power iteration started from
    /// `start` (the stiffest mode of an earlier estimate, as returned here),
    /// for re-estimating the step along a run.
    pub fn estimate_step_from(
        &self,
        x: &[Point3<f64>],
        start: Option<&[Vector3<f64>]>,
    ) -> Result<(StepEstimate, Vec<Vector3<f64>>), DynError> {
        let n = x.len();
        let m = &self.membrane;
        let sqm: Vec<f64> = m.masses.iter().map(|&mi| mi.sqrt()).collect();
        let (lambda, iterations, u) = self.stiffest(x, start)?;
        let mut w = vec![Vector3::zeros(); n];
        let omega_max = lambda.max(0.0).sqrt();
        // damping ratio of that mode: u . M^-1/2 C M^-1/2 u / (2 w)
        let c_of = |u: &[Vector3<f64>], out: &mut [Vector3<f64>]| {
            let v: Vec<Vector3<f64>> = (0..n)
                .map(|i| u[i] / sqm[i].max(f64::MIN_POSITIVE))
                .collect();
            out.iter_mut().for_each(|o| *o = Vector3::zeros());
            // -C v: add_damping gives -C v as a force
            self.add_damping(x, &v, out);
            for i in 0..n {
                out[i] = -out[i] / sqm[i].max(f64::MIN_POSITIVE);
            }
            m.project(out);
        };
        c_of(&u, &mut w);
        let cu = (0..n).map(|i| u[i].dot(&w[i])).sum::<f64>();
        let zeta = if omega_max > 0.0 {
            cu / (2.0 * omega_max)
        } else {
            0.0
        };
        // most damped mode: power iteration on M^-1/2 C M^-1/2
        let mut damping_rate = 0.0;
        if self.damping.iter().any(|&c| c > 0.0) {
            let mut q = u.clone();
            for _ in 0..100 {
                c_of(&q, &mut w);
                damping_rate = (0..n).map(|i| q[i].dot(&w[i])).sum::<f64>();
                q.copy_from_slice(&w);
                if normalise(&mut q) == 0.0 {
                    break;
                }
            }
        }
        // Gershgorin bound
        let mut s = vec![0.0; n];
        m.stiffness_bounds(x, &mut s)?;
        let omega_gershgorin = (0..n)
            .filter(|&i| !matches!(m.constraints[i], Constraint::Fixed) && m.masses[i] > 0.0)
            .map(|i| s[i] / m.masses[i])
            .fold(0.0, f64::max)
            .sqrt();
        Ok((
            StepEstimate {
                omega_max,
                zeta,
                damping_rate: damping_rate.max(0.0),
                omega_gershgorin,
                iterations,
            },
            u,
        ))
    }

    /// A velocity field along the stiffest mode at `x` (power iteration as
    /// in [`Dynamics::estimate_step`]), scaled to a tiny amplitude: 1e-6 of
    /// the body's size per unit of `omega_max` time.
    fn stiffest_mode(&self, x: &[Point3<f64>]) -> Result<Vec<Vector3<f64>>, DynError> {
        let n = x.len();
        let sqm: Vec<f64> = self
            .membrane
            .masses
            .iter()
            .map(|&mi| mi.sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let (lambda, _, u) = self.stiffest(x, None)?;
        let omega = lambda.max(0.0).sqrt();
        let amp = 1e-6 * self.size_m * omega;
        let vmax = (0..n)
            .map(|i| (u[i] / sqm[i]).norm())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        Ok((0..n).map(|i| u[i] / sqm[i] * (amp / vmax)).collect())
    }
}

/// Largest stable step of an integrator, measured: from the state `x`
/// (normally a loaded equilibrium), a velocity along the stiffest mode found
/// by [`Dynamics::estimate_step`] is integrated for `steps` steps of `h`; the
/// step is stable when the kinetic energy at the end has not grown above its
/// start. Bisection on `h` in `[lo, hi]` to a relative width `rel_tol`.
/// Returns `None` when `hi` is still stable.
pub fn measure_step_limit(
    dynamics: &mut Dynamics,
    x: &[Point3<f64>],
    integrator: Integrator,
    lo: f64,
    hi: f64,
    steps: usize,
    rel_tol: f64,
) -> Result<Option<f64>, DynError> {
    // the stiffest mode as the start velocity
    let mode = dynamics.stiffest_mode(x)?;
    let stable = |d: &mut Dynamics, h: f64| -> Result<bool, DynError> {
        let mut xx = x.to_vec();
        let mut v: Vec<Vector3<f64>> = mode.clone();
        let ke0 = d.kinetic(&v);
        let opts = DynOptions {
            integrator,
            dt_s: h,
            t_end_s: h * steps as f64,
            policy: StepPolicy::Unchecked,
            max_samples: 2,
            ..DynOptions::default()
        };
        match d.run(&mut xx, &mut v, &opts, &|_| 0.0) {
            Ok(_) => Ok(d.kinetic(&v) <= 1.5 * ke0),
            Err(DynError::Diverged { .. }) => Ok(false),
            Err(DynError::Sim(_)) => Ok(false),
            Err(e) => Err(e),
        }
    };
    if stable(dynamics, hi)? {
        return Ok(None);
    }
    let (mut a, mut b) = (lo, hi);
    while (b - a) > rel_tol * a {
        let mid = 0.5 * (a + b);
        if stable(dynamics, mid)? {
            a = mid;
        } else {
            b = mid;
        }
    }
    Ok(Some(0.5 * (a + b)))
}

/// Scales `u` to unit norm (unless zero); returns its norm before.
fn normalise(u: &mut [Vector3<f64>]) -> f64 {
    let s = u.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    if s > 0.0 {
        u.iter_mut().for_each(|v| *v /= s);
    }
    s
}

/// A deterministic number in [-1, 1] (splitmix64 of node and component).
fn pseudo_random(i: usize, k: u64) -> f64 {
    let mut s =
        (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ k.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 31;
    s = s.wrapping_mul(0x94D0_49BB_1331_11EB);
    s ^= s >> 29;
    (s % 2001) as f64 / 1000.0 - 1.0
}
