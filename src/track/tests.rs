//! Tests of the tracker on synthetic photos with known truth.

use std::path::Path;

use super::*;
use crate::experiment::Experiment;

#[test]
fn natural_order() {
    let mut v = vec!["img10.png", "img2.png", "img1.png", "img02.png", "a.png"];
    v.sort_by(|a, b| natural_cmp(a, b));
    assert_eq!(
        v,
        ["a.png", "img1.png", "img02.png", "img2.png", "img10.png"]
    );
}

#[test]
fn globs() {
    assert!(glob_match("*.png", "frame_001.png"));
    assert!(!glob_match("*.png", "frame_001.jpg"));
    assert!(glob_match("frame_??.jp*g", "frame_12.jpeg"));
    assert!(glob_match("f[0-9]*", "f7x"));
    assert!(!glob_match("f[!0-9]*", "f7x"));
    assert!(glob_match("*", "anything"));
}

fn write_tiny_experiment(dir: &Path) {
    let spec = spec(301, 0.0, 0.0, image::Encoding::Png);
    let spec = synth::SequenceSpec {
        width: 160,
        height: 120,
        ..spec
    };
    synth::write_sequence(dir, &spec, &synth::cap_frames(0.0375, 0.015, 3)).unwrap();
}

#[test]
fn truncated_files_are_caught_before_decoding() {
    let g = image::Gray {
        width: 16,
        height: 8,
        data: (0..128).map(|v| v as u8).collect(),
        tone: crate::track::image::Tone::LINEAR,
    };
    for enc in [image::Encoding::Png, image::Encoding::Jpeg(90)] {
        let bytes = image::encode(&g, enc).unwrap();
        assert!(image::check_complete(Path::new("a"), &bytes).is_ok());
        let cut = &bytes[..bytes.len() - 5];
        let e = image::check_complete(Path::new("a.img"), cut).unwrap_err();
        assert!(matches!(e, TrackError::Truncated { .. }), "{e}");
        let e = image::decode_gray(Path::new("b.img"), cut, None).unwrap_err();
        assert!(
            e.to_string().contains("b.img") && e.to_string().contains("truncated"),
            "{e}"
        );
    }
    let e = image::decode_gray(Path::new("c.png"), b"not an image", None).unwrap_err();
    assert!(matches!(e, TrackError::Unreadable { .. }), "{e}");
}

#[test]
fn empty_folder_and_unmatched_glob_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let e = list_photos(d.path(), "*.png").unwrap_err();
    assert!(matches!(e, TrackError::EmptyFolder { .. }), "{e}");
    std::fs::write(d.path().join("a1.jpg"), b"x").unwrap();
    let e = list_photos(d.path(), "*.png").unwrap_err();
    assert!(e.to_string().contains("`a1.jpg`"), "{e}");
    assert_eq!(list_photos(d.path(), "a?.jpg").unwrap().len(), 1);
    let e = list_photos(d.path(), "a[1.jpg").unwrap_err();
    assert!(matches!(e, TrackError::BadGlob { .. }), "{e}");
}

#[test]
fn pressure_log_must_cover_every_photo_once() {
    let d = tempfile::tempdir().unwrap();
    write_tiny_experiment(d.path());
    let exp = d.path().join("experiment.toml");
    std::fs::write(
        d.path().join("pressure.csv"),
        "file,pressure_pa\nframe_001.png,100\nframe_002.png,200\n",
    )
    .unwrap();
    let e = setup_from_experiment(&Experiment::read(&exp).unwrap()).unwrap_err();
    assert!(
        e.to_string()
            .contains("no pressure for photo `frame_003.png`"),
        "{e}"
    );
    std::fs::write(
        d.path().join("pressure.csv"),
        "file,pressure_pa\nframe_001.png,100\nframe_001.png,200\n",
    )
    .unwrap();
    let e = setup_from_experiment(&Experiment::read(&exp).unwrap()).unwrap_err();
    assert!(
        e.to_string().contains("line 3") && e.to_string().contains("already"),
        "{e}"
    );
}

