//! Integration tests of `bulge track` (and `bulge synth`): the real binary on
//! small synthetic experiments written by the library (spherical caps, so
//! that these tests do not depend on the material solver).

use std::fs;
use std::path::Path;

use bulge::track::image::{Encoding, Gray, encode};
use bulge::track::synth::{self, SequenceSpec};

use crate::util::{bulge_in, read_csv, tempdir};

const N: usize = 6;

/// A 320x240 sequence of `N` caps in `dir` (seed 201: used by no benchmark).
fn sequence(dir: &Path, enc: Encoding) -> synth::Written {
    let spec = SequenceSpec {
        drift: 0.02,
        ..SequenceSpec::plain(320, 240, 201, 1.0, 2.0, enc)
    };
    let frames = synth::cap_frames(0.0375, 0.02, N);
    synth::write_sequence(dir, &spec, &frames).expect("synthetic sequence")
}

fn edit(path: &Path, from: &str, to: &str) {
    let s = fs::read_to_string(path).unwrap();
    let mut done = false;
    let out: Vec<String> = s
        .lines()
        .map(|l| {
            if !done && l.starts_with(from) {
                done = true;
                to.to_string()
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "no line starting with {from:?} in {}", path.display());
    fs::write(path, out.join("\n") + "\n").unwrap();
}

/// The header then the records.
fn read_heights(path: &Path) -> Vec<Vec<String>> {
    let (head, mut rows) = read_csv(path);
    rows.insert(0, head);
    rows
}

#[test]
fn tracks_a_synthetic_sequence_to_sub_pixel_heights() {
    let d = tempdir();
    let w = sequence(d.path(), Encoding::Png);
    let run = bulge_in(d.path(), &["track", "experiment.toml", "-o", "heights.csv"]).ok();
    assert!(
        run.stdout.contains(&format!("tracked {N} of {N} photos")),
        "{}",
        run.stdout
    );
    let rows = read_heights(&d.path().join("heights.csv"));
    assert_eq!(
        rows[0].join(","),
        "frame,file,pressure_pa,apex_x_px,apex_y_px,score,height_m,height_std_m"
    );
    assert_eq!(rows.len(), N + 1);
    let mpp = w.scene.metres_per_pixel;
    for (r, t) in rows[1..].iter().zip(&w.truth) {
        assert_eq!(r[1], t.file);
        let y: f64 = r[4].parse().unwrap();
        let h: f64 = r[6].parse().unwrap();
        let std: f64 = r[7].parse().unwrap();
        // Bound: 0.2 px, twice the noisy RMS bound (a single frame, not an RMS).
        assert!(
            (y - t.apex_y_px).abs() < 0.2,
            "{}: row {y} vs {}",
            t.file,
            t.apex_y_px
        );
        assert!(
            (h - t.height_m).abs() < 0.2 * mpp,
            "{}: {h} vs {}",
            t.file,
            t.height_m
        );
        assert!(
            std > 0.0 && std < 0.2 * mpp,
            "{}: height_std_m {std}",
            t.file
        );
    }
}

#[test]
fn reference_frame_calibration_adds_the_prebulge() {
    let d = tempdir();
    let w = sequence(d.path(), Encoding::Png);
    let exp = d.path().join("experiment.toml");
    // Heights relative to frame 0, which stands at the true height h0.
    edit(&exp, "clamp_row_px", "");
    edit(
        &exp,
        "prebulge_height_m",
        &format!("prebulge_height_m = {}", w.truth[0].height_m),
    );
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"]).ok();
    let rows = read_heights(&d.path().join("h.csv"));
    let mpp = w.scene.metres_per_pixel;
    for (r, t) in rows[1..].iter().zip(&w.truth) {
        let h: f64 = r[6].parse().unwrap();
        assert!(
            (h - t.height_m).abs() < 0.3 * mpp,
            "{}: {h} vs {}",
            t.file,
            t.height_m
        );
    }
    let h0: f64 = rows[1][6].parse().unwrap();
    assert_eq!(h0, w.truth[0].height_m);
}

#[test]
fn unreadable_image_is_named() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    fs::write(
        d.path().join("photos/frame_003.png"),
        b"this is not an image",
    )
    .unwrap();
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"])
        .bad_input(&["frame_003.png", "cannot read"]);
    assert!(!d.path().join("h.csv").exists());
}

#[test]
fn truncated_png_and_jpeg_are_named() {
    for enc in [Encoding::Png, Encoding::Jpeg(90)] {
        let d = tempdir();
        sequence(d.path(), enc);
        let name = format!("frame_004.{}", enc.extension());
        let p = d.path().join("photos").join(&name);
        let bytes = fs::read(&p).unwrap();
        fs::write(&p, &bytes[..bytes.len() * 2 / 3]).unwrap();
        bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"])
            .bad_input(&[&name, "truncated"]);
        assert!(!d.path().join("h.csv").exists());
    }
}

#[test]
fn photos_of_mixed_sizes_are_refused() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    let small = Gray {
        width: 300,
        height: 200,
        data: vec![128; 300 * 200],
        tone: bulge::track::image::Tone::LINEAR,
    };
    fs::write(
        d.path().join("photos/frame_005.png"),
        encode(&small, Encoding::Png).unwrap(),
    )
    .unwrap();
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"]).bad_input(&[
        "frame_005.png",
        "300x200",
        "320x240",
        "frame_001.png",
    ]);
    assert!(!d.path().join("h.csv").exists());
}

