//! Validation against independent references (paper 000 Tables 1-2 with the
//! thin-shell values of NOTES section 3; Hencky's clamped disc).

use nalgebra::Point3;

use super::mesh::{self, Corner, DiscOptions, SphereOptions};
use super::scene::DiscPredictor;
use super::solve::{self, Options, Solver, Stay};
use super::springs::{Membrane, SpringModel};
use crate::material::{Material, Model};

fn linear(e: f64, nu: f64) -> Material {
    Material {
        model: Model::Linear { young_pa: e },
        poisson: nu,
        fit: None,
    }
}

/// Radii (mean, corner a, b, c) of the sphere octant at 10 kPa.
pub(crate) fn sphere_radii(model: SpringModel, e: f64, t: f64, n: usize, solver: Solver) -> [f64; 4] {
    let m = mesh::sphere_segment(SphereOptions {
        radius_m: 1.0,
        divisions: n,
        corners: [Corner::TypeII, Corner::TypeI, Corner::TypeI],
    })
    .unwrap();
    let mut mem = Membrane::new(&m, model, &linear(e, 0.3), t, 1100.0).unwrap();
    let mut x = m.nodes.clone();
    let mut ws = None;
    solve::continuation(&mut mem, &m.nodes, &mut x, 0.0, 1.0e4, solver, &Options::default(), &Stay, &mut ws).unwrap();
    let r = |i: usize| x[i].coords.norm();
    let mean = x.iter().map(|p| p.coords.norm()).sum::<f64>() / x.len() as f64;
    [mean, r(m.probe("corner_a").unwrap()), r(m.probe("corner_b").unwrap()), r(m.probe("corner_c").unwrap())]
}

/// Apex height of the clamped disc.
pub(crate) fn disc_height(model: SpringModel, mat: &Material, a: f64, t: f64, p: f64, rings: usize, sector: bool, solver: Solver) -> f64 {
    let m = mesh::disc(DiscOptions { radius_m: a, rings, sector }).unwrap();
    let mut mem = Membrane::new(&m, model, mat, t, 1100.0).unwrap();
    let mut x: Vec<Point3<f64>> = m.nodes.clone();
    let pred = DiscPredictor {
        radius_m: a,
        young_pa: mat.model.initial_young_pa(),
        thickness_m: t,
        poisson: mat.poisson,
    };
    let mut ws = None;
    solve::continuation(&mut mem, &m.nodes, &mut x, 0.0, p, solver, &Options::default(), &pred, &mut ws).unwrap();
    x[0].z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[ignore]
    fn explore() {
        for n in [8, 16, 32] {
            for model in [SpringModel::VanGelder, SpringModel::Tp] {
                let r = sphere_radii(model, 50e6, 1e-3, n, Solver::Newton);
                eprintln!("sphere n={n} {model:?} {r:?}");
            }
        }
        let mat = linear(1.0e6, 0.3);
        // w0/a about 0.02: p a/(E t) = (0.02/0.653)^3
        let (a, t) = (1.0, 1e-3);
        let p = (0.02f64 / 0.65344).powi(3) * 1.0e6 * t / a;
        for model in SpringModel::ALL {
            for n in [4, 8, 16, 32] {
                let h = disc_height(model, &mat, a, t, p, n, true, Solver::Newton);
                let k = h / (a * (p * a / (1.0e6 * t)).cbrt());
                eprintln!("disc {model:?} n={n} K={k:.5}");
            }
        }
    }
}