/// `[photos]` and `[pressure]` keys of the other source, or out of range,
/// are refused naming the key; `interval_s`/`start_s` time the photos and a
/// log by time gives each its interpolated pressure.
#[test]
fn photo_times_and_the_keys_of_each_source() {
    let d = tempfile::tempdir().unwrap();
    write_tiny_experiment(d.path());
    let exp = d.path().join("experiment.toml");
    let text = std::fs::read_to_string(&exp).unwrap();
    let with = |photos: &str, pressure: &str| {
        let t = text
            .replace("[photos]\n", &format!("[photos]\n{photos}"))
            .replace("csv = \"pressure.csv\"\n", pressure);
        std::fs::write(&exp, t).unwrap();
        setup_from_experiment(&Experiment::read(&exp).unwrap())
    };
    let file_join = "csv = \"pressure.csv\"\n";
    let e = with("every = 2\n", file_join).unwrap_err().to_string();
    assert!(
        e.contains("`every`/`times_s` choose the frames of a video"),
        "{e}"
    );
    let e = with("start_s = 1.0\n", file_join).unwrap_err().to_string();
    assert!(e.contains("start_s = 1 without interval_s"), "{e}");
    let e = with("interval_s = 0.0\n", file_join)
        .unwrap_err()
        .to_string();
    assert!(e.contains("interval_s = 0:"), "{e}");
    // times without a log by time: carried to the heights, pressures by file
    let s = with("interval_s = 0.25\nstart_s = 10.0\n", file_join).unwrap();
    let times: Vec<_> = s.frames.iter().map(|f| f.time_s).collect();
    assert_eq!(times, [Some(10.0), Some(10.25), Some(10.5)]);
    assert_eq!(s.frames[1].pressure_pa, 200.0);
    // a log by time on a clock 2 s behind the camera's
    std::fs::write(
        d.path().join("log.csv"),
        "time_s,pressure_pa\n7.5,0\n8.5,1000\n",
    )
    .unwrap();
    let log = "csv = \"log.csv\"\noffset_s = -2.0\n";
    let s = with("interval_s = 0.25\nstart_s = 10.0\n", log).unwrap();
    let p: Vec<f64> = s.frames.iter().map(|f| f.pressure_pa).collect();
    assert!(
        (p[0] - 500.0).abs() < 1e-9 && (p[2] - 1000.0).abs() < 1e-9,
        "{p:?}"
    );
    let e = with("interval_s = 0.5\nstart_s = 10.0\n", log)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("frame_003.png at 11 s") && e.contains("logger time 9 s"),
        "{e}"
    );
    let e = with("", log).unwrap_err().to_string();
    assert!(e.contains("the photos have no times"), "{e}");
    assert!(
        e.contains("frame_001.png has no time from the camera"),
        "{e}"
    );
    // The camera's clock: the photos as JPEG with EXIF DateTimeOriginal and
    // SubSecTimeOriginal, a quarter second apart; no interval_s.
    for k in 1..=3 {
        let png = d.path().join(format!("photos/frame_00{k}.png"));
        let bytes = std::fs::read(&png).unwrap();
        let g = image::decode_gray(&png, &bytes, None).unwrap();
        let jpeg = image::encode(&g.crop, image::Encoding::Jpeg(95)).unwrap();
        let sub = ["", "25", "50"][k - 1];
        let stamped = super::exif_time::tests::with_exif(
            &jpeg,
            "2026:11:23 09:59:59",
            (!sub.is_empty()).then_some(sub),
        );
        std::fs::write(d.path().join(format!("photos/frame_00{k}.jpg")), stamped).unwrap();
        std::fs::remove_file(&png).unwrap();
    }
    std::fs::write(
        d.path().join("log.csv"),
        "time_s,pressure_pa\n-1,0\n1,2000\n",
    )
    .unwrap();
    let text = text.replace("*.png", "*.jpg");
    std::fs::write(
        &exp,
        text.replace("csv = \"pressure.csv\"\n", "csv = \"log.csv\"\n"),
    )
    .unwrap();
    let s = setup_from_experiment(&Experiment::read(&exp).unwrap()).unwrap();
    let times: Vec<_> = s.frames.iter().map(|f| f.time_s).collect();
    assert_eq!(times, [Some(0.0), Some(0.25), Some(0.5)]);
    let p: Vec<f64> = s.frames.iter().map(|f| f.pressure_pa).collect();
    assert_eq!(p, [1000.0, 1250.0, 1500.0]);
    // Photos stamped to the same second with no sub-seconds cannot be told
    // apart on the log: refused, naming both photos.
    for k in 2..=3 {
        let path = d.path().join(format!("photos/frame_00{k}.jpg"));
        let bytes = std::fs::read(&path).unwrap();
        let g = image::decode_gray(&path, &bytes, None).unwrap();
        let jpeg = image::encode(&g.crop, image::Encoding::Jpeg(95)).unwrap();
        let stamped = super::exif_time::tests::with_exif(&jpeg, "2026:11:23 10:00:00", None);
        std::fs::write(&path, stamped).unwrap();
    }
    let e = setup_from_experiment(&Experiment::read(&exp).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("frame_003.jpg")
            && e.contains("the same time as")
            && e.contains("frame_002.jpg"),
        "{e}"
    );
}

