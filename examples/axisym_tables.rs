//! The axisymmetric reference's check tables, as quoted in docs/axisym.md:
//! Yang & Feng's neo-Hookean and Mooney-Rivlin discs, the limit point,
//! Hencky's linear membrane, and the hard cases.
//!
//! `cargo run --release --example axisym_tables`

use bulge::axisym::{Options, Solution, limit_point, solve_pole_stretch, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model, StrainMeasure};

const A: f64 = 0.0375;
const T: f64 = 3.5e-4;
const C1: f64 = 1.0e5;

fn specimen() -> Specimen {
    Specimen {
        radius_m: A,
        thickness_m: T,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    }
}

fn mat(model: Model, poisson: f64) -> Material {
    Material {
        model,
        poisson,
        fit: None,
    }
}

fn neo() -> Material {
    mat(Model::NeoHookean { c1_pa: C1 }, 0.5)
}

fn mooney() -> Material {
    mat(
        Model::MooneyRivlin {
            c1_pa: C1,
            c2_pa: 0.1 * C1,
        },
        0.5,
    )
}

fn dimless(sol: &Solution) -> (f64, f64) {
    (sol.pressure_pa * A / (C1 * T), sol.height_m / A)
}

fn main() {
    check_table();
    println!();
    hard_cases();
}

/// The check table: pole stretch -> pressure and height against Yang & Feng's
/// values, the limit point, Hencky's small-deflection limit.
fn check_table() {
    let o = Options::default();
    let table = [
        (1.01, 0.05138, 0.12361, 0.05666, 0.12367),
        (1.20, 1.99850, 0.53098, 2.30046, 0.53663),
        (2.00, 3.73911, 1.08307, 4.94098, 1.16113),
    ];
    for (l0, p_nh, h_nh, p_mr, h_mr) in table {
        let a = solve_pole_stretch(&neo(), &specimen(), l0, &o).unwrap();
        let b = solve_pole_stretch(&mooney(), &specimen(), l0, &o).unwrap();
        let (pa, ha) = dimless(&a);
        let (pb, hb) = dimless(&b);
        println!(
            "| {l0:.2} | {pa:.7} ({:+.1e}) | {ha:.7} ({:+.1e}) | {pb:.7} ({:+.1e}) | {hb:.7} ({:+.1e}) | shots {} {} res {:.1e} {:.1e}",
            pa / p_nh - 1.0,
            ha / h_nh - 1.0,
            pb / p_mr - 1.0,
            hb / h_mr - 1.0,
            a.iterations,
            b.iterations,
            a.residual,
            b.residual
        );
    }
    let lp = limit_point(&neo(), &specimen(), &o).unwrap().unwrap();
    let (p, h) = dimless(&lp);
    println!(
        "limit: P {p:.6} l0 {:.6} h/a {h:.6} shots {}",
        lp.pole_stretch, lp.iterations
    );
    println!("Hencky, linear: relative error of w0 by w0/a");
    for (nu, k) in [
        (0.0, 0.71832),
        (0.3, 0.65344),
        (0.45, 0.61117),
        (0.49, 0.59824),
    ] {
        let m = mat(Model::Linear { young_pa: 2.0e6 }, nu);
        let mut line = format!("| {nu} |");
        for w in [0.2f64, 0.1, 0.05, 0.02, 0.01] {
            let q = (w / k).powi(3);
            let s = solve_pressure(&m, &specimen(), q * 2.0e6 * T / A, &o).unwrap();
            let want = k * A * q.cbrt();
            line += &format!(" {:+.3} % |", 100.0 * (s.height_m / want - 1.0));
        }
        println!("{line}");
    }
    for model in [
        Model::NeoHookean { c1_pa: 2.0e5 },
        Model::MooneyRivlin {
            c1_pa: 1.8e5,
            c2_pa: 2.0e4,
        },
        Model::Ogden {
            mu_pa: vec![6.3e5, 1.2e3, -1.0e4],
            alpha: vec![1.3, 5.0, -2.0],
        },
    ] {
        let e = model.initial_young_pa();
        let mut line = format!("| {} |", model.name());
        for w in [0.2f64, 0.1, 0.05, 0.02, 0.01] {
            let q = (w / 0.59488).powi(3);
            let s =
                solve_pressure(&mat(model.clone(), 0.5), &specimen(), q * e * T / A, &o).unwrap();
            let want = 0.59488 * A * q.cbrt();
            line += &format!(" {:+.3} % |", 100.0 * (s.height_m / want - 1.0));
        }
        println!("{line}");
    }
    for (name, m) in [("neo", neo()), ("mr", mooney())] {
        for big_p in [0.01, 0.5, 2.0, 3.5] {
            let s = solve_pressure(&m, &specimen(), big_p * C1 * T / A, &o).unwrap();
            println!(
                "{name} P {big_p}: l0 {:.8} h/a {:.8} shots {} res {:.1e}",
                s.pole_stretch,
                s.height_m / A,
                s.iterations,
                s.residual
            );
        }
    }
}

