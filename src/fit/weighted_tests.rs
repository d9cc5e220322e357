//! The weighted fits to stress/strain points on synthetic bubble tests with
//! a known law: heights drawn about the exact ones of the law with a known
//! standard deviation, the stress stage run on them, the law fitted
//! weighted and unweighted, many times.

use super::data::Loaded;
use super::hyperelastic::Kind;
use super::material_fit::{FitDetail, FitModel, FitSettings, FittedMaterial, fit_material};
use super::quartic;
use super::uncertainty::student_t_quantile;
use crate::experiment::Specimen;
use crate::mechanics::{
    self, Modulus, ModulusStress, Options, Point, StrainMeasure, TrueStress, cap_radius,
    engineering_strain,
};
use crate::numerics::Rng;

/// The paper's latex disc (a = 37.5 mm, t = 0.5 mm).
fn disc() -> Specimen {
    Specimen {
        radius_m: 0.0375,
        thickness_m: 0.0005,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    }
}

/// The stress stage's choices the synthetic pressures are built for: the
/// secant modulus `(1 - nu) sigma / eps` of the pole stress `sigma = p R / 2t`.
fn options() -> Options {
    Options {
        strain: StrainMeasure::Engineering,
        true_stress: TrueStress::Paper,
        modulus: Modulus::Biaxial,
        modulus_stress: ModulusStress::Stress,
    }
}

/// Twenty heights from 8 % to 70 % of the radius: the first photos of a
/// test, where the secant modulus divides by a small strain, included.
fn heights(s: &Specimen) -> Vec<f64> {
    (0..20)
        .map(|j| s.radius_m * (0.08 + 0.62 * j as f64 / 19.0))
        .collect()
}

/// The pressure at which the cap of height `h` has the pole stress
/// `sigma(eps)`: `p = 2 t sigma / R` (the spherical-cap formulas).
fn pressure(s: &Specimen, h: f64, sigma: impl Fn(f64, f64) -> f64) -> f64 {
    let eps = engineering_strain(s.radius_m, 0.0, h);
    2.0 * s.thickness_m * sigma(eps, 1.0 + eps) / cap_radius(s.radius_m, h)
}

/// The exact points of the pole stress `sigma(eps)` at the heights `hs`,
/// the `j`-th with the standard deviation `sd(j)`.
fn exact_points(
    s: &Specimen,
    hs: &[f64],
    sigma: impl Fn(f64) -> f64,
    sd: impl Fn(usize) -> Option<f64>,
) -> Vec<Point> {
    hs.iter()
        .enumerate()
        .map(|(j, &h)| Point {
            pressure_pa: pressure(s, h, |e, _| sigma(e)),
            height_m: h,
            height_std_m: sd(j),
        })
        .collect()
}

/// The stress stage's rows of one synthetic test: the exact heights of the
/// law at `pressures`, each moved by a normal draw of `sd`.
fn rows(s: &Specimen, pressures: &[f64], exact: &[f64], sd: f64, rng: &mut Rng) -> Loaded {
    let points: Vec<Point> = pressures
        .iter()
        .zip(exact)
        .map(|(&p, &h)| Point {
            pressure_pa: p,
            height_m: h + sd * rng.normal(),
            height_std_m: Some(sd),
        })
        .collect();
    let rows = mechanics::stress_strain(s, &options(), &points).expect("valid points");
    Loaded::from_stress_rows(&rows, StrainMeasure::Engineering)
}

/// What many fits of one parameter gave.
#[derive(Default)]
struct Tally {
    sq_error: f64,
    covered: usize,
    chi2: f64,
    n: usize,
}

impl Tally {
    fn add(&mut self, value: f64, se: f64, truth: f64, t95: f64, chi2: Option<f64>) {
        self.sq_error += (value - truth).powi(2);
        self.covered += usize::from((value - truth).abs() <= t95 * se);
        self.chi2 += chi2.unwrap_or(f64::NAN);
        self.n += 1;
    }
    fn rms(&self) -> f64 {
        (self.sq_error / self.n as f64).sqrt()
    }
    fn coverage(&self) -> f64 {
        self.covered as f64 / self.n as f64
    }
    fn chi2(&self) -> f64 {
        self.chi2 / self.n as f64
    }
}

/// 400 synthetic tests (heights `hs` at pressures `ps`, 40 um of noise,
/// seeds from `seed`), each fitted with `model` unweighted and weighted;
/// `judged` reads the parameter judged, its standard error and
/// `chi2_per_dof` from a fit; its truth `truth`, `dof` the residual degrees
/// of freedom. Prints the tallies and returns them, unweighted first.
fn unweighted_and_weighted(
    (model, name): (FitModel, &str),
    (ps, hs): (&[f64], &[f64]),
    seed: u64,
    (truth, dof): (f64, usize),
    judged: impl Fn(&FittedMaterial) -> (f64, f64, Option<f64>),
) -> [Tally; 2] {
    let s = disc();
    let t95 = student_t_quantile(0.975, dof as f64);
    let mut out = [Tally::default(), Tally::default()];
    for i in 0..400 {
        let data = rows(&s, ps, hs, 40e-6, &mut Rng::new(seed + i));
        for (tally, weighted) in out.iter_mut().zip([false, true]) {
            let settings = FitSettings {
                model,
                weighted,
                ..FitSettings::default()
            };
            let f = fit_material(&data, &settings, "synthetic").expect("fits");
            assert_eq!(f.material.fit.as_ref().unwrap().weights.is_some(), weighted);
            let (value, se, chi2) = judged(&f);
            tally.add(value, se, truth, t95, chi2);
        }
    }
    for (how, t) in ["unweighted", "weighted"].iter().zip(&out) {
        println!(
            "{name} {how}: rms error {:.1} Pa, 95 % intervals cover {:.1} %, chi2/dof {:.3}",
            t.rms(),
            100.0 * t.coverage(),
            t.chi2()
        );
    }
    out
}

