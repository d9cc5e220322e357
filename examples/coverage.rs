//! Coverage of the 95 % intervals of the law corrected to the heights
//! (`bulge::fit::coverage`): many synthetic inflation tests with known
//! errors on the heights, the pressures, the calibration and the specimen,
//! each fitted as `bulge run` fits (relative errors, and weighted by the
//! heights' standard deviations as `--weighted` does); prints a Markdown table of the share of
//! intervals that hold the true parameters and the true heights, against
//! the 95 % asked for (the binomial standard deviation of a share of `n`
//! is `sqrt(0.95 * 0.05 / n)`: 1.5 points for 200 experiments).
//!
//!     cargo run --release --features harness --example coverage [experiments]
//!
//! With `--photos N`, the same study through photos
//! (`bulge::fit::coverage::photos`): N experiments per case, each rendered
//! by `bulge synth`'s renderer (sensor noise, blur, JPEG), written with an
//! experiment file that states the errors, and run through the pipeline
//! (track, stress, fit with the correction and its covariance, the band);
//! the heights' own errors are the tracker's. Each share is printed with
//! its binomial standard error `sqrt(s (1 - s) / n)`, the band's share with
//! the standard error from the spread of the experiments' own shares.
//!
//!     cargo run --release --features harness --example coverage -- --photos 100

use bulge::experiment::Specimen;
use bulge::fit::coverage::{self, Plan};
use bulge::fit::uncertainty::Sources;
use bulge::material::{Material, Model};

