//! What a pinhole camera at a finite distance does to the heights read
//! from the silhouette's top and to a scale read from the opening, on the
//! exact neo-Hookean bubbles of `bulge synth`'s default experiment
//! (a = 37.5 mm, t = 0.35 mm, C1 = 0.2 MPa, 12 photos at 308-3700 Pa), and
//! how well the pinhole model of `bulge::track::persp` (the pole's sphere
//! with 1.06 times the cap's radius) reads them back. The silhouette's top
//! is found by projecting 20001 points of each exact meridian (both sides
//! of the pole, in the plane through the camera and the axis). The focal
//! length gives 2a = 448 px at the ring's centre.
//!
//! Then photos drawn by that camera (`bulge synth --camera-distance-m`:
//! 1280x960, sRGB, blur 1.5 px, noise 3 grey levels, PNG; with and without
//! a barrel distortion k1 = -0.05 at focal length 1280 px that the lens
//! keys of `[camera]` undo), tracked with the scale and the clamp row given:
//! the largest height error with `[camera] distance_m` and without it (the
//! orthographic correction of `elevation_deg` alone), the apex row's RMS
//! error and the RMS of (error / stated standard deviation).
//!
//! `cargo run --release --example perspective`

use bulge::axisym::{Options, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::track::persp::{Pinhole, cap_radius};
use bulge::track::synth::{self, Look, SequenceSpec};
use bulge::track::{Elevation, image, pole_flattening, setup_from_experiment, track};

fn main() {
    let a = 0.0375;
    let specimen = Specimen {
        radius_m: a,
        thickness_m: 0.00035,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let material = Material {
        model: Model::NeoHookean { c1_pa: 0.2e6 },
        poisson: 0.45,
        fit: None,
    };
    let opts = Options {
        n_profile: 20001,
        ..Options::default()
    };
    let n = 12;
    let domes: Vec<_> = (1..=n)
        .map(|k| solve_pressure(&material, &specimen, 3700.0 * k as f64 / n as f64, &opts).unwrap())
        .collect();
    let h_max = domes.last().unwrap().height_m;
    let mpp_target = 2.0 * a / 448.0;
    println!(
        "| D, m | camera above the ring's centre, deg | top above the pole's image, px (first photo) | read as today, % (first / last photo) | opening's scale factor - 1, % | pinhole model, largest error, % |"
    );
    println!("|---|---|---|---|---|---|");
    for d in [0.25, 0.35, 0.45, 0.7, 1.0] {
        for up_deg in [None, Some(2.0), Some(4.0), Some(5.0)] {
            // level: the camera at the largest bubble's mid-height, aimed
            // level; raised: `up_deg` above the ring's centre, aimed at that
            // mid-height.
            let height = up_deg.map_or(0.5 * h_max, |u: f64| d * u.to_radians().tan());
            let slant = d.hypot(height);
            let cam = Pinhole::aimed(d, height, 0.5 * h_max, slant / mpp_target, [640.0, 480.0]);
            let v0 = cam.project([0.0, 0.0, 0.0])[1];
            let mpp = cam.centre_scale();
            let e = (height / d).atan();
            let mut first = None;
            let mut last = 0.0;
            let mut worst: f64 = 0.0;
            for s in &domes {
                let p = &s.profile;
                let top = p
                    .rho_m
                    .iter()
                    .zip(&p.z_m)
                    .flat_map(|(&r, &z)| {
                        [cam.project([0.0, -r, z])[1], cam.project([0.0, r, z])[1]]
                    })
                    .fold(f64::INFINITY, f64::min);
                let h = s.height_m;
                let t_px = v0 - top;
                // today's reading: row * scale, or the orthographic elevation
                // correction with the angle at which the ring's centre is seen
                let read = if height == 0.5 * h_max && up_deg.is_none() && e.abs() < 1e-3 {
                    t_px * mpp
                } else {
                    Elevation {
                        radians: e,
                        radius_m: a,
                    }
                    .height_px(t_px, None, a / mpp)
                    .0 * mpp
                };
                let today = 100.0 * (read / h - 1.0);
                if first.is_none() {
                    let pole = cam.project([0.0, 0.0, h])[1];
                    first = Some((pole - top, today));
                }
                last = today;
                let back = cam
                    .height_from_top_row(top, a, 2.0 * a, |h| {
                        pole_flattening(h / a).0 * cap_radius(a, h)
                    })
                    .unwrap();
                worst = worst.max((100.0 * (back / h - 1.0)).abs());
            }
            let (dpx, f_today) = first.unwrap();
            println!(
                "| {d} | {} | {dpx:.2} | {f_today:+.2} / {last:+.2} | {:+.3} | {worst:.3} |",
                up_deg.map_or(
                    format!("level at mid-height ({:.2})", e.to_degrees()),
                    |u| format!("{u}")
                ),
                100.0 * (cam.opening_scale_factor(a) - 1.0),
            );
        }
    }
    photos(&domes);
}

fn photos(domes: &[bulge::axisym::Solution]) {
    let frames: Vec<synth::SynthFrame> = domes
        .iter()
        .map(|s| synth::SynthFrame {
            pressure_pa: s.pressure_pa,
            silhouette: synth::Silhouette {
                rho_m: s.profile.rho_m.clone(),
                z_m: s.profile.z_m.clone(),
            },
        })
        .collect();
    println!();
    println!(
        "| D, m | looking down at the ring's centre, deg | distortion k1 | largest height error, % | without distance_m, % | apex row RMS, px | RMS(error / std) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut seed = 300;
    for d in [0.25, 0.45, 1.0] {
        for e_deg in [0.0, 2.5, 5.0] {
            for k1 in [0.0, -0.05] {
                seed += 1;
                let dir = tempfile::tempdir().unwrap();
                let s = SequenceSpec {
                    look: Look {
                        elevation_deg: e_deg,
                        camera_distance_m: d,
                        lens: (k1 != 0.0).then(|| bulge::track::lens::Lens {
                            k1,
                            image_size_px: Some([1280, 960]),
                            ..bulge::track::lens::Lens::pinhole(1280.0, 1280.0, 639.5, 479.5)
                        }),
                        ..Look::default()
                    },
                    ..SequenceSpec::plain(1280, 960, seed, 1.5, 3.0, image::Encoding::Png)
                };
                let w = synth::write_sequence(dir.path(), &s, &frames).unwrap();
                let path = dir.path().join("experiment.toml");
                let run = |path: &std::path::Path| {
                    let e = bulge::Experiment::read(path).unwrap();
                    track(
                        &setup_from_experiment(&e).unwrap(),
                        &bulge::track::Options::default(),
                        &|| {},
                    )
                    .unwrap()
                };
                let t = run(&path);
                let n = t.rows.len() as f64;
                let mut worst: f64 = 0.0;
                let (mut apex, mut z) = (0.0, 0.0);
                for (r, tr) in t.rows.iter().zip(&w.truth) {
                    worst = worst.max((100.0 * (r.height_m / tr.height_m - 1.0)).abs());
                    apex += (r.apex_y_px - tr.apex_y_px).powi(2);
                    z += ((r.height_m - tr.height_m) / r.height_std_m).powi(2);
                }
                let text = std::fs::read_to_string(&path).unwrap();
                std::fs::write(&path, text.replace(&format!("distance_m = {d:?}\n"), "")).unwrap();
                let plain = run(&path)
                    .rows
                    .iter()
                    .zip(&w.truth)
                    .map(|(r, tr)| (100.0 * (r.height_m / tr.height_m - 1.0)).abs())
                    .fold(0.0, f64::max);
                println!(
                    "| {d} | {e_deg} | {k1} | {worst:.3} | {plain:.2} | {:.3} | {:.2} |",
                    (apex / n).sqrt(),
                    (z / n).sqrt()
                );
            }
        }
    }
}
