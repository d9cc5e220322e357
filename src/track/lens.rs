//! The lens: the Brown-Conrady distortion model of OpenCV's `calibrate_camera`
//! and its inverse, applied to the points the tracker and `bulge init`
//! measure (never to whole photos).
//!
//! A point of the ideal pinhole image, `(u, v)` px, has normalised
//! coordinates `x = (u - cx) / fx`, `y = (v - cy) / fy`; the lens moves it to
//!
//! ```text
//! x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
//! y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
//! ```
//!
//! (`r^2 = x^2 + y^2`), seen at `(fx x_d + cx, fy y_d + cy)` in the photo
//! (Brown, "Decentering distortion of lenses", Photogrammetric Engineering
//! 32(3), 444-462, 1966; OpenCV's `calib3d` module). [`Lens::undistort`]
//! inverts it by Newton's method: the *undistorted* pixel of a photo's pixel,
//! in the pinhole image of the same focal lengths and principal point (what
//! OpenCV's `undistortPoints` returns with `P = K`).
//!
//! The tracker's apex is the top of a parabola fitted to the edge over a few
//! tens of columns; [`Lens::undistort_apex`] carries that top, with the
//! edge's curvature, through the map (docs/track.md, "The lens").

use serde::{Deserialize, Serialize};

/// Intrinsics and distortion coefficients of a calibrated camera (OpenCV's
/// camera matrix and `k1 k2 p1 p2 k3`), pixels of the photos.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lens {
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point, column, px.
    pub cx: f64,
    /// Principal point, row, px.
    pub cy: f64,
    /// Radial coefficients.
    pub k1: f64,
    /// Radial coefficients.
    pub k2: f64,
    /// Tangential coefficients.
    pub p1: f64,
    /// Tangential coefficients.
    pub p2: f64,
    /// Radial coefficients.
    pub k3: f64,
    /// The photo size the calibration was made at, `[width, height]` px
    /// (`None`: not checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_size_px: Option<[usize; 2]>,
}

/// The apex of an edge carried into the undistorted image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UndistortedApex {
    /// The top of the edge in the undistorted image, px.
    pub apex: [f64; 2],
    /// The edge's curvature `d2y/dx2` there, 1/px.
    pub curvature: f64,
    /// The row moved by the tangent's tilt, px (`-s^2 / (2 k)`; 0 when the
    /// curvature does not place the top within `max_shift_px`).
    pub tilt_row_px: f64,
}

impl Lens {
    /// The lens without distortion.
    pub fn pinhole(fx: f64, fy: f64, cx: f64, cy: f64) -> Lens {
        Lens {
            fx,
            fy,
            cx,
            cy,
            k1: 0.0,
            k2: 0.0,
            p1: 0.0,
            p2: 0.0,
            k3: 0.0,
            image_size_px: None,
        }
    }

    /// The lens of an experiment file's `[camera]` table (`Ok(None)`: no
    /// calibration given); the error names the key and the fix.
    pub fn from_config(c: &crate::experiment::CameraConfig) -> Result<Option<Lens>, String> {
        Ok(c.lens_keys()?.map(|(f, p, d)| Lens {
            fx: f[0],
            fy: f[1],
            cx: p[0],
            cy: p[1],
            k1: d[0],
            k2: d[1],
            p1: d[2],
            p2: d[3],
            k3: d[4],
            image_size_px: c.image_size_px,
        }))
    }

    /// The `[camera]` keys of this lens (the tone curve left unset).
    pub fn to_config(&self, reprojection_rms_px: Option<f64>) -> crate::experiment::CameraConfig {
        crate::experiment::CameraConfig {
            response: None,
            focal_px: Some([self.fx, self.fy]),
            principal_point_px: Some([self.cx, self.cy]),
            distortion: Some([self.k1, self.k2, self.p1, self.p2, self.k3]),
            image_size_px: self.image_size_px,
            reprojection_rms_px,
            distance_m: None,
        }
    }