#[test]
fn region_and_template_are_checked_against_the_image() {
    let d = tempfile::tempdir().unwrap();
    write_tiny_experiment(d.path());
    let exp = Experiment::read(d.path().join("experiment.toml")).unwrap();
    let mut setup = setup_from_experiment(&exp).unwrap();
    setup.roi = [100, 50, 100, 20];
    let e = track(&setup, &Options::default(), &|| {}).unwrap_err();
    assert!(
        matches!(
            e,
            TrackError::RegionOutside {
                width: 160,
                height: 120,
                ..
            }
        ),
        "{e}"
    );
    setup.roi = [60, 40, 10, 40];
    let e = track(&setup, &Options::default(), &|| {}).unwrap_err();
    assert!(
        matches!(
            e,
            TrackError::TemplateLargerThanRegion { tw: 16, th: 8, .. }
        ),
        "{e}"
    );
}

/// The experiment that `synth::write_sequence` wrote into `dir`, tracked
/// with `opts`.
fn tracked_in(dir: &Path, opts: &Options) -> Result<Tracked, TrackError> {
    let e = Experiment::read(dir.join("experiment.toml")).unwrap();
    track(&setup_from_experiment(&e).unwrap(), opts, &|| {})
}

/// Writes a cap sequence, tracks it, returns the apex errors.
fn accuracy(spec: &synth::SequenceSpec, n: usize, refine: Refine) -> synth::ApexErrors {
    let dir = tempfile::tempdir().unwrap();
    let frames = synth::cap_frames(spec.specimen.radius_m, 0.6 * spec.specimen.radius_m, n);
    let w = synth::write_sequence(dir.path(), spec, &frames).unwrap();
    let opts = Options {
        refine,
        ..Options::default()
    };
    let t = tracked_in(dir.path(), &opts).unwrap();
    assert_eq!(t.rows.len(), n);
    if std::env::var_os("BULGE_TRACK_DEBUG").is_some() {
        for (r, tr) in t.rows.iter().zip(&w.truth) {
            let e = r.edge.unwrap();
            eprintln!(
                "{} score {:.3} dy {:+.3} (std {:.3}) dx {:+.3} dx_q {:+.3} dx_v {:+.3} (std {:.3}) curv {:.5} rms {:.3} cols {}",
                r.file,
                r.score,
                r.apex_y_px - tr.apex_y_px,
                r.apex_y_std_px,
                r.apex_x_px - tr.apex_x_px,
                r.apex_quadratic_px[0] - tr.apex_x_px,
                e.x_vertex - tr.apex_x_px,
                e.x_std,
                e.curvature,
                e.rms,
                e.columns
            );
        }
    }
    synth::apex_errors(&t.rows, &w.truth)
}

/// Prints the errors and holds the reported apex row's RMS to `bound` px.
fn assert_row_rms(a: &synth::ApexErrors, bound: f64) {
    eprintln!("{a:?}");
    assert!(
        a.reported[1] <= bound,
        "RMS apex row error {} px > {bound}",
        a.reported[1]
    );
}

fn spec(seed: u64, blur: f64, noise: f64, enc: image::Encoding) -> synth::SequenceSpec {
    synth::SequenceSpec::plain(640, 480, seed, blur, noise, enc)
}

// Seeds 101.. are used by tests only; the benchmarks use seeds 1..=3.
#[test]
fn sub_pixel_apex_without_noise() {
    let a = accuracy(&spec(101, 0.0, 0.0, image::Encoding::Png), 10, Refine::Edge);
    assert_row_rms(&a, 0.05);
}

