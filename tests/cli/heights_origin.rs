//! `[heights] origin = "reference"` with the dome height given as a
//! number: the heights are displacements from the stress-free dome, so the
//! apex stands at each height plus `prebulge_height_m` (the key is
//! honoured, not read as heights above the clamp plane).

use std::fs;

use crate::util::{bulge_in, read_csv, repo, tempdir};

#[test]
fn heights_from_a_numeric_dome_are_raised_by_it() {
    let dir = tempdir();
    let h0 = 0.0313;
    fs::copy(
        repo().join("data/jekel/test3/heights.csv"),
        dir.path().join("heights.csv"),
    )
    .unwrap();
    fs::write(
        dir.path().join("e.toml"),
        format!(
            "[specimen]\nradius_m = 0.1\nthickness_m = 0.00081\npoisson = 0.45\nprebulge_height_m = {h0}\n\n[heights]\ncsv = \"heights.csv\"\norigin = \"reference\"\n"
        ),
    )
    .unwrap();
    // the law is not the point here: the quartic of the cap method, not
    // corrected, on TP MSS only (a later stage may still fail; the stress
    // stage's rows are written either way)
    let run = bulge_in(
        dir.path(),
        &[
            "run",
            "e.toml",
            "--out",
            "o",
            "--fit",
            "quartic",
            "--no-refine",
            "--no-axisym",
            "--models",
            "tp",
        ],
    );
    assert!(
        !run.stderr.contains("below the pre-bulge height"),
        "{}",
        run.stderr
    );
    let (mh, mrows) = read_csv(&dir.path().join("heights.csv"));
    let (sh, srows) = read_csv(&dir.path().join("o/stress_strain.csv"));
    let col = |h: &[String], n: &str| h.iter().position(|c| c == n).unwrap();
    let (mi, si) = (col(&mh, "height_m"), col(&sh, "height_m"));
    assert_eq!(srows.len(), mrows.len(), "{}", run.stderr);
    for (m, s) in mrows.iter().zip(&srows) {
        let d: f64 = m[mi].parse().unwrap();
        let h: f64 = s[si].parse().unwrap();
        assert!(
            (h - (d + h0)).abs() < 1e-9,
            "apex {h} m for displacement {d} m"
        );
    }
}
