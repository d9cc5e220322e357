//! Mesh-convergence tables of the mass-spring membrane (docs/simulate.md):
//! the sphere segment against thin-shell theory, the clamped disc against
//! Hencky's K(nu), and a neo-Hookean disc against its exact inflation.
//!
//! Run with `cargo run --release --example sim_convergence`.

#[path = "../tests/support/validation.rs"]
mod validation;

use bulge::material::{Material, Model};
use bulge::sim::mesh::{self, DiscOptions};
use bulge::sim::scene::DiscPredictor;
use bulge::sim::solve::{self, Options, Solver};
use bulge::sim::springs::{Membrane, SpringModel};
use validation::{HENCKY, disc_height, linear, sphere_radii};

fn main() {
    println!(
        "| divisions | model | mean R m | corner a (II) | corner b (I) | corner c (I) | spread m | error vs shell % |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for n in [8, 16, 32, 64] {
        for model in [SpringModel::VanGelder, SpringModel::Tp] {
            let r = sphere_radii(model, 50e6, 1e-3, n, Solver::Newton);
            let spread = r[1..].iter().cloned().fold(0.0, f64::max)
                - r[1..].iter().cloned().fold(9.0, f64::min);
            println!(
                "| {n} | {} | {:.5} | {:.5} | {:.5} | {:.5} | {:.5} | {:+.3} |",
                model.name(),
                r[0],
                r[1],
                r[2],
                r[3],
                spread,
                (r[0] / 1.08484 - 1.0) * 100.0
            );
        }
    }
    let (a, t, e) = (1.0, 1e-3, 1.0e6);
    for &(nu, k_nu) in &[HENCKY[1], HENCKY[3]] {
        println!(
            "\nHencky disc, nu = {nu}, w0/a = 0.02, K(nu) = {k_nu}: K = w0 / (a (p a / E t)^(1/3))\n"
        );
        println!("| rings | nodes (sector) | tp | tp-paper | van-gelder | lloyd |");
        println!("|---|---|---|---|---|---|");
        let mat = linear(e, nu);
        let p = (0.02f64 / k_nu).powi(3) * e * t / a;
        let scale = a * (p * a / (e * t)).cbrt();
        for n in [4, 8, 16, 32, 64, 128] {
            let ks: Vec<String> = SpringModel::ALL
                .iter()
                .map(|&m| {
                    format!(
                        "{:.5}",
                        disc_height(m, &mat, a, t, p, n, true, Solver::Newton) / scale
                    )
                })
                .collect();
            println!("| {n} | {} | {} |", (n + 1) * (n + 2) / 2, ks.join(" | "));
        }
    }
    // neo-Hookean through the equibiaxial secant modulus, against the exact
    // inflation (Adkins & Rivlin 1952: P = p a / (C1 t) = 1.99850 gives h/a = 0.53098)
    let nh = Material {
        model: Model::NeoHookean { c1_pa: 1.0e5 },
        poisson: 0.499,
        fit: None,
    };
    for &(pp, h_exact) in &[(0.05138, 0.12361), (1.99850, 0.53098), (3.73911, 1.08307)] {
        for model in [SpringModel::Tp, SpringModel::VanGelder] {
            for n in [16, 32, 64] {
                let m = mesh::disc(DiscOptions {
                    radius_m: 1.0,
                    rings: n,
                    sector: true,
                })
                .unwrap();
                let mut mem = Membrane::new(&m, model, &nh, 1e-3, 1100.0).unwrap();
                let mut x = m.nodes.clone();
                let pred = DiscPredictor {
                    radius_m: 1.0,
                    young_pa: 6.0e5,
                    thickness_m: 1e-3,
                    poisson: 0.499,
                };
                let mut ws = None;
                let p = pp * 1.0e5 * 1e-3;
                let out = solve::continuation(
                    &mut mem,
                    &m.nodes,
                    &mut x,
                    0.0,
                    p,
                    Solver::Newton,
                    &Options::default(),
                    &pred,
                    &mut ws,
                );
                match out {
                    Ok(_) => println!(
                        "neo-Hookean P = {pp}: {} n={n} h/a = {:.5} (exact {h_exact}, {:+.2} %)",
                        model.name(),
                        x[0].z,
                        (x[0].z / h_exact - 1.0) * 100.0
                    ),
                    Err(e) => println!("neo-Hookean P = {pp}: {} n={n}: {e}", model.name()),
                }
            }
        }
    }
}
