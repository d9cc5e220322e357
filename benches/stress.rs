//! The stress stage on 10 000 heights (flat start to H = 2a, every branch of
//! the arc-length formula), without and with uncertainty propagation.
//!
//! `cargo bench -p bulge-bench --bench stress`. The figures are in docs/stress.md.

use std::hint::black_box;

use bulge::experiment::Specimen;
use bulge::mechanics::{Options, Point, stress_strain};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let spec = Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let n = 10_000;
    let points: Vec<Point> = (0..n)
        .map(|i| {
            let f = i as f64 / (n - 1) as f64;
            Point {
                pressure_pa: 9000.0 * f,
                height_m: 2.0 * spec.radius_m * f,
                height_std_m: None,
            }
        })
        .collect();
    let with_std: Vec<Point> = points
        .iter()
        .map(|p| Point {
            height_std_m: Some(5e-5),
            ..*p
        })
        .collect();
    let opts = Options::default();
    c.bench_function("stress_strain 10k points", |b| {
        b.iter(|| stress_strain(black_box(&spec), &opts, black_box(&points)).unwrap())
    });
    c.bench_function("stress_strain 10k points with std", |b| {
        b.iter(|| stress_strain(black_box(&spec), &opts, black_box(&with_std)).unwrap())
    });
}

// No plots: the plotters backend needs system fonts, which CI machines lack.
criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
