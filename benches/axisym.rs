//! One equilibrium of the exact axisymmetric reference, to 1e-8.
//!
//! `cargo bench -p bulge-bench --bench axisym`. The figures are in docs/axisym.md.

use std::hint::black_box;

use bulge::axisym::{Options, solve_pole_stretch, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model, StrainMeasure};
use criterion::{Criterion, criterion_group, criterion_main};

fn specimen() -> Specimen {
    // The latex disc of Tudruj et al. (2023): a = 37.5 mm, t = 0.35 mm.
    Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    }
}

fn bench(c: &mut Criterion) {
    let opts = Options {
        rel_tol: 1e-8,
        tol: 1e-8,
        ..Options::default()
    };
    let height_only = Options {
        n_profile: 2,
        ..opts
    };
    let neo = Material {
        model: Model::NeoHookean { c1_pa: 1.0e5 },
        poisson: 0.5,
        fit: None,
    };
    let quartic = Material {
        model: Model::Quartic {
            coefficients_pa: vec![1.6e6, -2.4e6, 2.0e6, -0.6e6, 0.0],
            strain_range: [0.0, 1.0],
            strain_measure: StrainMeasure::Engineering,
        },
        poisson: 0.45,
        fit: None,
    };
    let s = specimen();
    // P = p a / (C1 t) = 2: pole stretch 1.2, h/a = 0.53.
    let p_neo = 2.0 * 1.0e5 * 3.5e-4 / 0.0375;
    let mut g = c.benchmark_group("axisym");
    g.bench_function(
        "solve_pressure neo-hookean P=2, 1e-8, 201-point profile",
        |b| b.iter(|| solve_pressure(&neo, &s, black_box(p_neo), &opts).unwrap()),
    );
    g.bench_function("solve_pressure neo-hookean P=2, 1e-8, height only", |b| {
        b.iter(|| solve_pressure(&neo, &s, black_box(p_neo), &height_only).unwrap())
    });
    g.bench_function("solve_pressure quartic 8940 Pa, 1e-8, height only", |b| {
        b.iter(|| solve_pressure(&quartic, &s, black_box(8940.0), &height_only).unwrap())
    });
    g.bench_function(
        "solve_pole_stretch neo-hookean l0=1.2, 1e-8, height only",
        |b| b.iter(|| solve_pole_stretch(&neo, &s, black_box(1.2), &height_only).unwrap()),
    );
    g.bench_function("solve_pressure neo-hookean P=2, 1e-10 (defaults)", |b| {
        b.iter(|| solve_pressure(&neo, &s, black_box(p_neo), &Options::default()).unwrap())
    });
    g.finish();
}

// No plots: criterion's plotters backend needs system fonts the CI machine
// does not have.
criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
