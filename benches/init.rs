//! `bulge init` against `bulge track`: the set-up found in 100 photos of
//! 1280x960 (spherical caps from 0.15 a to 0.6 a, noise 3, blur 1.5 px,
//! JPEG 90) against tracking the same photos with the experiment file it
//! wrote; paired runs (printed), then criterion.
//!
//! `cargo bench -p bulge-bench --bench init`; set `BULGE_BENCH_QUICK=1` for fewer samples.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

use bulge::experiment::Experiment;
use bulge::track::image::Encoding;
use bulge::track::synth::{self, SequenceSpec};
use bulge::track::{self, Options};

/// `init::find` on 100 photos of 1280x960 (caps from 0.15 a to 0.6 a,
/// noise 3, blur 1.5, JPEG 90) against tracking them with the file it
/// wrote: paired runs, then criterion.
fn init_speed(c: &mut Criterion) {
    use bulge::track::init::{self, Given, Sources};
    let quick = std::env::var_os("BULGE_BENCH_QUICK").is_some();
    let n = 100;
    let dir = tempfile::tempdir().unwrap();
    let s = SequenceSpec::plain(1280, 960, 7, 1.5, 3.0, Encoding::Jpeg(90));
    let a = s.specimen.radius_m;
    let frames: Vec<synth::SynthFrame> = (0..n)
        .map(|k| synth::SynthFrame {
            pressure_pa: 100.0 * (k + 1) as f64,
            silhouette: synth::Silhouette::spherical_cap(
                a,
                a * (0.15 + 0.45 * k as f64 / (n - 1) as f64),
                400,
            ),
        })
        .collect();
    synth::write_sequence(dir.path(), &s, &frames).unwrap();
    let photos = track::list_photos(&dir.path().join("photos"), "*.jpg").unwrap();
    let find = || init::find(&photos, a, Given::default()).unwrap();
    let found = find();
    let path = dir.path().join("init.toml");
    let text = found.experiment_toml(
        &s.specimen,
        &Sources {
            dir: "photos".into(),
            glob: "*.jpg".into(),
            video_every: None,
            count: n,
            pressure_csv: Some("pressure.csv".into()),
            points: None,
        },
    );
    std::fs::write(&path, text).unwrap();
    let setup = track::setup_from_experiment(&Experiment::read(&path).unwrap()).unwrap();
    let pairs = if quick { 5 } else { 11 };
    let (mut ti, mut tt, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..pairs {
        let t0 = std::time::Instant::now();
        std::hint::black_box(find());
        let i = t0.elapsed().as_secs_f64();
        let t0 = std::time::Instant::now();
        std::hint::black_box(track::track(&setup, &Options::default(), &|| {}).unwrap());
        let t = t0.elapsed().as_secs_f64();
        ti.push(i);
        tt.push(t);
        ratio.push(i / t);
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "Set-up against tracking, {n} photos of 1280x960 (median of {pairs} alternating runs):"
    );
    println!("| init s | track s | init / track |");
    println!("|---|---|---|");
    println!(
        "| {:.3} | {:.3} | {:.2} |",
        med(&mut ti),
        med(&mut tt),
        med(&mut ratio)
    );
    let mut g = c.benchmark_group("init_1280x960");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(10);
    if quick {
        g.warm_up_time(std::time::Duration::from_millis(500));
        g.measurement_time(std::time::Duration::from_secs(2));
    }
    g.bench_function("init", |b| b.iter(|| std::hint::black_box(find())));
    g.bench_function("track", |b| {
        b.iter(|| std::hint::black_box(track::track(&setup, &Options::default(), &|| {}).unwrap()))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    // No plots: the machine has no system fonts for criterion's plotters backend.
    config = Criterion::default().without_plots();
    targets = init_speed
}
criterion_main!(benches);
