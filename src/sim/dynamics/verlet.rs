//! Position Verlet (Verlet 1967) as Sudhamani & Merriliance (2019) write it,
//! drift-kick-drift: `q += v h/2; F = f(q, v); v += F/m h; q += v h/2`. The
//! dashpots see the velocity at the step's start.
//!
//! Undamped, it advances a mode of frequency `w` by the angle
//! `2 asin(w h / 2)` per step: second order, the period short by about
//! `(w h)^2 / 24` of itself, stable for `w h < 2`.

use nalgebra::{Point3, Vector3};

use super::{DynError, Dynamics, Step, StepCost};

/// Position Verlet with its force buffer.
pub(super) struct Verlet {
    f: Vec<Vector3<f64>>,
}

impl Verlet {
    /// A stepper for `n` nodes.
    pub(super) fn new(n: usize) -> Verlet {
        Verlet {
            f: vec![Vector3::zeros(); n],
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
        for i in 0..n {
            x[i] += v[i] * (0.5 * h);
        }
        d.total_force(x, v, &mut self.f)?;
        for i in 0..n {
            v[i] += self.f[i] * (h * d.inv_mass[i]);
            x[i] += v[i] * (0.5 * h);
        }
        Ok(StepCost::forces(1))
    }
}
