//! Integration tests of `bulge fit`: the real binary on Treloar's data, the
//! noisy-quartic fixture and every kind of bad input.

use crate::util::{bulge_in, fixture, read_csv, repo, tempdir};
use approx::assert_abs_diff_eq;
use bulge::material::{Material, Model};
use std::collections::HashMap;
use std::fs;
use std::path::Path;

fn treloar() -> String {
    repo()
        .join("data/treloar_equibiaxial.csv")
        .display()
        .to_string()
}

fn read_material(p: &Path) -> Material {
    toml::from_str(&fs::read_to_string(p).unwrap()).unwrap()
}

/// quantity -> value from fixtures/fit/treloar_reference.csv (numpy/scipy).
fn reference() -> HashMap<String, f64> {
    let (_, rows) = read_csv(&fixture("fit/treloar_reference.csv"));
    rows.into_iter()
        .map(|r| (r[0].clone(), r[1].parse().unwrap()))
        .collect()
}

fn fit_rmse(m: &Material) -> f64 {
    m.fit.as_ref().unwrap().rmse_pa
}

#[test]
fn treloar_all_models_writes_every_output() {
    let dir = tempdir();
    let run = bulge_in(
        dir.path(),
        &[
            "fit",
            &treloar(),
            "--model",
            "all",
            "-o",
            "out/treloar.toml",
        ],
    )
    .ok();
    for name in [
        "treloar.toml",
        "treloar_curve.csv",
        "treloar_residuals.csv",
        "treloar_models.csv",
        "treloar_fit.svg",
        "treloar_fit.png",
    ] {
        let p = dir.path().join("out").join(name);
        assert!(p.is_file(), "{name} missing; stdout:\n{}", run.stdout);
    }
    let m = read_material(&dir.path().join("out/treloar.toml"));
    assert!(m.model.hyperelastic().is_some());
    let fit = m.fit.as_ref().unwrap();
    assert_eq!(fit.drucker_stable, Some(true));
    let table = fs::read_to_string(dir.path().join("out/treloar_models.csv")).unwrap();
    // Header plus the seven models, exactly one selected.
    assert_eq!(table.lines().count(), 8, "{table}");
    assert_eq!(
        table.lines().filter(|l| l.contains(",true,true,")).count(),
        1,
        "{table}"
    );
    let png = fs::read(dir.path().join("out/treloar_fit.png")).unwrap();
    assert_eq!(&png[..4], b"\x89PNG");
    for model in [
        "neo-hookean",
        "mooney-rivlin",
        "yeoh",
        "ogden-1",
        "ogden-2",
        "ogden-3",
        "gent",
    ] {
        assert!(
            run.stdout.contains(model),
            "{model} not in the comparison table"
        );
    }
}

/// Ogden 3-term RMSE no worse than Ogden's 1972
/// parameters on the same points, through the binary.
#[test]
fn treloar_ogden3_beats_published_parameters() {
    let dir = tempdir();
    bulge_in(
        dir.path(),
        &[
            "fit",
            &treloar(),
            "--model",
            "ogden",
            "--ogden-terms",
            "3",
            "--no-plot",
        ],
    )
    .ok();
    let m = read_material(&dir.path().join("material.toml"));
    let Model::Ogden { mu_pa, alpha } = &m.model else {
        panic!("not ogden: {:?}", m.model)
    };
    assert_eq!((mu_pa.len(), alpha.len()), (3, 3));
    let published = reference()["ogden_1972_rmse_pa"];
    assert!(fit_rmse(&m) <= published, "{} > {published}", fit_rmse(&m));
    assert!(!dir.path().join("material_fit.png").exists());
}

/// Neo-Hookean and Mooney-Rivlin through the binary against the independent
/// numpy/scipy fits, to 3 significant digits.
#[test]
fn treloar_linear_models_match_independent_fit() {
    let r = reference();
    let dir = tempdir();
    bulge_in(
        dir.path(),
        &["fit", &treloar(), "--model", "neo-hookean", "-o", "nh.toml"],
    )
    .ok();
    let Model::NeoHookean { c1_pa } = read_material(&dir.path().join("nh.toml")).model else {
        panic!("not neo-hookean")
    };
    let sig3 = |a: f64, b: f64| ((a - b) / b).abs() < 5e-4;
    assert!(sig3(c1_pa, r["neo_hookean_c1_pa"]), "{c1_pa}");
    bulge_in(
        dir.path(),
        &[
            "fit",
            &treloar(),
            "--model",
            "mooney-rivlin",
            "-o",
            "mr.toml",
        ],
    )
    .ok();
    let Model::MooneyRivlin { c1_pa, c2_pa } = read_material(&dir.path().join("mr.toml")).model
    else {
        panic!("not mooney-rivlin")
    };
    assert!(sig3(c1_pa, r["mooney_rivlin_c1_pa"]), "{c1_pa}");
    assert!(sig3(c2_pa, r["mooney_rivlin_c2_pa"]), "{c2_pa}");
}

