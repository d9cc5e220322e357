//! Integration tests of `bulge study`: five synthetic specimens of one
//! Mooney-Rivlin rubber (C1 = 120 kPa, C2 = 30 kPa), written by `bulge
//! synth` with thicknesses scattered by about 3 %, each experiment file
//! giving the thickness as a lab measures it (the true one off by a few
//! micrometres, with `thickness_std_m`): the study's files, the truth
//! within the mean's interval, the resumed run, a changed specimen redone
//! alone, a failed specimen left out.

use std::fs;
use std::path::Path;

use crate::util::{bulge_in, read_csv, tempdir};

/// True thickness, m, and the one the experiment file gives (measured with
/// a micrometre's few micrometres of error).
const SPECIMENS: [(f64, f64); 5] = [
    (3.61e-4, 3.63e-4),
    (3.43e-4, 3.40e-4),
    (3.56e-4, 3.57e-4),
    (3.38e-4, 3.41e-4),
    (3.52e-4, 3.50e-4),
];
const SEEDS: [u64; 5] = [501, 512, 503, 504, 505];

fn synth(dir: &Path, n: usize) {
    fs::write(
        dir.join("mr.toml"),
        "model = \"mooney-rivlin\"\npoisson = 0.45\nc1_pa = 120000.0\nc2_pa = 30000.0\n",
    )
    .unwrap();
    let mut study = String::from(
        "# five specimens of one rubber\n[run]\nfit = \"mooney-rivlin\"\nmodels = []\n",
    );
    for (k, ((t_true, t_measured), seed)) in SPECIMENS.iter().zip(SEEDS).take(n).enumerate() {
        let name = format!("s{}", k + 1);
        bulge_in(
            dir,
            &[
                "synth",
                &name,
                "--material",
                "mr.toml",
                "--frames",
                "7",
                "--width",
                "320",
                "--height",
                "240",
                "--noise",
                "2",
                "--blur-px",
                "1",
                "--pressure-max-pa",
                "4500",
                "--seed",
                &seed.to_string(),
                "--thickness-m",
                &t_true.to_string(),
            ],
        )
        .ok();
        let path = dir.join(&name).join("experiment.toml");
        let text = fs::read_to_string(&path).unwrap();
        let line = format!("thickness_m = {t_true}\n");
        assert!(text.contains(&line), "{text}");
        fs::write(
            &path,
            text.replace(
                &line,
                &format!("thickness_m = {t_measured}\nthickness_std_m = 3e-6\n"),
            ),
        )
        .unwrap();
        study.push_str(&format!(
            "\n[[specimens]]\nexperiment = \"{name}/experiment.toml\"\n"
        ));
    }
    fs::write(dir.join("study.toml"), study).unwrap();
}

fn col(head: &[String], name: &str) -> usize {
    head.iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {head:?}"))
}

/// The row labelled `label` of study.csv, parameter `name`.
fn cell(rows: &[Vec<String>], head: &[String], label: &str, name: &str) -> f64 {
    let r = rows
        .iter()
        .find(|r| r[0] == label)
        .unwrap_or_else(|| panic!("no row {label}"));
    r[col(head, name)].parse().unwrap()
}