#[test]
fn template_larger_than_region_is_refused() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    let exp = d.path().join("experiment.toml");
    edit(&exp, "roi_px", "roi_px = [120, 60, 20, 10]");
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"]).bad_input(&[
        "experiment.toml",
        "template is 32x16 px",
        "20x10",
    ]);
}

#[test]
fn region_outside_the_image_is_refused() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    let exp = d.path().join("experiment.toml");
    edit(&exp, "roi_px", "roi_px = [250, 100, 100, 50]");
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"]).bad_input(&[
        "frame_001.png",
        "[250, 100, 100, 50]",
        "320x240",
        "roi_px",
    ]);
}

#[test]
fn photo_without_pressure_is_named() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    let p = d.path().join("pressure.csv");
    let s = fs::read_to_string(&p).unwrap();
    let kept: Vec<&str> = s.lines().filter(|l| !l.starts_with("frame_002")).collect();
    fs::write(&p, kept.join("\n") + "\n").unwrap();
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"])
        .bad_input(&["pressure.csv", "no pressure for photo `frame_002.png`"]);
}

#[test]
fn empty_folder_is_refused() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    for e in fs::read_dir(d.path().join("photos")).unwrap() {
        fs::remove_file(e.unwrap().path()).unwrap();
    }
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"])
        .bad_input(&["photos", "empty"]);
}

#[test]
fn glob_matching_nothing_is_refused() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    edit(
        &d.path().join("experiment.toml"),
        "glob",
        "glob = \"*.tif\"",
    );
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"])
        .bad_input(&["no file matches glob = \"*.tif\"", "frame_001.png"]);
}

#[test]
fn low_scores_fail_or_are_skipped() {
    let d = tempdir();
    sequence(d.path(), Encoding::Png);
    // Frame 3 replaced by a uniform grey photo: nothing to match.
    let flat = Gray {
        width: 320,
        height: 240,
        data: vec![128; 320 * 240],
        tone: bulge::track::image::Tone::LINEAR,
    };
    fs::write(
        d.path().join("photos/frame_003.png"),
        encode(&flat, Encoding::Png).unwrap(),
    )
    .unwrap();
    bulge_in(d.path(), &["track", "experiment.toml", "-o", "h.csv"]).bad_input(&[
        "frame_003.png",
        "--min-score",
        "--skip-bad-frames",
    ]);
    assert!(!d.path().join("h.csv").exists());
    let run = bulge_in(
        d.path(),
        &[
            "track",
            "experiment.toml",
            "-o",
            "h.csv",
            "--skip-bad-frames",
        ],
    )
    .ok();
    assert!(
        run.stderr.contains("skipped frame 2 (frame_003.png)"),
        "{}",
        run.stderr
    );
    assert!(run.stdout.contains("1 skipped"), "{}", run.stdout);
    let rows = read_heights(&d.path().join("h.csv"));
    assert_eq!(rows.len(), N); // header + N - 1 frames
    assert!(rows.iter().all(|r| r[1] != "frame_003.png"));
}

