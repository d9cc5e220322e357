//! The tracker on photos as they come: randomly framed synthetic
//! experiments (640x480, 1024x768 or 1280x960; 0.05-0.12 mm/px; blur, noise,
//! JPEG; `bulge::track::synth::random_camera`) of the exact neo-Hookean
//! bubble, six photos each up to an apex height of about 0.53 a, drawn
//! plain, with a specular highlight near the apex (grey 80), and with the
//! highlight, clutter behind the bubble (a shelf edge, cables) and uneven
//! light (0.3). Each is tracked with the true set-up and
//! `--skip-bad-frames`; the table gives per look the photos tracked, the
//! RMS apex-row error over them, the RMS of error / stated standard
//! deviation (about 1 when the stated uncertainty is honest), how many
//! are more than 4 of their stated standard deviations off (silently
//! wrong) and the worst ratio.
//! Seeds K..K+N-1 (`--seeds N`, default 16; `--first K`, default 1); the
//! tests use other seeds.
//!
//! Run: `cargo run --release --example track_looks [-- --seeds N] [--first K] [--verbose]`
//! (`--verbose` names every photo beyond 4 standard deviations or 0.3 px).

use bulge::experiment::Experiment;
use bulge::track::synth::{self, Look};
use bulge::track::{Options, setup_from_experiment, track};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = match args.iter().position(|a| a == "--seeds") {
        Some(i) => args.get(i + 1).ok_or("--seeds needs a number")?.parse()?,
        None => 16,
    };
    let first: u64 = match args.iter().position(|a| a == "--first") {
        Some(i) => args.get(i + 1).ok_or("--first needs a number")?.parse()?,
        None => 1,
    };
    let verbose = args.iter().any(|a| a == "--verbose");
    let gloss = Look {
        highlight_grey: 80.0,
        ..Look::default()
    };
    let looks = [
        ("plain", Look::default()),
        ("highlight 80", gloss),
        (
            "highlight 80, clutter, uneven light 0.3",
            Look {
                clutter: true,
                uneven_light: 0.3,
                ..gloss
            },
        ),
    ];
    println!(
        "| look | photos tracked | apex row RMS error, px | RMS error/std | beyond 4 std | worst error/std |"
    );
    println!("|---|---|---|---|---|---|");
    for (name, look) in looks {
        let (mut total, mut tracked, mut sum2, mut beyond, mut worst) = (0, 0, 0.0, 0, 0.0f64);
        let mut z2 = 0.0;
        for seed in first..first + seeds {
            let spec = synth::random_camera(seed, &[(640, 480), (1024, 768), (1280, 960)], look);
            let frames = synth::neo_hookean_bubble(&spec.specimen, 6)?;
            let dir = tempfile::tempdir()?;
            let w = synth::write_sequence(dir.path(), &spec, &frames)?;
            let e = Experiment::read(dir.path().join("experiment.toml"))?;
            let opts = Options {
                skip_bad_frames: true,
                ..Options::default()
            };
            // One sequence at a time: `track` decodes on rayon's pool itself.
            let t = track(&setup_from_experiment(&e)?, &opts, &|| {})?;
            total += w.truth.len();
            for r in &t.rows {
                let truth = w
                    .truth
                    .iter()
                    .find(|x| x.file == r.file)
                    .ok_or("no truth")?;
                let err = r.apex_y_px - truth.apex_y_px;
                let z = err.abs() / r.apex_y_std_px;
                tracked += 1;
                sum2 += err * err;
                z2 += z * z;
                beyond += usize::from(z > 4.0);
                if verbose && (z > 4.0 || err.abs() > 0.3) {
                    eprintln!(
                        "{name}, seed {seed} ({}x{}), {}: apex row {err:+.3} px off, stated std {:.3} px",
                        spec.width, spec.height, r.file, r.apex_y_std_px
                    );
                }
                worst = worst.max(z);
            }
        }
        println!(
            "| {name} | {tracked} of {total} | {:.3} | {:.2} | {beyond} | {worst:.1} |",
            (sum2 / tracked.max(1) as f64).sqrt(),
            (z2 / tracked.max(1) as f64).sqrt()
        );
    }
    Ok(())
}
