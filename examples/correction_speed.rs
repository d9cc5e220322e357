//! The correction of a law to the measured heights (`bulge::fit::inverse`),
//! with exact derivatives against central differences, side by side:
//! the bundled demo (tracked from its photos), a 12-point neo-Hookean
//! experiment up to 95 % of its limit pressure (exact heights), and a
//! well-posed case where both converge (a Mooney-Rivlin law 25 % and 50 %
//! off, corrected to its own exact heights at 6 pressures). Prints a
//! Markdown table: time, iterations, solves, rms height error, and how far
//! apart the two corrected laws' heights are.
//!
//!     cargo run --release --example correction_speed

use std::path::Path;
use std::time::Instant;

use bulge::axisym;
use bulge::experiment::{Experiment, Specimen};
use bulge::fit::inverse::{self, Derivatives, Measured, Refined};
use bulge::material::{Material, Model};
use bulge::mechanics::Point;
use bulge::pipeline::{self, Settings};

/// The cap-method law of `points` (the run's stress and fit stages, no
/// correction) and the heights it is corrected to.
fn cap_law(spec: &Specimen, points: Vec<Point>) -> (Material, Vec<Measured>) {
    let settings = Settings {
        refine: false,
        ..Settings::default()
    };
    let stress = pipeline::stress_stage(spec, &settings, points).expect("stress");
    let fit = pipeline::fit_stage(spec, &settings, &stress).expect("fit");
    (fit.material, pipeline::measured_heights(&stress.points))
}

fn demo() -> (Specimen, Material, Vec<Measured>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/demo/experiment.toml");
    let exp = Experiment::read(&path).expect("the demo's experiment file");
    let tracking = pipeline::track_stage(&exp, &Settings::default(), &|| {}).expect("tracking");
    let points = tracking.points();
    let (m, q) = cap_law(&exp.specimen, points);
    (exp.specimen, m, q)
}

/// Tudruj et al.'s (2023) latex disc, flat.
fn latex() -> Specimen {
    Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    }
}

fn near_limit() -> (Specimen, Material, Vec<Measured>) {
    let spec = latex();
    let truth = Material {
        model: Model::NeoHookean { c1_pa: 0.2e6 },
        poisson: 0.45,
        fit: None,
    };
    let opts = axisym::Options {
        n_profile: 2,
        ..axisym::Options::default()
    };
    let limit = axisym::limit_point(&truth, &spec, &opts)
        .expect("limit point")
        .expect("a neo-Hookean disc has one")
        .pressure_pa;
    let points = (1..=12)
        .map(|i| {
            let p = 0.95 * limit * i as f64 / 12.0;
            Point {
                pressure_pa: p,
                height_m: axisym::solve_pressure(&truth, &spec, p, &opts)
                    .expect("below the limit point")
                    .height_m,
                height_std_m: None,
            }
        })
        .collect();
    let (m, q) = cap_law(&spec, points);
    (spec, m, q)
}

fn mooney_rivlin() -> (Specimen, Material, Vec<Measured>) {
    let spec = latex();
    let m = |c1_pa, c2_pa| Material {
        model: Model::MooneyRivlin { c1_pa, c2_pa },
        poisson: 0.45,
        fit: None,
    };
    let opts = axisym::Options {
        n_profile: 2,
        ..axisym::Options::default()
    };
    let truth = m(0.12e6, 0.03e6);
    let measured = (1..=6)
        .map(|i| {
            let p = 500.0 * i as f64;
            Measured {
                pressure_pa: p,
                height_m: axisym::solve_pressure(&truth, &spec, p, &opts)
                    .expect("below the limit point")
                    .height_m,
                height_std_m: None,
            }
        })
        .collect();
    (spec, m(0.15e6, 0.015e6), measured)
}

fn main() {
    println!(
        "| case | derivatives | wall s | iterations | axisym solves | rms before % | rms after % |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|");
    for (name, (spec, start, measured)) in [
        ("data/demo (16 photos)", demo()),
        ("neo-Hookean, 12 points to 0.95 p_limit", near_limit()),
        (
            "Mooney-Rivlin from 25 % and 50 % off, 6 points",
            mooney_rivlin(),
        ),
    ] {
        let mut laws = Vec::new();
        let mut times = Vec::new();
        for d in [Derivatives::CentralDifferences, Derivatives::Exact] {
            let opts = inverse::Options {
                derivatives: d,
                ..inverse::Options::default()
            };
            let t0 = Instant::now();
            let r = inverse::refine(&start, &spec, &measured, &opts).expect("correction");
            let wall = t0.elapsed().as_secs_f64();
            times.push(wall);
            let pct = |e: &[Option<f64>]| Refined::rms(e).map_or(f64::NAN, |v| 100.0 * v);
            println!(
                "| {name} | {d:?} | {wall:.3} | {} | {} | {:.4} | {:.4} |",
                r.iterations,
                r.solves,
                pct(&r.before),
                pct(&r.after)
            );
            laws.push(r.material);
        }
        // The two corrected laws' heights at the measured pressures.
        let opts = axisym::Options {
            n_profile: 2,
            ..axisym::Options::default()
        };
        let gap = measured
            .iter()
            .map(|q| {
                let h: Vec<f64> = laws
                    .iter()
                    .map(|m| {
                        axisym::solve_pressure(m, &spec, q.pressure_pa, &opts)
                            .map_or(f64::NAN, |s| s.height_m)
                    })
                    .collect();
                (h[1] / h[0] - 1.0).abs()
            })
            .fold(0.0, f64::max);
        println!(
            "| {name} | speed-up {:.1}x, largest relative gap between the two laws' heights {gap:.2e} | | | | | |",
            times[0] / times[1]
        );
    }
}
