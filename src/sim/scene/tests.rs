//! Hencky's coefficient against the membrane equations, the first
//! guess, the scene file (valid and invalid) and the mesh sizing.

use std::io::Write;

use super::*;
use crate::material::Model;
use crate::sim::solve::Predictor;

/// Hencky's `K(nu)` by shooting on the Foppl-Hencky membrane equations,
/// independently of the table: with `rho = r / a`, the radial stress
/// resultant `N_r = E t (p a / (E t))^(2/3) S(rho)` and the deflection
/// `w = a (p a / (E t))^(1/3) W(rho)`, vertical equilibrium gives
/// `W' = -rho / (2 S)`, and compatibility with `N_theta = (rho S)'`
/// gives `rho S'' + 3 S' + rho / (8 S^2) = 0`, `S'(0) = 0`; the clamped
/// rim (`u = 0`) asks `(1 - nu) S(1) + S'(1) = 0`. `S(0)` is found by
/// bisection (RK4 from `rho = 1e-3` on the series
/// `S = S0 - rho^2 / (64 S0^2)`), and `K = W(0) = int_0^1 rho / (2 S)`.
fn hencky_k_by_shooting(nu: f64) -> f64 {
    let shoot = |s0: f64| -> (f64, f64) {
        let r0 = 1e-3;
        let n = 2000;
        let h = (1.0 - r0) / n as f64;
        let rhs = |r: f64, y: [f64; 3]| -> [f64; 3] {
            [
                y[1],
                -(3.0 * y[1] + r / (8.0 * y[0] * y[0])) / r,
                r / (2.0 * y[0]),
            ]
        };
        let mut y = [
            s0 - r0 * r0 / (64.0 * s0 * s0),
            -2.0 * r0 / (64.0 * s0 * s0),
            r0 * r0 / (4.0 * s0),
        ];
        let mut r = r0;
        for _ in 0..n {
            let add = |y: [f64; 3], k: [f64; 3], c: f64| std::array::from_fn(|j| y[j] + c * k[j]);
            let k1 = rhs(r, y);
            let k2 = rhs(r + h / 2.0, add(y, k1, h / 2.0));
            let k3 = rhs(r + h / 2.0, add(y, k2, h / 2.0));
            let k4 = rhs(r + h, add(y, k3, h));
            y = std::array::from_fn(|j| {
                y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
            });
            r += h;
        }
        ((1.0 - nu) * y[0] + y[1], y[2])
    };
    let (mut lo, mut hi) = (0.1, 2.0);
    let g_lo = shoot(lo).0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if (shoot(mid).0 > 0.0) == (g_lo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    shoot(0.5 * (lo + hi)).1
}

/// At the tabulated ratios the table agrees with the membrane equations
/// to its five digits (K(0.3) = 0.65344); between them the linear
/// interpolation stays within 0.25 %; outside [0, 0.5] it is clamped.
#[test]
fn hencky_k_matches_the_membrane_equations() {
    assert_eq!(hencky_k(0.3), 0.65344);
    for nu in [0.0, 0.25, 0.3, 1.0 / 3.0, 0.4, 0.45, 0.49, 0.5] {
        let k = hencky_k_by_shooting(nu);
        assert!(
            (hencky_k(nu) - k).abs() < 1e-5,
            "nu {nu}: {} vs {k}",
            hencky_k(nu)
        );
    }
    for nu in [0.05, 0.125, 0.2, 0.35, 0.47] {
        let k = hencky_k_by_shooting(nu);
        assert!(
            (hencky_k(nu) / k - 1.0).abs() < 2.5e-3,
            "nu {nu}: {} vs {k}",
            hencky_k(nu)
        );
    }
    assert_eq!(hencky_k(-0.1), hencky_k(0.0));
    assert_eq!(hencky_k(0.7), hencky_k(0.5));
    let ks: Vec<f64> = (0..=50).map(|i| hencky_k(i as f64 / 100.0)).collect();
    assert!(ks.windows(2).all(|w| w[1] < w[0]));
}

/// The first guess: Hencky's paraboloid at the first pressure (rim kept),
/// then the displacement scaled by `(p1 / p0)^(1/3)`.
#[test]
fn disc_predictor_starts_from_hencky_and_scales_by_the_cube_root() {
    let pred = DiscPredictor {
        radius_m: 0.05,
        young_pa: 2.0e6,
        thickness_m: 1e-3,
        poisson: 0.3,
    };
    let rest = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(0.025, 0.0, 0.0),
        Point3::new(0.0, 0.05, 0.0),
    ];
    let mut x = rest.clone();
    let p = 400.0;
    pred.predict(&rest, &mut x, 0.0, p);
    let w0 = 0.65344 * 0.05 * (p * 0.05 / (2.0e6 * 1e-3)).cbrt();
    assert!((x[0].z / w0 - 1.0).abs() < 1e-12, "{} vs {w0}", x[0].z);
    assert!((x[1].z / (0.75 * w0) - 1.0).abs() < 1e-12);
    assert_eq!(x[2], rest[2]);
    pred.predict(&rest, &mut x, p, 8.0 * p);
    assert!((x[0].z / (2.0 * w0) - 1.0).abs() < 1e-12);
    assert!((x[0].x - rest[0].x).abs() < 1e-15);
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::File::create(&p)
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    p
}