#[test]
fn five_specimens_resumed_and_redone() {
    let dir = tempdir();
    let d = dir.path();
    synth(d, 5);
    let first = bulge_in(d, &["study", "study.toml", "--out", "out"]).ok();
    assert!(!first.stderr.contains("reused"), "{}", first.stderr);
    let out = d.join("out");
    let (head, rows) = read_csv(&out.join("study.csv"));
    for c in [
        "specimen",
        "thickness_m",
        "c1_pa",
        "c1_std_pa",
        "c2_pa",
        "c2_std_pa",
        "outlier",
    ] {
        col(&head, c);
    }
    let labels: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        labels,
        [
            "s1",
            "s2",
            "s3",
            "s4",
            "s5",
            "mean",
            "std",
            "cv",
            "ci95_low",
            "ci95_high",
            "pooled",
            "joint"
        ]
    );
    // each specimen's thickness is the measured one its experiment file gives
    for (k, (_, t)) in SPECIMENS.iter().enumerate() {
        let v = cell(&rows, &head, &format!("s{}", k + 1), "thickness_m");
        assert!((v - t).abs() < 1e-12, "s{}: {v}", k + 1);
    }
    for (name, truth) in [("c1_pa", 120e3), ("c2_pa", 30e3)] {
        let (lo, hi) = (
            cell(&rows, &head, "ci95_low", name),
            cell(&rows, &head, "ci95_high", name),
        );
        assert!(lo <= truth && truth <= hi, "{name}: {lo}..{hi}");
        // one law fitted to every specimen's heights: inside the interval too
        let j = cell(&rows, &head, "joint", name);
        assert!(lo <= j && j <= hi, "{name}: joint {j}, {lo}..{hi}");
        // with its own standard error (cluster-robust by specimen)
        let j_std = cell(&rows, &head, "joint", &name.replace("_pa", "_std_pa"));
        eprintln!("{name}: joint {j} +- {j_std} (1 sigma)");
        assert!(j_std > 0.0 && j_std < 0.05 * j, "{name}: joint std {j_std}");
        let cv = cell(&rows, &head, "cv", name);
        assert!(cv > 0.0 && cv < 0.1, "{name}: cv {cv}");
    }
    for k in 1..=5 {
        let s = out.join(format!("specimens/s{k}"));
        for f in [
            "heights.csv",
            "material.toml",
            "report.html",
            "study_fit.toml",
        ] {
            assert!(s.join(f).is_file(), "{}", s.join(f).display());
        }
    }
    let html = fs::read_to_string(out.join("study.html")).unwrap();
    assert!(html.contains("data:image/png;base64,") && !html.contains("<script"));
    assert!(first.stdout.contains("c1 (kPa)"), "{}", first.stdout);
    let csv1 = fs::read(out.join("study.csv")).unwrap();

    // unchanged: every specimen read back, the same study
    let again = bulge_in(d, &["study", "study.toml", "--out", "out"]).ok();
    assert!(
        again.stderr.contains("reused 5 of 5 specimens"),
        "{}",
        again.stderr
    );
    assert_eq!(fs::read(out.join("study.csv")).unwrap(), csv1);

    // one specimen's thickness measured again: that one alone redone
    let p = d.join("s3/experiment.toml");
    let text = fs::read_to_string(&p).unwrap();
    fs::write(
        &p,
        text.replace("thickness_m = 0.000357", "thickness_m = 0.000356"),
    )
    .unwrap();
    let third = bulge_in(d, &["study", "study.toml", "--out", "out"]).ok();
    assert!(
        third
            .stderr
            .contains("reused 4 of 5 specimens (s1, s2, s4, s5)"),
        "{}",
        third.stderr
    );
    assert!(third.stderr.contains("done    s3"), "{}", third.stderr);
    let (head, rows) = read_csv(&out.join("study.csv"));
    assert!((cell(&rows, &head, "s3", "thickness_m") - 3.56e-4).abs() < 1e-12);

    // a broken photo: that specimen is named with its stage's error, the
    // study goes on with the four others and exits 1
    fs::write(d.join("s5/photos/frame_003.png"), b"not a png").unwrap();
    let fourth = bulge_in(d, &["study", "study.toml", "--out", "out"]);
    assert_eq!(fourth.status, 1, "{}", fourth.stderr);
    assert!(
        fourth.stderr.contains("failed  s5: stage `track`")
            && fourth.stderr.contains("frame_003.png")
            && fourth.stderr.contains("going on with the 4 specimens"),
        "{}",
        fourth.stderr
    );
    let (_, rows) = read_csv(&out.join("study.csv"));
    assert_eq!(rows.iter().filter(|r| r[0].starts_with('s')).count() - 1, 4);
    assert!(!out.join("specimens/s5/study_fit.toml").exists());
}

