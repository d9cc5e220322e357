use super::*;
use proptest::prelude::*;
use std::f64::consts::PI;

fn spec(a: f64, t: f64, nu: f64, h0: f64) -> Specimen {
    Specimen {
        radius_m: a,
        thickness_m: t,
        poisson: nu,
        prebulge_height_m: h0,
    }
}

fn one(s: &Specimen, o: &Options, p: f64, h: f64, sd: Option<f64>) -> Row {
    stress_strain(
        s,
        o,
        &[Point {
            pressure_pa: p,
            height_m: h,
            height_std_m: sd,
        }],
    )
    .expect("valid point")[0]
}

fn rel(got: f64, want: f64) -> f64 {
    if want == 0.0 {
        got.abs()
    } else {
        ((got - want) / want).abs()
    }
}

fn all_options() -> Vec<Options> {
    let mut v = Vec::new();
    for strain in [StrainMeasure::Engineering, StrainMeasure::Log] {
        for true_stress in [TrueStress::Paper, TrueStress::Incompressible] {
            for modulus in [Modulus::Biaxial, Modulus::Uniaxial] {
                for modulus_stress in [
                    ModulusStress::Nominal,
                    ModulusStress::Stress,
                    ModulusStress::True,
                ] {
                    v.push(Options {
                        strain,
                        true_stress,
                        modulus,
                        modulus_stress,
                    });
                }
            }
        }
    }
    v
}

fn parse_opts(f: &[&str]) -> Options {
    Options {
        strain: match f[6] {
            "engineering" => StrainMeasure::Engineering,
            _ => StrainMeasure::Log,
        },
        true_stress: match f[7] {
            "paper" => TrueStress::Paper,
            _ => TrueStress::Incompressible,
        },
        modulus: match f[8] {
            "biaxial" => Modulus::Biaxial,
            _ => Modulus::Uniaxial,
        },
        modulus_stress: match f[9] {
            "nominal" => ModulusStress::Nominal,
            "stress" => ModulusStress::Stress,
            _ => ModulusStress::True,
        },
    }
}

/// Every value and every d/dH of every option against
/// `fixtures/stress/reference.csv`, written by the independent 60-digit
/// script `fixtures/stress/reference.py` (acos form, numerical derivatives).
#[test]
fn matches_independent_reference_script() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/stress/reference.csv");
    let text = std::fs::read_to_string(path).expect("reference.csv");
    let mut worst_value = (0.0_f64, String::new());
    let mut worst_slope = (0.0_f64, String::new());
    let mut rows = 0;
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().expect("number");
        let opt = |i: usize| (!f[i].is_empty()).then(|| num(i));
        let s = spec(num(0), num(1), num(2), num(3));
        let o = parse_opts(&f);
        let (p, h) = (num(5), num(4));
        let got = one(&s, &o, p, h, None).value.to_array();
        let slope = height_derivatives(&s, &o, p, h).to_array();
        for k in 0..7 {
            let want = opt(10 + k);
            assert_eq!(
                got[k].is_some(),
                want.is_some(),
                "{} presence: {line}",
                DERIVED_COLUMNS[k]
            );
            if let (Some(g), Some(w)) = (got[k], want) {
                let e = rel(g, w);
                if e > worst_value.0 {
                    worst_value = (e, format!("{} in {line}", DERIVED_COLUMNS[k]));
                }
            }
            if let (Some(g), Some(w)) = (slope[k], opt(17 + k)) {
                // mp.diff of the acos form: compare against the scale of
                // the value over the height, not a derivative that vanishes
                // (dR/dH = 0 at the hemisphere).
                let scale = w.abs().max(got[k].unwrap_or(0.0).abs() / h * 1e-3);
                let e = (g - w).abs() / scale;
                if e > worst_slope.0 {
                    worst_slope = (e, format!("d{}/dH in {line}", DERIVED_COLUMNS[k]));
                }
            }
        }
        rows += 1;
    }
    assert_eq!(rows, 14 * 24, "every case under every option");
    eprintln!(
        "largest relative error, values: {:.3e} ({})",
        worst_value.0, worst_value.1
    );
    eprintln!(
        "largest relative error, d/dH:   {:.3e} ({})",
        worst_slope.0, worst_slope.1
    );
    assert!(worst_value.0 < 1e-14, "values: {worst_value:?}");
    assert!(worst_slope.0 < 1e-12, "derivatives: {worst_slope:?}");
}

/// Closed forms: the hemisphere `H = a` has `R = a`, `theta = pi/2`,
/// `s = pi a`.
#[test]
fn hemisphere_closed_form() {
    for a in [1.0, 0.0375, 3.0e-3] {
        assert!(rel(cap_radius(a, a), a) < 1e-15);
        assert!(rel(cap_half_angle(a, a), PI / 2.0) < 1e-15);
        assert!(rel(arc_length(a, a), PI * a) < 1e-15);
        assert!(rel(stretch(a, 0.0, a), PI / 2.0) < 1e-15);
    }
}