    /// Normalised coordinates -> distorted normalised coordinates, and the
    /// Jacobian `d(x_d, y_d) / d(x, y)`.
    fn distort_normalised(&self, x: f64, y: f64) -> ([f64; 2], [[f64; 2]; 2]) {
        let (k1, k2, k3, p1, p2) = (self.k1, self.k2, self.k3, self.p1, self.p2);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        let d_radial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2); // d radial / d r2
        let xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
        let yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
        let j = [
            [
                radial + 2.0 * x * x * d_radial + 2.0 * p1 * y + 6.0 * p2 * x,
                2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y,
            ],
            [
                2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y,
                radial + 2.0 * y * y * d_radial + 6.0 * p1 * y + 2.0 * p2 * x,
            ],
        ];
        ([xd, yd], j)
    }

    /// Where the lens shows the ideal (pinhole) pixel `u`, px.
    pub fn distort(&self, u: [f64; 2]) -> [f64; 2] {
        let (d, _) =
            self.distort_normalised((u[0] - self.cx) / self.fx, (u[1] - self.cy) / self.fy);
        [self.fx * d[0] + self.cx, self.fy * d[1] + self.cy]
    }

    /// The ideal (pinhole) pixel the lens shows at the photo's pixel `p`, px.
    /// Newton's method from `p` itself, to 1e-12 of the normalised
    /// coordinates (1e-9 px at a focal length of 1000 px).
    pub fn undistort(&self, p: [f64; 2]) -> [f64; 2] {
        let t = [(p[0] - self.cx) / self.fx, (p[1] - self.cy) / self.fy];
        let mut x = t;
        for _ in 0..50 {
            let (d, j) = self.distort_normalised(x[0], x[1]);
            let (rx, ry) = (d[0] - t[0], d[1] - t[1]);
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if !det.is_finite() || det.abs() < 1e-12 {
                break;
            }
            let dx = (j[1][1] * rx - j[0][1] * ry) / det;
            let dy = (j[0][0] * ry - j[1][0] * rx) / det;
            x = [x[0] - dx, x[1] - dy];
            if dx.hypot(dy) < 1e-14 {
                break;
            }
        }
        [self.fx * x[0] + self.cx, self.fy * x[1] + self.cy]
    }

    /// The top of an edge carried into the undistorted image: the edge near
    /// `apex` (the top of the photo's edge, px) is `y = apex_y + curvature /
    /// 2 (x - apex_x)^2`; it is mapped through [`Lens::undistort`], where its
    /// tangent at the mapped apex tilts by the map's shear (slope `s`) and its
    /// curvature becomes `k`: the undistorted edge's top is `s / k` columns
    /// aside and `s^2 / (2 k)` rows above the mapped apex. That term is left
    /// out when the top would lie more than `max_shift_px` columns aside
    /// (a nearly flat edge: the fit's columns do not reach it).
    pub fn undistort_apex(
        &self,
        apex: [f64; 2],
        curvature: f64,
        max_shift_px: f64,
    ) -> UndistortedApex {
        let u0 = self.undistort(apex);
        // Central differences along the edge, 2 px apart: the map varies
        // over hundreds of px, so their error (h^2/6 of the third
        // derivative) is far below the edge fit's precision.
        let h = 2.0;
        let at = |t: f64| self.undistort([apex[0] + t, apex[1] + 0.5 * curvature * t * t]);
        let (a, b) = (at(-h), at(h));
        let d = [(b[0] - a[0]) / (2.0 * h), (b[1] - a[1]) / (2.0 * h)];
        let dd = [
            (b[0] - 2.0 * u0[0] + a[0]) / (h * h),
            (b[1] - 2.0 * u0[1] + a[1]) / (h * h),
        ];
        let s = d[1] / d[0];
        let k = (dd[1] * d[0] - dd[0] * d[1]) / d[0].powi(3);
        let shift = -s / k;
        if k.is_finite() && k > 0.0 && shift.abs() <= max_shift_px {
            let tilt = -s * s / (2.0 * k);
            UndistortedApex {
                apex: [u0[0] + shift, u0[1] + tilt],
                curvature: k,
                tilt_row_px: tilt,
            }
        } else {
            UndistortedApex {
                apex: u0,
                curvature: if k.is_finite() { k } else { curvature },
                tilt_row_px: 0.0,
            }
        }
    }

    /// The largest displacement of the photo's pixels by the lens, px, over
    /// a `w` x `h` photo (its corners and edge midpoints).
    pub fn max_displacement_px(&self, w: usize, h: usize) -> f64 {
        let (w, h) = (w as f64 - 1.0, h as f64 - 1.0);
        [
            [0.0, 0.0],
            [w, 0.0],
            [0.0, h],
            [w, h],
            [w / 2.0, 0.0],
            [w / 2.0, h],
            [0.0, h / 2.0],
            [w, h / 2.0],
        ]
        .iter()
        .map(|&p| {
            let u = self.undistort(p);
            (u[0] - p[0]).hypot(u[1] - p[1])
        })
        .fold(0.0, f64::max)
    }
}

