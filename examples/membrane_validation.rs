//! The membrane model (`--model membrane`, constant-strain triangles with
//! the material's strain energy) against exact references:
//!
//! 1. the clamped disc against the exact axisymmetric inflation
//!    (`bulge::axisym`): a Mooney-Rivlin latex (C1 0.25 MPa, C2 0.02 MPa,
//!    a 37.5 mm, t 0.35 mm) at 14 pressures up to 90 % of its limit point,
//!    on 60-degree sectors of 8 to 64 rings: the largest relative height
//!    error and its observed order of convergence in the edge length;
//!
//! 2. the sphere segment against the closed form of a uniformly inflated
//!    neo-Hookean sphere, `p = 2 t P(l) / (R0 l^2)`, `P = 2 C1 (l - l^-5)`;
//! 3. the plane-strain strip: a rectangular window 8 times as long as wide
//!    at mid-length against the exact inflation of the infinite strip
//!    (docs/theory.md section 9), neo-Hookean and Ogden's three-term
//!    rubber;
//! 4. the 2:1 elliptical window: heights on meshes of 12 to 96 rings and
//!    their Richardson extrapolation.
//!
//! `cargo run --release --example membrane_validation` prints the tables of
//! docs/simulate.md.

use std::time::Instant;

#[path = "../tests/support/validation.rs"]
mod validation;

use bulge::axisym;
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::sim::scene::{MeshSettings, MeshSize, Scene, SceneKind, disc_mesh};
use bulge::sim::{SceneSolver, SpringModel};
use validation::bisect;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let which: Vec<String> = std::env::args().skip(1).collect();
    let run = |name: &str| which.is_empty() || which.iter().any(|w| w == name);
    if run("disc") {
        disc()?;
    }
    if run("sphere") {
        sphere()?;
    }
    if run("strip") {
        strip()?;
    }
    if run("ellipse") {
        ellipse()?;
    }
    Ok(())
}

