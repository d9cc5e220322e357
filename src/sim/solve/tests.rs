//! The static solvers on a clamped disc against Hencky's small-deflection
//! solution and against each other, and their building blocks on a
//! single triangle.

use nalgebra::{Point3, Vector3};

use super::*;
use crate::material::{Material, Model};
use crate::sim::mesh::{self, Constraint, DiscOptions, Mesh};
use crate::sim::springs::SpringModel;

const A: f64 = 0.0375;
const T: f64 = 0.35e-3;
const E: f64 = 1.0e6;
const NU: f64 = 0.45;
/// Hencky's coefficient K(0.45) of `w0 = K a (p a / (E t))^(1/3)`
/// (Hencky 1915, with Chien's 1948 correction; the scene module's tests
/// integrate the membrane equations to the same five digits).
const K_HENCKY: f64 = 0.61117;

fn material() -> Material {
    Material {
        model: Model::Linear { young_pa: E },
        poisson: NU,
        fit: None,
    }
}

fn disc(rings: usize) -> Mesh {
    mesh::disc(DiscOptions {
        radius_m: A,
        rings,
        sector: true,
    })
    .unwrap()
}

/// The pressure of Hencky's apex height `w0`, Pa.
fn hencky_pressure(w0: f64) -> f64 {
    (w0 / (K_HENCKY * A)).powi(3) * E * T / A
}

/// A paraboloid of apex height `w0` on the rest disc.
fn paraboloid(m: &Mesh, w0: f64) -> Vec<Point3<f64>> {
    m.nodes
        .iter()
        .map(|p| {
            let r2 = (p.x * p.x + p.y * p.y) / (A * A);
            Point3::new(p.x, p.y, w0 * (1.0 - r2).max(0.0))
        })
        .collect()
}

fn apex(m: &Mesh, x: &[Point3<f64>]) -> f64 {
    x[m.probe("apex").unwrap_or(0)].z
}