/// What tracking says without a lens calibration.
pub const UNCALIBRATED_NOTE: &str = "note: no lens calibration in [camera]: the photos are taken as a distortion-free (pinhole) camera's; a lens's radial distortion (0.5-1 % at the photo's edge is common) changes the heights by up to about as much (`bulge calibrate` measures it; docs/track.md)";

/// The tracker's final coordinates through the lens: the apex (photo
/// coordinates) undistorted, with the tilt term of its edge's curvature
/// when the edge was fitted (the top no further aside than half the fit's
/// columns), and the edge's curvature in the undistorted image. Without a
/// lens, both unchanged.
pub(super) fn undistort_tracked(
    lens: Option<&Lens>,
    apex: [f64; 2],
    edge: Option<super::matcher::EdgeFit>,
) -> ([f64; 2], Option<super::matcher::EdgeFit>) {
    let Some(l) = lens else {
        return (apex, edge);
    };
    match edge {
        Some(e) => {
            let u = l.undistort_apex(apex, e.curvature, 0.5 * e.columns as f64);
            // The curvature's standard error scales with it.
            let scale = if e.curvature != 0.0 {
                (u.curvature / e.curvature).abs()
            } else {
                1.0
            };
            (
                u.apex,
                Some(super::matcher::EdgeFit {
                    curvature: u.curvature,
                    curvature_std: e.curvature_std * scale,
                    y_curvature_cov: e.y_curvature_cov * scale,
                    ..e
                }),
            )
        }
        None => (l.undistort(apex), None),
    }
}

/// `bulge init`'s axis and opening through the lens: the axis column (at
/// the clamp row `row_u`, already the undistorted image's) undistorted, and
/// the opening's radius from its two ends on the clamp row. The sides' fit
/// runs on the photo's points over a few tens of rows near the opening's
/// ends, where the map is smooth: the fitted ends' images are the image's
/// fitted ends to first order (as for the tracker's apex). Without a lens,
/// unchanged.
pub(super) fn undistort_opening(
    lens: Option<&Lens>,
    axis_x: f64,
    row_u: f64,
    radius_px: Option<f64>,
) -> (f64, Option<f64>) {
    let Some(l) = lens else {
        return (axis_x, radius_px);
    };
    let row = photo_row(l, axis_x, row_u);
    let u = l.undistort([axis_x, row]);
    let a = radius_px.map(|a| {
        let left = l.undistort([axis_x - a, photo_row(l, axis_x - a, row_u)]);
        let right = l.undistort([axis_x + a, photo_row(l, axis_x + a, row_u)]);
        0.5 * (right[0] - left[0])
    });
    (u[0], a)
}

/// The photo row at column `x` of the undistorted image's row `row_u`
/// (a few Newton steps: the lens moves rows by a few px at most).
fn photo_row(l: &Lens, x: f64, row_u: f64) -> f64 {
    let mut y = row_u;
    for _ in 0..20 {
        let d = l.undistort([x, y])[1] - row_u;
        y -= d;
        if d.abs() < 1e-9 {
            break;
        }
    }
    y
}

/// The clamp's edge points `(column offset from the axis x0, row, step)` and
/// its ends (photo columns) through the lens: offsets from the axis's image,
/// undistorted rows; the ends as `x0` plus their offset in the undistorted
/// image. Without a lens, unchanged.
#[allow(clippy::type_complexity)]
pub(super) fn undistort_clamp(
    lens: Option<&Lens>,
    x0: f64,
    pts: Vec<(f64, f64, f64)>,
    ends: [Option<f64>; 2],
    row: f64,
) -> (Vec<(f64, f64, f64)>, [Option<f64>; 2]) {
    let Some(l) = lens else {
        return (pts, ends);
    };
    let axis = l.undistort([x0, row])[0];
    let pts = pts
        .into_iter()
        .map(|(d, e, s)| {
            let u = l.undistort([x0 + d, e]);
            (u[0] - axis, u[1], s)
        })
        .collect();
    let ends = ends.map(|e| e.map(|e| x0 + l.undistort([e, row])[0] - axis));
    (pts, ends)
}