#[test]
fn synth_writes_a_deterministic_experiment_that_track_recovers() {
    let d = tempdir();
    let args = [
        "--frames",
        "4",
        "--width",
        "320",
        "--height",
        "240",
        "--seed",
        "202",
        "--noise",
        "2",
        "--blur-px",
        "1",
        "--jpeg-quality",
        "90",
        "--pressure-max-pa",
        "5000",
    ];
    let mut a1 = vec!["synth", "one"];
    a1.extend(args);
    let run = bulge_in(d.path(), &a1).ok();
    assert!(
        run.stdout.contains("wrote 4 320x240 JPG photos"),
        "{}",
        run.stdout
    );
    let mut a2 = vec!["synth", "two"];
    a2.extend(args);
    bulge_in(d.path(), &a2).ok();
    for f in [
        "photos/frame_001.jpg",
        "photos/frame_004.jpg",
        "pressure.csv",
        "truth.csv",
        "experiment.toml",
    ] {
        let (x, y) = (
            fs::read(d.path().join("one").join(f)).unwrap(),
            fs::read(d.path().join("two").join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between two runs with the same seed");
    }
    let truth = fs::read_to_string(d.path().join("one/truth.csv")).unwrap();
    assert!(
        truth.starts_with("file,pressure_pa,height_m,apex_x_px,apex_y_px\n"),
        "{truth}"
    );
    let pressure = fs::read_to_string(d.path().join("one/pressure.csv")).unwrap();
    assert!(
        pressure.starts_with("file,pressure_pa\nframe_001.jpg,1250\n"),
        "{pressure}"
    );
    // Another seed gives other photos.
    let mut a3 = vec!["synth", "three"];
    a3.extend(args);
    *a3.iter_mut().find(|s| **s == "202").unwrap() = "203";
    bulge_in(d.path(), &a3).ok();
    assert_ne!(
        fs::read(d.path().join("one/photos/frame_001.jpg")).unwrap(),
        fs::read(d.path().join("three/photos/frame_001.jpg")).unwrap()
    );
    // The exact axisymmetric heights rise with pressure, and track finds them.
    bulge_in(
        &d.path().join("one"),
        &["track", "experiment.toml", "-o", "h.csv"],
    )
    .ok();
    let rows = read_heights(&d.path().join("one/h.csv"));
    let t: Vec<Vec<String>> = truth
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let mut last = 0.0;
    for (r, t) in rows[1..].iter().zip(&t) {
        let (y, ty): (f64, f64) = (r[4].parse().unwrap(), t[4].parse().unwrap());
        let th: f64 = t[2].parse().unwrap();
        assert!(th > last, "heights must rise with pressure");
        last = th;
        assert!((y - ty).abs() < 0.2, "{}: row {y} vs {ty}", t[0]);
    }
}

/// The lab look (random framing, a raised camera, uneven light, a
/// highlight, clutter) is drawn the same for the same seed, and its values
/// out of range or a framing that leaves the bubble out are refused naming
/// the flag.
#[test]
fn synth_draws_the_lab_look_deterministically_and_refuses_what_cannot_be() {
    let d = tempdir();
    let look = [
        "--frames",
        "3",
        "--width",
        "320",
        "--height",
        "240",
        "--seed",
        "204",
        "--random-framing",
        "--elevation-deg",
        "3",
        "--uneven-light",
        "0.3",
        "--highlight-grey",
        "90",
        "--clutter",
    ];
    for out in ["a", "b"] {
        let mut a = vec!["synth", out];
        a.extend(look);
        bulge_in(d.path(), &a).ok();
    }
    for f in [
        "photos/frame_001.png",
        "photos/frame_003.png",
        "truth.csv",
        "experiment.toml",
    ] {
        assert!(
            fs::read(d.path().join("a").join(f)).unwrap()
                == fs::read(d.path().join("b").join(f)).unwrap(),
            "{f} differs between two runs with the same seed"
        );
    }
    let toml = fs::read_to_string(d.path().join("a/experiment.toml")).unwrap();
    assert!(toml.contains("3.0 degrees above the clamp plane"), "{toml}");
    // The plain look differs from it.
    bulge_in(
        d.path(),
        &[
            "synth", "c", "--frames", "3", "--width", "320", "--height", "240", "--seed", "204",
        ],
    )
    .ok();
    assert_ne!(
        fs::read(d.path().join("a/photos/frame_001.png")).unwrap(),
        fs::read(d.path().join("c/photos/frame_001.png")).unwrap()
    );
    for (flag, value, said) in [
        ("--elevation-deg", "45", "0 to 30 degrees"),
        ("--uneven-light", "2", "0 to 0.8"),
        ("--highlight-grey", "300", "0 to 255"),
        ("--metres-per-pixel", "0", "positive scale"),
        ("--axis-x-px", "10", "side of the bubble"),
        ("--clamp-row-px", "236", "clamp ring"),
    ] {
        bulge_in(
            d.path(),
            &[
                "synth", "bad", "--frames", "2", "--width", "320", "--height", "240", flag, value,
            ],
        )
        .bad_input(&[flag, said]);
    }
}

#[test]
fn synth_refuses_a_pressure_above_the_limit_point() {
    let d = tempdir();
    bulge_in(
        d.path(),
        &["synth", "out", "--frames", "2", "--pressure-max-pa", "9000"],
    )
    .bad_input(&["9000 Pa", "limit point"]);
    assert!(!d.path().join("out/experiment.toml").exists());
}

#[test]
fn help_documents_every_flag_with_its_default() {
    let d = tempdir();
    let run = bulge_in(d.path(), &["track", "--help"]).ok();
    for f in [
        "--output",
        "--min-score",
        "--skip-bad-frames",
        "--refine",
        "--search-margin-px",
        "--edge-span-px",
        "--edge-window-px",
        "[default: 0.5]",
        "[default: edge]",
        "[default: 3]",
    ] {
        assert!(
            run.stdout.contains(f),
            "track --help lacks {f}:\n{}",
            run.stdout
        );
    }
    let run = bulge_in(d.path(), &["synth", "--help"]).ok();
    for f in [
        "--material",
        "--frames",
        "--pressure-max-pa",
        "--pressure-min-pa",
        "--radius-m",
        "--thickness-m",
        "--poisson",
        "--width",
        "--height",
        "--seed",
        "--blur-px",
        "--noise",
        "--drift",
        "--jpeg-quality",
        "--video",
        "--fps",
        "--log-rate-hz",
        "--log-offset-s",
        "--metres-per-pixel",
        "--axis-x-px",
        "--clamp-row-px",
        "--random-framing",
        "--elevation-deg",
        "--uneven-light",
        "--highlight-grey",
        "--clutter",
        "neo-Hookean",
    ] {
        assert!(
            run.stdout.contains(f),
            "synth --help lacks {f}:\n{}",
            run.stdout
        );
    }
}

/// The limit pressure of `bulge synth`'s default disc (a = 37.5 mm,
/// t = 0.35 mm) of `material`, from the exact axisymmetric solver; for a
/// law whose pressure rises monotonically (Mooney-Rivlin with C2/C1 above
/// about 0.1 on a clamped disc), the pressure at pole stretch 2.
fn limit_pressure(material: &bulge::material::Material) -> f64 {
    use bulge::axisym::{Options, limit_point, solve_pole_stretch};
    let specimen = bulge::experiment::Specimen {
        radius_m: 0.0375,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let o = Options::default();
    match limit_point(material, &specimen, &o).expect("solver") {
        Some(top) => top.pressure_pa,
        None => {
            solve_pole_stretch(material, &specimen, 2.0, &o)
                .expect("solver")
                .pressure_pa
        }
    }
}

/// Clean photos in equal pressure steps up to `fraction` of the limit
/// pressure of the material in `material_toml`, at `size`: every photo is
/// tracked (the curvature of the pole against the cap through the rim
/// changes with the height, by up to a fifth between coarse steps near the
/// limit, which the guards must allow).
fn clean_steps_to_near_the_limit_are_all_tracked(
    material_toml: &str,
    material: bulge::material::Material,
    frames: usize,
    fraction: f64,
    size: (u32, u32),
    seed: u64,
) {
    let d = tempdir();
    fs::write(d.path().join("material.toml"), material_toml).unwrap();
    let p_max = format!("{}", fraction * limit_pressure(&material));
    let (w, h) = (size.0.to_string(), size.1.to_string());
    let frames_s = frames.to_string();
    let seed_s = seed.to_string();
    bulge_in(
        d.path(),
        &[
            "synth",
            "out",
            "--material",
            "material.toml",
            "--frames",
            &frames_s,
            "--pressure-max-pa",
            &p_max,
            "--width",
            &w,
            "--height",
            &h,
            "--seed",
            &seed_s,
        ],
    )
    .ok();
    eprintln!("{size:?}: up to {p_max} Pa");
    let run = bulge_in(
        &d.path().join("out"),
        &["track", "experiment.toml", "-o", "heights.csv"],
    );
    assert!(
        run.status == 0
            && run
                .stdout
                .contains(&format!("tracked {frames} of {frames} photos")),
        "{size:?}: {}\n{}",
        run.stdout,
        run.stderr
    );
}

#[test]
fn a_mooney_rivlin_bubble_to_nine_tenths_of_its_pressure_at_pole_stretch_2_is_tracked() {
    let toml = "model = \"mooney-rivlin\"\npoisson = 0.45\nc1_pa = 220000.0\nc2_pa = 30000.0\n";
    let m = || bulge::material::Material {
        model: bulge::material::Model::MooneyRivlin {
            c1_pa: 2.2e5,
            c2_pa: 3.0e4,
        },
        poisson: 0.5,
        fit: None,
    };
    clean_steps_to_near_the_limit_are_all_tracked(toml, m(), 10, 0.9, (640, 480), 211);
    clean_steps_to_near_the_limit_are_all_tracked(toml, m(), 10, 0.9, (1280, 960), 212);
}

#[test]
fn a_neo_hookean_bubble_in_six_steps_to_its_limit_pressure_is_tracked() {
    let toml = "model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = 200000.0\n";
    let m = bulge::material::Material {
        model: bulge::material::Model::NeoHookean { c1_pa: 2.0e5 },
        poisson: 0.5,
        fit: None,
    };
    clean_steps_to_near_the_limit_are_all_tracked(toml, m, 6, 0.97, (640, 480), 213);
}