/// The quartic from a stress_strain.csv-style file equals the exact
/// least-squares solution of fixtures/fit/make_noisy_quartic.py.
#[test]
fn quartic_from_stress_strain_file_matches_fixture() {
    let dir = tempdir();
    let input = fixture("fit/noisy_quartic.csv").display().to_string();
    let run = bulge_in(
        dir.path(),
        &["fit", &input, "--model", "quartic", "--poisson", "0.45"],
    )
    .ok();
    assert!(run.stdout.contains("condition number"), "{}", run.stdout);
    let m = read_material(&dir.path().join("material.toml"));
    let Model::Quartic {
        coefficients_pa,
        strain_range,
        ..
    } = &m.model
    else {
        panic!("not quartic")
    };
    let text = fs::read_to_string(fixture("fit/noisy_quartic_expected.csv")).unwrap();
    let want: Vec<f64> = text
        .lines()
        .skip(1)
        .filter(|l| l.starts_with("4,"))
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(want.len(), 5);
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (g, w) in coefficients_pa.iter().zip(&want) {
        assert_abs_diff_eq!(g, w, epsilon = 1e-9 * scale);
    }
    assert_abs_diff_eq!(strain_range[0], 0.02, epsilon = 1e-12);
    assert_abs_diff_eq!(strain_range[1], 1.2, epsilon = 1e-12);
    assert_eq!(m.poisson, 0.45);
    let curve = fs::read_to_string(dir.path().join("material_curve.csv")).unwrap();
    assert!(curve.starts_with("stretch,strain,modulus_pa,implied_stress_pa"));
    assert_eq!(curve.lines().count(), 201);
}

/// Runs `bulge fit` on `content` and checks the refusal: exit 2, the
/// message has every needle, and nothing but the input is in the folder.
fn refused(content: &str, extra: &[&str], needles: &[&str]) {
    let dir = tempdir();
    let input = dir.path().join("in.csv");
    fs::write(&input, content).unwrap();
    let mut args = vec!["fit", "in.csv"];
    args.extend_from_slice(extra);
    bulge_in(dir.path(), &args).bad_input(needles);
    let left: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "outputs written on refused input: {left:?}");
    assert_eq!(
        fs::read_to_string(&input).unwrap(),
        content,
        "input modified"
    );
}

#[test]
fn refuses_fewer_points_than_parameters() {
    refused(
        "stretch,nominal_stress_pa\n1.1,1000\n1.2,2000\n1.3,2500\n",
        &["--model", "quartic"],
        &["in.csv", "3 data points", "5 parameters", "--degree"],
    );
    refused(
        "stretch,nominal_stress_pa\n1.1,1000\n1.2,2000\n",
        &["--model", "yeoh"],
        &["in.csv", "2 data points", "3 parameters"],
    );
}

#[test]
fn refuses_duplicate_stretch() {
    refused(
        "stretch,nominal_stress_pa\n1.1,1000\n1.2,2000\n1.2,2100\n1.3,2500\n",
        &["--model", "neo-hookean"],
        &["in.csv", "line 4", "stretch", "1.2 repeats", "sort"],
    );
}

#[test]
fn refuses_unsorted_stretch() {
    refused(
        "stretch,nominal_stress_pa\n1.1,1000\n1.3,2000\n1.2,2100\n1.4,2500\n",
        &["--model", "neo-hookean"],
        &["in.csv", "line 4", "1.2 is smaller than 1.3"],
    );
}

#[test]
fn refuses_unsorted_strain_in_stress_stage_file() {
    // Stretch increasing but the strain column out of order.
    refused(
        "stretch,strain,stress_pa,true_stress_pa,secant_modulus_pa\n1.1,0.1,1,1,5\n1.2,0.3,2,2,5\n1.3,0.2,3,3,5\n",
        &[],
        &["in.csv", "line 4", "strain 0.2 is smaller than 0.3"],
    );
}