/// Past the hemisphere (`H = 2a`): `R = 1.25 a`, `theta = 2 atan 2 =
/// acos(-3/5)`, `s = 2.5 a theta`. The paper's asin form (eqs 21-22)
/// returns `pi - theta` there: an arc of 2.318 a, shorter than the
/// hemisphere's pi a although the bubble is twice as high.
#[test]
fn past_the_hemisphere_atan_not_asin() {
    let a = 0.0375;
    let h = 2.0 * a;
    let theta = (-0.6_f64).acos();
    assert!(rel(cap_radius(a, h), 1.25 * a) < 1e-15);
    assert!(rel(cap_half_angle(a, h), theta) < 1e-15);
    assert!(rel(arc_length(a, h), 2.5 * a * theta) < 1e-15);
    let asin_theta = (2.0 * a * h / (a * a + h * h)).asin();
    assert!(rel(asin_theta, PI - theta) < 4e-15, "asin gives pi - theta");
    let paper_s = (a * a + h * h) / h * asin_theta;
    assert!(rel(paper_s, 2.5 * a * (PI - theta)) < 4e-15);
    assert!(
        paper_s < arc_length(a, a),
        "eqs 21-22: shorter than the hemisphere's arc"
    );
    assert!(arc_length(a, h) > 2.7 * a);
}

/// Small-H series (derived in the module doc):
/// `s / 2a = 1 + (2/3) x^2 - (2/15) x^4 + (2/35) x^6 - (2/63) x^8 + ...`.
/// Truncation after x^8 leaves `(2/99) x^10`, below 1e-17 relative for
/// `x <= 1e-2`. The naive `(a^2+H^2)/H asin(...) / 2a - 1` is shown to fail.
#[test]
fn flat_limit_series() {
    let a = 0.0375;
    assert_eq!(arc_length(a, 0.0), 2.0 * a);
    assert_eq!(stretch(a, 0.0, 0.0), 1.0);
    for x in [1e-2, 1e-3, 1e-5, 1e-8, 1e-12, 1e-150] {
        let y = x * x;
        let series = y * (2.0 / 3.0 - y * (2.0 / 15.0 - y * (2.0 / 35.0 - y * 2.0 / 63.0)));
        let h = x * a;
        assert!(
            rel(engineering_strain(a, 0.0, h), series) < 4e-16,
            "x = {x}"
        );
        assert!(rel(arc_excess(x), series) < 4e-16, "x = {x}");
        assert!(rel(arc_length(a, h), 2.0 * a * (1.0 + series)) < 2e-16);
    }
    // The paper's form in floating point at x = 1e-8: all digits lost.
    let (x, h) = (1e-8, 1e-8 * a);
    let naive = (a * a + h * h) / h * (2.0 * a * h / (a * a + h * h)).asin() / (2.0 * a) - 1.0;
    let exact = 2.0 / 3.0 * x * x;
    assert!(rel(naive, exact) > 0.5, "naive {naive} vs {exact}");
}

/// A pre-bulged case by hand (a = 1, h0 = 0.1, H = 0.5, 15-digit values
/// of atan): g(0.1) = 10.1 atan 0.1 = 10.1 * 0.0996686524911620
/// = 1.00665339016074, g(0.5) = 2.5 atan 0.5 = 2.5 * 0.463647609000806
/// = 1.15911902250202, lambda = 1.15145792368209.
#[test]
fn prebulged_by_hand() {
    let lambda = 1.159_119_022_502_02 / 1.006_653_390_160_74;
    assert!(rel(stretch(1.0, 0.1, 0.5), lambda) < 1e-13);
    assert!(rel(stretch(1.0, 0.1, 0.5), 1.151_457_923_682_09) < 1e-13);
    // s0 from h0 by the paper's eq 21 (asin is right below the hemisphere).
    let (a, h0) = (1.0_f64, 0.1_f64);
    let s0 = (a * a + h0 * h0) / h0 * (2.0 * a * h0 / (a * a + h0 * h0)).asin();
    assert!(rel(arc_length(a, h0), s0) < 1e-14);
    // At the pre-bulge height itself: stretch 1, strain 0, modulus empty.
    let s = spec(1.0, 1e-3, 0.45, 0.1);
    let r = one(&s, &Options::default(), 0.0, 0.1, Some(1e-4));
    assert_eq!(r.value.stretch, Some(1.0));
    assert_eq!(r.value.strain, Some(0.0));
    assert_eq!(r.value.secant_modulus_pa, None);
    assert_eq!(r.std.unwrap().secant_modulus_pa, None);
}

