//! The elevation correction: a camera raised above the clamp plane.

use super::*;

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
    use crate::track::types::{POLE_FLATTENING, POLE_FLATTENING_REL_STD};
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
