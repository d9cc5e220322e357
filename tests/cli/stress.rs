//! Integration tests of `bulge stress`: the real binary in a temporary folder.
//!
//! Expected values are closed forms of the spherical cap (hemisphere `H = a`:
//! `R = a`, `s = pi a`, `lambda = pi/2`; `H = 2a`: `R = 1.25 a`,
//! `theta = acos(-3/5)`), not outputs of the code under test.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fs;
use std::path::Path;

use crate::util::{Run, bulge_in, read_csv, repo, tempdir};

const A: f64 = 0.0375;
const T: f64 = 0.00035;
const NU: f64 = 0.45;

const SPECIMEN: &str = "[specimen]\nradius_m = 0.0375\nthickness_m = 0.00035\npoisson = 0.45\n";

const COLUMNS: &str = "pressure_pa,height_m,radius_m,arc_length_m,stretch,strain,stress_pa,true_stress_pa,secant_modulus_pa";

/// An output CSV as header + rows of named cells.
struct Csv {
    header: Vec<String>,
    rows: Vec<HashMap<String, String>>,
}

impl Csv {
    fn read(p: &Path) -> Self {
        let (header, rows) = read_csv(p);
        let rows = rows
            .into_iter()
            .map(|r| header.iter().cloned().zip(r).collect())
            .collect();
        Csv { header, rows }
    }

    fn num(&self, row: usize, col: &str) -> f64 {
        self.rows[row][col]
            .parse()
            .unwrap_or_else(|_| panic!("{col} at row {row}: {:?}", self.rows[row][col]))
    }

    fn cell(&self, row: usize, col: &str) -> &str {
        &self.rows[row][col]
    }
}

fn close(got: f64, want: f64, rtol: f64) {
    let scale = want.abs().max(f64::MIN_POSITIVE);
    assert!(
        (got - want).abs() <= rtol * scale,
        "got {got}, want {want} (rtol {rtol})"
    );
}

/// Heights at the flat start, the hemisphere (H = a) and H = 2a.
fn write_inputs(dir: &Path, heights: &str) {
    fs::write(dir.join("experiment.toml"), SPECIMEN).unwrap();
    fs::write(dir.join("heights.csv"), heights).unwrap();
}

const GOOD: &str =
    "frame,file,pressure_pa,height_m\n0,a.png,0,0\n1,b.png,4000,0.0375\n2,c.png,6000,0.075\n";

/// `bulge stress heights.csv --experiment experiment.toml -o OUTPUT` in `dir`.
fn stress_in(dir: &Path, output: &str) -> Run {
    bulge_in(
        dir,
        &[
            "stress",
            "heights.csv",
            "--experiment",
            "experiment.toml",
            "-o",
            output,
        ],
    )
}

#[test]
fn stress_good_run_closed_forms() {
    let dir = tempdir();
    write_inputs(dir.path(), GOOD);
    let run = stress_in(dir.path(), "out/ss.csv").ok();
    assert!(run.stderr.contains("3 rows"), "{}", run.stderr);
    let out = Csv::read(&dir.path().join("out/ss.csv"));
    assert_eq!(out.header.join(","), format!("frame,file,{COLUMNS}"));
    assert_eq!(out.rows.len(), 3);
    // carried columns and inputs copied verbatim
    assert_eq!((out.cell(1, "frame"), out.cell(1, "file")), ("1", "b.png"));
    assert_eq!(out.cell(1, "height_m"), "0.0375");
    // flat start: infinite radius and zero-strain modulus are empty, not inf/NaN
    assert_eq!(out.cell(0, "radius_m"), "");
    assert_eq!(out.cell(0, "secant_modulus_pa"), "");
    close(out.num(0, "arc_length_m"), 2.0 * A, 1e-15);
    assert_eq!(out.num(0, "strain"), 0.0);
    assert_eq!(out.num(0, "stress_pa"), 0.0);
    // hemisphere
    let sigma = 4000.0 * A / (2.0 * T);
    close(out.num(1, "radius_m"), A, 1e-15);
    close(out.num(1, "arc_length_m"), PI * A, 1e-15);
    close(out.num(1, "stretch"), PI / 2.0, 1e-15);
    close(out.num(1, "strain"), PI / 2.0 - 1.0, 1e-14);
    close(out.num(1, "stress_pa"), sigma, 1e-15);
    close(out.num(1, "true_stress_pa"), PI / 2.0 * sigma, 1e-15);
    close(
        out.num(1, "secant_modulus_pa"),
        (1.0 - NU) * PI / 2.0 * sigma / (PI / 2.0 - 1.0),
        1e-14,
    );
    // H = 2a: R = 1.25 a, theta = acos(-3/5) (the paper's asin gives pi - theta)
    let theta = (-0.6_f64).acos();
    close(out.num(2, "radius_m"), 1.25 * A, 1e-15);
    close(out.num(2, "arc_length_m"), 2.5 * A * theta, 1e-15);
    close(out.num(2, "stretch"), 1.25 * theta, 1e-15);
    close(
        out.num(2, "stress_pa"),
        6000.0 * 1.25 * A / (2.0 * T),
        1e-15,
    );
}