/// Newton at w0/a = 0.02 (small deflection, 8 rings in the sector):
/// the apex is Hencky's within 1 % (the mesh's error at this size, 0.3 %,
/// and the moderate-rotation terms Hencky drops),
/// and the residual is below the tolerance.
#[test]
fn newton_matches_hencky_on_a_small_disc() {
    let m = disc(8);
    let mut mem = Membrane::new(&m, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    let w0 = 0.02 * A;
    let p = hencky_pressure(w0);
    let mut x = paraboloid(&m, 0.7 * w0);
    let s = newton(&mut mem, &mut x, p, &Options::default()).unwrap();
    assert!(s.residual <= 1e-8, "{s:?}");
    let w = apex(&m, &x);
    eprintln!(
        "apex {w:.6e}, Hencky {w0:.6e}: {:+.3} %",
        (w / w0 - 1.0) * 100.0
    );
    assert!((w / w0 - 1.0).abs() < 0.01, "apex {w} vs Hencky {w0}");
}

/// A full disc of 10 000 nodes at 5 kPa (inflated from flat by
/// continuation), TP MSS and Van Gelder: the step solved through the
/// single-precision factors of the tangent's symmetric part gives the
/// equilibrium the LU of the whole tangent gives (same discrete
/// equations: heights within 1e-9), with no LU, and holds at most
/// 3.5 kB a node (2.4 kB measured; the LU of the whole tangent took
/// about 27 kB a node of the process's memory on a 4e4-node disc).
#[test]
fn the_preconditioned_step_solves_a_large_disc_in_little_memory() {
    let m = mesh::disc(DiscOptions {
        radius_m: A,
        rings: 58,
        sector: false,
    })
    .unwrap();
    assert!(m.nodes.len() >= PAR_MIN_NODES, "{}", m.nodes.len());
    for model in [SpringModel::Tp, SpringModel::VanGelder] {
        let mut heights = Vec::new();
        for lu in [false, true] {
            let mut mem = Membrane::new(&m, model, &material(), T, 1100.0).unwrap();
            let mut ws = NewtonWorkspace::new(&mem);
            if lu {
                ws.solver.use_lu_only();
            }
            let mut x = m.nodes.clone();
            let mut wso = Some(ws);
            continuation(
                &mut mem,
                &m.nodes,
                &mut x,
                0.0,
                5000.0,
                Solver::Newton,
                &Options::default(),
                &crate::sim::scene::DiscPredictor {
                    radius_m: A,
                    young_pa: E,
                    thickness_m: T,
                    poisson: NU,
                },
                &mut wso,
            )
            .unwrap();
            let ws = wso.unwrap();
            let st = ws.linear_stats();
            if lu {
                assert_eq!((st.single, st.double), (0, 0), "{st:?}");
            } else {
                assert!(st.single > 0 && st.lu == 0, "{model:?}: {st:?}");
                let per_node = ws.bytes() as f64 / m.nodes.len() as f64;
                eprintln!("{model:?}: {st:?}, {per_node:.0} bytes a node");
                assert!(per_node < 3500.0, "{per_node} bytes a node");
            }
            heights.push(apex(&m, &x));
        }
        let rel = (heights[0] / heights[1] - 1.0).abs();
        assert!(rel < 1e-9, "{model:?}: {heights:?}");
        assert!(heights[0] > 0.015 && heights[0] < 0.03, "{heights:?}");
    }
}

/// Dynamic relaxation reaches the Newton solution from the same guess
/// (to its tolerance).
#[test]
fn dynamic_relaxation_agrees_with_newton() {
    let m = disc(6);
    let w0 = 0.05 * A;
    let p = hencky_pressure(w0);
    let opts = Options {
        tolerance: 1e-7,
        ..Options::default()
    };
    let mut mem = Membrane::new(&m, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    let mut xn = paraboloid(&m, 0.8 * w0);
    newton(&mut mem, &mut xn, p, &opts).unwrap();
    let mut xd = paraboloid(&m, 0.8 * w0);
    let s = dynamic_relaxation(&mut mem, &mut xd, p, &opts).unwrap();
    assert!(s.residual <= 1e-7 && s.iterations > 0, "{s:?}");
    let (wn, wd) = (apex(&m, &xn), apex(&m, &xd));
    eprintln!("DR {wd:.9e} ({} steps), Newton {wn:.9e}", s.iterations);
    assert!((wd / wn - 1.0).abs() < 1e-6, "DR {wd} vs Newton {wn}");
    let dmax = xn
        .iter()
        .zip(&xd)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(dmax < 1e-5 * wn, "largest node difference {dmax}");
}

/// A predictor that starts every solve from a paraboloid near Hencky's
/// apex (not the library's predictor, to keep the test independent).
struct Paraboloid;

impl Predictor for Paraboloid {
    fn predict(&self, rest: &[Point3<f64>], x: &mut [Point3<f64>], _p0: f64, p1: f64) {
        let w0 = K_HENCKY * A * (p1 * A / (E * T)).cbrt();
        for (xi, r) in x.iter_mut().zip(rest) {
            let r2 = (r.x * r.x + r.y * r.y) / (A * A);
            *xi = Point3::new(r.x, r.y, 0.9 * w0 * (1.0 - r2).max(0.0));
        }
    }
}

/// Continued over rising pressures, the apex rises, every solve meets
/// the tolerance, and at small deflection the heights follow Hencky's
/// `p^(1/3)`.
#[test]
fn continuation_is_monotone_in_pressure() {
    let m = disc(6);
    let mut mem = Membrane::new(&m, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    let mut x = m.nodes.clone();
    let mut ws = None;
    let mut p0 = 0.0;
    let mut heights = Vec::new();
    let pressures = [0.5, 1.0, 2.0, 4.0, 8.0];
    for &p in &pressures {
        let s = continuation(
            &mut mem,
            &m.nodes,
            &mut x,
            p0,
            p,
            Solver::Newton,
            &Options::default(),
            &Paraboloid,
            &mut ws,
        )
        .unwrap();
        assert!(s.residual <= 1e-8, "{p} Pa: {s:?}");
        heights.push(apex(&m, &x));
        p0 = p;
    }
    eprintln!("heights {heights:?}");
    for w in heights.windows(2) {
        assert!(w[1] > w[0], "{heights:?}");
        // doubling the pressure: 2^(1/3), to the moderate-rotation
        // terms (w0/a = 0.023-0.058 here)
        assert!(
            (w[1] / w[0] / 2f64.cbrt() - 1.0).abs() < 2e-3,
            "{heights:?}"
        );
    }
}

/// A failed pressure step is halved, then reported with the last
/// pressure solved; `x` keeps that equilibrium.
#[test]
fn continuation_reports_the_last_equilibrium() {
    let m = disc(4);
    let mut mem = Membrane::new(&m, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    let mut x = m.nodes.clone();
    let mut ws = None;
    // one Newton iteration and no halving cannot solve from the flat disc
    let opts = Options {
        newton_iterations: 1,
        max_halvings: 0,
        ..Options::default()
    };
    let e = continuation(
        &mut mem,
        &m.nodes,
        &mut x,
        0.0,
        100.0,
        Solver::Newton,
        &opts,
        &Stay,
        &mut ws,
    )
    .unwrap_err();
    match e {
        SimError::NoEquilibrium {
            pressure_pa,
            last_pressure_pa,
            ..
        } => {
            assert_eq!(pressure_pa, 100.0);
            assert_eq!(last_pressure_pa, 0.0);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(x, m.nodes);
}

/// One triangle with a single degree of freedom (a node sliding on the
/// line of a linear spring): Newton lands on `F / k_eff`
/// (`k_eff = 5/4 E t sqrt(3)/4` for Lloyd springs, see the dynamics
/// tests) in a few iterations.
#[test]
fn newton_solves_a_linear_spring() {
    let l = 0.01;
    let d = Vector3::new(0.5, 0.5 * 3f64.sqrt(), 0.0);
    let m = Mesh::new(
        vec![
            Point3::origin(),
            Point3::new(l, 0.0, 0.0),
            Point3::from(d * l),
        ],
        vec![[0, 1, 2]],
        vec![Constraint::Fixed, Constraint::Fixed, Constraint::Line(d)],
    )
    .unwrap();
    let mut mem = Membrane::new(&m, SpringModel::Lloyd, &material(), T, 1100.0).unwrap();
    let k_eff = 1.25 * E * T * 3f64.sqrt() / 4.0;
    let s_want = 1e-6 * l;
    mem.node_loads = vec![(2, d * (k_eff * s_want))];
    let mut x = m.nodes.clone();
    let s = newton(&mut mem, &mut x, 0.0, &Options::default()).unwrap();
    assert!(s.iterations <= 3, "{s:?}");
    let got = (x[2] - m.nodes[2]).dot(&d);
    assert!((got / s_want - 1.0).abs() < 1e-5, "{got} vs {s_want}");
    assert!((x[2] - m.nodes[2] - d * got).norm() < 1e-12 * l);
}

/// The load's norm: each vertex of a triangle carries `p |T| / 3` along
/// its normal; nodal loads add; clamped nodes carry nothing.
#[test]
fn load_norm_of_one_triangle() {
    let nodes = vec![
        Point3::origin(),
        Point3::new(2.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let free = Mesh::new(nodes.clone(), vec![[0, 1, 2]], vec![Constraint::Free; 3]).unwrap();
    let mut mem = Membrane::new(&free, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    mem.pressure_pa = 3.0;
    let mut scratch = vec![Vector3::zeros(); 3];
    // |T| = 1: each node p/3 = 1 N along +z
    let n = load_norm(&mem, &nodes, &mut scratch);
    assert!((n - 3f64.sqrt()).abs() < 1e-12, "{n}");
    assert!((scratch[1] - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    mem.node_loads = vec![(0, Vector3::new(0.0, 0.0, 1.0))];
    let n = load_norm(&mem, &nodes, &mut scratch);
    assert!((n - 6f64.sqrt()).abs() < 1e-12, "{n}");
    let clamped = Mesh::new(
        nodes.clone(),
        vec![[0, 1, 2]],
        vec![Constraint::Fixed, Constraint::Fixed, Constraint::Free],
    )
    .unwrap();
    let mut mem = Membrane::new(&clamped, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    mem.pressure_pa = 3.0;
    assert!((load_norm(&mem, &nodes, &mut scratch) - 1.0).abs() < 1e-12);
}

/// Free directions per constraint (3, 2, 1, 0) and the pattern of one
/// triangle (every pair of its degrees of freedom).
#[test]
fn dofs_and_pattern_of_one_triangle() {
    let nodes = vec![
        Point3::origin(),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(1.0, 1.0, 0.0),
    ];
    let cons = vec![
        Constraint::Free,
        Constraint::Plane(Vector3::z()),
        Constraint::Line(Vector3::x()),
        Constraint::Fixed,
    ];
    let m = Mesh::new(nodes, vec![[0, 1, 2], [1, 3, 2]], cons).unwrap();
    let mem = Membrane::new(&m, SpringModel::Tp, &material(), T, 1100.0).unwrap();
    let dofs = Dofs::new(&mem);
    assert_eq!(dofs.len, 6);
    assert_eq!(dofs.start, vec![0, 3, 5, 6]);
    for (b, c) in dofs.basis.iter().zip(&m.constraints) {
        for (i, u) in b.iter().enumerate() {
            assert!((u.norm() - 1.0).abs() < 1e-12);
            assert!((c.project(*u) - u).norm() < 1e-12);
            for w in &b[..i] {
                assert!(u.dot(w).abs() < 1e-12);
            }
        }
    }
    // nodes 0, 1, 2 share a triangle: all 6 free directions couple
    let p = pattern(&mem, &dofs);
    assert_eq!(p.row_idx().len(), 36);
}

#[test]
fn options_and_solver_names() {
    assert!(Options::default().validate().is_ok());
    for tol in [0.0, 1.0, f64::NAN, -1e-3] {
        let o = Options {
            tolerance: tol,
            ..Options::default()
        };
        assert!(o.validate().is_err(), "{tol}");
    }
    let o = Options {
        newton_iterations: 0,
        ..Options::default()
    };
    assert!(o.validate().is_err());
    for s in [Solver::Newton, Solver::Dr] {
        assert_eq!(Solver::parse(s.name()), Some(s));
    }
    assert_eq!(Solver::parse("gauss"), None);
}
