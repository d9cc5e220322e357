//! Tests of `springs`.

use super::*;
use crate::material::{Model, StrainMeasure};
use crate::sim::mesh::{self, DiscOptions};

fn linear(e: f64, nu: f64) -> Material {
    Material {
        model: Model::Linear { young_pa: e },
        poisson: nu,
        fit: None,
    }
}

fn perturbed_disc() -> (Mesh, Vec<Point3<f64>>) {
    let m = mesh::disc(DiscOptions {
        radius_m: 1.0,
        rings: 4,
        sector: false,
    })
    .unwrap();
    // a deterministic, non-uniform deformation with stretch and rotation
    let x: Vec<Point3<f64>> = m
        .nodes
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let s = (i as f64 * 0.7).sin();
            Point3::new(
                p.x * 1.05 + 0.02 * s,
                p.y * 0.98 + 0.03 * p.x * p.x,
                0.2 * (1.0 - p.x * p.x - p.y * p.y) + 0.01 * (i as f64 * 1.3).cos(),
            )
        })
        .collect();
    (m, x)
}

/// Van Gelder and Lloyd springs are minus the gradient of their energy.
#[test]
fn van_gelder_and_lloyd_forces_are_energy_gradients() {
    let (m, x) = perturbed_disc();
    for model in [SpringModel::VanGelder, SpringModel::Lloyd] {
        let mem = Membrane::new(&m, model, &linear(2.0e6, 0.3), 1e-3, 1100.0).unwrap();
        let mut f = vec![Vector3::zeros(); x.len()];
        mem.forces(&x, &mut f).unwrap();
        let mut g = vec![Vector3::zeros(); x.len()];
        mem.forces_by_triangle(&x, &mut g).unwrap();
        let scale = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for i in 0..x.len() {
            assert!(
                (f[i] - g[i]).norm() < 1e-12 * scale,
                "fast and triangle paths differ"
            );
            for c in 0..3 {
                let h = 1e-6;
                let mut xp = x.clone();
                xp[i][c] += h;
                let mut xm = x.clone();
                xm[i][c] -= h;
                let du =
                    (mem.spring_energy(&xp).unwrap() - mem.spring_energy(&xm).unwrap()) / (2.0 * h);
                assert!(
                    (f[i][c] + du).abs() < 1e-6 * scale,
                    "{model:?} node {i} dir {c}: force {} vs -dU/dx {}",
                    f[i][c],
                    -du
                );
            }
        }
    }
}

/// The TP force form equals eq 10 (the paper's form with sines, before its
/// trigonometric rewriting into eq 11) times the extension, wherever the
/// side strain is not zero; and tp-paper agrees with it there.
#[test]
fn tp_force_form_equals_eq10_times_extension() {
    let nu = 0.45;
    let (e, t) = (3.0e6, 2e-3);
    // one acute triangle, deformed in 3D
    let p0 = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.1, 0.0),
        Point3::new(0.4, 0.9, 0.0),
    ];
    let p = [
        Point3::new(0.01, -0.02, 0.03),
        Point3::new(1.12, 0.08, -0.05),
        Point3::new(0.38, 1.01, 0.1),
    ];
    let m = Mesh::new(p0.to_vec(), vec![[0, 1, 2]], vec![Constraint::Free; 3]).unwrap();
    let side = |q: &[Point3<f64>; 3], k: usize| (q[SIDE[k].1] - q[SIDE[k].0]).norm();
    let area = |q: &[Point3<f64>; 3]| (q[1] - q[0]).cross(&(q[2] - q[0])).norm() / 2.0;
    let (a0, a) = (area(&p0), area(&p));
    // angles at the vertices of the rest triangle (alpha opposite side 0)
    let ang = |k: usize| {
        let u = p0[(k + 1) % 3] - p0[k];
        let v = p0[(k + 2) % 3] - p0[k];
        u.angle(&v)
    };
    let q: Vec<f64> = (0..3)
        .map(|k| {
            let (x0, x) = (side(&p0, k), side(&p, k));
            let eps_t = (x - x0) / x0;
            let (h0, h) = (2.0 * a0 / x0, 2.0 * a / x);
            (h - h0) / h0 + nu * eps_t
        })
        .collect();
    for model in [SpringModel::Tp, SpringModel::TpPaper] {
        let mem = Membrane::new(&m, model, &linear(e, nu), t, 1000.0).unwrap();
        for k in 0..3 {
            let (x0, x) = (side(&p0, k), side(&p, k));
            let eps_t = (x - x0) / x0;
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let s = |m: usize| ang(m).sin();
            let l0 = |m: usize| side(&p0, m);
            // eq 10 for side k (the minus sign on side k itself)
            let num = -l0(k) * q[k] * s(k) + l0(i) * q[i] * s(i) + l0(j) * q[j] * s(j);
            let kk = e * t / (1.0 - nu * nu) * num / (4.0 * l0(k) * eps_t * s(i) * s(j));
            let want = kk * (x - x0);
            // the tension of side k recovered from the nodal forces
            let tens = tensions(&mem, &p);
            assert!(
                (tens[k] - want).abs() < 1e-9 * want.abs(),
                "{model:?} side {k}: {} vs {want}",
                tens[k]
            );
        }
    }
}

