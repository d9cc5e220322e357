use super::*;
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
