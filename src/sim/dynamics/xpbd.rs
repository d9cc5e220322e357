//! Position-based dynamics with compliance (XPBD; Macklin, Mueller &
//! Chentanez 2016, with their constraint damping), as section 1.4 of
//! Sudhamani & Merriliance (2019) applies it to the springs: predict with the
//! external forces, project the distance constraints `|p_i - p_j| - l0` with
//! compliance `1/k`, then velocities from positions.
//!
//! A fixed compliance per spring needs a spring model whose stiffness does
//! not depend on the other sides of its triangles (Van Gelder, Lloyd) and a
//! constant modulus; [`check`] refuses the others.

use nalgebra::{Point3, Vector3};

use super::{DynError, Dynamics, Step, StepCost};
use crate::sim::solve::load_norm;
use crate::sim::springs::SpringModel;

/// Refuses the membranes XPBD cannot integrate (see the module docs).
pub(super) fn check(d: &Dynamics) -> Result<(), DynError> {
    if !matches!(
        d.membrane.model,
        SpringModel::VanGelder | SpringModel::Lloyd
    ) {
        return Err(DynError::BadParameter(format!(
            "xpbd projects distance constraints with a fixed compliance 1/k per spring; the {} model's spring stiffness depends on the other sides of its triangles, so it has no such form: use {} van-gelder or lloyd with xpbd, or another integrator",
            d.membrane.model.name(),
            crate::setting::Setting::Model
        )));
    }
    if !d.membrane.law.is_constant() {
        return Err(DynError::BadParameter(
            "xpbd needs a constant modulus (a linear material): its compliance 1/k is fixed per spring".into(),
        ));
    }
    Ok(())
}

/// XPBD with its buffers: the positions at the step's start, the
/// constraints' multipliers and the external forces.
pub(super) struct Xpbd {
    prev: Vec<Point3<f64>>,
    lambdas: Vec<f64>,
    fext: Vec<Vector3<f64>>,
    iterations: usize,
}

impl Xpbd {
    /// A stepper from positions `x`, for `edges` springs, with `iterations`
    /// constraint iterations per step.
    pub(super) fn new(x: &[Point3<f64>], edges: usize, iterations: usize) -> Xpbd {
        Xpbd {
            prev: x.to_vec(),
            lambdas: vec![0.0; edges],
            fext: vec![Vector3::zeros(); x.len()],
            iterations,
        }
    }
}

impl Step for Xpbd {
    fn step(
        &mut self,
        d: &Dynamics,
        x: &mut [Point3<f64>],
        v: &mut [Vector3<f64>],
        h: f64,
        _t: f64,
    ) -> Result<StepCost, DynError> {
        let Xpbd {
            prev,
            lambdas,
            fext,
            iterations,
        } = self;
        let n = x.len();
        load_norm(d.membrane, x, fext);
        prev.copy_from_slice(x);
        let cons = &d.membrane.constraints;
        for i in 0..n {
            let dv = cons[i].project(v[i] * h + fext[i] * (h * h * d.inv_mass[i]));
            x[i] += dv;
        }
        lambdas.iter_mut().for_each(|l| *l = 0.0);
        for _ in 0..(*iterations).max(1) {
            for (ei, e) in d.mesh.edges.iter().enumerate() {
                let k = d.edge_k[ei];
                if k.is_nan() || k <= 0.0 {
                    continue;
                }
                let (i, j) = (e[0] as usize, e[1] as usize);
                let dd = x[i] - x[j];
                let l = dd.norm();
                if l <= 0.0 {
                    continue;
                }
                let nrm = dd / l;
                let ni = cons[i].project(nrm);
                let nj = cons[j].project(nrm);
                let wsum = ni.norm_squared() * d.inv_mass[i] + nj.norm_squared() * d.inv_mass[j];
                if wsum <= 0.0 {
                    continue;
                }
                let l0 = (d.mesh.nodes[e[1] as usize] - d.mesh.nodes[e[0] as usize]).norm();
                let alpha = 1.0 / (k * h * h);
                let gamma = d.damping[ei] / (k * h);
                let c = l - l0;
                let rate = nrm.dot(&((x[i] - prev[i]) - (x[j] - prev[j])));
                let dl = (-c - alpha * lambdas[ei] - gamma * rate) / ((1.0 + gamma) * wsum + alpha);
                lambdas[ei] += dl;
                x[i] += ni * (dl * d.inv_mass[i]);
                x[j] -= nj * (dl * d.inv_mass[j]);
            }
        }
        for i in 0..n {
            v[i] = (x[i] - prev[i]) / h;
        }
        Ok(StepCost::forces(1))
    }
}
