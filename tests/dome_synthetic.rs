//! The dome search on synthetic slack-membrane data from an independent
//! solver: the exact axisymmetric inflation (`axisym::solve_pressure`) of a
//! clamped dome of known stress-free height `h0` and a known stiffening law,
//! its apex heights measured from a slack reference state that hangs below
//! the dome (as a 3D image correlation of a slack fabric gives them), with
//! seeded noise, through `bulge::dome::stage`.

use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::mechanics::Point;
use bulge::pipeline::Settings;

/// Seeded standard normal draws (Box-Muller on a 64-bit LCG).
fn normals(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| (-2.0 * u().ln()).sqrt() * (2.0 * std::f64::consts::PI * u()).cos())
        .collect()
}

fn case(h0: f64, reference: f64, noise: f64, seed: u64) -> (bulge::dome::Found, f64) {
    let spec = Specimen {
        radius_m: 0.1,
        thickness_m: 0.81e-3,
        poisson: 0.45,
        prebulge_height_m: h0,
    };
    // a stiffening law (Yeoh), a few MPa at small strain like a coated fabric
    let law = Material {
        model: Model::Yeoh {
            c1_pa: 1.5e6,
            c2_pa: 4.0e6,
            c3_pa: 0.0,
        },
        poisson: 0.45,
        fit: None,
    };
    let pressures: Vec<f64> = (0..12).map(|k| 2000.0 + 18000.0 * k as f64).collect();
    let z = normals(seed, pressures.len());
    let points: Vec<Point> = pressures
        .iter()
        .zip(&z)
        .map(|(&p, e)| {
            let apex = bulge::axisym::solve_pressure(&law, &spec, p, &Default::default())
                .unwrap()
                .height_m;
            let d = apex - reference;
            Point {
                pressure_pa: p,
                height_m: d * (1.0 + noise * e),
                height_std_m: None,
            }
        })
        .collect();
    let unknown = Specimen {
        prebulge_height_m: 0.0,
        ..spec
    };
    let (found, what) = bulge::dome::stage(&unknown, &Settings::default(), &points, true).unwrap();
    println!("h0 {h0} reference {reference} noise {noise}: {what}");
    (found, h0)
}

/// What the search guarantees on such data: a dome at which the law
/// (a quartic, the run's default) reproduces the heights with positive
/// stiffness, no trial aborting the search. What it does not: the dome
/// height itself. With a reference offset and a five-parameter law the
/// misfit has a long valley along which the law makes up for the dome, and
/// the quartic's own misfit to the true (Yeoh) law moves the optimum along
/// it: on the first case the search finds h0 = 27.6 mm for a true 12 mm
/// (docs/heights.md). The test records the found value and its stated
/// standard deviation and checks the first, not the second.
#[test]
fn the_dome_search_on_a_slack_membrane_reproduces_the_heights() {
    for (h0, reference) in [(0.012, 0.008), (0.02, 0.02)] {
        let (f, h0) = case(h0, reference, 2e-4, 7);
        println!(
            "true h0 {:.2} mm: found {:.2} mm +- {:?}, 95 % interval {:?} mm, determined {}, reference {:.2} mm, rms {:.4} %, {} trials, {} failed",
            1e3 * h0,
            1e3 * f.h0_m,
            f.h0_std_m.map(|s| 1e3 * s),
            f.h0_interval_m.map(|(lo, hi)| (1e3 * lo, 1e3 * hi)),
            f.h0_determined,
            1e3 * f.reference_m,
            100.0 * f.rms,
            f.trials,
            f.failed
        );
        // within the noise (2e-4 relative) and the quartic's model error
        assert!(f.rms < 1e-3, "rms {}", f.rms);
        assert!(f.h0_m > 0.0 && f.h0_m < 0.1);
    }
}