/// Spring tensions of a one-triangle membrane from its local forces: the
/// force on vertex i is sum over its two sides of T_s * unit(side).
fn tensions(mem: &Membrane, p: &[Point3<f64>; 3]) -> [f64; 3] {
    let f = mem.local(&mem.tris[0], p).unwrap();
    // vertex 0 sees sides 1 (to vertex 2... ) and 2 (to vertex 1)
    let u = |i: usize, j: usize| (p[j] - p[i]).normalize();
    let mut out = [0.0; 3];
    for (k, out_k) in out.iter_mut().enumerate() {
        // vertex k+1 holds side k (towards k+2) and side k+2 (towards k)
        let (vi, vj, vo) = ((k + 1) % 3, (k + 2) % 3, k);
        let a = u(vi, vj);
        let b = u(vi, vo);
        // f_vi = T_k a + T_other b; solve the 2x2 normal equations
        let fv = f[vi];
        let (aa, ab, bb) = (a.dot(&a), a.dot(&b), b.dot(&b));
        let (fa, fb) = (fv.dot(&a), fv.dot(&b));
        let det = aa * bb - ab * ab;
        *out_k = (fa * bb - fb * ab) / det;
    }
    out
}

/// Under uniform equibiaxial stretch the TP force is eq 16 times the
/// extension; for an equilateral triangle at nu = 1/3 that is Lloyd's
/// sqrt(3)/4 E t.
#[test]
fn tp_equibiaxial_reduces_to_eq16_and_lloyd() {
    let s3 = 3f64.sqrt();
    let p0 = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.5, s3 / 2.0, 0.0),
    ];
    let m = Mesh::new(p0.to_vec(), vec![[0, 1, 2]], vec![Constraint::Free; 3]).unwrap();
    let (e, t, nu) = (1.0e6, 1e-3, 1.0 / 3.0);
    let eps = 0.01;
    let p = p0.map(|q| Point3::from(q.coords * (1.0 + eps)));
    for model in [SpringModel::Tp, SpringModel::TpPaper, SpringModel::Lloyd] {
        let mem = Membrane::new(&m, model, &linear(e, nu), t, 1000.0).unwrap();
        let tens = tensions(&mem, &p);
        let lloyd = s3 / 4.0 * e * t * eps;
        for tk in tens {
            assert!(
                (tk - lloyd).abs() < 1e-9 * lloyd,
                "{model:?}: {tk} vs {lloyd}"
            );
        }
    }
}

#[test]
fn bad_poisson_and_modulus_are_refused() {
    let m = mesh::disc(DiscOptions {
        radius_m: 1.0,
        rings: 2,
        sector: true,
    })
    .unwrap();
    for nu in [0.5, -0.1, f64::NAN] {
        let e = Membrane::new(&m, SpringModel::Tp, &linear(1e6, nu), 1e-3, 1000.0).unwrap_err();
        assert!(e.to_string().contains("poisson"), "{e}");
    }
    let e = Membrane::new(&m, SpringModel::Tp, &linear(-1.0, 0.3), 1e-3, 1000.0).unwrap_err();
    assert!(e.to_string().contains("young_pa"), "{e}");
    // a quartic law that turns negative at strain 0.2 within its range
    let q = Material {
        model: Model::Quartic {
            coefficients_pa: vec![1.0e6, -5.0e6],
            strain_range: [0.0, 0.5],
            strain_measure: StrainMeasure::Engineering,
        },
        poisson: 0.45,
        fit: None,
    };
    let mem = Membrane::new(&m, SpringModel::Tp, &q, 1e-3, 1000.0).unwrap();
    let x: Vec<Point3<f64>> = m
        .nodes
        .iter()
        .map(|p| Point3::from(p.coords * 1.3))
        .collect();
    let mut f = vec![Vector3::zeros(); x.len()];
    let err = mem.forces(&x, &mut f).unwrap_err();
    match err {
        SimError::NonPositiveModulus {
            strain, young_pa, ..
        } => {
            assert!((strain - 0.3).abs() < 1e-9, "{strain}");
            assert!((young_pa - (1.0e6 - 5.0e6 * 0.3)).abs() < 1e-3);
        }
        other => panic!("{other}"),
    }
}

/// Quartic law held at its end values outside the fitted range.
#[test]
fn quartic_is_clamped_to_its_range() {
    let law = ModulusLaw::Quartic {
        coefficients_pa: vec![1.0e6, 2.0e6, 0.0, 0.0, 1.0e7],
        range: [0.05, 0.4],
        measure: StrainMeasure::Engineering,
    };
    let at = |e: f64| 1.0e6 + 2.0e6 * e + 1.0e7 * e.powi(4);
    assert_eq!(law.young(1.0).1, at(0.05));
    assert_eq!(law.young(1.9).1, at(0.4));
    assert!((law.young(1.2).1 - at(0.2)).abs() < 1e-6);
}
