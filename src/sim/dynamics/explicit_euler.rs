//! Explicit (forward) Euler: `x += h v; v += h a(x, v)`, both from the old
//! state.
//!
//! Its amplification of an undamped mode is `sqrt(1 + (w h)^2) > 1`: without
//! damping it has no stable step (see the step-limit module).

use nalgebra::{Point3, Vector3};

use super::{DynError, Dynamics, Step, StepCost};

/// Explicit Euler with its force buffer.
pub(super) struct ExplicitEuler {
    f: Vec<Vector3<f64>>,
}

impl ExplicitEuler {
    /// A stepper for `n` nodes.
    pub(super) fn new(n: usize) -> ExplicitEuler {
        ExplicitEuler {
            f: vec![Vector3::zeros(); n],
        }
    }
}

impl Step for ExplicitEuler {
    fn step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        _t: f64,
    ) -> Result<StepCost, DynError> {
        let n = x.len();
        d.total_force(x, v, &mut self.f)?;
        for i in 0..n {
            x[i] += v[i] * h;
            v[i] += self.f[i] * (h * d.inv_mass[i]);
        }
        Ok(StepCost::forces(1))
    }
}
