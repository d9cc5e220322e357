//! The discretisation error of each spring model, measured against the exact
//! axisymmetric reference: the paper's latex disc (a = 37.5 mm, t = 0.35 mm,
//! nu = 0.45) with a quartic E(eps) material, at the paper's three pressures,
//! on 60-degree sector meshes of increasing size, Newton to 1e-10.
//!
//! `cargo run --release --example axisym_vs_springs` prints the table of
//! docs/axisym.md. Both sides take the modulus the same way (at the strain of
//! the square root of the area stretch, clamped to the fitted range).

use std::time::Instant;

use bulge::axisym::{self, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model, StrainMeasure};
use bulge::sim::scene::DiscPredictor;
use bulge::sim::solve::{self, Solver};
use bulge::sim::{Membrane, SpringModel, mesh};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (a, t, nu) = (0.0375, 3.5e-4, 0.45);
    let specimen = Specimen {
        radius_m: a,
        thickness_m: t,
        poisson: nu,
        prebulge_height_m: 0.0,
    };
    // A latex-like softening secant modulus, fitted range 0..100 % strain.
    let material = Material {
        model: Model::Quartic {
            coefficients_pa: vec![1.6e6, -2.4e6, 2.0e6, -0.6e6, 0.0],
            strain_range: [0.0, 1.0],
            strain_measure: StrainMeasure::Engineering,
        },
        poisson: nu,
        fit: None,
    };
    let pressures = [5000.0, 7300.0, 8940.0];
    let exact: Vec<f64> = pressures
        .iter()
        .map(|&p| {
            solve_pressure(&material, &specimen, p, &axisym::Options::default()).map(|s| s.height_m)
        })
        .collect::<Result<_, _>>()?;
    println!(
        "reference (axisym, 1e-10): {}",
        exact
            .iter()
            .map(|h| format!("{:.6} mm", h * 1e3))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let opts = solve::Options {
        tolerance: 1e-10,
        ..solve::Options::default()
    };
    let rings = [4usize, 8, 16, 32, 64];
    let mut notes = Vec::new();
    println!();
    println!(
        "| model | rings | nodes | {} | wall s |",
        pressures
            .map(|p| format!("{p} Pa: h mm (error)"))
            .join(" | ")
    );
    println!("|---|---|---|---|---|---|---|");
    for model in SpringModel::ALL {
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for &n in &rings {
            let m = mesh::disc(mesh::DiscOptions {
                radius_m: a,
                rings: n,
                sector: true,
            })?;
            let mut mem = Membrane::new(&m, model, &material, t, 1100.0)?;
            let mut x = m.nodes.clone();
            let pred = DiscPredictor {
                radius_m: a,
                young_pa: material.model.initial_young_pa(),
                thickness_m: t,
                poisson: nu,
            };
            let mut ws = None;
            let t0 = Instant::now();
            let mut p0 = 0.0;
            let mut cells = Vec::new();
            let mut hs = Vec::new();
            for (&p, &h_ref) in pressures.iter().zip(&exact) {
                match solve::continuation(
                    &mut mem,
                    &m.nodes,
                    &mut x,
                    p0,
                    p,
                    Solver::Newton,
                    &opts,
                    &pred,
                    &mut ws,
                ) {
                    Ok(_) => {
                        let h = x[0].z;
                        hs.push(h);
                        cells.push(format!(
                            "{:.4} ({:+.2} %)",
                            h * 1e3,
                            (h / h_ref - 1.0) * 100.0
                        ));
                    }
                    Err(e) => {
                        hs.push(f64::NAN);
                        cells.push("no equilibrium".into());
                        notes.push(format!("{} on {n} rings at {p} Pa: {e}", model.name()));
                        break;
                    }
                }
                p0 = p;
            }
            while cells.len() < pressures.len() {
                cells.push("-".into());
                hs.push(f64::NAN);
            }
            println!(
                "| {} | {n} | {} | {} | {:.3} |",
                model.name(),
                m.nodes.len(),
                cells.join(" | "),
                t0.elapsed().as_secs_f64()
            );
            rows.push(hs);
        }
        // Richardson limit from the two finest meshes (error ~ 1/n^2).
        let k = rows.len();
        let lim: Vec<String> = (0..pressures.len())
            .map(|j| {
                let (h1, h2) = (rows[k - 2][j], rows[k - 1][j]);
                let l = (4.0 * h2 - h1) / 3.0;
                if l.is_finite() {
                    format!("{:.4} ({:+.2} %)", l * 1e3, (l / exact[j] - 1.0) * 100.0)
                } else {
                    "-".into()
                }
            })
            .collect();
        println!(
            "| {} | limit (Richardson {}-{}) | | {} | |",
            model.name(),
            rings[k - 2],
            rings[k - 1],
            lim.join(" | ")
        );
    }
    for n in notes {
        println!("\n{n}");
    }
    Ok(())
}
