//! `bulge run` on measured heights (`[heights]` in place of `[photos]`):
//! the two public real tests of a slack coated fabric in data/jekel, and
//! the heights file's errors.

use std::fs;
use std::path::Path;

use crate::util::{bulge_in, read_csv, repo, tempdir};

/// The rms relative error of the TP MSS heights against the measured ones
/// (as the run compared them: `stress_strain.csv`'s heights, which carry
/// the reference's apex height found), over every pressure.
fn tp_rms(out: &Path) -> (f64, usize) {
    let (sh, srows) = read_csv(&out.join("stress_strain.csv"));
    let (mh, mrows) = read_csv(&out.join("simulated.csv"));
    let col = |h: &[String], n: &str| h.iter().position(|c| c == n).unwrap();
    let (sp, shh) = (col(&sh, "pressure_pa"), col(&sh, "height_m"));
    let (mp, mhh, mm) = (
        col(&mh, "pressure_pa"),
        col(&mh, "height_m"),
        col(&mh, "model"),
    );
    let mut sum = 0.0;
    let mut n = 0;
    for r in &srows {
        let p: f64 = r[sp].parse().unwrap();
        let h: f64 = r[shh].parse().unwrap();
        let sim = mrows
            .iter()
            .find(|m| m[mm] == "tp" && m[mp].parse::<f64>().unwrap() == p)
            .and_then(|m| m[mhh].parse::<f64>().ok())
            .unwrap_or_else(|| panic!("no TP height at {p} Pa"));
        sum += ((sim - h) / h).powi(2);
        n += 1;
    }
    ((sum / n as f64).sqrt(), n)
}

/// Every real test, with `[heights]` and `prebulge_height_m = "fit"`, runs
/// through `bulge run` with default settings and the TP MSS heights are
/// within 0.5 % rms of the measured ones (one test per series, so that the
/// two runs share the machine with the other tests).
#[test]
fn real_slack_fabric_test_1_runs_from_its_heights_within_half_a_percent() {
    real_slack_fabric_test("test1");
}

/// As above, the second public series.
#[test]
fn real_slack_fabric_test_3_runs_from_its_heights_within_half_a_percent() {
    real_slack_fabric_test("test3");
}

fn real_slack_fabric_test(test: &str) {
    let dir = tempdir();
    let src = repo().join("data/jekel").join(test);
    for f in ["experiment.toml", "heights.csv"] {
        fs::copy(src.join(f), dir.path().join(f)).unwrap();
    }
    let run = bulge_in(dir.path(), &["run", "experiment.toml", "--out", "out"]).ok();
    assert!(
        run.stderr.contains("found from the heights"),
        "{}",
        run.stderr
    );
    let (rms, n) = tp_rms(&dir.path().join("out"));
    assert!(n >= 36, "{test}: {n} points compared");
    assert!(rms < 0.005, "{test}: TP MSS rms {:.3} %", 100.0 * rms);
    // the law written has positive stiffness: no such warning on it
    // (the table of laws may name another law that has it, never chosen)
    let summary = fs::read_to_string(dir.path().join("out/summary.md")).unwrap();
    assert!(
        !summary.contains("the law has negative stiffness"),
        "{summary}"
    );
    assert!(
        !summary
            .lines()
            .any(|l| l.contains(", chosen") && l.contains("negative stiffness")),
        "{summary}"
    );
}

fn experiment(dir: &Path, heights: &str, extra: &str) {
    fs::write(dir.join("h.csv"), heights).unwrap();
    fs::write(
        dir.join("e.toml"),
        format!(
            "[specimen]\nradius_m = 0.1\nthickness_m = 0.0008\npoisson = 0.45\n\n[heights]\ncsv = \"h.csv\"\n{extra}"
        ),
    )
    .unwrap();
}

#[test]
fn a_bad_heights_file_is_refused_with_file_line_value_and_fix() {
    let dir = tempdir();
    experiment(
        dir.path(),
        "pressure_pa,height_m\n1000,0.01\n900,0.012\n",
        "",
    );
    bulge_in(dir.path(), &["run", "e.toml", "--out", "o"]).bad_input(&[
        "h.csv",
        "line 3",
        "900",
        "increasing pressure",
    ]);
    experiment(dir.path(), "pressure_pa,height_m\n1000,10\n2000,12\n", "");
    bulge_in(dir.path(), &["run", "e.toml", "--out", "o"]).bad_input(&[
        "h.csv",
        "line 2",
        "millimetres",
    ]);
    experiment(dir.path(), "pressure,height_m\n1000,0.01\n2000,0.012\n", "");
    bulge_in(dir.path(), &["run", "e.toml", "--out", "o"]).bad_input(&["h.csv", "pressure_pa"]);
    experiment(
        dir.path(),
        "pressure_pa,height_m\n1000,0.01\n2000,0.012\n",
        "\n[photos]\ndir = \"photos\"\nroi_px = [224, 156, 192, 215]\ntemplate_rect_px = [288, 322, 64, 32]\nreference_frame = 0\n",
    );
    bulge_in(dir.path(), &["run", "e.toml", "--out", "o"]).bad_input(&["[heights] and [photos]"]);
}

/// The commands that need the dome height as a number refuse "fit" by name
/// and say where it is found.
#[test]
fn stress_refuses_a_dome_still_to_be_found_by_name() {
    let dir = tempdir();
    fs::write(
        dir.path().join("e.toml"),
        "[specimen]\nradius_m = 0.1\nthickness_m = 0.0008\npoisson = 0.45\nprebulge_height_m = \"fit\"\n",
    )
    .unwrap();
    fs::write(
        dir.path().join("h.csv"),
        "pressure_pa,height_m\n1000,0.01\n2000,0.012\n",
    )
    .unwrap();
    bulge_in(
        dir.path(),
        &["stress", "h.csv", "--experiment", "e.toml", "-o", "s.csv"],
    )
    .bad_input(&["prebulge_height_m", "[heights]"]);
}
