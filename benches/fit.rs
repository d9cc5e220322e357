//! Fit times: the polynomial modulus law on 10^3 points, and each
//! hyperelastic model on Treloar's 17 equibiaxial points (multi-start
//! included, as `bulge fit` runs it).
//!
//!     cargo bench -p bulge-bench --bench fit

use bulge::fit::StressMeasure;
use bulge::fit::hyperelastic::{self, Equibiaxial, Kind};
use bulge::fit::quartic;
use bulge::io::Table;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn quartic_1000(c: &mut Criterion) {
    let n = 1000;
    let strain: Vec<f64> = (0..n)
        .map(|i| 0.01 + 1.5 * i as f64 / (n - 1) as f64)
        .collect();
    let coeffs = [1.2e6, -1.5e6, 1.1e6, -2.0e5, 4.0e4];
    // Deterministic pseudo-noise of about 1 %.
    let modulus: Vec<f64> = strain
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            quartic::eval(&coeffs, e)
                * (1.0 + 0.01 * ((i as f64 * 12.9898).sin() * 43758.5453).fract())
        })
        .collect();
    c.bench_function("quartic degree 4, 1000 points", |b| {
        b.iter(|| quartic::fit(black_box(&strain), black_box(&modulus), 4).unwrap())
    });
}

fn hyperelastic_treloar(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/treloar_equibiaxial.csv");
    let t = Table::read(&path).unwrap();
    let data = Equibiaxial {
        stretch: t.numbers("stretch").unwrap(),
        stress_pa: t.numbers("nominal_stress_pa").unwrap(),
        measure: StressMeasure::Nominal,
    };
    let mut g = c.benchmark_group("treloar");
    for kind in Kind::all() {
        g.bench_function(kind.label(), |b| {
            b.iter(|| hyperelastic::fit(black_box(kind), black_box(&data)).unwrap())
        });
    }
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .without_plots()
}

criterion_group! {
    name = benches;
    config = config();
    targets = quartic_1000, hyperelastic_treloar
}
criterion_main!(benches);