/// A 1280x960 sequence: the 128 px template is searched at a quarter of
/// the resolution for the edge fit's seed; the integer mode searches at
/// half resolution first, then matches at full resolution near the
/// coarse peak.
#[test]
fn coarse_to_fine_search_on_larger_photos() {
    let s = synth::SequenceSpec {
        width: 1280,
        height: 960,
        ..spec(103, 1.5, 3.0, image::Encoding::Jpeg(85))
    };
    let a = accuracy(&s, 6, Refine::Edge);
    assert_row_rms(&a, 0.1);
    // The full-resolution integer match (after the coarse search at
    // half resolution) is right to a pixel.
    let i = accuracy(&s, 6, Refine::Integer);
    assert!(
        i.integer[1] <= 1.0,
        "integer match row error {} px",
        i.integer[1]
    );
}

/// 4000x3000 photos (the 400 px template searched at 1/8 of the
/// resolution for the edge fit's seed). Slow in a debug build (drawing
/// the photos): `cargo test --lib -- --ignored large_photos`.
#[test]
#[ignore]
fn sub_pixel_apex_on_large_photos() {
    let s = synth::SequenceSpec {
        width: 4000,
        height: 3000,
        ..spec(104, 1.0, 2.0, image::Encoding::Jpeg(90))
    };
    let a = accuracy(&s, 6, Refine::Edge);
    assert_row_rms(&a, 0.1);
}

#[test]
fn sub_pixel_apex_with_noise_blur_and_jpeg() {
    let a = accuracy(
        &spec(102, 1.5, 3.0, image::Encoding::Jpeg(85)),
        10,
        Refine::Edge,
    );
    assert_row_rms(&a, 0.1);
}

/// A sequence of spherical caps with clutter behind the bubble (a shelf
/// edge and a cable across the apex's path), uneven light and a specular
/// highlight near the apex, tracked with `skip_bad_frames`: returns the
/// tracking and the truth.
fn lab_sequence(
    seed: u64,
    look: synth::Look,
    skip: bool,
) -> (Result<Tracked, TrackError>, Vec<synth::Truth>) {
    let s = synth::SequenceSpec {
        width: 1280,
        height: 960,
        look,
        ..spec(seed, 1.5, 3.0, image::Encoding::Jpeg(90))
    };
    let frames = synth::cap_frames(s.specimen.radius_m, 0.6 * s.specimen.radius_m, 12);
    written_and_tracked(&s, &frames, skip)
}

/// Holds every tracked frame's apex row within 4 of its stated standard
/// deviations of the truth (none silently wrong); returns the errors, px.
fn kept_within_4_sd(rows: &[FrameResult], truth: &[synth::Truth], what: &str) -> Vec<f64> {
    rows.iter()
        .map(|r| {
            let tr = truth.iter().find(|tr| tr.file == r.file).unwrap();
            let err = r.apex_y_px - tr.apex_y_px;
            assert!(
                err.abs() <= 4.0 * r.apex_y_std_px,
                "{what} {}: apex row {err:+.3} px off, stated std {:.3} px",
                r.file,
                r.apex_y_std_px
            );
            err
        })
        .collect()
}

/// `frames` written as `s` into a temporary folder and tracked with the
/// experiment file written beside them (the true set-up): the tracking and
/// the truth.
fn written_and_tracked(
    s: &synth::SequenceSpec,
    frames: &[synth::SynthFrame],
    skip: bool,
) -> (Result<Tracked, TrackError>, Vec<synth::Truth>) {
    let dir = tempfile::tempdir().unwrap();
    let w = synth::write_sequence(dir.path(), s, frames).unwrap();
    let opts = Options {
        skip_bad_frames: skip,
        ..Options::default()
    };
    (tracked_in(dir.path(), &opts), w.truth)
}