fn material(model: Model) -> Material {
    Material {
        model,
        poisson: 0.45,
        fit: None,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--photos") {
        let n = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(100);
        photos(n);
        return;
    }
    let n: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(200);
    let specimen = Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    // A laboratory's errors: heights 30 um (0.2 px at 150 um/px), pressure
    // noise 4 Pa, gauge 0.5 % of the reading, thickness 3 %, radius 0.3 %,
    // scale 0.3 %, clamp row 20 um.
    let all = Sources {
        pressure_std_pa: 4.0,
        pressure_relative_std: 0.005,
        thickness_std_m: 0.03 * 3.5e-4,
        radius_std_m: 0.003 * 0.0375,
        scale_relative_std: 0.003,
        height_offset_std_m: 2e-5,
        ..Sources::default()
    };
    let mr = material(Model::MooneyRivlin {
        c1_pa: 0.12e6,
        c2_pa: 0.03e6,
    });
    let nh = material(Model::NeoHookean { c1_pa: 0.2e6 });
    let cases: Vec<(&str, Plan)> = vec![
        (
            "Mooney-Rivlin, 8 photos, every source",
            Plan {
                truth: mr.clone(),
                specimen,
                pressures_pa: (0..8).map(|i| 600.0 + 350.0 * i as f64).collect(),
                height_std_m: 3e-5,
                sources: all,
                experiments: n,
                seed: 1,
                weighted: false,
            },
        ),
        (
            "Mooney-Rivlin, 8 photos, heights 5 um (shared errors dominate)",
            Plan {
                truth: mr.clone(),
                specimen,
                pressures_pa: (0..8).map(|i| 600.0 + 350.0 * i as f64).collect(),
                height_std_m: 5e-6,
                sources: all,
                experiments: n,
                seed: 1_000_001,
                weighted: false,
            },
        ),
        (
            "neo-Hookean, 12 photos, every source",
            Plan {
                truth: nh.clone(),
                specimen,
                pressures_pa: (0..12).map(|i| 500.0 + 450.0 * i as f64).collect(),
                height_std_m: 3e-5,
                sources: all,
                experiments: n,
                seed: 2_000_001,
                weighted: false,
            },
        ),
        (
            "neo-Hookean, 12 photos, heights 6 um (as the tracker's at 640x480)",
            Plan {
                truth: nh.clone(),
                specimen,
                pressures_pa: (0..12).map(|i| 500.0 + 450.0 * i as f64).collect(),
                height_std_m: 6e-6,
                sources: all,
                experiments: n,
                seed: 3_000_001,
                weighted: false,
            },
        ),
    ];
    println!(
        "| case | fit | experiments | parameter | covered | covered, points' errors only | mean std error | heights in the band |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let both: Vec<(&str, &str, Plan)> = cases
        .into_iter()
        .flat_map(|(name, plan)| {
            let weighted = Plan {
                weighted: true,
                ..plan.clone()
            };
            [(name, "relative", plan), (name, "weighted", weighted)]
        })
        .collect();
    for (name, how, plan) in &both {
        let t0 = std::time::Instant::now();
        let c = coverage::run(plan, &plan.truth).expect("the plan runs");
        let share = |k: usize| 100.0 * k as f64 / c.experiments as f64;
        for (j, p) in c.names.iter().enumerate() {
            println!(
                "| {name} | {how} | {} | {p} | {:.1} % | {:.1} % | {:.2} % | {} |",
                c.experiments,
                share(c.covered[j]),
                share(c.covered_points_only[j]),
                100.0 * c.mean_relative_std[j],
                if j == 0 {
                    format!(
                        "{:.1} % +- {:.1} of {}",
                        100.0 * c.band.0 as f64 / c.band.1 as f64,
                        100.0 * c.band_std_error,
                        c.band.1
                    )
                } else {
                    String::new()
                }
            );
        }
        eprintln!("{name}, {how}: {:.1} s", t0.elapsed().as_secs_f64());
    }
}

#[cfg(not(feature = "opencv"))]
fn photos(_: usize) {
    eprintln!("--photos needs the opencv feature (the default features)");
    std::process::exit(2);
}

/// The study through photos: `n` experiments per case.
#[cfg(feature = "opencv")]
fn photos(n: usize) {
    use bulge::fit::FitModel;
    use bulge::fit::coverage::photos::{self, Camera, PhotoPlan};
    use bulge::fit::hyperelastic::Kind;
    use bulge::track::image::Encoding;

    let specimen = Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let mr = material(Model::MooneyRivlin {
        c1_pa: 0.12e6,
        c2_pa: 0.03e6,
    });
    let nh = material(Model::NeoHookean { c1_pa: 0.2e6 });
    // The pressure readings and the sheet, as asked of a laboratory:
    // reading noise 4 Pa, gauge 0.5 % of the reading, thickness 3 %.
    let readings = Sources {
        pressure_std_pa: 4.0,
        pressure_relative_std: 0.005,
        thickness_std_m: 0.03 * 3.5e-4,
        ..Sources::default()
    };
    // And the radius 0.3 %, the scale 0.3 %, the clamp row 20 um.
    let all = Sources {
        radius_std_m: 0.003 * 0.0375,
        scale_relative_std: 0.003,
        height_offset_std_m: 2e-5,
        ..readings
    };
    let noise_only = Sources {
        pressure_std_pa: 4.0,
        ..Sources::default()
    };
    let camera = Camera {
        width: 640,
        height: 480,
        blur_px: 1.5,
        noise_grey: 3.0,
        encoding: Encoding::Jpeg(85),
    };
    let small = Camera {
        width: 320,
        height: 240,
        blur_px: 1.0,
        noise_grey: 3.0,
        encoding: Encoding::Jpeg(90),
    };
    let mr_p: Vec<f64> = (0..8).map(|i| 600.0 + 350.0 * i as f64).collect();
    let plan = |truth: &Material, kind, pressures: &Vec<f64>, sources, camera, seed| PhotoPlan {
        truth: truth.clone(),
        fit: FitModel::Hyperelastic(kind),
        specimen,
        pressures_pa: pressures.clone(),
        sources,
        camera,
        experiments: n,
        seed,
        weighted: false,
    };
    let cases: Vec<(&str, PhotoPlan)> = vec![
        (
            "Mooney-Rivlin, 8 photos 640x480, pressures and thickness",
            plan(&mr, Kind::MooneyRivlin, &mr_p, readings, camera, 1),
        ),
        (
            "Mooney-Rivlin, 8 photos 640x480, photos and reading noise only",
            plan(
                &mr,
                Kind::MooneyRivlin,
                &mr_p,
                noise_only,
                camera,
                1_000_001,
            ),
        ),
        (
            "Mooney-Rivlin, 8 photos 320x240, photos and reading noise only",
            plan(&mr, Kind::MooneyRivlin, &mr_p, noise_only, small, 2_000_001),
        ),
        (
            "neo-Hookean, 12 photos 640x480, every source",
            plan(
                &nh,
                Kind::NeoHookean,
                &(0..12).map(|i| 500.0 + 450.0 * i as f64).collect(),
                all,
                camera,
                3_000_001,
            ),
        ),
    ];
    println!(
        "| case | fit | experiments | parameter | covered | covered, points' errors only | mean std error | heights in the band | tracker RMS(err/std), mean std |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let dir = tempfile::tempdir().expect("a temporary folder");
    let both: Vec<(&str, &str, PhotoPlan)> = cases
        .into_iter()
        .flat_map(|(name, plan)| {
            let weighted = PhotoPlan {
                weighted: true,
                ..plan.clone()
            };
            [(name, "relative", plan), (name, "weighted", weighted)]
        })
        .collect();
    for (name, how, plan) in &both {
        let t0 = std::time::Instant::now();
        let r = photos::run(plan, dir.path(), 0).expect("the plan runs");
        let c = &r.coverage;
        let share = |k: usize, n: usize| {
            let s = k as f64 / n.max(1) as f64;
            format!(
                "{:.1} % +- {:.1}",
                100.0 * s,
                100.0 * (s * (1.0 - s) / n.max(1) as f64).sqrt()
            )
        };
        for (j, p) in c.names.iter().enumerate() {
            let (band, tracker) = if j == 0 {
                (
                    format!(
                        "{:.1} % +- {:.1} of {}",
                        100.0 * c.band.0 as f64 / c.band.1.max(1) as f64,
                        100.0 * c.band_std_error,
                        c.band.1
                    ),
                    format!("{:.2}, {:.1} um", r.height_z_rms, 1e6 * r.mean_height_std_m),
                )
            } else {
                (String::new(), String::new())
            };
            println!(
                "| {name} | {how} | {} | {p} | {} | {} | {:.2} % | {band} | {tracker} |",
                c.experiments,
                share(c.covered[j], c.experiments),
                share(c.covered_points_only[j], c.experiments),
                100.0 * c.mean_relative_std[j],
            );
        }
        for (i, why) in &r.failed {
            eprintln!("{name}, {how}: experiment {i} left out: {why}");
        }
        eprintln!("{name}, {how}: {:.1} s", t0.elapsed().as_secs_f64());
    }
}