#[test]
fn stress_flags_equal_experiment_file() {
    let dir = tempdir();
    write_inputs(dir.path(), GOOD);
    stress_in(dir.path(), "a.csv").ok();
    bulge_in(
        dir.path(),
        &[
            "stress",
            "heights.csv",
            "--radius-m",
            "0.0375",
            "--thickness-m",
            "0.00035",
            "--poisson",
            "0.45",
            "-o",
            "b.csv",
        ],
    )
    .ok();
    assert_eq!(
        fs::read(dir.path().join("a.csv")).unwrap(),
        fs::read(dir.path().join("b.csv")).unwrap()
    );
}

#[test]
fn stress_every_option() {
    let dir = tempdir();
    write_inputs(dir.path(), "pressure_pa,height_m\n4000,0.0375\n");
    let sigma = 4000.0 * A / (2.0 * T);
    let lambda = PI / 2.0;
    let run = |extra: &[&str]| {
        let mut args = vec![
            "stress",
            "heights.csv",
            "--experiment",
            "experiment.toml",
            "-o",
            "o.csv",
        ];
        args.extend_from_slice(extra);
        bulge_in(dir.path(), &args).ok();
        Csv::read(&dir.path().join("o.csv"))
    };
    let o = run(&["--strain", "log"]);
    close(o.num(0, "strain"), lambda.ln(), 1e-15);
    close(
        o.num(0, "secant_modulus_pa"),
        (1.0 - NU) * lambda * sigma / lambda.ln(),
        1e-14,
    );
    let o = run(&["--true-stress", "incompressible"]);
    close(o.num(0, "true_stress_pa"), lambda * lambda * sigma, 1e-15);
    let o = run(&["--modulus", "uniaxial"]);
    close(
        o.num(0, "secant_modulus_pa"),
        lambda * sigma / (lambda - 1.0),
        1e-14,
    );
    let o = run(&["--modulus-stress", "stress"]);
    close(
        o.num(0, "secant_modulus_pa"),
        (1.0 - NU) * sigma / (lambda - 1.0),
        1e-14,
    );
    let o = run(&["--modulus-stress", "true"]);
    close(
        o.num(0, "secant_modulus_pa"),
        (1.0 - NU) * lambda * sigma / (lambda - 1.0),
        1e-14,
    );
    let o = run(&[
        "--modulus-stress",
        "true",
        "--true-stress",
        "incompressible",
    ]);
    close(
        o.num(0, "secant_modulus_pa"),
        (1.0 - NU) * lambda * lambda * sigma / (lambda - 1.0),
        1e-14,
    );
    let o = run(&[
        "--modulus-stress",
        "nominal",
        "--true-stress",
        "incompressible",
    ]);
    close(
        o.num(0, "secant_modulus_pa"),
        (1.0 - NU) * lambda * sigma / (lambda - 1.0),
        1e-14,
    );
    let o = run(&[
        "--strain",
        "log",
        "--true-stress",
        "incompressible",
        "--modulus",
        "uniaxial",
        "--modulus-stress",
        "true",
    ]);
    close(
        o.num(0, "secant_modulus_pa"),
        lambda * lambda * sigma / lambda.ln(),
        1e-14,
    );
    let o = run(&[
        "--strain",
        "engineering",
        "--true-stress",
        "paper",
        "--modulus",
        "biaxial",
    ]);
    close(o.num(0, "true_stress_pa"), lambda * sigma, 1e-15);
}

