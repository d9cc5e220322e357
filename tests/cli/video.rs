//! Lab data as it comes: a video instead of a photo folder, and a pressure
//! logger on its own clock (`time_s,pressure_pa`), written by `bulge synth
//! --video --log-rate-hz --log-offset-s` and read by `bulge track` and
//! `bulge run`.

use std::fs;
use std::path::Path;

use crate::util::{bulge_in, read_csv, tempdir};

const FRAMES: usize = 8;
const FPS: f64 = 2.0;
const RATE_HZ: f64 = 7.0;
const OFFSET: &str = "0.4";
const P_MAX: f64 = 3200.0;

/// A 320x240 synthetic test of `FRAMES` PNG photos, also as `test.avi`, with a
/// 7 Hz pressure log whose clock is 0.4 s ahead of the camera's.
fn experiment(dir: &Path) {
    let run = bulge_in(
        dir,
        &[
            "synth",
            "x",
            "--frames",
            &FRAMES.to_string(),
            "--pressure-max-pa",
            &P_MAX.to_string(),
            "--width",
            "320",
            "--height",
            "240",
            "--seed",
            "211",
            "--noise",
            "2",
            "--blur-px",
            "1",
            "--video",
            "test.avi",
            "--fps",
            "2",
            "--log-rate-hz",
            "7",
            "--log-offset-s",
            OFFSET,
        ],
    )
    .ok();
    assert!(
        run.stdout.contains("test.avi") && run.stdout.contains("pressure_log.csv"),
        "{}",
        run.stdout
    );
}

fn column(head: &[String], name: &str) -> usize {
    head.iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {head:?}"))
}

fn numbers(path: &Path, name: &str) -> Vec<f64> {
    let (head, rows) = read_csv(path);
    let c = column(&head, name);
    rows.iter().map(|r| r[c].parse().unwrap()).collect()
}

/// The bound of linear interpolation between log samples `1 / RATE_HZ`
/// apart, `h^2 / 8 max|p''|`, for the synthetic ramp (a quarter step times
/// `sin^2(pi t fps)` on top of the straight line through the photos).
fn interpolation_bound() -> f64 {
    let step = (P_MAX - P_MAX / FRAMES as f64) / (FRAMES - 1) as f64;
    let max_p2 = 0.25 * step * 2.0 * std::f64::consts::PI.powi(2) * FPS * FPS;
    (1.0 / RATE_HZ).powi(2) / 8.0 * max_p2
}

fn edit(path: &Path, from: &str, to: &str) {
    let s = fs::read_to_string(path).unwrap();
    assert!(s.contains(from), "{} lacks {from:?}", path.display());
    fs::write(path, s.replacen(from, to, 1)).unwrap();
}

#[test]
fn a_video_tracks_to_the_heights_of_its_photos() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    bulge_in(&x, &["track", "experiment.toml", "-o", "photos.csv"]).ok();
    let run = bulge_in(&x, &["track", "experiment_video.toml", "-o", "video.csv"]).ok();
    assert!(
        run.stdout
            .contains(&format!("tracked {FRAMES} of {FRAMES}")),
        "{}",
        run.stdout
    );
    // The photo folder's columns are unchanged; a video adds time_s last.
    let (head, _) = read_csv(&x.join("photos.csv"));
    assert_eq!(
        head.join(","),
        "frame,file,pressure_pa,apex_x_px,apex_y_px,score,height_m,height_std_m"
    );
    let (head, rows) = read_csv(&x.join("video.csv"));
    assert_eq!(
        head.join(","),
        "frame,file,pressure_pa,apex_x_px,apex_y_px,score,height_m,height_std_m,time_s"
    );
    assert_eq!(rows.len(), FRAMES);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[1], format!("frame {k:06}"));
        let t: f64 = r[8].parse().unwrap();
        assert!((t - k as f64 / FPS).abs() < 1e-9, "frame {k}: time {t}");
    }
    // The video holds the same pixels as the PNG photos, compressed (Motion
    // JPEG, quality 95): each height within twice the two stated
    // uncertainties combined (measured: at most 0.53 of them combined).
    let (hp, sp) = (
        numbers(&x.join("photos.csv"), "height_m"),
        numbers(&x.join("photos.csv"), "height_std_m"),
    );
    let (hv, sv) = (
        numbers(&x.join("video.csv"), "height_m"),
        numbers(&x.join("video.csv"), "height_std_m"),
    );
    let mut worst: f64 = 0.0;
    for k in 0..FRAMES {
        let ratio = (hv[k] - hp[k]).abs() / sp[k].hypot(sv[k]);
        worst = worst.max(ratio);
        assert!(
            ratio <= 2.0,
            "frame {k}: video {} m, photo {} m, stds {} and {} m",
            hv[k],
            hp[k],
            sv[k],
            sp[k]
        );
    }
    eprintln!("video against photos: largest |dh| / combined std = {worst:.2}");
    // And the truth, as for photos (0.2 px).
    let truth = numbers(&x.join("truth.csv"), "height_m");
    let mpp = 2.0 * 0.0375 / (0.7 * 320.0);
    for k in 0..FRAMES {
        assert!(
            (hv[k] - truth[k]).abs() < 0.2 * mpp,
            "frame {k}: {} vs {}",
            hv[k],
            truth[k]
        );
    }
}