#[test]
fn refuses_zero_and_negative_stretch() {
    refused(
        "stretch,nominal_stress_pa\n0,0\n1.2,2000\n",
        &["--model", "neo-hookean"],
        &["in.csv", "line 2", "stretch 0 is not positive"],
    );
    refused(
        "stretch,nominal_stress_pa\n1.0,0\n-1.2,2000\n",
        &["--model", "gent"],
        &["in.csv", "line 3", "stretch -1.2 is not positive"],
    );
}

#[test]
fn refuses_nan() {
    refused(
        "stretch,nominal_stress_pa\n1.0,0\n1.2,NaN\n1.3,3000\n",
        &["--model", "neo-hookean"],
        &[
            "in.csv",
            "line 3",
            "nominal_stress_pa",
            "`NaN` is not a finite number",
        ],
    );
}

#[test]
fn refuses_empty_and_header_only_files() {
    refused("", &[], &["in.csv", "empty"]);
    refused(
        "stretch,nominal_stress_pa\n",
        &[],
        &["in.csv", "no data lines"],
    );
}

#[test]
fn refuses_bad_flags_and_missing_columns() {
    let ok = "stretch,nominal_stress_pa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,4\n1.5,5\n";
    refused(ok, &["--poisson", "0.5"], &["--poisson 0.5", "[0, 0.5)"]);
    refused(
        ok,
        &["--model", "ogden", "--ogden-terms", "4"],
        &["--ogden-terms 4"],
    );
    refused(
        "stretch,force_n\n1,0\n1.1,1\n",
        &[],
        &["in.csv", "no stress column", "force_n"],
    );
    refused(
        "stretch,stress_pa\n1,0\n1.1,1\n",
        &[],
        &["in.csv", "--stress-measure"],
    );
}

#[test]
fn help_documents_every_flag() {
    let dir = tempdir();
    let run = bulge_in(dir.path(), &["fit", "--help"]).ok();
    for flag in [
        "--model",
        "--degree",
        "--ogden-terms",
        "--poisson",
        "--stress-measure",
        "--strain-measure",
        "--modulus",
        "--output",
        "--samples",
        "--no-plot",
        "quartic",
        "mooney-rivlin",
        "Default 4",
    ] {
        assert!(
            run.stdout.contains(flag),
            "--help lacks {flag}:\n{}",
            run.stdout
        );
    }
}

/// A softening material (stress peaks inside the range): the law is
/// accepted but every output says where it is unphysical.
#[test]
fn warns_where_the_law_is_unphysical() {
    let dir = tempdir();
    let mut csv = String::from("stretch,cauchy_stress_pa\n");
    for i in 1..=10 {
        let l = 1.0 + 0.1 * i as f64;
        let s = 1.0e5 * (std::f64::consts::PI * (l - 1.0) / 1.2).sin();
        csv.push_str(&format!("{l},{s}\n"));
    }
    fs::write(dir.path().join("soft.csv"), &csv).unwrap();
    let run = bulge_in(
        dir.path(),
        &["fit", "soft.csv", "--model", "quartic", "--no-plot"],
    )
    .ok();
    assert!(
        run.stderr.contains("warning:") && run.stderr.contains("does not increase"),
        "{}",
        run.stderr
    );
    let m = read_material(&dir.path().join("material.toml"));
    let w = &m.fit.as_ref().unwrap().warnings;
    assert!(!w.is_empty());
}

/// Columns `a` and `b` of a CSV file, as numbers.
fn columns(p: &Path, a: &str, b: &str) -> Vec<(f64, f64)> {
    let (head, rows) = read_csv(p);
    let (ia, ib) = (
        head.iter().position(|h| h == a).unwrap(),
        head.iter().position(|h| h == b).unwrap(),
    );
    rows.iter()
        .map(|f| (f[ia].parse().unwrap(), f[ib].parse().unwrap()))
        .collect()
}

/// The demo's photos tracked (`h.csv`, with each height's standard
/// deviation) and their stress and strain (`ss.csv`) in `d`; the demo's
/// experiment file.
fn demo_stress_strain(d: &Path) -> String {
    let exp = repo().join("data/demo/experiment.toml");
    let exp = exp.to_str().unwrap();
    bulge_in(d, &["track", exp, "-o", "h.csv"]).ok();
    bulge_in(d, &["stress", "h.csv", "--experiment", exp, "-o", "ss.csv"]).ok();
    exp.to_string()
}

