//! `bulge calibrate` on synthetic photos of a chessboard through a lens of
//! known distortion, and `bulge init --camera` copying the lens.

use super::util::*;
use bulge::track::calibrate::{Board, write_board_photos};
use bulge::track::lens::Lens;

fn truth() -> Lens {
    Lens {
        k1: -0.1,
        k2: 0.05,
        image_size_px: Some([640, 480]),
        ..Lens::pinhole(800.0, 800.0, 318.7, 241.2)
    }
}

/// 13 poses at 640x480, blur 0.8 px, noise 2 grey levels: the focal length
/// and k1 come back within about 4 of the standard deviations OpenCV states
/// for such a set (0.45 px and 0.002 on 12 poses), the reprojection error
/// under 0.1 px; the table written reads back as an experiment's [camera].
#[test]
fn calibrate_recovers_the_lens_and_writes_a_camera_table() {
    let d = tempdir();
    let board = Board {
        inner: [9, 6],
        square_m: 0.005,
    };
    write_board_photos(
        &d.path().join("board"),
        &board,
        &truth(),
        [640, 480],
        13,
        0.8,
        2.0,
        11,
    )
    .unwrap();
    // a photo without the board is named and skipped
    std::fs::copy(
        d.path().join("board/board_01.png"),
        d.path().join("board/board_00_blank.png"),
    )
    .unwrap();
    let blank = bulge::track::image::Gray::new(640, 480, vec![128; 640 * 480]);
    let bytes = bulge::track::image::encode(&blank, bulge::track::image::Encoding::Png).unwrap();
    std::fs::write(d.path().join("board/board_00_blank.png"), bytes).unwrap();
    let r = calibrate_board(d.path());
    assert!(
        r.stderr.contains("skipped board_00_blank.png"),
        "{}",
        r.stderr
    );
    let text = std::fs::read_to_string(d.path().join("camera.toml")).unwrap();
    eprintln!("{}{}{text}", r.stdout, r.stderr);
    #[derive(serde::Deserialize)]
    struct File {
        camera: bulge::experiment::CameraConfig,
    }
    let f: File = toml::from_str(&text).unwrap();
    let l = Lens::from_config(&f.camera).unwrap().unwrap();
    let t = truth();
    assert!(
        (l.fx - t.fx).abs() < 2.0 && (l.fy - t.fy).abs() < 2.0,
        "{l:?}"
    );
    assert!((l.k1 - t.k1).abs() < 0.008, "{l:?}");
    assert_eq!(l.image_size_px, Some([640, 480]));
    let rms = f.camera.reprojection_rms_px.unwrap();
    assert!(rms < 0.1, "{rms}");
}

#[test]
fn too_few_photos_are_refused_with_the_fix() {
    let d = tempdir();
    let board = Board {
        inner: [9, 6],
        square_m: 0.005,
    };
    write_board_photos(
        &d.path().join("board"),
        &board,
        &truth(),
        [640, 480],
        2,
        0.8,
        2.0,
        3,
    )
    .unwrap();
    bulge_in(
        d.path(),
        &[
            "calibrate",
            "board",
            "--square-m",
            "0.005",
            "-o",
            "camera.toml",
        ],
    )
    .bad_input(&["found in 2 of 2 photos", "at least 3", "10-20 poses"]);
    assert!(!d.path().join("camera.toml").exists());
    bulge_in(
        d.path(),
        &[
            "calibrate",
            "board",
            "--square-m",
            "0.005",
            "--inner-corners",
            "9",
            "-o",
            "camera.toml",
        ],
    )
    .bad_input(&["--inner-corners 9", "9x6"]);
}

/// A camera placed as a lab places it: 0.45 m from the bubble's axis, 3
/// degrees above the clamp ring's centre, aimed near the mid-height of the
/// largest bubble (the ring's centre at row 598 of 960, the principal
/// point at 479.5), through a lens with barrel distortion. The lens is
/// calibrated from chessboard photos drawn through it (`bulge calibrate`);
/// `bulge init` is given the opening's radius, the thickness and that
/// camera table only, and finds the clamp row, the elevation, the scale
/// and the camera's distance (its focal length times the scale); `bulge
/// track` with what it wrote gives every height within 0.3 % of the truth.
#[test]
fn a_calibrated_camera_at_mid_height_needs_only_the_opening() {
    let d = tempdir();
    bulge_in(
        d.path(),
        &[
            "synth",
            "exp",
            "--frames",
            "8",
            "--width",
            "1280",
            "--height",
            "960",
            "--camera-distance-m",
            "0.45",
            "--elevation-deg",
            "3",
            "--clamp-row-px",
            "598",
            "--lens-k1",
            "-0.1",
            "--blur-px",
            "1.3",
            "--noise",
            "2",
            "--jpeg-quality",
            "90",
            "--seed",
            "7",
        ],
    )
    .ok();
    // The lens the photos were drawn through, photographed on a board.
    #[derive(serde::Deserialize)]
    struct File {
        camera: bulge::experiment::CameraConfig,
    }
    let text = std::fs::read_to_string(d.path().join("exp/experiment.toml")).unwrap();
    let f: File = toml::from_str(&text).unwrap();
    let lens = Lens::from_config(&f.camera).unwrap().unwrap();
    let board = Board {
        inner: [9, 6],
        square_m: 0.005,
    };
    write_board_photos(
        &d.path().join("board"),
        &board,
        &lens,
        [1280, 960],
        12,
        1.0,
        2.0,
        5,
    )
    .unwrap();
    calibrate_board(d.path());
    let r = bulge_in(
        d.path(),
        &[
            "init",
            "exp/photos",
            "--radius-m",
            "0.0375",
            "--thickness-m",
            "0.00035",
            "--camera",
            "camera.toml",
            "--pressure",
            "exp/pressure.csv",
            "-o",
            "setup.toml",
        ],
    )
    .ok();
    eprintln!("{}", r.stdout);
    assert!(r.stdout.contains("m from the axis"), "{}", r.stdout);
    let setup = std::fs::read_to_string(d.path().join("setup.toml")).unwrap();
    let found: toml::Value = toml::from_str(&setup).unwrap();
    let dist = found["camera"]["distance_m"].as_float().unwrap();
    assert!((dist / 0.45 - 1.0).abs() < 0.02, "distance {dist} m");
    bulge_in(d.path(), &["track", "setup.toml", "-o", "h.csv"]).ok();
    assert_heights_within(
        &d.path().join("h.csv"),
        &d.path().join("exp/truth.csv"),
        0.003,
    );
}

/// `bulge calibrate board --square-m 0.005 --inner-corners 9x6 -o
/// camera.toml` in `dir` (the boards of [`write_board_photos`] with a 9x6
/// board of 5 mm squares), which must succeed.
fn calibrate_board(dir: &std::path::Path) -> Run {
    bulge_in(
        dir,
        &[
            "calibrate",
            "board",
            "--square-m",
            "0.005",
            "--inner-corners",
            "9x6",
            "-o",
            "camera.toml",
        ],
    )
    .ok()
}
