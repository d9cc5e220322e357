//! The exact axisymmetric reference from the library: the paper's latex disc
//! (a = 37.5 mm, t = 0.35 mm) as a neo-Hookean membrane at the paper's three
//! pressures, its limit point, and the start of one profile as CSV.
//!
//! `cargo run --release --example axisym`

use bulge::axisym::{Options, limit_point, profile_csv, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let specimen = Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    // mu = 2 C1 = 0.6 MPa: a soft latex.
    let material = Material {
        model: Model::NeoHookean { c1_pa: 3.0e5 },
        poisson: 0.5,
        fit: None,
    };
    let opts = Options::default();
    println!("pressure_pa,height_m,pole_stretch,shots,residual,wall_ms");
    for p in [5000.0, 7300.0, 8940.0] {
        let t0 = std::time::Instant::now();
        let s = solve_pressure(&material, &specimen, p, &opts)?;
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        println!(
            "{p},{:.6e},{:.8},{},{:.1e},{ms:.2}",
            s.height_m, s.pole_stretch, s.iterations, s.residual
        );
    }
    let top = limit_point(&material, &specimen, &opts)?.expect("neo-Hookean peaks");
    println!(
        "limit point: {:.2} Pa at pole stretch {:.5}, height {:.5e} m",
        top.pressure_pa, top.pole_stretch, top.height_m
    );
    match solve_pressure(&material, &specimen, 1.1 * top.pressure_pa, &opts) {
        Ok(_) => println!("unexpected: solved above the limit point"),
        Err(e) => println!("error: {e}"),
    }
    let s = solve_pressure(
        &material,
        &specimen,
        8940.0,
        &Options {
            n_profile: 6,
            ..opts
        },
    )?;
    print!("{}", String::from_utf8(profile_csv(&s).into_bytes())?);

    // Speed against error: one pressure point (8940 Pa, height only) at
    // several tolerances, against a 1e-13 solution.
    let reference = solve_pressure(
        &material,
        &specimen,
        8940.0,
        &Options {
            rel_tol: 1e-13,
            tol: 1e-13,
            n_profile: 2,
            ..opts
        },
    )?;
    println!("tolerance,height_error,shots,wall_ms");
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let o = Options {
            rel_tol: tol,
            tol,
            n_profile: 2,
            ..opts
        };
        let n = 100;
        let t0 = std::time::Instant::now();
        let mut s = None;
        for _ in 0..n {
            s = Some(solve_pressure(&material, &specimen, 8940.0, &o)?);
        }
        let ms = t0.elapsed().as_secs_f64() * 1e3 / n as f64;
        let s = s.expect("n > 0");
        println!(
            "{tol:e},{:+.1e},{},{ms:.3}",
            s.height_m / reference.height_m - 1.0,
            s.iterations
        );
    }
    Ok(())
}