/// The hard cases: tiny pressures, near and past the pressure maximum, the
/// falling branch, a softening law and Gent's stiffening.
fn hard_cases() {
    let o = Options::default();
    for big_p in [1e-9, 1e-6, 1e-3] {
        let r = solve_pressure(&neo(), &specimen(), big_p * C1 * T / A, &o);
        match r {
            Ok(s) => println!(
                "tiny P {big_p:e}: l0-1 {:.6e} h/a {:.6e} shots {} (Hencky h/a {:.6e})",
                s.pole_stretch - 1.0,
                s.height_m / A,
                s.iterations,
                0.59488 * (big_p / 6.0f64).cbrt()
            ),
            Err(e) => println!("tiny P {big_p:e}: {e}"),
        }
    }
    for f in [0.9, 0.999, 0.99999, 1.0 + 1e-6] {
        let r = solve_pressure(&neo(), &specimen(), f * 3.758347 * C1 * T / A, &o);
        match r {
            Ok(s) => println!(
                "near max {f}: l0 {:.6} shots {}",
                s.pole_stretch, s.iterations
            ),
            Err(e) => println!("near max {f}: {e}"),
        }
    }
    for l0 in [2.5, 3.0, 3.5, 4.0, 5.0] {
        match solve_pole_stretch(&neo(), &specimen(), l0, &o) {
            Ok(s) => {
                let (p, h) = dimless(&s);
                println!(
                    "falling branch l0 {l0}: P {p:.6} h/a {h:.6} shots {}",
                    s.iterations
                )
            }
            Err(e) => println!("falling branch l0 {l0}: {e}"),
        }
    }
    let bad = mat(
        Model::Quartic {
            coefficients_pa: vec![1.0e6, -3.0e6],
            strain_range: [0.0, 0.5],
            strain_measure: StrainMeasure::Engineering,
        },
        0.45,
    );
    for p in [2000.0, 20000.0] {
        match solve_pressure(&bad, &specimen(), p, &o) {
            Ok(s) => println!(
                "softening quartic {p}: l0 {:.5} h {:.5}",
                s.pole_stretch, s.height_m
            ),
            Err(e) => println!("softening quartic {p}: {e}"),
        }
    }
    match solve_pole_stretch(&bad, &specimen(), 1.4, &o) {
        Ok(s) => println!("softening quartic l0 1.4: p {:.5}", s.pressure_pa),
        Err(e) => println!("softening quartic l0 1.4: {e}"),
    }
    let gent = mat(
        Model::Gent {
            mu_pa: 2.0e5,
            jm: 20.0,
        },
        0.5,
    );
    match limit_point(&gent, &specimen(), &o) {
        Ok(Some(s)) => println!(
            "gent Jm 20 limit: p {:.3} l0 {:.4} shots {}",
            s.pressure_pa, s.pole_stretch, s.iterations
        ),
        Ok(None) => println!("gent Jm 20: no limit up to 4"),
        Err(e) => println!("gent: {e}"),
    }
    for p in [10_000.0, 100_000.0] {
        match solve_pressure(&gent, &specimen(), p, &o) {
            Ok(s) => println!(
                "gent p {p}: l0 {:.5} h/a {:.5} shots {}",
                s.pole_stretch,
                s.height_m / A,
                s.iterations
            ),
            Err(e) => println!("gent p {p}: {e}"),
        }
    }
}