#[test]
fn a_seven_hertz_log_with_a_clock_offset_gives_each_frame_its_pressure() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    let truth = numbers(&x.join("truth.csv"), "pressure_pa");
    let bound = interpolation_bound();
    for (exp, out) in [
        ("experiment_log.toml", "log.csv"),
        ("experiment_video.toml", "video.csv"),
    ] {
        bulge_in(&x, &["track", exp, "-o", out]).ok();
        let p = numbers(&x.join(out), "pressure_pa");
        let t = numbers(&x.join(out), "time_s");
        assert_eq!(p.len(), FRAMES);
        let mut worst: f64 = 0.0;
        for k in 0..FRAMES {
            assert!((t[k] - k as f64 / FPS).abs() < 1e-9, "{exp}: time {}", t[k]);
            let e = (p[k] - truth[k]).abs();
            worst = worst.max(e);
            assert!(
                e <= bound,
                "{exp}: frame {k}: {} Pa from the log, {} Pa true, bound {bound} Pa",
                p[k],
                truth[k]
            );
        }
        eprintln!("{exp}: largest pressure error {worst:.2} Pa (bound {bound:.2} Pa)");
    }
    // Without the offset the frames are read 0.4 s early on the logger's
    // clock: far from the bound (a whole step is 400 Pa).
    edit(
        &x.join("experiment_log.toml"),
        "offset_s = 0.4",
        "offset_s = 0.0",
    );
    bulge_in(&x, &["track", "experiment_log.toml", "-o", "zero.csv"]).ok();
    let p = numbers(&x.join("zero.csv"), "pressure_pa");
    let worst = p
        .iter()
        .zip(&truth)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst > 10.0 * bound, "offset ignored: {worst} Pa");
}

#[test]
fn a_frame_outside_the_log_is_refused_with_both_spans() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    // The wrong sign puts the first photo at -0.4 s on the logger's clock,
    // before its first sample at 0 s.
    edit(
        &x.join("experiment_log.toml"),
        "offset_s = 0.4",
        "offset_s = -0.4",
    );
    bulge_in(&x, &["track", "experiment_log.toml", "-o", "h.csv"]).bad_input(&[
        "pressure_log.csv",
        "frame_001.png at 0 s",
        "logger time -0.4 s",
        "outside the log's span 0..",
        "the frames span 0..3.5 s",
        "fix `offset_s`",
        "logger time = frame time + offset_s",
    ]);
    assert!(!x.join("h.csv").exists());
}

#[test]
fn log_times_must_increase_strictly() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    let log = x.join("pressure_log.csv");
    let text = fs::read_to_string(&log).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    // line 5 repeats line 4's time
    let t4 = lines[3].split(',').next().unwrap().to_string();
    let p5 = lines[4].split(',').nth(1).unwrap().to_string();
    let repeated = format!("{t4},{p5}");
    lines[4] = &repeated;
    fs::write(&log, lines.join("\n") + "\n").unwrap();
    bulge_in(&x, &["track", "experiment_log.toml", "-o", "h.csv"]).bad_input(&[
        "pressure_log.csv",
        "line 5",
        "time_s",
        "not after the previous row's",
        "increase strictly",
    ]);
    assert!(!x.join("h.csv").exists());
}

#[test]
fn video_and_photo_folder_together_are_refused() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    let exp = x.join("experiment_video.toml");
    edit(&exp, "video = ", "dir = \"photos\"\nvideo = ");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "h.csv"]).bad_input(&[
        "experiment_video.toml",
        "both `video` and `dir`",
        "keep one",
    ]);
    edit(&exp, "dir = \"photos\"\n", "glob = \"*.png\"\n");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "h.csv"])
        .bad_input(&["experiment_video.toml", "`video` and `glob`"]);
    edit(&exp, "glob = \"*.png\"\nvideo = \"test.avi\"\n", "");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "h.csv"])
        .bad_input(&["needs `dir", "or `video"]);
    edit(&exp, "[photos]\n", "[photos]\nvideo = \"missing.avi\"\n");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "h.csv"]).bad_input(&[
        "missing.avi",
        "cannot read the video",
        "fix `video`",
    ]);
    assert!(!x.join("h.csv").exists());
}

