//! Spring-force throughput: one nodal-force evaluation of the full
//! bubble disc at 5 kPa-like deformation, serial (`Membrane::forces`) and
//! parallel (`sim::par::ParForces` in rayon pools of 1 and 2 threads), for
//! Van Gelder (throughput in spring updates: edges) and TP MSS (triangle
//! updates), at about 1e4 and 1e5 nodes. Targets: 2e7 spring updates/s
//! (Van Gelder) and 1e7 triangle updates/s (TP) on one core; a speed-up on
//! two cores from 1e4 nodes.
//!
//! `cargo bench -p bulge-bench --bench dynamics` (criterion's "thrpt" is updates per second).

use std::hint::black_box;

use bulge::material::{Material, Model};
use bulge::sim::mesh::{self, DiscOptions};
use bulge::sim::par::ParForces;
use bulge::sim::springs::{Membrane, SpringModel};
use criterion::{BenchmarkId, Criterion, Throughput};
use nalgebra::{Point3, Vector3};

fn bench(c: &mut Criterion) {
    let mat = Material {
        model: Model::Linear { young_pa: 1.0e6 },
        poisson: 0.45,
        fit: None,
    };
    let mut g = c.benchmark_group("forces");
    g.sample_size(20);
    for nodes in [10_000usize, 100_000] {
        let rings = mesh::disc_rings_for_nodes(nodes, false);
        let m = mesh::disc(DiscOptions {
            radius_m: 0.0375,
            rings,
            sector: false,
        })
        .unwrap();
        // an inflated shape: Hencky-like profile, 20 mm apex
        let x: Vec<Point3<f64>> = m
            .nodes
            .iter()
            .map(|p| {
                let r2 = (p.x * p.x + p.y * p.y) / (0.0375 * 0.0375);
                Point3::new(p.x, p.y, 0.02 * (1.0 - r2).max(0.0))
            })
            .collect();
        let n = m.nodes.len();
        for model in [SpringModel::VanGelder, SpringModel::Tp] {
            let mut mem = Membrane::new(&m, model, &mat, 0.35e-3, 1100.0).unwrap();
            mem.pressure_pa = 5000.0;
            let units = if model == SpringModel::Tp {
                m.triangles.len()
            } else {
                m.edges.len()
            };
            g.throughput(Throughput::Elements(units as u64));
            let mut f = vec![Vector3::zeros(); n];
            g.bench_function(
                BenchmarkId::new(format!("{}/serial", model.name()), n),
                |b| b.iter(|| mem.forces(black_box(&x), &mut f).unwrap()),
            );
            for threads in [1usize, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut pf = ParForces::new(&m, &mem);
                g.bench_function(
                    BenchmarkId::new(format!("{}/par{threads}", model.name()), n),
                    |b| b.iter(|| pool.install(|| pf.forces(&mem, black_box(&x), &mut f).unwrap())),
                );
            }
        }
    }
    g.finish();
}

fn main() {
    let mut c = Criterion::default().without_plots().configure_from_args();
    bench(&mut c);
    c.final_summary();
}