/// `bulge fit --to-heights` on the demo's stress_strain.csv: the exact
/// axisymmetric inflation with the corrected law (solved by `bulge simulate
/// --model axisym`, checked against closed forms in its own tests)
/// reproduces the measured heights within 1 % rms, where the law fitted to
/// the points alone is more than 1.5 % off (the spherical-cap bias).
#[test]
fn to_heights_corrects_the_law_to_the_measured_heights() {
    let dir = tempdir();
    let d = dir.path();
    let exp = demo_stress_strain(d);
    let exp = exp.as_str();
    bulge_in(d, &["fit", "ss.csv", "--no-plot", "-o", "cap.toml"]).ok();
    bulge_in(
        d,
        &[
            "fit",
            "ss.csv",
            "--no-plot",
            "--to-heights",
            exp,
            "-o",
            "fixed.toml",
        ],
    )
    .ok();
    let fixed = read_material(&d.join("fixed.toml"));
    let refined = fixed.fit.as_ref().unwrap().refined.as_ref().unwrap();
    assert!(refined.constraint.is_some(), "{refined:?}");
    // The corrected quartic stays physical: its implied stress E(eps) eps
    // rises over the whole strain range (no snap-through inside the data).
    let Model::Quartic {
        coefficients_pa,
        strain_range: [lo, hi],
        ..
    } = &fixed.model
    else {
        panic!("{:?}", fixed.model)
    };
    for k in 0..=400 {
        let eps = lo + (hi - lo) * k as f64 / 400.0;
        let slope: f64 = coefficients_pa
            .iter()
            .enumerate()
            .map(|(j, c)| (j + 1) as f64 * c * eps.powi(j as i32))
            .sum();
        assert!(
            slope > 0.0,
            "implied stress falls at strain {eps}: slope {slope}"
        );
    }
    let measured = columns(&d.join("ss.csv"), "pressure_pa", "height_m");
    let pressures: Vec<String> = measured.iter().map(|m| m.0.to_string()).collect();
    let rms = |material: &str| {
        let out = format!("{material}.csv");
        bulge_in(
            d,
            &[
                "simulate",
                "--experiment",
                exp,
                "--material",
                &format!("{material}.toml"),
                "--model",
                "axisym",
                "--pressures",
                &pressures.join(","),
                "-o",
                &out,
            ],
        )
        .ok();
        let sim = columns(&d.join(&out), "pressure_pa", "height_m");
        assert_eq!(sim.len(), measured.len());
        let sq: f64 = sim
            .iter()
            .zip(&measured)
            .map(|(s, m)| (s.1 / m.1 - 1.0).powi(2))
            .sum();
        (sq / sim.len() as f64).sqrt()
    };
    let (cap, fixed) = (rms("cap"), rms("fixed"));
    assert!(fixed < 0.01, "corrected law: rms height error {fixed}");
    assert!(cap > 0.015, "cap law: rms height error {cap}");
    // Input without heights is refused, naming the columns.
    bulge_in(d, &["fit", &treloar(), "--to-heights", exp, "-o", "t.toml"])
        .bad_input(&["pressure_pa and height_m"]);
}