#[test]
fn the_weighted_modulus_law_is_closer_to_the_truth_and_its_intervals_cover_it() {
    let s = disc();
    let k = Modulus::Biaxial.factor(s.poisson);
    // A secant modulus falling then rising, as rubber's does.
    let truth = [1.0e6, -1.5e6, 2.5e6];
    let hs = heights(&s);
    let ps: Vec<f64> = hs
        .iter()
        .map(|&h| pressure(&s, h, |e, _| quartic::eval(&truth, e) * e / k))
        .collect();
    let [plain, weighted] = unweighted_and_weighted(
        (FitModel::Quartic { degree: 2 }, "quartic c0"),
        (&ps, &hs),
        7000,
        (truth[0], hs.len() - 3),
        |f| {
            let FitDetail::Quartic(q) = &f.detail else {
                panic!("a quartic")
            };
            let se = q.std_errors_pa.as_ref().expect("standard errors")[0];
            (q.coefficients_pa[0], se, q.chi2_per_dof)
        },
    );
    // The weighted estimate is the better one by far: the small-strain
    // points, whose modulus divides by a small strain, no longer steer the
    // law; and the unweighted intervals, which take every point as sure as
    // the others, promise too much.
    assert!(weighted.rms() < 0.6 * plain.rms());
    assert!(plain.coverage() < 0.85);
    // The weighted intervals hold their promise (400 runs: 95 % +- 1.1 %
    // at one sd)...
    assert!((0.92..=0.98).contains(&weighted.coverage()));
    // ...and the standard deviations carried from the heights' explain the
    // residuals' scatter.
    assert!((0.85..=1.15).contains(&weighted.chi2()));
}

#[test]
fn the_weighted_neo_hookean_fit_covers_its_truth() {
    let s = disc();
    let c1 = 0.2e6;
    // The Cauchy stress `2 C1 (l^2 - l^-4)` of an equibiaxial neo-Hookean
    // membrane at the cap's stretch, as the stress stage's rows read it
    // (`l^2 p R / 2t`): the pole stress is that over `l^2`.
    let hs = heights(&s);
    let ps: Vec<f64> = hs
        .iter()
        .map(|&h| pressure(&s, h, |_, l| 2.0 * c1 * (l * l - l.powi(-4)) / (l * l)))
        .collect();
    let [plain, weighted] = unweighted_and_weighted(
        (FitModel::Hyperelastic(Kind::NeoHookean), "neo-Hookean C1"),
        (&ps, &hs),
        9000,
        (c1, hs.len() - 1),
        |f| {
            let FitDetail::Hyper { fits, best } = &f.detail else {
                panic!("a hyperelastic fit")
            };
            let p = &fits[*best].params[0];
            let se = p.std_error.expect("a standard error");
            (p.value, se, fits[*best].chi2_per_dof)
        },
    );
    assert!(weighted.rms() < plain.rms());
    assert!((0.92..=0.98).contains(&weighted.coverage()));
    assert!((0.85..=1.15).contains(&weighted.chi2()));
}

#[test]
fn a_weighted_fit_of_rows_without_uncertainty_says_it_was_not_weighted() {
    let s = disc();
    let hs = heights(&s);
    let points = exact_points(&s, &hs, |e| 1e6 * e, |_| None);
    let rows = mechanics::stress_strain(&s, &options(), &points).unwrap();
    let data = Loaded::from_stress_rows(&rows, StrainMeasure::Engineering);
    let f = fit_material(
        &data,
        &FitSettings {
            weighted: true,
            ..FitSettings::default()
        },
        "synthetic",
    )
    .unwrap();
    let prov = f.material.fit.as_ref().unwrap();
    assert!(prov.weights.is_none() && prov.chi2_per_dof.is_none());
    assert!(
        f.warnings.iter().any(|w| w.contains("fitted unweighted")),
        "{:?}",
        f.warnings
    );
}

#[test]
fn stress_strain_csv_carries_the_shifts_that_weigh_the_fits() {
    let s = disc();
    let hs = heights(&s);
    let points = exact_points(
        &s,
        &hs,
        |e| 1e6 * e * (1.0 + e),
        |j| Some(10e-6 * (1.0 + j as f64)),
    );
    let rows = mechanics::stress_strain(&s, &options(), &points).unwrap();
    let direct = Loaded::from_stress_rows(&rows, StrainMeasure::Engineering);
    let out = crate::pipeline::StressOut {
        points,
        rows,
        shifts: Vec::new(),
    };
    let bytes = out.csv(None).into_bytes();
    let table = crate::io::Table::parse(std::path::Path::new("ss.csv"), &bytes).unwrap();
    let opts = super::data::LoadOptions {
        stress_measure: None,
        strain_measure: None,
        poisson: s.poisson,
        modulus: Modulus::Biaxial,
    };
    let read = super::data::load(&table, &opts).unwrap();
    assert_eq!(read.shifts.len(), direct.shifts.len());
    for (a, b) in read.shifts.iter().zip(&direct.shifts) {
        let (a, b) = (a.expect("read"), b.expect("direct"));
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y.abs().max(1e-300);
        assert!(close(a.stretch, b.stretch) && close(a.strain, b.strain));
        assert!(close(a.stress_pa, b.stress_pa), "{a:?} {b:?}");
        assert!(
            close(a.modulus_pa.unwrap(), b.modulus_pa.unwrap()),
            "{a:?} {b:?}"
        );
        // Below the hemisphere a rising height lowers the pole stress and
        // the secant modulus: the signs the correlations carry.
        assert!(b.modulus_pa.unwrap() < 0.0);
    }
}
