//! Position Verlet (Verlet 1967), drift-kick-drift, with the dashpots split
//! off symmetrically (Strang 1968): half a step of damping, the undamped
//! `q += v h/2; v += f(q)/m h; q += v h/2`, half a step of damping. Each
//! damping half-step integrates `m v' = -C v` at fixed positions with the
//! explicit midpoint rule, so the whole step is second order with damping
//! too. (Sudhamani & Merriliance (2019) evaluate the dashpots with the
//! step's start velocity inside the kick, which is first order in the
//! damping.)
//!
//! Undamped, it advances a mode of frequency `w` by the angle
//! `2 asin(w h / 2)` per step: the period short by about `(w h)^2 / 24` of
//! itself, stable for `w h < 2`. The damping half-steps shrink velocities
//! and leave that limit as it is while `h < 4 / c` for every damping rate
//! `c` of `M^-1 C` (the midpoint rule's real-axis limit), see
//! [`super::step_limit`].

use nalgebra::{Point3, Vector3};

use super::{DynError, Dynamics, Step, StepCost};

/// Position Verlet with its force buffers.
pub(super) struct Verlet {
    f: Vec<Vector3<f64>>,
    v_mid: Vec<Vector3<f64>>,
    /// The active dashpots at the positions of the current damping
    /// half-step (both of its evaluations are at the same positions).
    pots: Vec<(usize, usize, f64, Vector3<f64>)>,
    /// Whether any dashpot acts (else the damping half-steps are skipped).
    damped: bool,
}

impl Verlet {
    /// A stepper for `n` nodes, with or without dashpots.
    pub(super) fn new(n: usize, damped: bool) -> Verlet {
        Verlet {
            f: vec![Vector3::zeros(); n],
            v_mid: vec![Vector3::zeros(); n],
            pots: Vec::new(),
            damped,
        }
    }

    /// `m v' = -C(x) v` over `tau` by the explicit midpoint rule.
    fn damp(&mut self, d: &Dynamics, x: &[Point3<f64>], v: &mut [Vector3<f64>], tau: f64) {
        self.pots.clear();
        self.pots.extend(d.dashpots(x));
        let pots = &self.pots;
        let accel = |v: &[Vector3<f64>], f: &mut [Vector3<f64>]| {
            f.iter_mut().for_each(|fi| *fi = Vector3::zeros());
            super::damping::add_dashpot_forces(pots.iter().copied(), v, f);
            d.membrane.project(f);
        };
        accel(v, &mut self.f);
        for (i, vm) in self.v_mid.iter_mut().enumerate() {
            *vm = v[i] + self.f[i] * (0.5 * tau * d.inv_mass[i]);
        }
        accel(&self.v_mid, &mut self.f);
        for (i, vi) in v.iter_mut().enumerate() {
            *vi += self.f[i] * (tau * d.inv_mass[i]);
        }
    }
}

impl Step for Verlet {
    fn step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        _t: f64,
    ) -> Result<StepCost, DynError> {
        let n = x.len();
        let damped = self.damped;
        if damped {
            self.damp(d, x, v, 0.5 * h);
        }
        for i in 0..n {
            x[i] += v[i] * (0.5 * h);
        }
        d.forces(x, &mut self.f)?;
        d.membrane.project(&mut self.f);
        for i in 0..n {
            v[i] += self.f[i] * (h * d.inv_mass[i]);
            x[i] += v[i] * (0.5 * h);
        }
        if damped {
            self.damp(d, x, v, 0.5 * h);
        }
        Ok(StepCost::forces(1))
    }
}
