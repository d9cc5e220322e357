//! The membrane model (`--model membrane`: constant-strain triangles with
//! the material's strain energy) against exact references: the clamped disc
//! against the exact axisymmetric inflation, the sphere segment against the
//! closed form of a uniformly inflated sphere, and a long rectangular window
//! at mid-length against the exact inflation of the infinite strip in plane
//! strain (docs/theory.md section 9). The tables of these checks on more
//! meshes: `cargo run --release --example membrane_validation`.

#[path = "support/validation.rs"]
mod validation;

use bulge::axisym;
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::sim::scene::{MeshSettings, MeshSize, Scene, SceneKind, disc_mesh};
use bulge::sim::{SceneSolver, SpringModel};
use validation::bisect;

fn material(model: Model) -> Material {
    Material {
        model,
        poisson: 0.45,
        fit: None,
    }
}

/// The membrane model's heights over `pressures` on `scene`'s mesh.
fn heights(scene: &Scene) -> Vec<f64> {
    let mesh = scene.build_mesh().unwrap();
    let mut s = SceneSolver::on_mesh(scene, mesh, SpringModel::Membrane).unwrap();
    let done = s
        .sweep(&scene.pressures_pa, |_, _| {})
        .map_err(|(_, stop)| stop.error)
        .unwrap();
    assert!(done.iter().all(|q| q.stats.residual <= 1e-8));
    done.iter().map(|q| q.height_m).collect()
}

fn scene(kind: SceneKind, m: &Material, pressures: &[f64], size: MeshSize) -> Scene {
    Scene {
        kind,
        thickness_m: 0.35e-3,
        pressures_pa: pressures.to_vec(),
        material: m.clone(),
        density_kg_m3: 1100.0,
        mesh: MeshSettings {
            size: Some(size),
            ..MeshSettings::default()
        },
        loads: Vec::new(),
    }
}