/// The exact inflation (Adkins & Rivlin 1952): for a neo-Hookean membrane at h/a = 0.53098 (pole
/// stretch 1.20) the mean stretch s1/s0 is 1.179.
#[test]
fn mean_stretch_understates_pole_stretch() {
    let lambda = stretch(1.0, 0.0, 0.53098);
    assert!((lambda - 1.179).abs() < 1e-3, "{lambda}");
    assert!(lambda < 1.20);
}

/// Every option: the relations between them hold exactly (to rounding).
#[test]
fn every_option() {
    let s = spec(0.0375, 0.00035, 0.45, 0.002);
    let (p, h) = (5000.0, 0.03);
    let base = one(&s, &Options::default(), p, h, None).value;
    let lambda = base.stretch.unwrap();
    let eps = base.strain.unwrap();
    let sigma = base.stress_pa.unwrap();
    assert!(rel(sigma, p * cap_radius(0.0375, h) / (2.0 * 0.00035)) < 1e-15);
    assert!(rel(base.true_stress_pa.unwrap(), lambda * sigma) < 1e-15);
    assert!(rel(base.secant_modulus_pa.unwrap(), 0.55 * lambda * sigma / eps) < 1e-15);
    for o in all_options() {
        let v = one(&s, &o, p, h, None).value;
        let strain = match o.strain {
            StrainMeasure::Engineering => eps,
            StrainMeasure::Log => lambda.ln(),
        };
        let t = match o.true_stress {
            TrueStress::Paper => lambda * sigma,
            TrueStress::Incompressible => lambda * lambda * sigma,
        };
        let sm = match o.modulus_stress {
            ModulusStress::Nominal => lambda * sigma,
            ModulusStress::Stress => sigma,
            ModulusStress::True => t,
        };
        let k = match o.modulus {
            Modulus::Biaxial => 0.55,
            Modulus::Uniaxial => 1.0,
        };
        assert!(rel(v.strain.unwrap(), strain) < 1e-15, "{o:?}");
        assert!(rel(v.true_stress_pa.unwrap(), t) < 1e-15, "{o:?}");
        assert!(
            rel(v.secant_modulus_pa.unwrap(), k * sm / strain) < 1e-14,
            "{o:?}"
        );
        assert_eq!(v.stress_pa, base.stress_pa);
        assert_eq!(v.radius_m, base.radius_m);
        assert_eq!(v.arc_length_m, base.arc_length_m);
    }
}

/// The flat start: no radius (infinite), zero stress, zero strain, no
/// modulus, and nothing that is NaN or infinite.
#[test]
fn flat_zero_pressure_row() {
    let s = spec(0.0375, 0.00035, 0.45, 0.0);
    for o in all_options() {
        let r = one(&s, &o, 0.0, 0.0, Some(1e-5));
        let v = r.value;
        assert_eq!(v.radius_m, None);
        assert_eq!(v.arc_length_m, Some(0.075));
        assert_eq!(
            (v.strain, v.stress_pa, v.true_stress_pa),
            (Some(0.0), Some(0.0), Some(0.0))
        );
        assert_eq!(v.secant_modulus_pa, None);
        let sd = r.std.unwrap();
        assert_eq!(sd.radius_m, None);
        assert_eq!(sd.stress_pa, Some(0.0));
        for x in sd.to_array().into_iter().flatten() {
            assert!(x.is_finite());
        }
    }
}

/// `q_std = |dq/dH| sigma_H` against central finite differences of the
/// values themselves, for every option, on both sides of the hemisphere,
/// near the flat start and pre-bulged. Step `d = 1e-5 H`: truncation
/// O(d^2) ~ 1e-10 relative, rounding O(eps / 1e-5) ~ 1e-11.
#[test]
fn uncertainty_matches_finite_differences() {
    let sd = 1e-4;
    let mut worst: f64 = 0.0;
    for (h0, h, p) in [
        (0.0, 0.004, 100.0),
        (0.0, 0.02, 3000.0),
        (0.0, 0.0375, 6000.0),
        (0.0, 0.07, 8000.0),
        (0.003, 0.01, 1000.0),
        (0.003, 0.05, 7000.0),
    ] {
        let s = spec(0.0375, 0.00035, 0.45, h0);
        for o in all_options() {
            let r = one(&s, &o, p, h, Some(sd));
            let d = 1e-5 * h;
            let up = one(&s, &o, p, h + d, None).value.to_array();
            let dn = one(&s, &o, p, h - d, None).value.to_array();
            let got = r.std.unwrap().to_array();
            let val = r.value.to_array();
            for k in 0..7 {
                let fd = (up[k].unwrap() - dn[k].unwrap()) / (2.0 * d) * sd;
                // scale: the derivative itself, or for a vanishing one
                // (dR/dH at the hemisphere) the value over the height
                let scale = fd.abs().max(val[k].unwrap().abs() / h * sd * 1e-3);
                let e = (got[k].unwrap() - fd.abs()).abs() / scale;
                worst = worst.max(e);
                assert!(
                    e < 1e-7,
                    "{} {o:?} h0={h0} H={h}: {} vs {fd}",
                    STD_COLUMNS[k],
                    got[k].unwrap()
                );
            }
        }
    }
    eprintln!("uncertainty vs finite differences: largest relative difference {worst:.2e}");
}