const DISC: &str = r#"
kind = "disc"
radius_m = 0.0375
thickness_m = 0.00035
pressure_pa = [5000, 7300.5]

[material]
model = "linear"
young_pa = 1.0e6
poisson = 0.45

[mesh]
nodes = 153
"#;

#[test]
fn reads_a_disc_scene() {
    let dir = tempfile::tempdir().unwrap();
    let s = Scene::read(write(dir.path(), "scene.toml", DISC)).unwrap();
    assert_eq!(
        s.kind,
        SceneKind::Disc {
            radius_m: 0.0375,
            dome_height_m: 0.0
        }
    );
    assert_eq!(s.thickness_m, 0.00035);
    assert_eq!(s.pressures_pa, vec![5000.0, 7300.5]);
    assert_eq!(s.material.model, Model::Linear { young_pa: 1.0e6 });
    assert_eq!(s.material.poisson, 0.45);
    assert_eq!(s.density_kg_m3, DEFAULT_DENSITY_KG_M3);
    assert_eq!(s.mesh.size, Some(MeshSize::Nodes(153)));
    assert!(s.mesh.symmetry);
    // (n + 1)(n + 2) / 2 nodes in the sector: 16 rings
    let m = s.build_mesh().unwrap();
    assert_eq!(m.nodes.len(), 153);
    // the apex is the reported height
    let mut x = m.nodes.clone();
    let apex = m.probe("apex").unwrap_or(0);
    x[apex].z = 0.012;
    assert_eq!(s.measure(&m, &x), (0.012, vec![]));
}

#[test]
fn reads_a_material_file_relative_to_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "rubber.toml",
        "model = \"linear\"\nyoung_pa = 2.0e6\npoisson = 0.49\n",
    );
    let text = "kind = \"sphere-segment\"\nradius_m = 1.0\nthickness_m = 0.001\npressure_pa = [100]\nmaterial = \"rubber.toml\"\ndensity_kg_m3 = 960\n[mesh]\ncorners = [\"I\", \"II\", \"I\"]\n";
    let s = Scene::read(write(dir.path(), "s.toml", text)).unwrap();
    assert_eq!(s.material.model, Model::Linear { young_pa: 2.0e6 });
    assert_eq!(s.density_kg_m3, 960.0);
    assert_eq!(
        s.mesh.corners,
        [Corner::TypeI, Corner::TypeII, Corner::TypeI]
    );
    assert_eq!(s.extra_columns().len(), 7);
}

/// Each broken file is refused with a message naming what is wrong.
#[test]
fn refuses_invalid_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            DISC.replace("radius_m = 0.0375", "radius_m = 0.0375\ncolour = \"red\""),
            "colour",
        ),
        (
            DISC.replace("radius_m = 0.0375", "radius_m = -0.0375"),
            "radius_m",
        ),
        (
            DISC.replace("thickness_m = 0.00035", "thickness_m = 0.0"),
            "thickness_m",
        ),
        (DISC.replace("radius_m = 0.0375", ""), "radius_m"),
        (DISC.replace("\"disc\"", "\"cube\""), "cube"),
        (DISC.replace("[5000, 7300.5]", "[5000, -1]"), "pressure 2"),
        (
            DISC.replace("[5000, 7300.5]", "[5000, \"high\"]"),
            "pressure_pa entry 2",
        ),
        (DISC.replace("poisson = 0.45", "poisson = 0.5"), "poisson"),
        (
            DISC.replace("nodes = 153", "nodes = 153\nedge_length_m = 0.002"),
            "at most one",
        ),
        (DISC.replace("nodes = 153", "accuracy = 0.7"), "accuracy"),
        (
            DISC.replace("nodes = 153", "corners = [\"I\", \"III\", \"I\"]"),
            "III",
        ),
        (
            format!("{DISC}\n[[load]]\nat = \"corner\"\nforce_n = [0.0, 0.0, -1.0]\n"),
            "sheet",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let e = Scene::read(write(dir.path(), &format!("bad{k}.toml"), text))
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "case {k}: `{needle}` not in: {e}");
    }
}