/// A Mooney-Rivlin latex disc (C1 0.25 MPa, C2 0.02 MPa, a 37.5 mm, t
/// 0.35 mm) at 14 pressures up to 90 % of the pressure at pole stretch 4
/// (the law has no limit point; h/a up to 1.22): on a 32-ring sector the
/// membrane is within 0.5 % of the exact heights at every pressure, and the
/// error falls with the square of the edge length (16 -> 32 rings).
#[test]
fn disc_matches_the_exact_axisymmetric_inflation() {
    let spec = Specimen {
        radius_m: 0.0375,
        thickness_m: 0.35e-3,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let mat = material(Model::MooneyRivlin {
        c1_pa: 0.25e6,
        c2_pa: 0.02e6,
    });
    let opts = axisym::Options::default();
    assert!(axisym::limit_point(&mat, &spec, &opts).unwrap().is_none());
    let top = axisym::solve_pole_stretch(&mat, &spec, 4.0, &opts)
        .unwrap()
        .pressure_pa;
    let pressures: Vec<f64> = (1..=14).map(|k| 0.9 * top * k as f64 / 14.0).collect();
    let exact: Vec<f64> = pressures
        .iter()
        .map(|&p| {
            axisym::solve_pressure(&mat, &spec, p, &opts)
                .unwrap()
                .height_m
        })
        .collect();
    let worst = |rings: usize| -> f64 {
        let sc = Scene::from_specimen(&spec, mat.clone(), pressures.clone());
        let mesh = disc_mesh(spec.radius_m, 0.0, rings, true).unwrap();
        let mut s = SceneSolver::on_mesh(&sc, mesh, SpringModel::Membrane).unwrap();
        let done = s
            .sweep(&pressures, |_, _| {})
            .map_err(|e| e.1.error)
            .unwrap();
        done.iter()
            .zip(&exact)
            .map(|(q, h)| q.height_m / h - 1.0)
            .fold(0.0_f64, |a, e| a.max(e.abs()))
    };
    let (e16, e32) = (worst(16), worst(32));
    assert!(e32 < 0.005, "32 rings: largest error {e32}");
    let order = (e16 / e32).log2();
    assert!(
        (1.7..2.3).contains(&order),
        "observed order {order} ({e16}, {e32})"
    );
}

/// The neo-Hookean sphere octant (C1 0.25 MPa, R0 50 mm) against the
/// closed form `p = 2 t P(l) / (R0 l^2)`, `P = 2 C1 (l - l^-5)`, at 0.3, 0.6
/// and 0.9 of its limit pressure (at `l = 7^(1/6)`): the mean radius within
/// 0.5 % of `l R0 - R0` on 32 divisions.
#[test]
fn sphere_segment_matches_the_closed_form() {
    let (c1, r0, t) = (0.25e6, 0.05, 0.35e-3);
    let p_of = |l: f64| 2.0 * t * 2.0 * c1 * (l - l.powi(-5)) / (r0 * l * l);
    let l_max = 7f64.powf(1.0 / 6.0);
    let pressures: Vec<f64> = [0.3, 0.6, 0.9].iter().map(|f| f * p_of(l_max)).collect();
    let sc = scene(
        SceneKind::SphereSegment { radius_m: r0 },
        &material(Model::NeoHookean { c1_pa: c1 }),
        &pressures,
        MeshSize::Nodes(33 * 34 / 2),
    );
    for (h, &p) in heights(&sc).iter().zip(&pressures) {
        let exact = r0 * (bisect(|l| p_of(l) - p, 1.0, l_max) - 1.0);
        assert!((h / exact - 1.0).abs() < 0.005, "{p} Pa: {h} vs {exact}");
    }
}

/// A rectangular window 8 times as long as wide (160 x 20 mm), quarter
/// with mirror planes, 8 cells across the half-width: the apex at
/// mid-length within 0.5 % of the infinite strip's, `p b / t = P1(l, 1) sin
/// th` with `l = th / sin th` and `h = b tan(th / 2)`, for neo-Hookean and
/// Ogden's three-term rubber, at arc half-angles 0.5, 1.0 and 1.4 rad.
#[test]
fn long_rectangle_matches_the_plane_strain_strip() {
    let (w, t) = (0.02, 0.35e-3);
    let b = w / 2.0;
    let c1 = 0.25e6;
    let (mu, alpha) = ([0.63e6, 0.0012e6, -0.01e6], [1.3, 5.0, -2.0]);
    let nh = move |l: f64| 2.0 * c1 * (l - l.powi(-3));
    let og = move |l: f64| {
        (0..3)
            .map(|i| mu[i] * (l.powf(alpha[i] - 1.0) - l.powf(-alpha[i] - 1.0)))
            .sum::<f64>()
    };
    type Law<'a> = &'a dyn Fn(f64) -> f64;
    let cases: [(Model, Law); 2] = [
        (Model::NeoHookean { c1_pa: c1 }, &nh),
        (
            Model::Ogden {
                mu_pa: mu.to_vec(),
                alpha: alpha.to_vec(),
            },
            &og,
        ),
    ];
    for (model, p1) in cases {
        let angles = [0.5f64, 1.0, 1.4];
        let pressures: Vec<f64> = angles
            .iter()
            .map(|&th| t / b * p1(th / th.sin()) * th.sin())
            .collect();
        let sc = scene(
            SceneKind::Rectangle {
                length_m: 8.0 * w,
                width_m: w,
            },
            &material(model.clone()),
            &pressures,
            MeshSize::EdgeLength(b / 8.0),
        );
        for ((h, th), p) in heights(&sc).iter().zip(angles).zip(&pressures) {
            let exact = b * (th / 2.0).tan();
            assert!(
                (h / exact - 1.0).abs() < 0.005,
                "{} at {p} Pa: {h} vs {exact}",
                model.name()
            );
        }
    }
}