fn disc() -> Res<()> {
    let spec = Specimen {
        radius_m: 0.0375,
        thickness_m: 0.35e-3,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let mat = Material {
        model: Model::MooneyRivlin {
            c1_pa: 0.25e6,
            c2_pa: 0.02e6,
        },
        poisson: 0.45,
        fit: None,
    };
    // This law (C2/C1 = 0.08) has no limit point: its pressure rises at
    // every pole stretch (12.4 kPa at 4, 15.6 kPa at 8), flattening above
    // about 2.5. The top pressure is 90 % of the pressure at pole stretch 4,
    // the end of axisym's default search.
    let opts = axisym::Options::default();
    let t0 = Instant::now();
    let top = match axisym::limit_point(&mat, &spec, &opts)? {
        Some(lim) => lim.pressure_pa,
        None => axisym::solve_pole_stretch(&mat, &spec, opts.max_pole_stretch, &opts)?.pressure_pa,
    };
    let pressures: Vec<f64> = (1..=14).map(|k| 0.9 * top * k as f64 / 14.0).collect();
    let exact: Vec<f64> = pressures
        .iter()
        .map(|&p| axisym::solve_pressure(&mat, &spec, p, &opts).map(|s| s.height_m))
        .collect::<Result<_, _>>()?;
    let t_exact = t0.elapsed().as_secs_f64();
    println!(
        "Mooney-Rivlin disc: top of the searched branch {:.1} Pa; 14 pressures {:.1} .. {:.1} Pa; exact heights {:.4} .. {:.4} mm (axisym, {:.2} s)",
        top,
        pressures[0],
        pressures[13],
        exact[0] * 1e3,
        exact[13] * 1e3,
        t_exact
    );
    println!();
    println!("| model | rings | nodes | largest error | at pressure | observed order | wall s |");
    println!("|---|---|---|---|---|---|---|");
    for model in [SpringModel::Membrane, SpringModel::Tp] {
        let mut last: Option<(usize, f64)> = None;
        for rings in [8usize, 16, 32, 64] {
            let mesh = disc_mesh(spec.radius_m, 0.0, rings, true)?;
            let nodes = mesh.nodes.len();
            let scene = Scene::from_specimen(&spec, mat.clone(), pressures.clone());
            let t1 = Instant::now();
            let mut s = SceneSolver::on_mesh(&scene, mesh, model)?;
            let done = s
                .sweep(&pressures, |_, _| {})
                .map_err(|(_, stop)| stop.error)?;
            let wall = t1.elapsed().as_secs_f64();
            let (worst, at) = done
                .iter()
                .zip(&exact)
                .map(|(q, h)| ((q.height_m / h - 1.0), q.pressure_pa))
                .fold(
                    (0.0_f64, 0.0),
                    |a, b| if b.0.abs() > a.0.abs() { b } else { a },
                );
            let order = last
                .map(|(n0, e0)| {
                    format!(
                        "{:.2}",
                        (e0.abs() / worst.abs()).ln() / (rings as f64 / n0 as f64).ln()
                    )
                })
                .unwrap_or_else(|| "-".into());
            println!(
                "| {} | {rings} | {nodes} | {:+.4} % | {:.0} Pa | {order} | {wall:.2} |",
                model.name(),
                worst * 100.0,
                at
            );
            last = Some((rings, worst));
        }
    }
    Ok(())
}

/// A scene of `kind` with `material`, t = 0.35 mm, meshed at `size`.
fn scene(kind: SceneKind, material: &Material, pressures: &[f64], size: MeshSize) -> Scene {
    Scene {
        kind,
        thickness_m: 0.35e-3,
        pressures_pa: pressures.to_vec(),
        material: material.clone(),
        density_kg_m3: 1100.0,
        mesh: MeshSettings {
            size: Some(size),
            ..MeshSettings::default()
        },
        loads: Vec::new(),
    }
}

/// Heights of the membrane model over the pressures, the node count and the
/// wall time.
fn heights(scene: &Scene) -> Res<(Vec<f64>, usize, f64)> {
    let t0 = Instant::now();
    let mesh = scene.build_mesh()?;
    let nodes = mesh.nodes.len();
    let mut s = SceneSolver::on_mesh(scene, mesh, SpringModel::Membrane)?;
    let done = s
        .sweep(&scene.pressures_pa, |_, _| {})
        .map_err(|(_, stop)| stop.error)?;
    Ok((
        done.iter().map(|q| q.height_m).collect(),
        nodes,
        t0.elapsed().as_secs_f64(),
    ))
}

fn sphere() -> Res<()> {
    let (c1, r0, t) = (0.25e6, 0.05, 0.35e-3);
    let mat = Material {
        model: Model::NeoHookean { c1_pa: c1 },
        poisson: 0.45,
        fit: None,
    };
    // p(l) = 2 t P(l) / (R0 l^2), P = 2 C1 (l - l^-5); its maximum at l = 7^(1/6)
    let p_of = |l: f64| 2.0 * t * 2.0 * c1 * (l - l.powi(-5)) / (r0 * l * l);
    let l_max = 7f64.powf(1.0 / 6.0);
    let pressures: Vec<f64> = [0.3, 0.6, 0.9].iter().map(|f| f * p_of(l_max)).collect();
    let exact: Vec<f64> = pressures
        .iter()
        .map(|&p| r0 * (bisect(|l| p_of(l) - p, 1.0, l_max) - 1.0))
        .collect();
    println!();
    println!(
        "Neo-Hookean sphere octant (C1 0.25 MPa, R0 50 mm, t 0.35 mm), mean radius growth R - R0 against the closed form; pressures {} Pa",
        pressures
            .iter()
            .map(|p| format!("{p:.1}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!();
    println!("| divisions | nodes | error at 0.3 | 0.6 | 0.9 of the limit pressure | wall s |");
    println!("|---|---|---|---|---|---|");
    for n in [8usize, 16, 32, 64] {
        let sc = scene(
            SceneKind::SphereSegment { radius_m: r0 },
            &mat,
            &pressures,
            MeshSize::Nodes((n + 1) * (n + 2) / 2),
        );
        let (h, nodes, wall) = heights(&sc)?;
        let e: Vec<String> = h
            .iter()
            .zip(&exact)
            .map(|(h, x)| format!("{:+.4} %", (h / x - 1.0) * 100.0))
            .collect();
        println!("| {n} | {nodes} | {} | {wall:.2} |", e.join(" | "));
    }
    Ok(())
}

/// The exact apex height of the infinite strip of half-width `b` at
/// pressure `p`: the arc of half-angle `th` with `p b / t = P1(th / sin th,
/// 1) sin th` and `h = b tan(th / 2)` (docs/theory.md section 9).
fn strip_height(p1: &dyn Fn(f64) -> f64, b: f64, t: f64, p: f64) -> f64 {
    let g = |th: f64| p1(th / th.sin()) * th.sin() - p * b / t;
    let th = bisect(g, 1e-6, 1.5);
    b * (th / 2.0).tan()
}

fn strip() -> Res<()> {
    let (w, t) = (0.02, 0.35e-3);
    let b = w / 2.0;
    let c1 = 0.25e6;
    let (mu, alpha) = ([0.63e6, 0.0012e6, -0.01e6], [1.3, 5.0, -2.0]);
    // P1(l, 1) of each law in plane strain (l2 = 1, l3 = 1 / l), closed forms
    let nh = move |l: f64| 2.0 * c1 * (l - l.powi(-3));
    let og = move |l: f64| {
        (0..3)
            .map(|i| mu[i] * (l.powf(alpha[i] - 1.0) - l.powf(-alpha[i] - 1.0)))
            .sum::<f64>()
    };
    type Law<'a> = &'a dyn Fn(f64) -> f64;
    let cases: [(&str, Material, Law); 2] = [
        (
            "neo-Hookean C1 0.25 MPa",
            Material {
                model: Model::NeoHookean { c1_pa: c1 },
                poisson: 0.45,
                fit: None,
            },
            &nh,
        ),
        (
            "Ogden-3 (Ogden 1972)",
            Material {
                model: Model::Ogden {
                    mu_pa: mu.to_vec(),
                    alpha: alpha.to_vec(),
                },
                poisson: 0.45,
                fit: None,
            },
            &og,
        ),
    ];
    println!();
    println!(
        "Rectangular window 160 x 20 mm (quarter with mirror planes), t 0.35 mm: mid-length apex height against the infinite strip (arc half-angles 0.5, 1.0, 1.4 rad)"
    );
    println!();
    println!("| law | half-width cells | nodes | error at th 0.5 | 1.0 | 1.4 | wall s |");
    println!("|---|---|---|---|---|---|---|");
    for (name, mat, p1) in cases {
        let pressures: Vec<f64> = [0.5f64, 1.0, 1.4]
            .iter()
            .map(|&th| t / b * p1(th / th.sin()) * th.sin())
            .collect();
        let exact: Vec<f64> = pressures
            .iter()
            .map(|&p| strip_height(p1, b, t, p))
            .collect();
        for cells in [4usize, 8, 16, 32] {
            let sc = scene(
                SceneKind::Rectangle {
                    length_m: 8.0 * w,
                    width_m: w,
                },
                &mat,
                &pressures,
                MeshSize::EdgeLength(b / cells as f64),
            );
            let (h, nodes, wall) = heights(&sc)?;
            let e: Vec<String> = h
                .iter()
                .zip(&exact)
                .map(|(h, x)| format!("{:+.4} %", (h / x - 1.0) * 100.0))
                .collect();
            println!(
                "| {name} | {cells} | {nodes} | {} | {wall:.2} |",
                e.join(" | ")
            );
        }
    }
    Ok(())
}

fn ellipse() -> Res<()> {
    let (a, b) = (0.0375, 0.01875);
    let mat = Material {
        model: Model::MooneyRivlin {
            c1_pa: 0.25e6,
            c2_pa: 0.02e6,
        },
        poisson: 0.45,
        fit: None,
    };
    let pressures = [4000.0, 8000.0, 12000.0];
    println!();
    println!(
        "2:1 elliptical window (semi-axes 37.5 and 18.75 mm), Mooney-Rivlin C1 0.25 MPa, C2 0.02 MPa, t 0.35 mm: apex height, mm"
    );
    println!();
    println!("| rings | nodes | 4000 Pa | 8000 Pa | 12000 Pa | wall s |");
    println!("|---|---|---|---|---|---|");
    let mut all = Vec::new();
    for rings in [12usize, 24, 48, 96] {
        let sc = scene(
            SceneKind::Ellipse {
                semi_axes_m: [a, b],
            },
            &mat,
            &pressures,
            MeshSize::Nodes(1 + 3 * rings * (rings + 1)),
        );
        let (h, nodes, wall) = heights(&sc)?;
        println!(
            "| {rings} | {nodes} | {} | {wall:.2} |",
            h.iter()
                .map(|v| format!("{:.5}", v * 1e3))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        all.push(h);
    }
    // observed order from the last three meshes, and Richardson's limit
    let n = all.len();
    let mut order = Vec::new();
    let mut limit = Vec::new();
    #[allow(clippy::needless_range_loop)] // k runs over the pressures of every mesh
    for k in 0..pressures.len() {
        let (h1, h2, h3) = (all[n - 3][k], all[n - 2][k], all[n - 1][k]);
        let q = ((h2 - h1) / (h3 - h2)).abs().ln() / 2f64.ln();
        order.push(q);
        limit.push(h3 + (h3 - h2) / (2f64.powf(q) - 1.0));
    }
    println!(
        "| extrapolated | | {} | |",
        limit
            .iter()
            .map(|v| format!("{:.5}", v * 1e3))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!(
        "| observed order | | {} | |",
        order
            .iter()
            .map(|v| format!("{v:.2}"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    Ok(())
}
