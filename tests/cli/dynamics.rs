//! Integration tests of `bulge simulate --dynamic`.
use std::fs;

use crate::util::{bulge_in, read_csv, tempdir};

const DISC: &str = r#"
kind = "disc"
radius_m = 0.0375
thickness_m = 0.00035
pressure_pa = [5000]

[material]
model = "linear"
young_pa = 1.0e6
poisson = 0.45

[mesh]
nodes = 21
"#;

const SHEET: &str = r#"
kind = "sheet"
length_m = 0.1
width_m = 0.1
thickness_m = 0.001
density_kg_m3 = 1060

[material]
model = "linear"
young_pa = 3500
poisson = 0.45

[mesh]
nodes = 60

[[load]]
at = "middle"
force_n = [0.0, -0.01, 0.0]
"#;

fn col(head: &[String], row: &[String], name: &str) -> f64 {
    let i = head
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    row[i]
        .parse()
        .unwrap_or_else(|_| panic!("{name} = {:?}", row[i]))
}

/// A pressure step on the disc, critically damped springs: Verlet and
/// implicit Euler settle to the static height within 0.5 %, overshoot it
/// first, and the trace is written.
#[test]
fn disc_pressure_step_settles_to_the_static_height() {
    let dir = tempdir();
    fs::write(dir.path().join("scene.toml"), DISC).unwrap();
    bulge_in(
        dir.path(),
        &[
            "simulate",
            "scene.toml",
            "--dynamic",
            "--integrator",
            "verlet,implicit-euler",
            "--t-end",
            "0.06",
            "--damping",
            "1",
            "--trace",
            "trace.csv",
            "-o",
            "dyn.csv",
        ],
    )
    .ok();
    let (head, rows) = read_csv(&dir.path().join("dyn.csv"));
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let (h, hs, peak) = (
            col(&head, r, "height_m"),
            col(&head, r, "static_height_m"),
            col(&head, r, "peak_m"),
        );
        assert!((h - hs).abs() < 5e-3 * hs, "{r:?}");
        assert!(peak > 1.2 * hs, "a step response overshoots: {r:?}");
    }
    let trace = fs::read_to_string(dir.path().join("trace.csv")).unwrap();
    assert!(trace.lines().count() > 100 && !trace.contains("NaN"));
}

/// The refuse policy names the limit; xpbd refuses the tp model; explicit
/// Euler without damping has no stable step. All exit 2 and write nothing.
#[test]
fn refusals_are_clear() {
    let dir = tempdir();
    fs::write(dir.path().join("scene.toml"), DISC).unwrap();
    let base = [
        "simulate",
        "scene.toml",
        "--dynamic",
        "--t-end",
        "0.001",
        "-o",
        "dyn.csv",
    ];
    let with = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        bulge_in(dir.path(), &a)
    };
    with(&["--dt", "1e-3", "--step-policy", "refuse"])
        .bad_input(&["stable step of verlet", "--dt"]);
    with(&["--integrator", "xpbd"]).bad_input(&["xpbd", "van-gelder"]);
    with(&["--integrator", "explicit-euler", "--damping", "0"])
        .bad_input(&["unstable at every step"]);
    with(&["--integrator", "leapfrog"]).bad_input(&["leapfrog"]);
    bulge_in(
        dir.path(),
        &["simulate", "scene.toml", "--dynamic", "-o", "dyn.csv"],
    )
    .bad_input(&["--t-end"]);
    assert!(!dir.path().join("dyn.csv").exists());
}

