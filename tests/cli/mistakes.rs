//! Ordinary mistakes and hostile input across the subcommands: every one
//! refused before any work, with exit 2 and a message naming the value and
//! the fix, and nothing written.

use std::fs;

use crate::util::{bulge_in, tempdir};

/// An output path of the wrong kind is the user's mistake (exit 2), named
/// before any work: `-o` a folder, `--vtk` a file, `synth` into a file.
#[test]
fn output_paths_of_the_wrong_kind_are_refused() {
    let dir = tempdir();
    let d = dir.path();
    fs::create_dir_all(d.join("adir")).unwrap();
    fs::write(d.join("afile"), "").unwrap();
    let data = crate::util::repo().join("data/treloar_equibiaxial.csv");
    let data = data.to_str().unwrap();
    bulge_in(d, &["fit", data, "-o", "adir"]).bad_input(&["-o", "adir", "is a folder"]);
    let heights = crate::util::repo().join("data/demo/heights.csv");
    let exp = crate::util::repo().join("data/demo/experiment.toml");
    bulge_in(
        d,
        &[
            "stress",
            heights.to_str().unwrap(),
            "--experiment",
            exp.to_str().unwrap(),
            "-o",
            "adir",
        ],
    )
    .bad_input(&["is a folder"]);
    let scene = crate::util::repo().join("data/scenes/latex-disc.toml");
    bulge_in(d, &["simulate", scene.to_str().unwrap(), "--vtk", "afile"])
        .bad_input(&["--vtk", "is a file"]);
    bulge_in(d, &["synth", "afile"]).bad_input(&["is a file"]);
    assert_eq!(fs::read(d.join("afile")).unwrap().len(), 0);
}

/// Resource limits are named before the work: a photo too big to draw, a
/// blur that erases the bubble, a curve of absurdly many samples.
#[test]
fn resource_limits_are_named_before_the_work() {
    let dir = tempdir();
    let d = dir.path();
    bulge_in(
        d,
        &["synth", "s", "--width", "100000", "--height", "100000"],
    )
    .bad_input(&["--max-memory-gb"]);
    bulge_in(d, &["synth", "s", "--blur-px", "1000000"]).bad_input(&["--blur-px", "erases"]);
    assert!(!d.join("s").exists());
    let data = crate::util::repo().join("data/treloar_equibiaxial.csv");
    bulge_in(
        d,
        &["fit", data.to_str().unwrap(), "--samples", "100000000"],
    )
    .bad_input(&["--samples"]);
    assert!(!d.join("material.toml").exists());
}

/// A pressure too small for double precision to resolve on the membrane is
/// not reported as solved; the message prints the pressure in a few digits.
#[test]
fn a_pressure_below_round_off_is_not_solved() {
    let dir = tempdir();
    let scene = crate::util::repo().join("data/scenes/latex-disc.toml");
    let r = bulge_in(
        dir.path(),
        &[
            "simulate",
            scene.to_str().unwrap(),
            "--pressures",
            "1e-300",
            "-o",
            "s.csv",
        ],
    );
    assert_eq!(r.status, 1, "{}", r.stderr);
    assert!(r.stderr.contains("1.00000e-300 Pa"), "{}", r.stderr);
    assert!(r.stderr.contains("too small"), "{}", r.stderr);
    let csv = fs::read_to_string(dir.path().join("s.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1, "a row was written: {csv}");
}

/// Nonsense that used to give empty cells or a silent duplicate: a derived
/// value beyond double precision is refused naming its row and column; an
/// input column that the output writes is refused; a height at round-off
/// level gets a warning.
#[test]
fn stress_refuses_what_it_cannot_compute() {
    let dir = tempdir();
    let d = dir.path();
    let stress = |name: &str, text: &str| {
        fs::write(d.join(name), text).unwrap();
        let args = [
            "stress",
            name,
            "--radius-m",
            "0.0375",
            "--thickness-m",
            "0.00035",
            "--poisson",
            "0.45",
            "-o",
            "out.csv",
        ];
        bulge_in(d, &args)
    };
    stress("big.csv", "pressure_pa,height_m\n1.7e308,0.01\n").bad_input(&[
        "big.csv",
        "line 2",
        "stress_pa",
        "inf",
        "units",
    ]);
    stress("dup.csv", "pressure_pa,height_m,stress_pa\n1000,0.01,5\n").bad_input(&[
        "dup.csv",
        "`stress_pa`",
        "rename or drop",
    ]);
    assert!(!d.join("out.csv").exists());
    let r = stress("tiny.csv", "pressure_pa,height_m\n1000,1e-12\n").ok();
    assert!(r.stderr.contains("round-off"), "{}", r.stderr);
}