/// At H = 2a: dR/dH = (1 - a^2/H^2)/2 = 3/8, so stress_std = p/(2t) 3/8 sd
/// and the stress's error runs with the strain's;
/// ds/dH = 2 g'(2) with g'(x) = (1 - 1/x^2) atan x + 1/x.
#[test]
fn stress_height_uncertainty_flag_and_column() {
    let dir = tempdir();
    write_inputs(dir.path(), "pressure_pa,height_m\n6000,0.075\n");
    let sd = 1e-4;
    bulge_in(
        dir.path(),
        &[
            "stress",
            "heights.csv",
            "--experiment",
            "experiment.toml",
            "-o",
            "o.csv",
            "--height-std-m",
            "1e-4",
        ],
    )
    .ok();
    let o = Csv::read(&dir.path().join("o.csv"));
    assert_eq!(
        o.header.join(","),
        format!(
            "{COLUMNS},height_std_m,radius_std_m,arc_length_std_m,stretch_std,strain_std,stress_std_pa,true_stress_std_pa,secant_modulus_std_pa,strain_stress_corr,strain_modulus_corr"
        )
    );
    // Past the hemisphere the cap rounds as it rises: dR/dH = 3/8 > 0, the
    // stress rises with the strain.
    close(o.num(0, "strain_stress_corr"), 1.0, 0.0);
    let gp = 0.75 * 2.0_f64.atan() + 0.5;
    close(o.num(0, "height_std_m"), sd, 0.0);
    close(o.num(0, "radius_std_m"), 0.375 * sd, 1e-14);
    close(o.num(0, "arc_length_std_m"), 2.0 * gp * sd, 1e-14);
    close(o.num(0, "stretch_std"), gp / A * sd, 1e-14);
    close(
        o.num(0, "stress_std_pa"),
        6000.0 / (2.0 * T) * 0.375 * sd,
        1e-14,
    );
    for c in ["true_stress_std_pa", "secant_modulus_std_pa"] {
        assert!(o.num(0, c) > 0.0);
    }

    // The same uncertainty from a column: same numbers, column carried.
    fs::write(
        dir.path().join("h2.csv"),
        "height_std_m,pressure_pa,height_m\n1e-4,6000,0.075\n",
    )
    .unwrap();
    bulge_in(
        dir.path(),
        &[
            "stress",
            "h2.csv",
            "--experiment",
            "experiment.toml",
            "-o",
            "o2.csv",
        ],
    )
    .ok();
    let o2 = Csv::read(&dir.path().join("o2.csv"));
    assert_eq!(o2.header[0], "height_std_m");
    assert_eq!(o2.header.iter().filter(|h| *h == "height_std_m").count(), 1);
    for c in ["radius_std_m", "stress_std_pa", "secant_modulus_std_pa"] {
        assert_eq!(o.cell(0, c), o2.cell(0, c), "{c}");
    }
}

#[test]
fn stress_demo_data_runs() {
    let dir = tempdir();
    let data = repo().join("data/demo");
    let out = dir.path().join("ss.csv");
    bulge_in(
        dir.path(),
        &[
            "stress",
            data.join("heights.csv").to_str().unwrap(),
            "--experiment",
            data.join("experiment.toml").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
    )
    .ok();
    let o = Csv::read(&out);
    assert_eq!(o.header.join(","), format!("frame,{COLUMNS}"));
    // The exact inflation (Adkins & Rivlin 1952): the mean stretch at h/a = 0.53098 is 1.179 (pole: 1.20)
    close(o.num(2, "stretch"), 1.179, 1e-3);
}

/// Runs a refused case and checks exit 2, the message and that nothing is written.
fn refused(heights: &str, toml: &str, extra: &[&str], needles: &[&str]) {
    let dir = tempdir();
    fs::write(dir.path().join("experiment.toml"), toml).unwrap();
    fs::write(dir.path().join("heights.csv"), heights).unwrap();
    let mut args = vec!["stress", "heights.csv", "-o", "out.csv"];
    if !extra.iter().any(|a| a.starts_with("--radius")) {
        args.extend(["--experiment", "experiment.toml"]);
    }
    args.extend_from_slice(extra);
    bulge_in(dir.path(), &args).bad_input(needles);
    assert!(!dir.path().join("out.csv").exists(), "no output on refusal");
    let leftovers: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 2, "only the two inputs remain");
}

#[test]
fn stress_refuses_missing_column() {
    refused(
        "pressure_pa,apex_m\n0,0\n",
        SPECIMEN,
        &[],
        &[
            "heights.csv",
            "line 1",
            "`height_m`",
            "found: pressure_pa, apex_m",
            "add it",
        ],
    );
}

#[test]
fn stress_refuses_non_numeric_and_nan() {
    refused(
        "pressure_pa,height_m\n0,0\n100,abc\n",
        SPECIMEN,
        &[],
        &[
            "heights.csv",
            "line 3",
            "`height_m`",
            "`abc`",
            "decimal number",
        ],
    );
    refused(
        "pressure_pa,height_m\nNaN,0.01\n",
        SPECIMEN,
        &[],
        &["heights.csv", "line 2", "`pressure_pa`", "`NaN`", "finite"],
    );
}

