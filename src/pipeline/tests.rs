use super::*;
use crate::Refusal;
use crate::experiment::Specimen;
use crate::material::Material;
use crate::material::Model;
use crate::mechanics::Point;

/// A neo-Hookean disc's pressure peaks at `P = 3.758347 C1 t / a`
/// (Yang & Feng 1970; see docs/theory.md): 3507.8 Pa here.
#[test]
fn pressures_above_the_measurements_and_the_limit_point_are_flagged() {
    let spec = Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let material = Material {
        model: Model::NeoHookean { c1_pa: 1.0e5 },
        poisson: 0.5,
        fit: None,
    };
    let measured: Vec<Point> = [500.0, 1000.0, 2000.0]
        .map(|p| Point {
            pressure_pa: p,
            height_m: 0.01,
            height_std_m: None,
        })
        .to_vec();
    let none = extrapolation_warnings(&spec, &material, &measured, &[500.0, 2000.0]);
    assert!(none.is_empty(), "{none:?}");
    let w = extrapolation_warnings(&spec, &material, &measured, &[1500.0, 3000.0, 3600.0]);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].starts_with("3000, 3600 Pa above the largest measured pressure (2000 Pa)"));
    assert!(
        w[1].starts_with("3600 Pa past the limit point of the fitted law (3507.79"),
        "{}",
        w[1]
    );
}

/// The one sweep of `bulge run` and `bulge simulate`: past a neo-Hookean
/// disc's limit point (Adkins and Rivlin 1952: p a / (C1 t) = 3.7583) the
/// spring model stops with one failure naming the limit, the pressures above
/// are marked untried, the rows below are kept; the axisymmetric reference
/// solves each pressure on its own; the reference on a non-circular scene is
/// refused as bad input.
#[test]
fn one_sweep_keeps_the_rows_below_a_limit_point_and_marks_the_rest() {
    use crate::sim::scene::{MeshSize, Scene};
    use crate::sim::solve::{Options, Solver};
    use crate::sim::springs::{HeightModel, SpringModel};
    let (a, t, c1) = (0.0375, 0.35e-3, 1.0e5);
    let material = Material {
        model: Model::NeoHookean { c1_pa: c1 },
        poisson: 0.49,
        fit: None,
    };
    let limit = 3.7583 * c1 * t / a;
    let spec = Specimen {
        radius_m: a,
        thickness_m: t,
        poisson: 0.49,
        prebulge_height_m: 0.0,
    };
    let pressures = vec![0.3 * limit, 0.6 * limit, 1.2 * limit, 1.3 * limit];
    let mut scene = Scene::from_specimen(&spec, material.clone(), pressures.clone());
    scene.mesh.size = Some(MeshSize::Nodes(60));
    let (mesh, sizing) = scene_mesh(
        &scene,
        &[SpringModel::Tp],
        Solver::Newton,
        Options::default(),
    )
    .unwrap();
    assert!(sizing.is_none());
    let request = SceneRequest {
        models: vec![SpringModel::Tp],
        solvers: vec![Solver::Newton],
        axisym: true,
        profile: true,
        options: Options::default(),
    };
    let ticks = std::cell::Cell::new(0);
    let mut seen = 0;
    let out = simulate_scene(&scene, &mesh, &request, &mut |_, _| seen += 1, &|| {
        ticks.set(ticks.get() + 1)
    })
    .unwrap();
    assert_eq!(ticks.get(), 8, "one tick per model and pressure");
    assert_eq!(seen, 2, "two spring equilibria");
    let [ax, tp] = &out.runs[..] else {
        panic!("two runs: {:?}", out.runs.len())
    };
    assert_eq!(ax.model, HeightModel::Axisym);
    let outcomes: Vec<Outcome> = tp.points.iter().map(|p| p.outcome).collect();
    assert_eq!(
        outcomes,
        [
            Outcome::Solved,
            Outcome::Solved,
            Outcome::Failed,
            Outcome::NotTried
        ]
    );
    assert!(tp.stop.is_some());
    let failures: Vec<&str> = tp.failures().collect();
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(failures[0].contains("limit"), "{}", failures[0]);
    // the reference: heights below the limit, none above it, each on its own
    let has: Vec<bool> = ax.points.iter().map(|p| p.height_m.is_some()).collect();
    assert_eq!(has, [true, true, false, false]);
    let last = out.axisym_last.as_ref().expect("the profile at 0.6 limit");
    assert_eq!(Some(last.height_m), ax.points[1].height_m);
    // the CSV has the solved rows only: 2 reference + 2 tp
    let csv = String::from_utf8(simulated_csv(&out.runs).into_bytes()).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4, "{csv}");

    let ellipse = Scene::from_window(
        &spec,
        &crate::experiment::Window::Ellipse {
            semi_axes_m: [a, 0.5 * a],
        },
        material,
        pressures,
    );
    let err = simulate_scene(&ellipse, &mesh, &request, &mut |_, _| {}, &|| {}).unwrap_err();
    assert!(err.is_bad_input(), "{err}");
    assert!(err.to_string().contains("circular disc only"), "{err}");
}