/// Experiment files given directly are named by their folders; a study
/// file with a misspelt key, one specimen, or two specimens of one name is
/// refused naming the file, the key and the fix.
#[test]
fn experiment_files_directly_and_bad_study_files() {
    let dir = tempdir();
    let d = dir.path();
    synth(d, 2);
    for k in [1, 2] {
        let p = d.join(format!("s{k}/experiment.toml"));
        let text = fs::read_to_string(&p).unwrap();
        fs::write(&p, text + "\n[run]\nmodels = []\n").unwrap();
    }
    let r = bulge_in(
        d,
        &[
            "study",
            "s1/experiment.toml",
            "s2/experiment.toml",
            "--fit",
            "neo-hookean",
            "--out",
            "direct",
        ],
    )
    .ok();
    assert!(r.stderr.contains("neo-hookean"), "{}", r.stderr);
    let (head, rows) = read_csv(&d.join("direct/study.csv"));
    col(&head, "c1_std_pa");
    assert_eq!(rows[0][0], "s1");
    assert_eq!(rows[1][0], "s2");
    assert!(d.join("direct/specimens/s2/report.html").is_file());
    fs::write(
        d.join("typo.toml"),
        "[[specimens]]\nexperimnt = \"s1/experiment.toml\"\n",
    )
    .unwrap();
    bulge_in(d, &["study", "typo.toml", "--out", "o"]).bad_input(&[
        "typo.toml",
        "experimnt",
        "did you mean `experiment`",
    ]);
    fs::write(
        d.join("one.toml"),
        "[[specimens]]\nexperiment = \"s1/experiment.toml\"\n",
    )
    .unwrap();
    bulge_in(d, &["study", "one.toml", "--out", "o"])
        .bad_input(&["one.toml", "two specimens or more"]);
    fs::write(
        d.join("twice.toml"),
        "[[specimens]]\nexperiment = \"s1/experiment.toml\"\nname = \"a\"\n[[specimens]]\nexperiment = \"s2/experiment.toml\"\nname = \"a\"\n",
    )
    .unwrap();
    bulge_in(d, &["study", "twice.toml", "--out", "o"])
        .bad_input(&["two specimens are named `a`", "distinct `name`"]);
    // one experiment under two names would count one specimen twice
    fs::write(
        d.join("same.toml"),
        "[[specimens]]\nexperiment = \"s1/experiment.toml\"\nname = \"a\"\n[[specimens]]\nexperiment = \"./s1/../s1/experiment.toml\"\nname = \"b\"\n",
    )
    .unwrap();
    bulge_in(d, &["study", "same.toml", "--out", "o"])
        .bad_input(&["`a` and `b` are one experiment file", "list it once"]);
    bulge_in(d, &["study", "s1/experiment.toml", "--out", "o"])
        .bad_input(&["two specimens or more"]);
    // the study's output folder may not hold its inputs
    bulge_in(d, &["study", "study.toml", "--out", "s1"]).bad_input(&["--out", "never overwritten"]);
    let help = bulge_in(d, &["study", "--help"]).ok();
    for f in [
        "--out",
        "--redo",
        "--fit",
        "--models",
        "--weighted",
        "[[specimens]]",
        "study_fit.toml",
    ] {
        assert!(help.stdout.contains(f), "--help lacks {f}");
    }
}

/// Labs with a gauge or DIC bring heights, not photos: experiment files
/// with `[heights]` are specimens of a study too. Both specimens here carry
/// the exact heights of the demo's neo-Hookean bubble (C1 = 200 kPa, t =
/// 0.35 mm); the second file states a thickness 2 % larger, and since a
/// neo-Hookean membrane's pressure scales with `C1 t`, its law must come out
/// at 200 / 1.02 = 196.08 kPa.
#[test]
fn measured_heights_are_specimens_of_a_study() {
    let dir = tempdir();
    let d = dir.path();
    let (_, truth) = read_csv(&crate::util::repo().join("data/demo/truth.csv"));
    let mut csv = String::from("pressure_pa,height_m\n");
    for r in &truth {
        // file,pressure_pa,height_m,...
        csv.push_str(&format!("{},{}\n", r[1], r[2]));
    }
    fs::write(d.join("heights.csv"), csv).unwrap();
    for (name, t) in [("a", 0.00035), ("b", 0.00035 * 1.02)] {
        fs::write(
            d.join(format!("{name}.toml")),
            format!(
                "[specimen]\nradius_m = 0.0375\nthickness_m = {t}\npoisson = 0.45\n\n[heights]\ncsv = \"heights.csv\"\n"
            ),
        )
        .unwrap();
    }
    bulge_in(
        d,
        &[
            "study",
            "a.toml",
            "b.toml",
            "--out",
            "out",
            "--fit",
            "neo-hookean",
        ],
    )
    .ok();
    let (header, rows) = read_csv(&d.join("out/study.csv"));
    let c1 = header.iter().position(|h| h == "c1_pa").unwrap();
    let of = |name: &str| -> f64 {
        rows.iter().find(|r| r[0] == name).unwrap()[c1]
            .parse()
            .unwrap()
    };
    for (name, want) in [("a", 200e3), ("b", 200e3 / 1.02)] {
        let got = of(name);
        assert!(
            (got / want - 1.0).abs() < 0.002,
            "{name}: C1 {got} Pa against {want} Pa"
        );
    }
    let mean = of("mean");
    assert!(
        (mean / (0.5 * (200e3 + 200e3 / 1.02)) - 1.0).abs() < 0.002,
        "{mean}"
    );
}