#[test]
fn stress_refuses_negative_pressure() {
    refused(
        "pressure_pa,height_m\n0,0\n10,0.001\n-5,0.002\n",
        SPECIMEN,
        &[],
        &[
            "heights.csv",
            "line 4",
            "`pressure_pa`",
            "-5",
            "negative",
            "zero offset",
        ],
    );
}

#[test]
fn stress_refuses_height_below_prebulge() {
    let toml = format!("{SPECIMEN}prebulge_height_m = 0.002\n");
    refused(
        "pressure_pa,height_m\n0,0.002\n10,0.0015\n",
        &toml,
        &[],
        &[
            "heights.csv",
            "line 3",
            "`height_m`",
            "0.0015",
            "pre-bulge height h0 = 0.002",
            "add h0",
        ],
    );
    refused(
        "pressure_pa,height_m\n0,-0.001\n",
        SPECIMEN,
        &[],
        &[
            "line 2",
            "`height_m`",
            "-0.001",
            "below the pre-bulge height",
        ],
    );
}

#[test]
fn stress_refuses_bad_specimen_in_file() {
    let h = "pressure_pa,height_m\n0,0\n";
    refused(
        h,
        "[specimen]\nradius_m = 0\nthickness_m = 0.00035\npoisson = 0.45\n",
        &[],
        &["experiment.toml", "line 2", "radius_m = 0", "positive"],
    );
    refused(
        h,
        "[specimen]\nradius_m = 0.0375\nthickness_m = -0.00035\npoisson = 0.45\n",
        &[],
        &[
            "experiment.toml",
            "line 3",
            "thickness_m = -0.00035",
            "positive",
        ],
    );
    refused(
        h,
        "[specimen]\nradius_m = 0.0375\nthickness_m = 0.00035\npoisson = 0.5\n",
        &[],
        &["experiment.toml", "line 4", "poisson = 0.5", "[0, 0.5)"],
    );
}

#[test]
fn stress_refuses_bad_specimen_flags() {
    let h = "pressure_pa,height_m\n0,0\n";
    let flags = |r: &'static str, t: &'static str, nu: &'static str| {
        ["--radius-m", r, "--thickness-m", t, "--poisson", nu]
    };
    refused(
        h,
        SPECIMEN,
        &flags("-0.01", "0.00035", "0.45"),
        &["--radius-m", "radius_m = -0.01", "positive"],
    );
    refused(
        h,
        SPECIMEN,
        &flags("0.0375", "0", "0.45"),
        &["--thickness-m", "thickness_m = 0", "positive"],
    );
    refused(
        h,
        SPECIMEN,
        &flags("0.0375", "0.00035", "-0.1"),
        &["--poisson", "poisson = -0.1", "[0, 0.5)"],
    );
    refused(
        h,
        SPECIMEN,
        &flags("0.0375", "0.00035", "0.5"),
        &["--poisson", "poisson = 0.5"],
    );
}

#[test]
fn stress_refuses_conflicting_or_bad_uncertainty() {
    refused(
        "pressure_pa,height_m,height_std_m\n0,0,1e-5\n",
        SPECIMEN,
        &["--height-std-m", "1e-5"],
        &[
            "heights.csv",
            "height_std_m",
            "drop the flag",
            "or drop the column",
        ],
    );
    refused(
        "pressure_pa,height_m\n0,0\n",
        SPECIMEN,
        &["--height-std-m", "-1e-5"],
        &["--height-std-m -0.00001", ">= 0"],
    );
    refused(
        "pressure_pa,height_m,height_std_m\n0,0,1e-5\n10,0.01,-2e-5\n",
        SPECIMEN,
        &[],
        &[
            "heights.csv",
            "line 3",
            "`height_std_m`",
            "-0.00002",
            "negative",
        ],
    );
}

#[test]
fn stress_refuses_pressure_on_a_flat_disc() {
    refused(
        "pressure_pa,height_m\n50,0\n",
        SPECIMEN,
        &[],
        &[
            "heights.csv",
            "line 2",
            "flat membrane cannot carry pressure",
        ],
    );
}

#[test]
fn stress_refuses_to_overwrite_its_input() {
    let dir = tempdir();
    write_inputs(dir.path(), GOOD);
    stress_in(dir.path(), "heights.csv")
        .bad_input(&["is the input", "inputs are never overwritten"]);
    assert_eq!(
        fs::read_to_string(dir.path().join("heights.csv")).unwrap(),
        GOOD
    );
}

