//! `bulge init` on randomly framed synthetic experiments of the exact
//! neo-Hookean bubble (five photos to about 0.53 a; blur, noise, JPEG;
//! `bulge::track::synth::random_camera`): the set-up found from the photos
//! alone, the heights tracked with the experiment file it wrote. Per camera
//! elevation (0-5 degrees above the clamp plane; 800x600 or 1024x768 with
//! the clamp in the picture when raised, 640x480 to 1280x960 when level) a
//! row of the ranges over seeds 1..=N (`--seeds N`, default 8; the tests use
//! seeds from 201): scale error and its stated standard deviation, clamp
//! row error, elevation error, the largest height error of each experiment;
//! with the scale found, and given.
//!
//! Run: `cargo run --release --features harness --example init_accuracy [-- --seeds N] [--verbose]`

use bulge::track::synth::neo_hookean_bubble;
use bulge::track::synth::trial::{InitTrial, init_and_track};
use bulge::track::synth::{self, Look};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = match args.iter().position(|a| a == "--seeds") {
        Some(i) => args.get(i + 1).ok_or("--seeds needs a number")?.parse()?,
        None => 8,
    };
    let verbose = args.iter().any(|a| a == "--verbose");
    println!(
        "| elevation, degrees | scale | scale error, % | stated scale std, % | clamp row error, px | elevation error, degrees | largest height error, % | within 0.5 % |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for elevation in [0.0, 1.0, 2.0, 3.0, 4.0, 5.0] {
        let sizes: &[(usize, usize)] = if elevation == 0.0 {
            &[(640, 480), (800, 600), (1024, 768), (1280, 960)]
        } else {
            &[(800, 600), (1024, 768)]
        };
        for scale_given in [false, true] {
            let mut all: Vec<InitTrial> = Vec::new();
            for seed in 1..=seeds {
                let mut spec = synth::random_camera(
                    seed,
                    sizes,
                    Look {
                        elevation_deg: elevation,
                        ..Look::default()
                    },
                );
                if elevation > 0.0 {
                    // The clamp's ends (1.25 a) in the picture.
                    spec.framing.axis_x_px = Some(0.5 * spec.width as f64 - 0.3);
                }
                let dir = tempfile::tempdir()?;
                let frames = neo_hookean_bubble(&spec.specimen, 5)?;
                // One experiment at a time: `track` decodes on rayon's pool.
                let t = init_and_track(dir.path(), &spec, &frames, scale_given)?;
                if verbose {
                    eprintln!(
                        "{elevation} degrees, seed {seed} ({}x{}): {t:?}",
                        spec.width, spec.height
                    );
                }
                all.push(t);
            }
            let range = |f: &dyn Fn(&InitTrial) -> f64| {
                let v: Vec<f64> = all.iter().map(f).collect();
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (lo, hi)
            };
            let (s0, s1) = range(&|t| 100.0 * t.scale);
            let (d0, d1) = range(&|t| 100.0 * t.scale_std);
            let (c0, c1) = range(&|t| t.clamp_px);
            let (e0, e1) = range(&|t| t.elevation_deg);
            let (h0, h1) = range(&|t| 100.0 * t.heights);
            let ok = all.iter().filter(|t| t.heights <= 0.005).count();
            let scale = if scale_given { "given" } else { "found" };
            let (s, d) = if scale_given {
                ("-".to_string(), "-".to_string())
            } else {
                (format!("{s0:+.3} to {s1:+.3}"), format!("{d0:.3}-{d1:.3}"))
            };
            println!(
                "| {elevation} | {scale} | {s} | {d} | {c0:+.3} to {c1:+.3} | {e0:+.3} to {e1:+.3} | {h0:.3}-{h1:.3} | {ok} of {} |",
                all.len()
            );
        }
    }
    Ok(())
}