/// The elliptical and rectangular windows read, mesh at their sizes and
/// report the apex; a missing or bad size is named.
#[test]
fn reads_ellipse_and_rectangle_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let ell = DISC
        .replace("\"disc\"", "\"ellipse\"")
        .replace("radius_m = 0.0375", "semi_axes_m = [0.04, 0.02]")
        .replace("nodes = 153", "nodes = 169");
    let s = Scene::read(write(dir.path(), "e.toml", &ell)).unwrap();
    assert_eq!(
        s.kind,
        SceneKind::Ellipse {
            semi_axes_m: [0.04, 0.02]
        }
    );
    let m = s.build_mesh().unwrap();
    assert_eq!(m.nodes.len(), 169);
    let mut x = m.nodes.clone();
    x[m.probe("apex").unwrap()].z = 0.01;
    assert_eq!(s.measure(&m, &x).0, 0.01);
    let rect = DISC
        .replace("\"disc\"", "\"rectangle\"")
        .replace("radius_m = 0.0375", "length_m = 0.08\nwidth_m = 0.02")
        .replace("nodes = 153", "edge_length_m = 0.0025");
    let s = Scene::read(write(dir.path(), "r.toml", &rect)).unwrap();
    let m = s.build_mesh().unwrap();
    // the quarter: 16 x 4 cells
    assert_eq!(m.nodes.len(), 17 * 5);
    assert_eq!(m.symmetry_copies, 4);
    for (text, needle) in [
        (ell.replace("semi_axes_m = [0.04, 0.02]", ""), "semi_axes_m"),
        (
            ell.replace("[0.04, 0.02]", "[0.04, -0.02]"),
            "semi_axes_m = -0.02",
        ),
        (rect.replace("width_m = 0.02", ""), "width_m"),
    ] {
        let e = Scene::read(write(dir.path(), "bad.toml", &text))
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
}

/// An empty pressure list reads (the command line may give the
/// pressures) but does not validate when pressures are needed.
#[test]
fn empty_pressures_read_but_do_not_validate() {
    let dir = tempfile::tempdir().unwrap();
    let text = DISC.replace("[5000, 7300.5]", "[]");
    let s = Scene::read(write(dir.path(), "s.toml", &text)).unwrap();
    assert!(s.pressures_pa.is_empty());
    assert!(s.validate(false).is_ok());
    assert!(s.validate(true).unwrap_err().to_string().contains("empty"));
}

#[test]
fn parses_pressure_lists() {
    assert_eq!(
        parse_pressures("5000, 7300,8940").unwrap(),
        vec![5000.0, 7300.0, 8940.0]
    );
    assert!(
        parse_pressures("5000,abc")
            .unwrap_err()
            .to_string()
            .contains("`abc`")
    );
    assert!(
        parse_pressures("5000,-1")
            .unwrap_err()
            .to_string()
            .contains("pressure 2")
    );
    assert!(parse_pressures("").is_err());
    assert!(
        validate_pressures(&[])
            .unwrap_err()
            .to_string()
            .contains("empty")
    );
    assert!(validate_pressures(&[1.0, f64::NAN]).is_err());
}

/// The disc's rings for an accuracy: never fewer for a tighter accuracy,
/// at least 4, and the fewest whose modelled error `C n^-1.7` meets the
/// accuracy for the worst model asked for.
#[test]
fn disc_rings_for_accuracy_is_monotone_and_sufficient() {
    let mut last = 0;
    for i in 0..60 {
        let acc = 0.4 * 0.85f64.powi(i);
        let n = disc_rings_for_accuracy(acc, &[]);
        assert!(n >= last && n >= 4, "acc {acc}: {n} after {last}");
        last = n;
        let c = 0.5; // Lloyd, the worst
        if n > 4 {
            assert!(c * (n as f64).powf(-1.7) <= acc * (1.0 + 1e-12));
            assert!(c * ((n - 1) as f64).powf(-1.7) > acc);
        }
        let tp = disc_rings_for_accuracy(acc, &[SpringModel::Tp]);
        assert!(tp <= n);
    }
    assert_eq!(disc_rings_for_accuracy(0.3, &[]), 4);
    // TP MSS: C = 0.045, so 0.5 % needs ceil(9^(1/1.7)) = 4 rings, 0.1 %
    // ceil(45^(1/1.7)) = 10
    assert_eq!(disc_rings_for_accuracy(0.005, &[SpringModel::Tp]), 4);
    assert_eq!(disc_rings_for_accuracy(0.001, &[SpringModel::Tp]), 10);
}

/// The other mesh sizes of the disc: an edge length `h` gives
/// `ceil(a / h)` rings, the default 16.
#[test]
fn disc_mesh_sizes() {
    let mut s = Scene {
        kind: SceneKind::Disc {
            radius_m: 0.03,
            dome_height_m: 0.0,
        },
        thickness_m: 1e-3,
        pressures_pa: vec![],
        material: Material {
            model: Model::Linear { young_pa: 1e6 },
            poisson: 0.45,
            fit: None,
        },
        density_kg_m3: DEFAULT_DENSITY_KG_M3,
        mesh: MeshSettings::default(),
        loads: vec![],
    };
    let sector_nodes = |n: usize| (n + 1) * (n + 2) / 2;
    assert_eq!(
        s.build_mesh().unwrap().nodes.len(),
        sector_nodes(DEFAULT_DISC_RINGS)
    );
    s.mesh.size = Some(MeshSize::EdgeLength(0.0035));
    assert_eq!(s.build_mesh().unwrap().nodes.len(), sector_nodes(9));
    s.mesh.size = Some(MeshSize::Accuracy(0.001));
    assert_eq!(
        s.build_mesh_for(&[SpringModel::Tp]).unwrap().nodes.len(),
        sector_nodes(10)
    );
}