/// Several experiments tracked at once, each on threads of its own (as a
/// program tracking several folders does): every run gives exactly what
/// the experiment gives alone. OpenCV's thread count is a process-wide
/// setting, made once; made by every run, two runs setting it at the same
/// moment crashed the process.
#[test]
fn experiments_tracked_at_once_give_what_each_gives_alone() {
    let dirs: Vec<_> = [121u64, 122]
        .iter()
        .map(|&seed| {
            let dir = tempfile::tempdir().unwrap();
            let s = spec(seed, 1.0, 2.0, image::Encoding::Png);
            let frames = synth::cap_frames(s.specimen.radius_m, 0.5 * s.specimen.radius_m, 6);
            synth::write_sequence(dir.path(), &s, &frames).unwrap();
            dir
        })
        .collect();
    let run = |dir: &Path| tracked_in(dir, &Options::default()).unwrap();
    let alone: Vec<Tracked> = dirs.iter().map(|d| run(d.path())).collect();
    assert!(alone.iter().all(|t| t.rows.len() == 6));
    std::thread::scope(|scope| {
        let runs: Vec<_> = (0..4)
            .map(|k| {
                let dir = dirs[k % 2].path();
                scope.spawn(move || (k % 2, (0..3).map(|_| run(dir)).collect::<Vec<_>>()))
            })
            .collect();
        for r in runs {
            let (i, tracked) = r.join().unwrap();
            for t in tracked {
                assert_eq!(
                    t.rows, alone[i].rows,
                    "experiment {i} tracked beside others"
                );
                assert_eq!(t.skipped, alone[i].skipped, "experiment {i}");
            }
        }
    });
}

/// Clutter and gloss: every frame is either tracked within its stated
/// uncertainty (4 standard deviations; none silently wrong) or left out
/// with the reason; over the tracked frames of three seeds the apex row is
/// within 0.1 px RMS; without `skip_bad_frames` a frame left out fails the
/// run naming the frame and its file.
#[test]
fn clutter_and_gloss_are_tracked_or_left_out_by_name() {
    let look = synth::Look {
        uneven_light: 0.3,
        highlight_grey: 90.0,
        clutter: true,
        ..synth::Look::default()
    };
    let (mut sum2, mut n, mut total) = (0.0, 0usize, 0usize);
    for seed in [111, 112, 113] {
        let (t, truth) = lab_sequence(seed, look, true);
        let t = t.unwrap();
        total += truth.len();
        for r in &t.rows {
            let tr = truth.iter().find(|tr| tr.file == r.file).unwrap();
            let err = r.apex_y_px - tr.apex_y_px;
            if let Some(e) = r.edge {
                eprintln!(
                    "seed {seed} {} dy {err:+.3} (std {:.3}) dx {:+.2} curv {:.3e} rms {:.3} cols {} h {:.1}",
                    r.file,
                    r.apex_y_std_px,
                    r.apex_x_px - tr.apex_x_px,
                    e.curvature,
                    e.rms,
                    e.columns,
                    tr.apex_y_px
                );
            }
        }
        for err in kept_within_4_sd(&t.rows, &truth, &format!("seed {seed}")) {
            sum2 += err * err;
            n += 1;
        }
        for s in &t.skipped {
            assert!(!s.reason.is_empty(), "seed {seed}: {s:?}");
            eprintln!(
                "seed {seed}: left out {} ({}): {}",
                s.frame, s.file, s.reason
            );
        }
        if let Some(first) = t.skipped.first() {
            let (e, _) = lab_sequence(seed, look, false);
            let e = e.unwrap_err().to_string();
            assert!(
                e.contains(&format!("frame {}", first.frame)) && e.contains(&first.file),
                "{e}"
            );
        }
    }
    let rms = (sum2 / n as f64).sqrt();
    eprintln!("{n} of {total} frames tracked, apex row RMS {rms:.3} px");
    assert!(rms <= 0.1, "apex row RMS {rms:.3} px over {n} frames");
    assert!(3 * n >= 2 * total, "only {n} of {total} frames tracked");
}

/// A dark line behind the bubble just above its top: the template, cut
/// with that line in its background, matched on the line in the second
/// photo, where the edge fit found no top. That photo was written 7.7 px
/// high with a stated 0.5 px (seed 336, 640x480, clutter, a highlight and
/// uneven light); it is now left out by name, and every photo kept is
/// within 4 of its stated standard deviations.
#[test]
fn a_template_match_without_the_bubbles_edge_is_left_out_by_name() {
    let look = synth::Look {
        clutter: true,
        highlight_grey: 80.0,
        uneven_light: 0.3,
        elevation_deg: 0.0,
        // The scene this case was found on: drawn in grey levels.
        response: crate::camera::Response::Linear,
        ..synth::Look::default()
    };
    let spec = synth::random_camera(336, &[(640, 480), (1024, 768)], look);
    let frames = synth::trial::neo_hookean_bubble(&spec.specimen, 6).unwrap();
    let (t, truth) = written_and_tracked(&spec, &frames, true);
    let t = t.unwrap();
    let skipped = t.skipped.iter().find(|s| s.file == "frame_002.jpg");
    assert!(
        skipped.is_some_and(|s| s.reason.contains("no edge of the bubble's top")),
        "{:?}",
        t.skipped
    );
    assert!(!t.rows.is_empty());
    kept_within_4_sd(&t.rows, &truth, "seed 336");
}

