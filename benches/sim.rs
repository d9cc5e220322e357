//! Benchmarks of the membrane solver.
//!
//! * `forces/*`: one force evaluation on discs of about 1e4 and 1e5 nodes;
//!   throughput in spring updates (Van Gelder, Lloyd: edges) or triangle
//!   updates (TP MSS) per second.
//! * `disc3/*`: the latex disc of Tudruj et al. (2023) (a = 37.5 mm, t = 0.35 mm,
//!   nu = 0.45, linear E = 1 MPa) solved at 5000, 7300 and 8940 Pa from rest,
//!   per spring model, solver and mesh size.
//!
//! `BULGE_SIM_TABLE=1 cargo bench -p bulge-bench --bench sim` prints instead the tables of
//! docs/simulate.md: time against mesh size and against the height error
//! (single timed runs, one core), the reference being the finest mesh of the
//! same model.

use std::hint::black_box;
use std::time::Instant;

use bulge::material::{Material, Model};
use bulge::sim::mesh::{self, DiscOptions};
use bulge::sim::scene::DiscPredictor;
use bulge::sim::solve::{self, Options, Solver};
use bulge::sim::springs::{Membrane, SpringModel};
use criterion::{BenchmarkId, Criterion, Throughput};
use nalgebra::{Point3, Vector3};

const A: f64 = 0.0375;
const T: f64 = 0.35e-3;
const PRESSURES: [f64; 3] = [5000.0, 7300.0, 8940.0];

fn material() -> Material {
    Material {
        model: Model::Linear { young_pa: 1.0e6 },
        poisson: 0.45,
        fit: None,
    }
}

/// Heights at the three pressures, total iterations.
fn solve3(model: SpringModel, solver: Solver, rings: usize, tol: f64) -> ([f64; 3], usize) {
    let m = mesh::disc(DiscOptions {
        radius_m: A,
        rings,
        sector: true,
    })
    .unwrap();
    let mat = material();
    let mut mem = Membrane::new(&m, model, &mat, T, 1100.0).unwrap();
    let pred = DiscPredictor {
        radius_m: A,
        young_pa: 1.0e6,
        thickness_m: T,
        poisson: 0.45,
    };
    let opts = Options {
        tolerance: tol,
        ..Options::default()
    };
    let mut x = m.nodes.clone();
    let mut ws = None;
    let mut h = [0.0; 3];
    let mut its = 0;
    let mut p0 = 0.0;
    for (k, &p) in PRESSURES.iter().enumerate() {
        let s = solve::continuation(
            &mut mem, &m.nodes, &mut x, p0, p, solver, &opts, &pred, &mut ws,
        )
        .unwrap();
        its += s.iterations;
        h[k] = x[0].z;
        p0 = p;
    }
    (h, its)
}

fn deformed(m: &mesh::Mesh) -> Vec<Point3<f64>> {
    m.nodes
        .iter()
        .map(|p| {
            let r2 = (p.x * p.x + p.y * p.y) / (A * A);
            Point3::new(p.x * 1.01, p.y * 1.01, 0.4 * A * (1.0 - r2))
        })
        .collect()
}

fn bench_forces(c: &mut Criterion) {
    let mut g = c.benchmark_group("forces");
    g.sample_size(20);
    for rings in [140usize, 446] {
        let m = mesh::disc(DiscOptions {
            radius_m: A,
            rings,
            sector: true,
        })
        .unwrap();
        let x = deformed(&m);
        let mut f = vec![Vector3::zeros(); x.len()];
        for model in SpringModel::ALL {
            let mut mem = Membrane::new(&m, model, &material(), T, 1100.0).unwrap();
            mem.pressure_pa = 5000.0;
            let n = match model {
                SpringModel::VanGelder | SpringModel::Lloyd => mem.springs(),
                _ => mem.triangles(),
            };
            g.throughput(Throughput::Elements(n as u64));
            g.bench_with_input(BenchmarkId::new(model.name(), m.nodes.len()), &x, |b, x| {
                b.iter(|| mem.forces(black_box(x), &mut f).unwrap())
            });
        }
    }
    g.finish();
}

fn bench_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("disc3");
    g.sample_size(10);
    for model in [SpringModel::Tp, SpringModel::VanGelder] {
        for (solver, sizes) in [
            (Solver::Newton, &[6usize, 12, 43][..]),
            (Solver::Dr, &[6usize, 12, 24][..]),
        ] {
            for &rings in sizes {
                let nodes = (rings + 1) * (rings + 2) / 2;
                g.bench_function(
                    BenchmarkId::new(format!("{}/{}", model.name(), solver.name()), nodes),
                    |b| b.iter(|| solve3(model, solver, rings, 1e-8)),
                );
            }
        }
    }
    g.finish();
}

fn tables() {
    println!("## Disc at three pressures: time against mesh size and height error\n");
    println!(
        "Newton, tolerance 1e-8 (DR: 1e-6), one core (faer sequential), optimised build (dev profile at opt-level 3). Error: largest of the three"
    );
    println!("heights' deviation from the same model's finest mesh, %.\n");
    println!("| model | solver | rings | nodes | h(8940 Pa) mm | error % | iterations | time s |");
    println!("|---|---|---|---|---|---|---|---|");
    let sizes = [6usize, 8, 12, 16, 24, 32, 48, 64, 96, 140, 200, 300, 446];
    for model in SpringModel::ALL {
        let mut rows = Vec::new();
        for &rings in &sizes {
            let t0 = Instant::now();
            let (h, its) = solve3(model, Solver::Newton, rings, 1e-8);
            rows.push((Solver::Newton, rings, h, its, t0.elapsed().as_secs_f64()));
        }
        for &rings in &sizes[..6] {
            let t0 = Instant::now();
            let (h, its) = solve3(model, Solver::Dr, rings, 1e-6);
            rows.push((Solver::Dr, rings, h, its, t0.elapsed().as_secs_f64()));
        }
        let href = rows
            .iter()
            .find(|r| r.0 == Solver::Newton && r.1 == 446)
            .expect("finest")
            .2;
        for (solver, rings, h, its, wall) in rows {
            let err = (0..3)
                .map(|k| ((h[k] - href[k]) / href[k]).abs())
                .fold(0.0, f64::max)
                * 100.0;
            println!(
                "| {} | {} | {} | {} | {:.4} | {:.3} | {} | {:.4} |",
                model.name(),
                solver.name(),
                rings,
                (rings + 1) * (rings + 2) / 2,
                h[2] * 1e3,
                err,
                its,
                wall
            );
        }
    }
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    if std::env::var_os("BULGE_SIM_TABLE").is_some() {
        tables();
        return;
    }
    let mut c = Criterion::default().without_plots().configure_from_args();
    bench_forces(&mut c);
    bench_solve(&mut c);
    c.final_summary();
}
