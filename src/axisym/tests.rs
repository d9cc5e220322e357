//! Checks against independent references: NOTES section 3 (Adkins & Rivlin /
//! Yang & Feng values for neo-Hookean and Mooney-Rivlin discs, the
//! neo-Hookean pressure maximum, Hencky's K(nu) for the linear membrane).

use super::*;
use crate::material::Model;

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

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

/// NOTES section 3 table: P = p a / (C1 t) and h/a at three pole stretches.
#[test]
fn notes_check_values() {
    let table = [
        (1.01, 0.05138, 0.12361, 0.05666, 0.12367),
        (1.20, 1.99850, 0.53098, 2.30046, 0.53663),
        (2.00, 3.73911, 1.08307, 4.94098, 1.16113),
    ];
    let o = Options::default();
    for (l0, p_nh, h_nh, p_mr, h_mr) in table {
        let (p, h) = dimless(&solve_pole_stretch(&neo(), &specimen(), l0, &o).unwrap());
        assert!(rel(p, p_nh) < 1e-4, "neo-Hookean l0 {l0}: P {p} vs {p_nh}");
        assert!(
            rel(h, h_nh) < 1e-4,
            "neo-Hookean l0 {l0}: h/a {h} vs {h_nh}"
        );
        let (p, h) = dimless(&solve_pole_stretch(&mooney(), &specimen(), l0, &o).unwrap());
        assert!(
            rel(p, p_mr) < 1e-4,
            "Mooney-Rivlin l0 {l0}: P {p} vs {p_mr}"
        );
        assert!(
            rel(h, h_mr) < 1e-4,
            "Mooney-Rivlin l0 {l0}: h/a {h} vs {h_mr}"
        );
    }
}

/// Prints the check table of docs/axisym.md (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn print_check_table() {
    let o = Options::default();
    for l0 in [1.01, 1.2, 2.0] {
        let a = solve_pole_stretch(&neo(), &specimen(), l0, &o).unwrap();
        let b = solve_pole_stretch(&mooney(), &specimen(), l0, &o).unwrap();
        let (pa, ha) = dimless(&a);
        let (pb, hb) = dimless(&b);
        println!(
            "| {l0:.2} | {pa:.6} | {ha:.6} | {pb:.6} | {hb:.6} | shots {} {} res {:.1e} {:.1e}",
            a.iterations, b.iterations, a.residual, b.residual
        );
    }
    let lp = limit_point(&neo(), &specimen(), &o).unwrap().unwrap();
    let (p, h) = dimless(&lp);
    println!(
        "limit: P {p:.6} l0 {:.6} h/a {h:.6} shots {}",
        lp.pole_stretch, lp.iterations
    );
}