/// Clutter a few rows above the top in the photo at the lowest pressure
/// (seed 512, 640x480, clutter, a highlight and uneven light): no emptier
/// photo shows the background behind that top, so the line cannot be told
/// from it. That photo was written 0.58 px high at 10 stated standard
/// deviations; it is now left out by name. And where the emptiest photo
/// shows a cable in the rows above a later top (seed 540, its third
/// photo), the step model reads the difference from the emptiest photo as
/// the centroid does: that photo was written 0.54 px high at 8 standard
/// deviations. Every photo kept of both is within 4 of its stated standard
/// deviations.
#[test]
fn clutter_on_the_emptiest_photos_top_is_left_out_by_name() {
    let look = synth::Look {
        clutter: true,
        highlight_grey: 80.0,
        uneven_light: 0.3,
        elevation_deg: 0.0,
        ..Default::default()
    };
    // Tracked with `--skip-bad-frames`: at least 3 photos kept, each
    // within 4 stated standard deviations.
    let tracked = |seed: u64| {
        let spec = synth::random_camera(seed, &[(640, 480), (1024, 768)], look);
        let frames = synth::trial::neo_hookean_bubble(&spec.specimen, 6).unwrap();
        let (t, truth) = written_and_tracked(&spec, &frames, true);
        let t = t.unwrap();
        assert!(t.rows.len() >= 3, "seed {seed}: {:?}", t.skipped);
        kept_within_4_sd(&t.rows, &truth, &format!("seed {seed}"));
        t
    };
    let t = tracked(512);
    let first = t.skipped.iter().find(|s| s.file == "frame_001.jpg");
    assert!(
        first.is_some_and(|s| s.reason.contains("lowest pressure")),
        "{:?}",
        t.skipped
    );
    let t = tracked(540);
    assert!(
        t.rows.iter().any(|r| r.file == "frame_003.jpg"),
        "{:?}",
        t.skipped
    );
}

/// A highlight on small photos (640x480, randomly framed, seeds 401-410,
/// six photos of the exact neo-Hookean bubble each): there it lies within
/// a pixel or two of the edge and spoils the columns on one side of the
/// apex, which the fit on the bubble's axis and its mirror test are for.
/// Every photo kept lies within 4 of its stated standard deviations (none
/// silently wrong), at least 50 of the 60 are kept, and the apex row's RMS
/// error is at most 0.15 px (measured: 58 kept, 0.119 px, the worst 3.7
/// standard deviations off; the 0.1 px asked of photos with a highlight is
/// met on larger photos, not yet on these). The tracker before the fit on
/// the axis failed it: seed 402's first photo 0.38 px off, 7 standard
/// deviations.
#[test]
fn a_highlight_on_small_photos_is_tracked_within_its_uncertainty() {
    let look = synth::Look {
        highlight_grey: 80.0,
        ..synth::Look::default()
    };
    let (mut errors, mut total) = (Vec::new(), 0);
    for seed in 401..=410 {
        let spec = synth::random_camera(seed, &[(640, 480)], look);
        let frames = synth::trial::neo_hookean_bubble(&spec.specimen, 6).unwrap();
        let (t, truth) = written_and_tracked(&spec, &frames, true);
        total += truth.len();
        errors.extend(kept_within_4_sd(
            &t.unwrap().rows,
            &truth,
            &format!("seed {seed}"),
        ));
    }
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    eprintln!("{} of {total} kept, apex row RMS {rms:.3} px", errors.len());
    assert!(errors.len() >= 50, "{} of {total} kept", errors.len());
    assert!(
        rms <= 0.15,
        "apex row RMS {rms:.3} px over {} photos",
        errors.len()
    );
}

