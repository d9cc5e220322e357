//! `bulge init` on synthetic experiments: random framing, a raised camera,
//! clutter and gloss. Seeds 201.. are used by these tests only; the
//! benchmark (`cargo run --release --example init_accuracy`) uses 1..=N.

use super::init::{self, Given};
use super::synth::neo_hookean_bubble as bubble;
use super::synth::trial::{InitTrial, init_and_track};
use super::synth::{self, Look, SequenceSpec};
use super::*;
use crate::experiment::Experiment;

/// `bulge init` and `bulge track` on `photos` photos of `s` (a neo-Hookean
/// bubble) in a temporary folder; panics with init's or the tracker's
/// message when either refuses.
fn set_up_and_track(s: &SequenceSpec, photos: usize) -> InitTrial {
    let dir = tempfile::tempdir().unwrap();
    let frames = bubble(&s.specimen, photos).unwrap();
    init_and_track(dir.path(), s, &frames, false).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Prints each case and holds the bounds.
fn check(cases: impl IntoIterator<Item = (u64, SequenceSpec)>, n: usize, heights: bool) {
    let cases: Vec<(u64, SequenceSpec)> = cases.into_iter().collect();
    // One case after the other: tracking itself runs on the rayon pool
    // and waits for it.
    let out: Vec<(u64, String, InitTrial)> = cases
        .iter()
        .map(|(seed, spec)| {
            let dir = tempfile::tempdir().unwrap();
            let frames = bubble(&spec.specimen, n).unwrap();
            let o = init_and_track(dir.path(), spec, &frames, false)
                .unwrap_or_else(|e| panic!("{e:#}"));
            if !spec.look.clutter {
                assert_eq!(o.tracked[0], o.tracked[1], "seed {seed}: {o:?}");
            }
            (
                *seed,
                format!("{}x{} {:?}", spec.width, spec.height, spec.look),
                o,
            )
        })
        .collect();
    for (seed, what, o) in &out {
        eprintln!("seed {seed} {what}: {o:?}");
    }
    for (seed, _, o) in &out {
        assert!(o.scale_std < 0.01, "seed {seed}: stated scale std {o:?}");
        assert!(o.scale.abs() <= 0.003, "seed {seed}: scale {o:?}");
        assert!(o.clamp_px.abs() <= 0.5, "seed {seed}: clamp row {o:?}");
        assert!(o.elevation_deg.abs() <= 0.5, "seed {seed}: elevation {o:?}");
        if heights {
            assert!(o.heights <= 0.005, "seed {seed}: heights {o:?}");
        }
    }
}

/// 20 seeds of random framing (level camera): the scale within 0.3 %, the
/// clamp row within 0.5 px, and the heights tracked with the file init
/// wrote within 0.5 % of the truth at every photo.
#[test]
fn init_sets_up_randomly_framed_photos() {
    let sizes = [(640, 480), (800, 600), (1024, 768), (1280, 960)];
    check(
        (201..=220).map(|s| (s, synth::random_camera(s, &sizes, Look::default()))),
        5,
        true,
    );
}

/// A camera 0 to 5 degrees above the clamp plane (the clamp's ends in the
/// picture): the scale within 0.3 %, the elevation within 0.5 degree and
/// the heights, corrected for it, within 0.5 %.
#[test]
fn init_finds_the_elevation_of_a_raised_camera() {
    let sizes = [(800, 600), (1024, 768)];
    check(
        (0..=5).map(|k| {
            let seed = 241 + k;
            let mut s = synth::random_camera(
                seed,
                &sizes,
                Look {
                    elevation_deg: k as f64,
                    ..Look::default()
                },
            );
            // The clamp (1.25 a) in the picture: the axis in the middle.
            // The scale is found too: at 5 degrees the clamp's face hides
            // the sides up to 0.065 a above the plane, and the opening is
            // extrapolated to it.
            s.framing.axis_x_px = Some(0.5 * s.width as f64 - 0.3);
            (seed, s)
        }),
        5,
        true,
    );
}

/// Clutter behind the bubble and a highlight on it: init finds the same
/// set-up (the clutter stands still, the bubble grows).
#[test]
fn init_is_not_misled_by_clutter_and_gloss() {
    let sizes = [(1024, 768), (1280, 960)];
    check(
        (251..=253).map(|seed| {
            let s = synth::random_camera(
                seed,
                &sizes,
                Look {
                    clutter: true,
                    highlight_grey: 80.0,
                    uneven_light: 0.3,
                    elevation_deg: 0.0,
                    ..Default::default()
                },
            );
            (seed, s)
        }),
        5,
        false,
    );
}

/// Photos that show no growing bubble, a bubble cut by the border and a
/// clamp below the picture are refused, naming what and the keys.
#[test]
fn init_refuses_what_it_cannot_find() {
    let dir = tempfile::tempdir().unwrap();
    let spec = synth::random_camera(261, &[(640, 480)], Look::default());
    let frames = bubble(&spec.specimen, 4).unwrap();
    let w = synth::write_sequence(dir.path(), &spec, &frames).unwrap();
    let photos = list_photos(&dir.path().join("photos"), "*.jpg").unwrap();
    let a = spec.specimen.radius_m;
    let err = |paths: &[std::path::PathBuf]| {
        init::find(paths, a, Given::default())
            .unwrap_err()
            .to_string()
    };
    // The same photo twice: nothing grows.
    let e = err(&[photos[0].clone(), photos[0].clone()]);
    assert!(
        e.contains("the bubble not found") && e.contains("roi_px"),
        "{e}"
    );
    // Cropped copies: the top cut through the tallest bubble, or the
    // bottom above the clamp.
    let crop = |name: &str, y0: usize, y1: usize| -> Vec<std::path::PathBuf> {
        let sub = dir.path().join(name);
        std::fs::create_dir_all(&sub).unwrap();
        photos
            .iter()
            .map(|p| {
                let g = image::read_gray(p, None).unwrap().crop;
                let c = g.crop(0, y0, g.width, y1 - y0);
                let out = sub.join(p.file_name().unwrap()).with_extension("png");
                std::fs::write(&out, image::encode(&c, image::Encoding::Png).unwrap()).unwrap();
                out
            })
            .collect()
    };
    let top = w
        .truth
        .iter()
        .map(|t| t.apex_y_px)
        .fold(f64::INFINITY, f64::min);
    let c = w.scene.clamp_row_px;
    let e = err(&crop("cut", (top + 0.3 * (c - top)) as usize, 480));
    assert!(e.contains("cut by the photo's top border"), "{e}");
    let e = err(&crop("low", 0, (c - 0.15 * (c - top)) as usize));
    assert!(e.contains("clamp") && e.contains("clamp_row_px"), "{e}");
}

/// The tracker on randomly framed photos with clutter, uneven light and a
/// highlight that sits against the apex's edge (seeds 251-253, 1024x768 or
/// 1280x960, the true set-up): every frame kept is within 4 of its stated
/// standard deviations (the bias floor included) and the apex row is within
/// 0.1 px RMS over all of them. The highlight's flank under the edge moved
/// the centroids by 0.2-0.3 px here, ten times the stated uncertainty,
/// until the edge was tested against the step model.
#[test]
fn a_highlight_against_the_edge_is_tracked_within_its_uncertainty() {
    let look = Look {
        clutter: true,
        highlight_grey: 80.0,
        uneven_light: 0.3,
        elevation_deg: 0.0,
        ..Default::default()
    };
    let (mut sum2, mut n, mut total, mut two_sided) = (0.0, 0usize, 0usize, 0usize);
    for seed in 251..=253 {
        let dir = tempfile::tempdir().unwrap();
        let spec = synth::random_camera(seed, &[(1024, 768), (1280, 960)], look);
        let w =
            synth::write_sequence(dir.path(), &spec, &bubble(&spec.specimen, 5).unwrap()).unwrap();
        let e = Experiment::read(dir.path().join("experiment.toml")).unwrap();
        let opts = Options {
            skip_bad_frames: true,
            ..Options::default()
        };
        let t = track(&setup_from_experiment(&e).unwrap(), &opts, &|| {}).unwrap();
        total += w.truth.len();
        for r in &t.rows {
            let tr = w.truth.iter().find(|x| x.file == r.file).unwrap();
            let err = r.apex_y_px - tr.apex_y_px;
            let std = r.apex_y_std_px;
            eprintln!("seed {seed} {}: {err:+.3} px (std {std:.3})", r.file);
            assert!(
                err.abs() <= 4.0 * std,
                "seed {seed} {}: apex row {err:+.3} px off, stated std {std:.3} px",
                r.file
            );
            sum2 += err * err;
            n += 1;
            two_sided += usize::from(r.edge.is_some_and(|e| e.two_sided));
        }
    }
    let rms = (sum2 / n as f64).sqrt();
    eprintln!("{n} of {total} frames, apex row RMS {rms:.3} px, {two_sided} from the step model");
    assert!(rms <= 0.1, "apex row RMS {rms:.3} px");
    assert!(3 * n >= 2 * total, "only {n} of {total} frames tracked");
}

/// A camera rolled about its view axis sees the clamp's edge tilted: up to
/// `MAX_ROLL_DEG` the roll is found (and the clamp row at the axis and the
/// scale as for a level camera), beyond it the photos are refused, naming
/// the roll. Before the clamp fits had a slope, a roll of 2 degrees gave a
/// clamp row 4.2 px off and an elevation of 1.8 degrees, exit 0.
#[test]
fn a_rolled_camera_is_measured_or_refused_by_name() {
    use opencv::core::{BORDER_REPLICATE, Mat, Point2f, Size};
    use opencv::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let spec = synth::random_camera(262, &[(1024, 768)], Look::default());
    let w = synth::write_sequence(dir.path(), &spec, &bubble(&spec.specimen, 5).unwrap()).unwrap();
    let photos = list_photos(&dir.path().join("photos"), "*.jpg").unwrap();
    // The photos turned by `deg` (counter-clockwise) about the clamp ring's
    // centre, as PNG.
    let rolled = |deg: f64| -> Vec<std::path::PathBuf> {
        let sub = dir.path().join(format!("roll{deg}"));
        std::fs::create_dir_all(&sub).unwrap();
        let centre = Point2f::new(w.scene.axis_x_px as f32, w.scene.clamp_row_px as f32);
        let m = opencv::imgproc::get_rotation_matrix_2d(centre, deg, 1.0).unwrap();
        photos
            .iter()
            .map(|p| {
                let g = image::read_gray(p, None).unwrap().crop;
                let src =
                    Mat::new_rows_cols_with_data(g.height as i32, g.width as i32, &g.data).unwrap();
                let mut out = Mat::default();
                let size = Size::new(g.width as i32, g.height as i32);
                opencv::imgproc::warp_affine(
                    &src,
                    &mut out,
                    &m,
                    size,
                    opencv::imgproc::INTER_LINEAR,
                    BORDER_REPLICATE,
                    Default::default(),
                )
                .unwrap();
                let r = image::Gray {
                    width: g.width,
                    height: g.height,
                    data: out.data_bytes().unwrap().to_vec(),
                    tone: crate::track::image::Tone::LINEAR,
                };
                let path = sub.join(p.file_name().unwrap()).with_extension("png");
                std::fs::write(&path, image::encode(&r, image::Encoding::Png).unwrap()).unwrap();
                path
            })
            .collect()
    };
    let a = spec.specimen.radius_m;
    let f = init::find(&rolled(0.8), a, Given::default()).unwrap();
    eprintln!(
        "0.8 degrees: roll {:?}, scale {:+.4} %, clamp row {:+.3} px",
        f.roll_deg,
        100.0 * (f.metres_per_pixel.value / w.scene.metres_per_pixel - 1.0),
        f.clamp_row_px.value - w.scene.clamp_row_px
    );
    // Counter-clockwise: the edge rises to the right (rows fall).
    assert!((f.roll_deg.value + 0.8).abs() < 0.02, "{:?}", f.roll_deg);
    assert!((f.metres_per_pixel.value / w.scene.metres_per_pixel - 1.0).abs() < 0.003);
    assert!((f.clamp_row_px.value - w.scene.clamp_row_px).abs() < 0.5);
    let e = init::find(&rolled(2.0), a, Given::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("rolled") && e.contains("-2.0") && e.contains("clamp_row_px"),
        "{e}"
    );
}

/// A pinhole camera 0.25 to 1 m from the axis, 0 to 5 degrees above the
/// ring's centre, its distance given (the ring's ends in the picture):
/// through the ring's far side seen from that camera the scale is within
/// 0.3 %, the ring centre's row within 0.5 px and the heights tracked with
/// the file init wrote within 0.3 %. (An orthographic reading of the same
/// photos has the scale 0.35 % small at 0.45 m and the row 3-9 px off; the
/// opening's sides extrapolated to the plane without the pinhole's bias,
/// `meridian::unbiased`, had it +0.31 % at 0.45 m and 5 degrees.)
#[test]
fn init_sets_up_a_pinhole_camera_at_a_given_distance() {
    // The 5-degree cases at 1024x768: at 800x600 the random framing of
    // the 1 m case puts the opening 280 px wide, where the scale's stated
    // standard deviation (0.29 %) is itself about the 0.3 % asked.
    let cases = [
        (0.45, 0.0, (800, 600)),
        (0.45, 3.0, (800, 600)),
        (0.25, 2.0, (800, 600)),
        (0.25, 5.0, (1024, 768)),
        (1.0, 5.0, (1024, 768)),
    ];
    pinhole_cases(261, &cases, None);
}

/// A ring wider than the picture (its ends out of it: 1280x960 at 6.8e-5
/// m per px, the ring 1380 px wide) seen from 3 and 5 degrees above its
/// centre, the distance given: the ring's ellipse is placed through the
/// pinhole from its far side alone, its outer radius fitted with it (an
/// orthographic reading must refuse: nothing places the ellipse). Every
/// photo tracked, the scale within 0.3 %, the ring centre's row within 1.5
/// px (stated 0.5-1 px: the far side alone determines it poorly), the
/// heights within 1 % and covered by all the stated terms (RMS(error / all
/// stated) below 2: the row's error is common to the photos and stated as
/// `clamp_row_std_px`).
#[test]
fn init_places_a_ring_whose_ends_are_out_of_the_picture() {
    for (d, e, seed) in [(0.45, 5.0, 4), (1.0, 3.0, 7)] {
        let mut s = SequenceSpec::plain(
            1280,
            960,
            seed,
            1.3,
            2.0,
            crate::track::image::Encoding::Jpeg(90),
        );
        s.framing.metres_per_pixel = Some(6.8e-5);
        s.framing.clamp_row_px = Some(850.0);
        s.look = Look {
            elevation_deg: e,
            camera_distance_m: d,
            ..Look::default()
        };
        let o = set_up_and_track(&s, 6);
        eprintln!("D {d} m, e {e} deg: {o:?}");
        assert_eq!(o.tracked[0], o.tracked[1], "{o:?}");
        assert!(o.scale.abs() <= 0.003, "D {d} e {e}: scale {o:?}");
        assert!(o.clamp_px.abs() <= 1.5, "D {d} e {e}: clamp row {o:?}");
        assert!(o.heights <= 0.01, "D {d} e {e}: heights {o:?}");
        assert!(o.rms_z_all < 2.0, "D {d} e {e}: stated {o:?}");
    }
}

/// Init and track on `cases` (distance m, elevation deg, photo size) of
/// random framings from seed `first` on, the axis in the middle, through
/// `lens` when given (the distance then found from its focal length, as
/// `synth::trial` lets init do): every photo tracked, the scale within 0.3 %
/// and within three of its stated deviations, the ring centre's row within
/// 0.5 px and the heights within 0.3 %.
fn pinhole_cases(
    first: u64,
    cases: &[(f64, f64, (usize, usize))],
    lens: Option<crate::track::lens::Lens>,
) {
    let mut out = Vec::new();
    for (k, &(d, e, size)) in cases.iter().enumerate() {
        let seed = first + k as u64;
        let mut s = synth::random_camera(
            seed,
            &[size],
            Look {
                elevation_deg: e,
                camera_distance_m: d,
                lens,
                ..Look::default()
            },
        );
        s.framing.axis_x_px = Some(0.5 * (s.width as f64 - 1.0));
        let o = set_up_and_track(&s, 4);
        eprintln!("D {d} m, e {e} deg, lens {}: {o:?}", lens.is_some());
        out.push((d, e, o));
    }
    for (d, e, o) in &out {
        assert_eq!(o.tracked[0], o.tracked[1], "D {d} e {e}: {o:?}");
        assert!(o.scale.abs() <= 0.003, "D {d} e {e}: scale {o:?}");
        assert!(
            o.scale.abs() < 3.0 * o.scale_std,
            "D {d} e {e}: scale {o:?}"
        );
        assert!(o.clamp_px.abs() <= 0.5, "D {d} e {e}: clamp row {o:?}");
        assert!(o.heights <= 0.003, "D {d} e {e}: heights {o:?}");
    }
}

/// A pinhole camera 0.25 to 1 m from the axis, 0 to 5 degrees above the
/// ring's centre, through a lens with a barrel distortion (`k1 = -0.1`)
/// whose calibration (focal length, principal point, distortion) init is
/// given, but not the distance: init finds it from the focal length and
/// the scale. The scale within 0.3 %, the ring centre's row within 0.5 px
/// and the heights tracked with the file init wrote within 0.3 %.
#[test]
fn init_finds_the_distance_from_a_calibrated_lens() {
    let size = (1024, 768);
    let lens = crate::track::lens::Lens {
        k1: -0.1,
        image_size_px: Some([size.0, size.1]),
        // the focal length and principal point become the pinhole's
        ..crate::track::lens::Lens::pinhole(1000.0, 1000.0, 511.5, 383.5)
    };
    let cases = [(0.25, 5.0, size), (0.45, 0.0, size), (1.0, 3.0, size)];
    pinhole_cases(281, &cases, Some(lens));
}

/// A raised camera over a ring whose top face is lit lighter than both the
/// wall and the ring's side (a machined ring under a lamp): the face is a
/// light band whose lower edge is the strongest step in the column, and
/// init must take its upper edge, the ring's far side. Orthographic at 2-4
/// degrees and a pinhole at 0.45 m, 3 degrees: the scale within 0.3 %, the
/// clamp row within 0.5 px, the elevation within 0.5 degree and the
/// heights within 0.5 %.
#[test]
fn init_takes_the_far_side_of_a_lit_ring_face() {
    let sizes = [(800, 600), (1024, 768)];
    let lit = |e: f64, d: f64| Look {
        elevation_deg: e,
        camera_distance_m: d,
        ring_face_grey: 230.0,
        ..Look::default()
    };
    let cases = [(2.0, 0.0), (3.0, 0.0), (4.0, 0.0), (3.0, 0.45)];
    check(
        cases.iter().enumerate().map(|(k, &(e, d))| {
            let seed = 271 + k as u64;
            let mut s = synth::random_camera(seed, &sizes, lit(e, d));
            s.framing.axis_x_px = Some(0.5 * s.width as f64 - 0.3);
            (seed, s)
        }),
        5,
        true,
    );
}

/// A raised camera over a ring whose top face is as light as the wall
/// behind it, so that its far side shows no step and only its front does;
/// bulge's photos draw the face's shade on down a flange below the front
/// (its lower edge lies a flange's height below the clamp plane), so the
/// clamp plane is placed on the dome's base instead (the opening's near
/// half, in front of the face). Orthographic at 2 and 3 degrees and a
/// pinhole at 0.45 m, 3 degrees and 0.25 m, 5 degrees: the scale within
/// 0.3 %, the clamp row within 0.5 px, the elevation within 0.5 degree and
/// the heights within 0.5 % (the front taken for the face's would put the
/// row 25 px low at 1280x960 and the heights 7-20 % high). A flange lower
/// than a tenth of the opening's radius is refused, naming it.
#[test]
fn init_places_the_clamp_on_the_dome_base_when_the_face_matches_the_wall() {
    let sizes = [(1024, 768), (1280, 960)];
    let matching = |e: f64, d: f64| Look {
        elevation_deg: e,
        camera_distance_m: d,
        ring_face_grey: 190.0,
        ..Look::default()
    };
    let cases = [(2.0, 0.0), (3.0, 0.0), (3.0, 0.45), (3.0, 0.25)];
    check(
        cases.iter().enumerate().map(|(k, &(e, d))| {
            let seed = 291 + k as u64;
            let mut s = synth::random_camera(seed, &sizes, matching(e, d));
            s.framing.axis_x_px = Some(0.5 * s.width as f64 - 0.3);
            // the opening 60 % of the width: the flange (2.5 % of the
            // height) within a tenth of its radius below the plane
            s.framing.metres_per_pixel = Some(2.0 * s.specimen.radius_m / (0.6 * s.width as f64));
            (seed, s)
        }),
        5,
        true,
    );
}

/// A raised camera over a ring whose top face is shaded between the wall
/// and the ring's side (grey 120 between 190 and 38), so that its far side
/// and the flange's lower edge below its front are steps of one polarity;
/// the flange's edge lies below the rows searched near the axis and
/// within them towards the ring's ends, so each column's lowest step is
/// the far side in some columns and the flange's edge in others (the plane
/// was set 19 px low at a stated 3 px at 800x600, 0.45 m, 3 degrees). The
/// ring's top edge is one curve: the far side is taken. Pinholes at 0.45 m
/// (3 and 2 degrees) and orthographic at 3 degrees: the scale within 0.3 %,
/// the clamp row within 0.5 px, the elevation within 0.5 degree and the
/// heights within 0.5 %.
#[test]
fn init_takes_the_far_side_when_a_flange_shows_below_the_face_in_part() {
    let shaded = |e: f64, d: f64| Look {
        elevation_deg: e,
        camera_distance_m: d,
        ring_face_grey: 120.0,
        ..Look::default()
    };
    let cases = [(3.0, 0.45), (2.0, 0.45), (3.0, 0.0)];
    check(
        cases.iter().enumerate().map(|(k, &(e, d))| {
            let seed = 301 + k as u64;
            let mut s = synth::random_camera(seed, &[(800, 600)], shaded(e, d));
            s.framing.axis_x_px = Some(0.5 * s.width as f64 - 0.3);
            s.framing.clamp_row_px = Some(0.8 * s.height as f64);
            // the opening 70 % of the width, as in the case above
            s.framing.metres_per_pixel = Some(2.0 * s.specimen.radius_m / (0.7 * s.width as f64));
            (seed, s)
        }),
        5,
        true,
    );
}

/// A light dome in front of a dark wall, over a ring whose face is a
/// little lighter than the wall (grey 58 on 45, its side 38), seen from
/// 0.6 m and 3 degrees up, lit from one side: the ring's steps are 2-5
/// levels of light, judged in the photo's levels (`init/contrast.rs`), and
/// the apexes are placed on the sides' axis. Every photo tracked, the
/// scale within 0.3 %, the heights within 1 % and within three of all
/// their stated deviations (RMS over the photos). The same with a face
/// darker than the wall and its side (grey 20) and no side light: the
/// face's front then lies below the rows searched in most columns, where
/// each column's strongest rising step is the wall's texture, and the
/// ring's top edge is chosen by the columns' votes weighted by their steps
/// (`init/clamp.rs`, `top_family`).
#[test]
fn init_sets_up_a_light_dome_on_a_dark_wall() {
    for (face, side_light, seed) in [(58.0, 0.35, 232), (20.0, 0.0, 231)] {
        let mut s =
            SequenceSpec::plain(800, 600, seed, 1.5, 2.0, crate::track::image::Encoding::Png);
        s.look = Look {
            bubble_grey: 205.0,
            background_grey: 45.0,
            ring_face_grey: face,
            side_light,
            camera_distance_m: 0.6,
            elevation_deg: 3.0,
            ..Look::default()
        };
        let o = set_up_and_track(&s, 6);
        eprintln!("face {face}: {o:?}");
        assert_eq!(o.tracked[0], o.tracked[1], "face {face}: {o:?}");
        assert!(o.scale.abs() <= 0.003, "face {face}: scale {o:?}");
        assert!(o.heights <= 0.01, "face {face}: heights {o:?}");
        assert!(o.rms_z_all < 3.0, "face {face}: stated {o:?}");
    }
}

/// A light dome lit from one side in front of a dark wall, the ring's face
/// lit lighter than the dome (the init sweep's clean seed 93: 1280x960,
/// noise 3-4 levels, a blur of 1.4 px and a motion blur, a Mooney-Rivlin
/// dome to 0.97 of its limit pressure, 0.42 m away and 2.4 degrees up).
/// The swept band leans 25 px towards the lit side, and about that axis
/// the ring's two ends are not mirrored: steps 3 and 4 are done again
/// about the sides' axis. Every photo tracked, the scale within 0.3 %, the
/// ring's row within 0.5 px, the heights within 0.3 % and within three of
/// all their stated deviations.
#[test]
fn init_reads_the_ring_about_the_sides_axis() {
    let mut case =
        crate::track::synth::sweep::draw(93, false, &crate::track::synth::sweep::SIZES).unwrap();
    case.spec.look.camera_distance_m = 0.42139;
    case.spec.look.elevation_deg = 2.40696;
    let dir = tempfile::tempdir().unwrap();
    let o = init_and_track(dir.path(), &case.spec, &case.frames, false)
        .unwrap_or_else(|e| panic!("{e:#}"));
    eprintln!("{o:?}");
    assert_eq!(o.tracked[0], o.tracked[1], "{o:?}");
    assert!(o.scale.abs() <= 0.003, "scale {o:?}");
    assert!(o.clamp_px.abs() <= 0.5, "clamp row {o:?}");
    assert!(o.heights <= 0.003, "heights {o:?}");
    assert!(o.rms_z_all < 3.0, "stated {o:?}");
}

/// A clean sequence whose edge noise changes between photos by more than
/// its sampling spread (1280x960, JPEG 90, blur 1.3 px, noise 2 grey; a
/// pinhole 1 m away and 5 degrees above the ring, the framing moved by a
/// fraction of a pixel as `examples/camera_grid.rs` moves its seed 9):
/// the residual RMS of the eighth photo's edge is 1.6 times the median of
/// the three before, at 3.8 of its sampling deviations, and nothing else
/// is wrong with it. The residual rule is no physical bound: the photo is
/// kept with a warning that names it, every photo is tracked, and the
/// heights are within 0.3 %. (Should the rule no longer fire here, the
/// warning's assertion fails: this sequence then no longer tests the
/// warning, and another must be found.)
#[test]
fn a_residual_beyond_its_sampling_spread_alone_is_a_warning() {
    let mut place = synth::Rng::new(9 ^ 0x5eed_f4a3);
    let base = SequenceSpec::plain(1280, 960, 9, 1.3, 2.0, image::Encoding::Jpeg(90));
    let s = SequenceSpec {
        framing: synth::Framing {
            clamp_row_px: Some(768.0 + place.uniform()),
            axis_x_px: Some(640.0 + place.uniform()),
            ..synth::Framing::default()
        },
        look: Look {
            elevation_deg: 5.0,
            camera_distance_m: 1.0,
            ..Look::default()
        },
        ..base
    };
    let o = set_up_and_track(&s, 8);
    eprintln!("{o:?}");
    assert_eq!(o.tracked, [8, 8], "{o:?}");
    assert!(o.heights <= 0.003, "{o:?}");
    assert!(
        o.warnings.iter().any(|w| w.contains("residual RMS")),
        "{:?}",
        o.warnings
    );
    assert!(
        o.warnings
            .iter()
            .all(|w| w.contains("residual RMS") && w.contains("frame_008.jpg")),
        "{:?}",
        o.warnings
    );
}
