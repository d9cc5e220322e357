//! Symplectic (semi-implicit) Euler: `v += h a(x, v); x += h v`, the
//! position updated with the new velocity; symplectic when undamped.

use nalgebra::{Point3, Vector3};

use super::{DynError, Dynamics, Step, StepCost};

/// Symplectic Euler with its force buffer.
pub(super) struct SymplecticEuler {
    f: Vec<Vector3<f64>>,
}

impl SymplecticEuler {
    /// A stepper for `n` nodes.
    pub(super) fn new(n: usize) -> SymplecticEuler {
        SymplecticEuler {
            f: vec![Vector3::zeros(); n],
        }
    }
}

impl Step for SymplecticEuler {
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
            v[i] += self.f[i] * (h * d.inv_mass[i]);
            x[i] += v[i] * h;
        }
        Ok(StepCost::forces(1))
    }
}