/// A specular highlight just below the apex (no clutter): every frame
/// tracked, the apex row within 0.1 px RMS.
#[test]
fn a_highlight_below_the_apex_does_not_bias_the_edge() {
    let look = synth::Look {
        highlight_grey: 90.0,
        ..synth::Look::default()
    };
    let (t, truth) = lab_sequence(114, look, false);
    let a = synth::apex_errors(&t.unwrap().rows, &truth);
    assert_eq!(a.frames, truth.len());
    assert_row_rms(&a, 0.1);
}

/// The guards on their own: an apex below the clamp plane, one that moves
/// against the pressure, one far from the prediction, and an edge whose
/// curvature or columns do not follow the dome's are refused with the
/// reason; a plausible next apex is accepted.
#[test]
fn the_plausibility_guards_refuse_what_a_dome_cannot_do() {
    use super::decode::Guard;
    use super::matcher::EdgeFit;
    let edge = |curvature: f64, rms: f64, columns: usize| EdgeFit {
        y: 0.0,
        y_std: 0.02,
        x_vertex: 100.0,
        x_std: 0.5,
        curvature,
        curvature_std: 1e-5,
        columns,
        rms,
        two_sided: false,
        clutter_on_top: false,
    };
    // Clamp plane at row 200; apexes at heights 40, 50 px (curvature per px
    // of height 2e-5).
    let mut g = Guard::new(Some(200.0), None, 64, false);
    g.accept(
        100.0,
        [100.0, 160.0],
        [0.5, 0.02],
        Some(&edge(8e-4, 0.1, 120)),
    );
    g.accept(
        200.0,
        [100.0, 150.0],
        [0.5, 0.02],
        Some(&edge(1e-3, 0.1, 120)),
    );
    let ok = g.check(
        300.0,
        [100.2, 141.0],
        [0.5, 0.02],
        Some(&edge(1.18e-3, 0.1, 120)),
    );
    assert!(ok.is_ok(), "{ok:?}");
    let why = |apex: [f64; 2], e: EdgeFit| g.check(300.0, apex, [0.5, 0.02], Some(&e)).unwrap_err();
    assert!(why([100.0, 201.0], edge(1e-3, 0.1, 120)).contains("clamp plane"));
    assert!(why([100.0, 152.0], edge(1e-3, 0.1, 120)).contains("against the pressure"));
    assert!(
        why([100.0, 120.0], edge(1.6e-3, 0.1, 120))
            .contains("from where the frames before predict")
    );
    assert!(why([100.0, 141.0], edge(1e-5, 0.1, 120)).contains("curvature"));
    assert!(why([100.0, 141.0], edge(1.18e-3, 1.5, 120)).contains("columns disagree"));
    assert!(why([100.0, 141.0], edge(1.18e-3, 0.1, 40)).contains("columns against"));
    assert!(why([130.0, 141.0], edge(1.18e-3, 0.1, 120)).contains("apex column moved"));
}

/// The elevation correction against closed forms: the outline of a sphere
/// of radius `R` whose pole is `h` above the clamp ring's centre tops out
/// `(h - R) cos e + R` above it (the latitude at polar angle `e` seen edge
/// on); from that top and a well measured `1 / R` the height is recovered,
/// and without a measured curvature from the membrane's pole radius,
/// `POLE_FLATTENING` times the spherical cap's through the rim `a`. A
/// measured curvature as uncertain as the membrane's pulls the radius
/// half way.
#[test]
fn the_elevation_correction_inverts_the_outline_of_a_cap() {
    use super::types::{POLE_FLATTENING, POLE_FLATTENING_REL_STD};
    let a = 224.0;
    for e_deg in [0.5f64, 3.0, 5.0, 20.0] {
        let el = Elevation {
            radians: e_deg.to_radians(),
            radius_m: 0.0375,
        };
        let e = el.radians;
        for h in [20.0f64, 60.0, 134.0] {
            let r_cap = (a * a + h * h) / (2.0 * h);
            if 2.0 * (h / a).atan() < e {
                continue; // the top is then the ring's back, not a latitude of the cap
            }
            let top = |r: f64| (h - r) * e.cos() + r;
            let (by_curvature, _) = el.height_px(top(r_cap), Some((1.0 / r_cap, 1e-7 / r_cap)), a);
            assert!(
                (by_curvature - h).abs() < 1e-6,
                "{e_deg} deg, h {h}: {by_curvature}"
            );
            let r_pole = POLE_FLATTENING * r_cap;
            let (by_rim, std) = el.height_px(top(r_pole), None, a);
            assert!((by_rim - h).abs() < 1e-6, "{e_deg} deg, h {h}: {by_rim}");
            // d h / d R = -(1 - cos e) / cos e
            let want = (1.0 - e.cos()) / e.cos() * POLE_FLATTENING_REL_STD * r_pole;
            assert!((std / want - 1.0).abs() < 1e-6, "{std} against {want}");
            // The pole's curvature measured with the membrane's relative
            // error: their mean, by the curvatures.
            let k_m = 1.0 / (1.2 * r_cap);
            let k = 0.5 * (k_m + 1.0 / r_pole);
            let (both, _) = el.height_px(
                top(1.0 / k),
                Some((k_m, POLE_FLATTENING_REL_STD / r_pole)),
                a,
            );
            assert!((both - h).abs() < 1e-6, "{e_deg} deg, h {h}: {both}");
        }
    }
}

