//! Coverage of the 95 % intervals of the law corrected to the heights
//! (`bulge::fit::coverage`): many synthetic inflation tests with known
//! errors on the heights, the pressures, the calibration and the specimen,
//! each fitted as `bulge run` fits (relative errors, and weighted by the
//! heights' standard deviations as `--weighted` does); prints a Markdown table of the share of
//! intervals that hold the true parameters and the true heights, against
//! the 95 % asked for (the binomial standard deviation of a share of `n`
//! is `sqrt(0.95 * 0.05 / n)`: 1.5 points for 200 experiments).
//!
//!     cargo run --release --example coverage [experiments]

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
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200);
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
                        "{:.1} % of {}",
                        100.0 * c.band.0 as f64 / c.band.1 as f64,
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
