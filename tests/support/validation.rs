//! Shared helpers of the validation tests and the convergence-table example:
//! the sphere segment of Tudruj et al. (2023, section 4) and the clamped disc
//! of Hencky (1915), solved from rest.
#![allow(dead_code)]

use nalgebra::Point3;

use bulge::material::{Material, Model};
use bulge::sim::mesh::{self, Corner, DiscOptions, SphereOptions};
use bulge::sim::scene::DiscPredictor;
use bulge::sim::solve::{self, Options, Solver, Stay};
use bulge::sim::springs::{Membrane, SpringModel};

/// A `linear` material.
pub fn linear(e: f64, nu: f64) -> Material {
    Material {
        model: Model::Linear { young_pa: e },
        poisson: nu,
        fit: None,
    }
}

/// Radii (mean, corner a, b, c) of Tudruj et al.'s (2023) sphere octant (R0 = 1 m,
/// nu = 0.3, corners II, I, I) at 10 kPa, for modulus `e` and thickness `t`
/// on `n` divisions.
pub fn sphere_radii(model: SpringModel, e: f64, t: f64, n: usize, solver: Solver) -> [f64; 4] {
    let m = mesh::sphere_segment(SphereOptions {
        radius_m: 1.0,
        divisions: n,
        corners: [Corner::TypeII, Corner::TypeI, Corner::TypeI],
    })
    .unwrap();
    let mut mem = Membrane::new(&m, model, &linear(e, 0.3), t, 1100.0).unwrap();
    let mut x = m.nodes.clone();
    let mut ws = None;
    solve::continuation(
        &mut mem,
        &m.nodes,
        &mut x,
        0.0,
        1.0e4,
        solver,
        &Options::default(),
        &Stay,
        &mut ws,
    )
    .unwrap();
    let r = |i: usize| x[i].coords.norm();
    let mean = x.iter().map(|p| p.coords.norm()).sum::<f64>() / x.len() as f64;
    [
        mean,
        r(m.probe("corner_a").unwrap()),
        r(m.probe("corner_b").unwrap()),
        r(m.probe("corner_c").unwrap()),
    ]
}

/// Apex height of the clamped disc (radius `a`, thickness `t`) at pressure
/// `p`, solved from rest on `rings` rings.
#[allow(clippy::too_many_arguments)]
pub fn disc_height(
    model: SpringModel,
    mat: &Material,
    a: f64,
    t: f64,
    p: f64,
    rings: usize,
    sector: bool,
    solver: Solver,
) -> f64 {
    let m = mesh::disc(DiscOptions {
        radius_m: a,
        rings,
        sector,
    })
    .unwrap();
    let mut mem = Membrane::new(&m, model, mat, t, 1100.0).unwrap();
    let mut x: Vec<Point3<f64>> = m.nodes.clone();
    let pred = DiscPredictor {
        radius_m: a,
        young_pa: mat.model.initial_young_pa(),
        thickness_m: t,
        poisson: mat.poisson,
    };
    let mut ws = None;
    solve::continuation(
        &mut mem,
        &m.nodes,
        &mut x,
        0.0,
        p,
        solver,
        &Options::default(),
        &pred,
        &mut ws,
    )
    .unwrap();
    x[0].z
}

/// Hencky's K(nu) for the clamped circular membrane, `w0 = K a (p a / (E t))^(1/3)`:
/// the published series solution of Hencky (1915), tabulated by Poisson ratio.
pub const HENCKY: [(f64, f64); 4] = [
    (0.0, 0.71832),
    (0.3, 0.65344),
    (1.0 / 3.0, 0.64478),
    (0.45, 0.61117),
];

/// The root of `f` in `[lo, hi]` by bisection (`f(lo)`, `f(hi)` of opposite signs).
pub fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