/// Photos of spherical caps from 0 to 5 degrees above the clamp plane,
/// with `elevation_deg` in the experiment file: every height within 0.5 %
/// of the truth; without it, the first photo's height is more than 1 % too
/// high at 5 degrees (what the correction removes); the key out of range
/// or without the clamp row is refused.
#[test]
fn heights_from_a_raised_camera_are_corrected() {
    for e_deg in [0.0, 2.5, 5.0] {
        let dir = tempfile::tempdir().unwrap();
        let s = synth::SequenceSpec {
            look: synth::Look {
                elevation_deg: e_deg,
                ..synth::Look::default()
            },
            ..spec(121, 1.0, 2.0, image::Encoding::Png)
        };
        // Heights from 0.15 a to 0.6 a: below 0.15 a, the top of a cap
        // seen from 5 degrees is lower than the back of the fixture's
        // top face (1.25 a sin e above the ring's centre), against which it
        // is not seen.
        let frames: Vec<synth::SynthFrame> = (0..8)
            .map(|k| synth::SynthFrame {
                pressure_pa: 100.0 * (k + 1) as f64,
                silhouette: synth::Silhouette::spherical_cap(
                    0.0375,
                    0.0375 * (0.15 + 0.45 * k as f64 / 7.0),
                    400,
                ),
            })
            .collect();
        let w = synth::write_sequence(dir.path(), &s, &frames).unwrap();
        let path = dir.path().join("experiment.toml");
        let heights = |path: &Path| {
            let e = Experiment::read(path).unwrap();
            let t = track(
                &setup_from_experiment(&e).unwrap(),
                &Options::default(),
                &|| {},
            )
            .unwrap();
            assert_eq!(t.rows.len(), w.truth.len());
            t.rows
                .iter()
                .zip(&w.truth)
                .map(|(r, tr)| r.height_m / tr.height_m - 1.0)
                .collect::<Vec<f64>>()
        };
        let rel = heights(&path);
        let worst = rel.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        eprintln!("{e_deg} degrees: worst {:.3} %", 100.0 * worst);
        assert!(worst <= 0.005, "{e_deg} degrees: {rel:?}");
        if e_deg == 5.0 {
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.contains("elevation_deg = 5.0"), "{text}");
            std::fs::write(&path, text.replace("elevation_deg = 5.0\n", "")).unwrap();
            let plain = heights(&path);
            assert!(plain[0] > 0.01, "uncorrected {plain:?}");
            // out of range, or without the clamp row, it is refused
            for (from, to, said) in [
                (
                    "\nclamp_row_px =",
                    "\nelevation_deg = 45.0\nclamp_row_px =",
                    "0 to 30 degrees",
                ),
                (
                    "\nclamp_row_px =",
                    "\nelevation_deg = 3.0\n# =",
                    "needs clamp_row_px",
                ),
            ] {
                std::fs::write(
                    &path,
                    text.replace("elevation_deg = 5.0\n", "")
                        .replacen(from, to, 1),
                )
                .unwrap();
                let e = setup_from_experiment(&Experiment::read(&path).unwrap()).unwrap_err();
                assert!(e.to_string().contains(said), "{e}");
            }
        }
    }
}
