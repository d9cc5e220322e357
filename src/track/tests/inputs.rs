//! The inputs: file names and globs, truncated or missing files, the pressure
//! log and photo times, region and template against the image.

use super::*;

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
        let stamped = crate::track::exif_time::tests::with_exif(
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
        let stamped = crate::track::exif_time::tests::with_exif(&jpeg, "2026:11:23 10:00:00", None);
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