#[test]
fn refused_points() {
    let s = spec(0.0375, 0.00035, 0.45, 0.002);
    let o = Options::default();
    let pt = |p: f64, h: f64, sd: Option<f64>| Point {
        pressure_pa: p,
        height_m: h,
        height_std_m: sd,
    };
    let err = |pts: &[Point]| stress_strain(&s, &o, pts).unwrap_err();
    let e = err(&[pt(10.0, 0.01, None), pt(-1.0, 0.01, None)]);
    assert_eq!(
        e,
        StressError::Point {
            index: 1,
            problem: PointError::NegativePressure { pressure_pa: -1.0 }
        }
    );
    let StressError::Point { problem, .. } = err(&[pt(10.0, 0.001, None)]) else {
        panic!("expected a point error")
    };
    assert_eq!(problem.column(), "height_m");
    assert!(
        problem
            .to_string()
            .contains("below the pre-bulge height h0 = 0.002")
    );
    let StressError::Point { problem, .. } = err(&[pt(f64::NAN, 0.01, None)]) else {
        panic!("expected a point error")
    };
    assert_eq!(problem.column(), "pressure_pa");
    let StressError::Point { problem, .. } = err(&[pt(1.0, 0.01, Some(-1e-5))]) else {
        panic!("expected a point error")
    };
    assert_eq!(problem.column(), "height_std_m");
    let flat = spec(0.0375, 0.00035, 0.45, 0.0);
    assert!(matches!(
        stress_strain(&flat, &o, &[pt(5.0, 0.0, None)]),
        Err(StressError::Point {
            problem: PointError::FlatUnderPressure { .. },
            ..
        })
    ));
    for bad in [
        spec(0.0, 0.00035, 0.45, 0.0),
        spec(0.0375, -1e-3, 0.45, 0.0),
        spec(0.0375, 0.00035, 0.5, 0.0),
        spec(0.0375, 0.00035, -0.1, 0.0),
    ] {
        assert!(matches!(
            stress_strain(&bad, &o, &[pt(1.0, 0.01, None)]),
            Err(StressError::Specimen(_))
        ));
    }
}

proptest! {
    /// Invariants: s >= 2a, R >= a, stretch >= 1 and increasing with H,
    /// log strain <= engineering strain, ds/dH >= 0.
    #[test]
    fn invariants(a in 1e-3f64..1.0, x0 in 0.0f64..1.5, dx1 in 0.0f64..3.0, frac in 0.0f64..1.0) {
        let h0 = x0 * a;
        let h2 = h0 + dx1 * a;
        let h1 = h0 + frac * (h2 - h0);
        prop_assert!(arc_length(a, h1) >= 2.0 * a);
        if h1 > 0.0 {
            prop_assert!(cap_radius(a, h1) >= a * (1.0 - 1e-15));
        }
        let (l1, l2) = (stretch(a, h0, h1), stretch(a, h0, h2));
        prop_assert!(l1 >= 1.0);
        prop_assert!(l2 >= l1, "{} {}", l1, l2);
        let eps = engineering_strain(a, h0, h2);
        prop_assert!(eps.ln_1p() <= eps);
        prop_assert!(arc_ratio_slope(h1 / a) >= 0.0);
    }

    /// The series and closed forms agree where they meet (x = 1/2), and
    /// the divided difference agrees with the plain difference when the
    /// heights are far apart.
    #[test]
    fn branches_agree(x in 0.3f64..0.7, x0 in 0.0f64..0.2) {
        let y = x * x;
        let closed = (x + 1.0 / x) * x.atan() - 1.0;
        prop_assert!(rel(arc_excess(x), closed) < 1e-14);
        let slope_closed = (1.0 - 1.0 / y) * x.atan() + 1.0 / x;
        prop_assert!(rel(arc_ratio_slope(x), slope_closed) < 1e-13);
        let x1 = x0 + 0.25;
        let diff = arc_ratio_difference(x0, x1, 0.25);
        prop_assert!(rel(diff, arc_excess(x1) - arc_excess(x0)) < 1e-13);
    }
}
