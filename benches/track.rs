//! `bulge track` speed and accuracy.
//!
//! 1. Accuracy table (printed): RMS apex error against the synthetic truth
//!    for the integer match (minMaxLoc alone), the 2-D quadratic peak fit and
//!    the edge fit, on 640x480 sequences of 20 spherical caps, seeds 1..=3
//!    (the tests use other seeds), clean PNG and noisy (noise 3 grey levels,
//!    blur 1.5 px, JPEG quality 85).
//! 2. Speed (criterion): photos per second for `track` against decoding
//!    alone (read + OpenCV grayscale decode, in parallel the same way) on the
//!    same JPEG files, at 640x480 and 4000x3000.
//!
//! `cargo bench -p bulge-bench --bench track`; set `BULGE_BENCH_QUICK=1` for fewer samples.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rayon::prelude::*;

use bulge::experiment::Experiment;
use bulge::track::image::{Encoding, decode_mat};
use bulge::track::synth::{self, SequenceSpec};
use bulge::track::{self, Options, Refine};

fn write(dir: &std::path::Path, s: &SequenceSpec, n: usize) -> (track::Setup, synth::Written) {
    let frames = synth::cap_frames(s.specimen.radius_m, 0.6 * s.specimen.radius_m, n);
    let w = synth::write_sequence(dir, s, &frames).expect("sequence");
    let e = Experiment::read(dir.join("experiment.toml")).expect("experiment");
    (track::setup_from_experiment(&e).expect("setup"), w)
}

fn accuracy_table() {
    println!("\nRMS apex error, px (640x480, 20 frames per seed, seeds 1..=3, x / y):");
    println!(
        "| condition | integer (minMaxLoc) | quadratic peak fit | edge fit (reported) | RMS(err/std) of y |"
    );
    println!("|---|---|---|---|---|");
    for (name, blur, noise, enc) in [
        ("clean, PNG", 0.0, 0.0, Encoding::Png),
        ("noise 3, blur 1.5, JPEG 85", 1.5, 3.0, Encoding::Jpeg(85)),
    ] {
        let mut sq = [[0.0f64; 2]; 3];
        let mut z2 = 0.0;
        let mut n = 0usize;
        for seed in 1..=3u64 {
            let dir = tempfile::tempdir().unwrap();
            let (setup, w) = write(
                dir.path(),
                &SequenceSpec::plain(640, 480, seed, blur, noise, enc),
                20,
            );
            // Each refinement tracked on its own (the edge mode's seed is a
            // coarser match, not the full-resolution one).
            let errors = |refine| {
                // Frames the plausibility guards refuse are left out
                // (counted on stderr), as `--skip-bad-frames` does.
                let opts = Options {
                    refine,
                    skip_bad_frames: true,
                    ..Options::default()
                };
                let t = track::track(&setup, &opts, &|| {}).unwrap();
                if !t.skipped.is_empty() {
                    eprintln!(
                        "seed {seed}, {refine:?}: {} frames left out",
                        t.skipped.len()
                    );
                }
                synth::apex_errors(&t.rows, &w.truth)
            };
            let e = errors(Refine::Edge);
            let (ei, eq) = (errors(Refine::Integer), errors(Refine::Quadratic));
            for (s, v) in sq.iter_mut().zip([ei.integer, eq.quadratic, e.reported]) {
                s[0] += v[0] * v[0] * e.frames as f64;
                s[1] += v[1] * v[1] * e.frames as f64;
            }
            z2 += e.y_z_rms * e.y_z_rms * e.frames as f64;
            n += e.frames;
        }
        let f = |s: [f64; 2]| {
            format!(
                "{:.3} / {:.3}",
                (s[0] / n as f64).sqrt(),
                (s[1] / n as f64).sqrt()
            )
        };
        println!(
            "| {name} | {} | {} | {} | {:.2} |",
            f(sq[0]),
            f(sq[1]),
            f(sq[2]),
            (z2 / n as f64).sqrt()
        );
    }
    println!();
}

fn speed(c: &mut Criterion) {
    accuracy_table();
    let quick = std::env::var_os("BULGE_BENCH_QUICK").is_some();
    println!("Paired runs (median of alternating decode-only / track runs), photos per second:");
    println!("| size | photos | decode only | track (edge) | ratio |");
    println!("|---|---|---|---|---|");
    for (w, h, n) in [(640usize, 480usize, 32usize), (4000, 3000, 8)] {
        let dir = tempfile::tempdir().unwrap();
        let (setup, written) = write(
            dir.path(),
            &SequenceSpec::plain(w, h, 9, 1.0, 2.0, Encoding::Jpeg(90)),
            n,
        );
        let paths: Vec<PathBuf> = setup.frames.iter().map(|f| f.path.clone()).collect();
        eprintln!(
            "{w}x{h}: {n} JPEG photos, {:.1} MB",
            written.photo_bytes as f64 / 1e6
        );
        let t = track::track(&setup, &Options::default(), &|| {}).unwrap();
        eprintln!(
            "{w}x{h}: matching and fitting take {:.2} ms per photo (sequential part)",
            1e3 * t.locate_seconds / n as f64
        );
        // Paired measurement: decoding alone and tracking alternate, so that
        // both see the same machine load (the ratio is what matters).
        let decode_all = || {
            paths.par_iter().for_each(|p| {
                let bytes = std::fs::read(p).unwrap();
                std::hint::black_box(decode_mat(&bytes).unwrap());
            })
        };
        let pairs = if quick { 7 } else { 15 };
        let (mut td, mut tt, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..pairs {
            let t0 = std::time::Instant::now();
            decode_all();
            let d = t0.elapsed().as_secs_f64();
            let t0 = std::time::Instant::now();
            std::hint::black_box(track::track(&setup, &Options::default(), &|| {}).unwrap());
            let t = t0.elapsed().as_secs_f64();
            td.push(n as f64 / d);
            tt.push(n as f64 / t);
            ratio.push(d / t);
        }
        let med = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        println!(
            "| {w}x{h} | {n} | {:.1} | {:.1} | {:.2} |",
            med(&mut td),
            med(&mut tt),
            med(&mut ratio)
        );
        let mut g = c.benchmark_group(format!("track_{w}x{h}"));
        g.throughput(Throughput::Elements(n as u64));
        g.sample_size(10);
        if quick {
            g.warm_up_time(std::time::Duration::from_millis(500));
            g.measurement_time(std::time::Duration::from_secs(2));
        }
        g.bench_function("decode_only", |b| {
            b.iter(|| {
                paths.par_iter().for_each(|p| {
                    let bytes = std::fs::read(p).unwrap();
                    let m = decode_mat(&bytes).unwrap();
                    std::hint::black_box(m);
                })
            })
        });
        for refine in [Refine::Edge, Refine::Integer] {
            let opts = Options {
                refine,
                ..Options::default()
            };
            g.bench_function(format!("track_{refine:?}").to_lowercase(), |b| {
                b.iter(|| std::hint::black_box(track::track(&setup, &opts, &|| {}).unwrap()))
            });
        }
        g.finish();
    }
}

criterion_group! {
    name = benches;
    // No plots: the machine has no system fonts for criterion's plotters backend.
    config = Criterion::default().without_plots();
    targets = speed
}
criterion_main!(benches);