#[test]
fn stress_help_documents_every_flag_and_default() {
    let dir = tempdir();
    let h = bulge_in(dir.path(), &["stress", "--help"]).ok().stdout;
    for needle in [
        "--experiment",
        "--radius-m",
        "--thickness-m",
        "--poisson",
        "--prebulge-height-m",
        "--strain",
        "--true-stress",
        "--modulus",
        "--modulus-stress",
        "--height-std-m",
        "--output",
        "[default: engineering]",
        "[default: paper]",
        "[default: biaxial]",
        "[default: nominal]",
        "Default 0",
    ] {
        assert!(h.contains(needle), "--help lacks {needle}:\n{h}");
    }
}

/// A pre-bulged disc past the hemisphere, through the flags (h0 = 2 mm,
/// H = 60 mm, p = 9 kPa); expected values from the 60-digit independent
/// script `fixtures/stress/reference.py` (its reference.csv row
/// `0.0375,0.00035,0.45,0.002,0.06,9000.0,engineering,paper,biaxial,nominal`).
#[test]
#[allow(clippy::excessive_precision)] // the reference's 20 digits, copied verbatim
fn stress_prebulged_past_hemisphere_via_flags() {
    let dir = tempdir();
    fs::write(
        dir.path().join("heights.csv"),
        "pressure_pa,height_m\n0,0.002\n9000,0.06\n",
    )
    .unwrap();
    bulge_in(
        dir.path(),
        &[
            "stress",
            "heights.csv",
            "--radius-m",
            "0.0375",
            "--thickness-m",
            "0.00035",
            "--poisson",
            "0.45",
            "--prebulge-height-m",
            "0.002",
            "-o",
            "o.csv",
        ],
    )
    .ok();
    let o = Csv::read(&dir.path().join("o.csv"));
    assert_eq!(o.num(0, "stretch"), 1.0);
    assert_eq!(o.cell(0, "secant_modulus_pa"), "");
    close(o.num(1, "radius_m"), 4.1718749999999998456e-2, 1e-15);
    close(o.num(1, "arc_length_m"), 1.6891037628594138558e-1, 1e-15);
    close(o.num(1, "stretch"), 2.2478781295264048393, 1e-15);
    close(o.num(1, "strain"), 1.2478781295264048393, 1e-15);
    close(o.num(1, "stress_pa"), 5.3638392857142855703e+5, 1e-15);
    close(o.num(1, "true_stress_pa"), 1.2057257020651675634e+6, 1e-15);
    close(
        o.num(1, "secant_modulus_pa"),
        5.3142139480200742625e+5,
        1e-15,
    );
}

/// With the experiment's other standard deviations, `<stem>_sources.csv`
/// gives every point's change for each input's error; at H = a the cap is a
/// hemisphere (R = a, dR/dH = 0), so a thinner or thicker sheet moves the
/// stress by -sigma t_std / t and a gauge gain by sigma g, with
/// sigma = p a / 2t.
#[test]
fn stress_writes_each_input_errors_change_of_every_point() {
    let dir = tempdir();
    let d = dir.path();
    write_inputs(d, "pressure_pa,height_m\n4000,0.0375\n");
    let with_std = format!(
        "{SPECIMEN}thickness_std_m = 1e-5\n[pressure]\ncsv = \"pressure.csv\"\nstd_pa = 5.0\nrelative_std = 0.01\n"
    );
    fs::write(d.join("experiment.toml"), with_std).unwrap();
    let run = stress_in(d, "o.csv").ok();
    assert!(run.stderr.contains("o_sources.csv"), "{}", run.stderr);
    let s = Csv::read(&d.join("o_sources.csv"));
    let sources: Vec<&str> = (0..3).map(|r| s.cell(r, "source")).collect();
    assert_eq!(sources, ["pressure_noise", "pressure_gain", "thickness"]);
    let sigma = 4000.0 * A / (2.0 * T);
    close(s.num(0, "stress_shift_pa"), sigma * 5.0 / 4000.0, 1e-12);
    close(s.num(1, "stress_shift_pa"), sigma * 0.01, 1e-12);
    close(s.num(2, "stress_shift_pa"), -sigma * 1e-5 / T, 1e-8);
    for r in 0..3 {
        assert_eq!(s.num(r, "strain_shift"), 0.0);
        assert_eq!(s.cell(r, "point"), "1");
    }

    // Without them, nothing beside the output.
    write_inputs(d, "pressure_pa,height_m\n4000,0.0375\n");
    stress_in(d, "p.csv").ok();
    assert!(!d.join("p_sources.csv").exists());
}