/// `bulge fit --to-heights` with a rectangular `[window]` (60 x 20 mm):
/// heights of a neo-Hookean rubber (C1 0.25 MPa), made by the membrane
/// model on the mesh the correction uses, go through `bulge stress` (the
/// cap formulas with the half-width as radius: a biased law) and `bulge fit
/// --model neo-hookean --to-heights`: the corrected C1 is the one that made
/// the heights, to 1e-4, where the cap law is far off.
#[test]
fn to_heights_through_the_membrane_on_a_rectangular_window() {
    use bulge::experiment::{Specimen, Window};
    use bulge::sim::scene::Scene;
    use bulge::sim::{SceneSolver, SpringModel};
    let dir = tempdir();
    let d = dir.path();
    let spec = Specimen {
        radius_m: 0.01,
        thickness_m: 0.35e-3,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let window = Window::Rectangle {
        length_m: 0.06,
        width_m: 0.02,
    };
    let c1 = 0.25e6;
    let truth = Material {
        model: Model::NeoHookean { c1_pa: c1 },
        poisson: 0.45,
        fit: None,
    };
    let pressures = [2000.0, 4000.0, 6000.0, 8000.0, 10000.0];
    let scene = Scene::from_window(&spec, &window, truth, pressures.to_vec());
    let mut s =
        SceneSolver::on_mesh(&scene, scene.build_mesh().unwrap(), SpringModel::Membrane).unwrap();
    let done = s.sweep(&pressures, |_, _| {}).unwrap();
    let mut csv = String::from("pressure_pa,height_m\n");
    for q in &done {
        csv.push_str(&format!("{},{:e}\n", q.pressure_pa, q.height_m));
    }
    fs::write(d.join("h.csv"), csv).unwrap();
    fs::write(
        d.join("exp.toml"),
        "[specimen]\nradius_m = 0.01\nthickness_m = 0.00035\npoisson = 0.45\n\n[window]\nshape = \"rectangle\"\nlength_m = 0.06\nwidth_m = 0.02\n",
    )
    .unwrap();
    bulge_in(
        d,
        &[
            "stress",
            "h.csv",
            "--experiment",
            "exp.toml",
            "-o",
            "ss.csv",
        ],
    )
    .ok();
    let fit = |extra: &[&str], out: &str| {
        let mut args = vec!["fit", "ss.csv", "--model", "neo-hookean", "--no-plot"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out]);
        bulge_in(d, &args).ok();
        match read_material(&d.join(out)).model {
            Model::NeoHookean { c1_pa } => c1_pa,
            m => panic!("{m:?}"),
        }
    };
    let cap = fit(&[], "cap.toml");
    let fixed = fit(&["--to-heights", "exp.toml"], "fixed.toml");
    assert!((cap / c1 - 1.0).abs() > 0.05, "the cap law is {cap}");
    assert!((fixed / c1 - 1.0).abs() < 1e-4, "corrected {fixed} vs {c1}");
    let m = read_material(&d.join("fixed.toml"));
    let refined = m.fit.unwrap().refined.unwrap();
    assert!(
        refined.method.contains("rectangle window"),
        "{}",
        refined.method
    );
}

#[test]
fn weighted_fit_uses_the_heights_uncertainty_or_says_it_could_not() {
    let dir = tempdir();
    let d = dir.path();
    demo_stress_strain(d);
    let args = ["fit", "ss.csv", "--no-plot", "--weighted", "-o", "w.toml"];
    let run = bulge_in(d, &args).ok();
    assert!(!run.stderr.contains("fitted unweighted"), "{}", run.stderr);
    let m = read_material(&d.join("w.toml"));
    let fit = m.fit.as_ref().unwrap();
    assert!(fit.weights.is_some(), "{fit:?}");
    // The quartic follows the cap's points within the tracking's noise.
    let chi2 = fit.chi2_per_dof.expect("chi2 per degree of freedom");
    assert!(chi2 > 0.05 && chi2 < 20.0, "chi2 / dof = {chi2}");

    // A flat first row (no pressure, no strain) moves with nothing: its
    // zero shifts take either sign, and the fit is weighted still.
    let heights = repo().join("data/demo/heights.csv");
    let exp = repo().join("data/demo/experiment.toml");
    let (heights, exp) = (heights.to_str().unwrap(), exp.to_str().unwrap());
    let args = [
        "stress",
        heights,
        "--experiment",
        exp,
        "--height-std-m",
        "5e-5",
        "-o",
        "f.csv",
    ];
    bulge_in(d, &args).ok();
    let args = [
        "fit",
        "f.csv",
        "--model",
        "neo-hookean",
        "--no-plot",
        "--weighted",
        "-o",
        "f.toml",
    ];
    let run = bulge_in(d, &args).ok();
    assert!(!run.stderr.contains("fitted unweighted"), "{}", run.stderr);
    assert!(
        read_material(&d.join("f.toml"))
            .fit
            .unwrap()
            .weights
            .is_some()
    );

    // Raw data carry no uncertainty: fitted unweighted, and said so.
    let t = treloar();
    let args = ["fit", &t, "--no-plot", "--weighted", "-o", "t.toml"];
    let run = bulge_in(d, &args).ok();
    assert!(run.stderr.contains("fitted unweighted"), "{}", run.stderr);
    let m = read_material(&d.join("t.toml"));
    assert!(m.fit.as_ref().unwrap().weights.is_none());
}