/// The clamp's row in the photo at the opening's sides, columns `x0 - a`
/// and `x0 + a` (their mean), for the search of the sides, which reads the
/// photo's rows and extrapolates them to this row (`row_u` without a
/// lens). A lens bends the plane's row: with a barrel distortion of 0.2 %
/// at the sides the row there lies a pixel or two above the axis's, and
/// extrapolating the sides to the axis's row had the opening 0.1-0.2 %
/// wide.
pub(super) fn clamp_row_at_sides(lens: Option<&Lens>, x0: f64, a: f64, row_u: f64) -> f64 {
    lens.map_or(row_u, |l| {
        0.5 * (photo_row(l, x0 - a, row_u) + photo_row(l, x0 + a, row_u))
    })
}

/// The photo size against the calibration's: an error naming both and the
/// fix when they differ.
pub(super) fn check_size(
    lens: Option<&Lens>,
    experiment: &std::path::Path,
    w: usize,
    h: usize,
) -> Result<(), super::TrackError> {
    match lens.and_then(|l| l.image_size_px) {
        Some([cw, ch]) if [cw, ch] != [w, h] => Err(super::TrackError::Config {
            path: experiment.to_path_buf(),
            message: format!(
                "[camera] image_size_px = [{cw}, {ch}] but the photos are {w}x{h} px: the lens calibration is for another photo size; calibrate with photos of this size (`bulge calibrate`), or remove focal_px, principal_point_px, distortion and image_size_px"
            ),
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lens() -> Lens {
        Lens {
            k1: -0.12,
            k2: 0.05,
            p1: 4e-4,
            p2: -3e-4,
            k3: 0.0,
            ..Lens::pinhole(1000.0, 1002.0, 322.0, 238.0)
        }
    }

    #[test]
    fn undistort_inverts_distort() {
        let l = lens();
        for &u in &[[0.0, 0.0], [640.0, 480.0], [320.0, 10.0], [17.0, 400.0]] {
            let p = l.distort(u);
            let back = l.undistort(p);
            assert!(
                (back[0] - u[0]).abs() < 1e-8 && (back[1] - u[1]).abs() < 1e-8,
                "{u:?} {back:?}"
            );
        }
    }

    /// A radial map by hand: with only k1, a point at normalised radius r
    /// moves out to r (1 + k1 r^2).
    #[test]
    fn radial_by_hand() {
        let l = Lens {
            k1: 0.1,
            ..Lens::pinhole(800.0, 800.0, 0.0, 0.0)
        };
        let p = l.distort([400.0, 0.0]);
        assert!((p[0] - 400.0 * (1.0 + 0.1 * 0.25)).abs() < 1e-12 && p[1] == 0.0);
    }

    /// The fitted apex carried through the map agrees with a parabola fitted
    /// to the undistorted edge points themselves (docs/track.md, "The lens").
    #[test]
    fn apex_through_the_map_equals_fitting_undistorted_points() {
        let l = lens();
        // A dome's top, a circle of radius R in the ideal image, seen at
        // several places in the photo.
        for &(cx, top, r) in &[
            (320.0, 100.0, 300.0),
            (520.0, 60.0, 150.0),
            (100.0, 400.0, 400.0),
            (600.0, 30.0, 80.0),
        ] {
            let truth = [cx, top];
            // The photo's edge: distorted circle points, a parabola fitted
            // to them over +-25 columns around their top.
            let ideal = |x: f64| [x, top + r - (r * r - (x - cx) * (x - cx)).sqrt()];
            let photo: Vec<[f64; 2]> = (-400..=400)
                .map(|i| l.distort(ideal(cx + i as f64 * 0.1)))
                .collect();
            let top_d = photo
                .iter()
                .copied()
                .fold([0.0, f64::INFINITY], |a, p| if p[1] < a[1] { p } else { a });
            let near: Vec<[f64; 2]> = photo
                .iter()
                .copied()
                .filter(|p| (p[0] - top_d[0]).abs() <= 25.0)
                .collect();
            let (v_d, k_d) = parabola_vertex(&near);
            let via_map = l.undistort_apex(v_d, k_d, 25.0).apex;
            let undist: Vec<[f64; 2]> = near.iter().map(|&p| l.undistort(p)).collect();
            let (v_u, _) = parabola_vertex(&undist);
            assert!((via_map[1] - v_u[1]).abs() < 0.01, "{via_map:?} {v_u:?}");
            // and both within the parabola's own bias of the circle's top
            assert!((v_u[1] - truth[1]).abs() < 0.02, "{v_u:?} {truth:?}");
        }
    }

    /// Least-squares parabola y = a + b x + c x^2 through the points: its
    /// vertex and d2y/dx2.
    fn parabola_vertex(p: &[[f64; 2]]) -> ([f64; 2], f64) {
        let x0 = p.iter().map(|q| q[0]).sum::<f64>() / p.len() as f64;
        let mut m = nalgebra::Matrix3::<f64>::zeros();
        let mut r = nalgebra::Vector3::<f64>::zeros();
        for q in p {
            let t = q[0] - x0;
            let v = nalgebra::Vector3::new(1.0, t, t * t);
            m += v * v.transpose();
            r += v * q[1];
        }
        let c = m.lu().solve(&r).unwrap();
        let xv = -c[1] / (2.0 * c[2]);
        ([x0 + xv, c[0] + c[1] * xv + c[2] * xv * xv], 2.0 * c[2])
    }

    /// Photos drawn through a lens of 1 % barrel distortion at the photo's
    /// edge, tracked with the lens in `[camera]`: every height within 0.3 %
    /// of the truth. Without it, the error is printed (docs/track.md).
    #[test]
    fn heights_through_a_calibrated_lens() {
        use crate::track::{Options, setup_from_experiment, synth, track};
        let truth_lens = Lens {
            k1: -0.04,
            image_size_px: Some([640, 480]),
            ..Lens::pinhole(640.0, 640.0, 319.5, 239.5)
        };
        let spec = synth::SequenceSpec {
            look: synth::Look {
                lens: Some(truth_lens),
                ..Default::default()
            },
            ..synth::SequenceSpec::plain(
                640,
                480,
                131,
                1.2,
                1.0,
                crate::track::image::Encoding::Png,
            )
        };
        let dir = tempfile::tempdir().unwrap();
        let frames = synth::cap_frames(0.0375, 0.6 * 0.0375, 8);
        let w = synth::write_sequence(dir.path(), &spec, &frames).unwrap();
        let exp = crate::experiment::Experiment::read(dir.path().join("experiment.toml")).unwrap();
        let mut setup = setup_from_experiment(&exp).unwrap();
        assert_eq!(setup.lens, Some(truth_lens));
        let worst = |setup: &crate::track::Setup| {
            let t = track(setup, &Options::default(), &|| {}).unwrap();
            assert_eq!(t.rows.len(), frames.len());
            t.rows
                .iter()
                .zip(&w.truth)
                .map(|(r, tr)| (r.height_m - tr.height_m) / tr.height_m)
                .fold(0.0f64, |a, e| if e.abs() > a.abs() { e } else { a })
        };
        let with = worst(&setup);
        setup.lens = None;
        let without = worst(&setup);
        eprintln!("largest relative height error: with the lens {with:+.5}, without {without:+.5}");
        assert!(with.abs() < 0.003, "{with}");
    }

    #[cfg(feature = "opencv")]
    #[test]
    fn undistort_agrees_with_opencv() {
        use opencv::core::{Mat, Point2d, Vector};
        let l = lens();
        let k =
            Mat::from_slice_2d(&[[l.fx, 0.0, l.cx], [0.0, l.fy, l.cy], [0.0, 0.0, 1.0]]).unwrap();
        let coefs = [l.k1, l.k2, l.p1, l.p2, l.k3];
        let d = Mat::from_slice(&coefs).unwrap();
        let pts = [
            [3.0, 5.0],
            [630.0, 470.0],
            [320.0, 240.0],
            [100.0, 420.0],
            [600.0, 20.0],
        ];
        let src: Vector<Point2d> = pts.iter().map(|p| Point2d::new(p[0], p[1])).collect();
        let mut dst = Vector::<Point2d>::new();
        // OpenCV iterates its fixed-point inverse: ask for many steps.
        let crit = opencv::core::TermCriteria::new(3, 200, 1e-14).unwrap();
        opencv::calib3d::undistort_points_iter(&src, &mut dst, &k, &d, &Mat::default(), &k, crit)
            .unwrap();
        for (p, q) in pts.iter().zip(dst.iter()) {
            let u = l.undistort(*p);
            assert!(
                (u[0] - q.x).abs() < 1e-6 && (u[1] - q.y).abs() < 1e-6,
                "{p:?}: {u:?} vs {q:?}"
            );
        }
    }
}