#[test]
fn video_frames_are_chosen_by_time_or_step_and_a_time_outside_is_refused() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    let exp = x.join("experiment_video.toml");
    // Frames at 0, 0.5, ... 3.5 s: the nearest to 0.1, 1.4 and 2.6 s.
    edit(&exp, "every = 1", "times_s = [0.1, 1.4, 2.6]");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "t.csv"]).ok();
    let (_, rows) = read_csv(&x.join("t.csv"));
    let names: Vec<&str> = rows.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(names, ["frame 000000", "frame 000003", "frame 000005"]);
    edit(&exp, "times_s = [0.1, 1.4, 2.6]", "every = 3");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "e.csv"]).ok();
    let (_, rows) = read_csv(&x.join("e.csv"));
    let names: Vec<&str> = rows.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(names, ["frame 000000", "frame 000003", "frame 000006"]);
    // A frame that fails the score is named by its place in the video.
    bulge_in(
        &x,
        &[
            "track",
            "experiment_video.toml",
            "-o",
            "h.csv",
            "--min-score",
            "0.9999",
        ],
    )
    .bad_input(&["test.avi (frame 000003)", "frame 1:", "--min-score"]);
    edit(&exp, "every = 3", "times_s = [0.0, 1.0, 9.5]");
    bulge_in(&x, &["track", "experiment_video.toml", "-o", "h.csv"]).bad_input(&[
        "experiment_video.toml",
        "times_s[2] = 9.5 s",
        "outside the video's span 0..3.5 s",
        "8 frames at 2 frames/s",
    ]);
    assert!(!x.join("h.csv").exists());
}

#[test]
fn a_log_by_time_needs_frame_times_and_an_offset_needs_a_log_by_time() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    let exp = x.join("experiment_log.toml");
    edit(&exp, "interval_s = 0.5", "");
    bulge_in(&x, &["track", "experiment_log.toml", "-o", "h.csv"]).bad_input(&[
        "pressure_log.csv",
        "the photos have no times",
        "interval_s",
    ]);
    let exp = x.join("experiment.toml");
    edit(
        &exp,
        "csv = \"pressure.csv\"",
        "csv = \"pressure.csv\"\noffset_s = 1.0",
    );
    bulge_in(&x, &["track", "experiment.toml", "-o", "h.csv"]).bad_input(&[
        "offset_s = 1",
        "joined by file name",
        "remove offset_s",
    ]);
    assert!(!x.join("h.csv").exists());
}

#[test]
fn run_reads_a_video_and_draws_on_its_frames() {
    let d = tempdir();
    experiment(d.path());
    let x = d.path().join("x");
    bulge_in(&x, &["run", "experiment_video.toml", "--out", "../out"]).ok();
    let out = d.path().join("out");
    let (head, rows) = read_csv(&out.join("heights.csv"));
    assert_eq!(head.last().map(String::as_str), Some("time_s"));
    assert_eq!(rows.len(), FRAMES);
    let html = fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("frame 000007"), "the last frame's picture");
    assert!(html.contains("data:image/png;base64,"));
}

#[test]
fn synth_refuses_a_video_without_a_log() {
    let d = tempdir();
    bulge_in(
        d.path(),
        &["synth", "out", "--frames", "2", "--video", "test.avi"],
    )
    .bad_input(&["--video test.avi", "--log-rate-hz"]);
    bulge_in(
        d.path(),
        &[
            "synth",
            "out",
            "--frames",
            "2",
            "--log-rate-hz",
            "7",
            "--video",
            "test.mkv",
        ],
    )
    .bad_input(&[".avi", ".mp4"]);
    assert!(!d.path().join("out").exists());
}

/// A video with a frame damaged in its middle: the back-end stops (or skips
/// it), so the frames after it would be lost or would each take the time
/// and pressure of the frame before. It is refused with the count its
/// header gives and the count that can be read, and nothing is written.
#[test]
fn a_damaged_video_is_refused_with_both_counts() {
    let dir = tempdir();
    let d = dir.path();
    experiment(d);
    let avi = d.join("x/test.avi");
    let mut bytes = fs::read(&avi).unwrap();
    // The JPEG frames' start markers; the middle one's data overwritten.
    let starts: Vec<usize> = bytes
        .windows(3)
        .enumerate()
        .filter(|(_, w)| *w == [0xFF, 0xD8, 0xFF])
        .map(|(i, _)| i)
        .collect();
    assert_eq!(starts.len(), FRAMES);
    let k = starts[FRAMES / 2];
    bytes[k..k + 600].fill(0x55);
    fs::write(&avi, bytes).unwrap();
    bulge_in(d, &["track", "x/experiment_video.toml", "-o", "h.csv"]).bad_input(&[
        "test.avi",
        &format!("its header says {FRAMES} frames"),
        "can be read",
    ]);
    assert!(!d.join("h.csv").exists());
}