/// Sudhamani & Merriliance's sheet with an in-plane load: held in its plane, a larger step is
/// sub-stepped, the loaded node moves along -y.
#[test]
fn sheet_in_plane_load_substeps() {
    let dir = tempdir();
    fs::write(dir.path().join("sheet.toml"), SHEET).unwrap();
    let r = bulge_in(
        dir.path(),
        &[
            "simulate",
            "sheet.toml",
            "--dynamic",
            "--model",
            "van-gelder",
            "--integrator",
            "symplectic-euler,xpbd",
            "--dt",
            "0.01",
            "--t-end",
            "0.5",
            "-o",
            "dyn.csv",
        ],
    )
    .ok();
    assert!(r.stderr.contains("held in z = 0"), "{}", r.stderr);
    let (head, rows) = read_csv(&dir.path().join("dyn.csv"));
    assert!(col(&head, &rows[0], "substeps") > 1.0, "{rows:?}");
    for row in &rows {
        assert!(col(&head, row, "height_m") > 0.0);
    }
}

/// A static run of a sheet under nodal loads alone (no pressure) is solved
/// once, at pressure 0, and agrees with where a damped dynamic run of the
/// same sheet comes to rest.
#[test]
fn static_sheet_under_loads_alone() {
    let dir = tempdir();
    fs::write(dir.path().join("sheet.toml"), SHEET).unwrap();
    bulge_in(
        dir.path(),
        &[
            "simulate",
            "sheet.toml",
            "--model",
            "van-gelder",
            "-o",
            "static.csv",
        ],
    )
    .ok();
    let (head, rows) = read_csv(&dir.path().join("static.csv"));
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(col(&head, &rows[0], "pressure_pa"), 0.0);
    let static_m = col(&head, &rows[0], "height_m");
    assert!(static_m > 0.0);
    bulge_in(
        dir.path(),
        &[
            "simulate",
            "sheet.toml",
            "--model",
            "van-gelder",
            "--dynamic",
            "--integrator",
            "implicit-euler",
            "--damping",
            "1",
            "--dt",
            "0.01",
            "--t-end",
            "3",
            "-o",
            "dyn.csv",
        ],
    )
    .ok();
    let (head, rows) = read_csv(&dir.path().join("dyn.csv"));
    let settled = col(&head, &rows[0], "height_m");
    assert!(
        (settled - static_m).abs() < 1e-2 * static_m,
        "static {static_m} vs settled {settled}"
    );
}

/// TP MSS run with (almost) no damping is warned of: its forces are not
/// conservative. Van Gelder's springs are, and get no such warning.
#[test]
fn undamped_tp_is_warned_of() {
    let dir = tempdir();
    fs::write(dir.path().join("scene.toml"), DISC).unwrap();
    let args = |model: &'static str| {
        [
            "simulate",
            "scene.toml",
            "--dynamic",
            "--model",
            model,
            "--damping",
            "0",
            "--t-end",
            "0.002",
            "-o",
            "dyn.csv",
        ]
    };
    let tp = bulge_in(dir.path(), &args("tp")).ok();
    assert!(tp.stderr.contains("not conservative"), "{}", tp.stderr);
    let vg = bulge_in(dir.path(), &args("van-gelder")).ok();
    assert!(!vg.stderr.contains("not conservative"), "{}", vg.stderr);
}

/// The membrane model through the integrators: a pressure step on a
/// neo-Hookean disc, critically damped, settles to the static height of the
/// same model within 0.5 % with Verlet and implicit Euler.
#[test]
fn membrane_model_pressure_step_settles() {
    let dir = tempdir();
    let scene = DISC.replace(
        "model = \"linear\"\nyoung_pa = 1.0e6",
        "model = \"neo-hookean\"\nc1_pa = 170000.0",
    );
    fs::write(dir.path().join("scene.toml"), scene).unwrap();
    bulge_in(
        dir.path(),
        &[
            "simulate",
            "scene.toml",
            "--model",
            "membrane",
            "--dynamic",
            "--integrator",
            "verlet,implicit-euler",
            "--t-end",
            "0.06",
            "--damping",
            "1",
            "-o",
            "dyn.csv",
        ],
    )
    .ok();
    let (head, rows) = read_csv(&dir.path().join("dyn.csv"));
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let (h, hs) = (col(&head, r, "height_m"), col(&head, r, "static_height_m"));
        assert!((h - hs).abs() < 5e-3 * hs, "{r:?}");
    }
}
