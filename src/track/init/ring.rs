//! The clamp ring seen by a pinhole camera at a known distance (`bulge init
//! --camera-distance-m`, or `[camera] distance_m`): the ring's top edge
//! beside the bubble is the far side of the image of its outer circle, a
//! circle of radius `A` in the clamp plane around the axis. Its rows are
//! fitted as that circle seen by [`Pinhole::from_view`] (the camera `D`
//! from the axis, looking down at the ring's centre at `e`, the centre's
//! row `v0`, the scale `s` at the centre): the centre's row, the elevation
//! and `A` together, with the roll's slope across the photo. The middle of
//! the ellipse's image is not the image of the ring's centre (its near half
//! is seen larger than its far half), so an orthographic fit of the same
//! points puts the centre's row a few pixels off; the pinhole fit does not.
//! The scale at the centre then follows from the opening's width through
//! its tangent points ([`Pinhole::opening_scale_factor`]).

use super::*;
use crate::track::persp::Pinhole;
use crate::track::synth::pinhole::circle_rows;

/// The ring found through the pinhole.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ring {
    /// The ring centre's image row.
    pub(super) row: Estimate,
    /// The angle at which the camera looks down at the ring's centre, rad.
    pub(super) elevation_rad: Estimate,
    /// The outer circle's radius, m.
    pub(super) outer_radius_m: f64,
}

/// The camera of the set-up: `D` from the axis, the principal point's row
/// `principal_row` and the axis's column `x0`.
pub(super) fn camera(d_m: f64, e: f64, v0: f64, mpp: f64, x0: f64, principal_row: f64) -> Pinhole {
    Pinhole::from_view(d_m, e, v0, mpp, None, [x0, principal_row])
}

/// The far side's row of the outer circle of radius `outer_m` at image
/// column `x`, or its near side's when `near` (`None` beyond the circle's
/// ends).
fn side_row(p: &Pinhole, outer_m: f64, x: f64, near: bool) -> Option<f64> {
    circle_rows(p, outer_m, 0.0, x).map(|r| if near { r.1 } else { r.0 })
}

/// What gives the circle's radius in [`fit_ring`].
#[derive(Debug, Clone, Copy)]
pub(super) enum Radius {
    /// The ring's ends, this many px from the axis: the radius whose
    /// tangent points they are.
    Ends(f64),
    /// Fitted with the rest.
    Fitted,
    /// Known, m: the opening's, for the dome's base.
    Known(f64),
}

/// Fits a circle in the clamp plane around the axis seen from `at`, its
/// far side (its near side when `near`: the face's front, or the dome's
/// base) to `points` (image column, row) by Gauss-Newton from the start
/// `(v0, e, radius)`, the scale at the centre held: the parameters with
/// standard errors from the residuals (inflated for their correlation
/// along the edge). Points beyond the circle's current ends and beyond
/// 3.5 robust deviations are left out.
pub(super) fn fit_ring(
    points: &[[f64; 2]],
    at: &View,
    start: [f64; 3],
    radius: Radius,
    near: bool,
    hold_e: bool,
) -> Option<Ring> {
    let (x0, d_m, mpp, principal_row) = (at.x0, at.d, at.mpp, at.principal_row);
    let mut q = [start[0], start[1], start[2], 0.0];
    // With the ring's ends in the picture, its radius is the one whose
    // tangent points are `ends_half_px` apart from the axis:
    // `W = f A / (cos theta sqrt(D'^2 - A^2))` solved for `A`.
    let outer = |p: &Pinhole, q: &[f64; 4]| match radius {
        Radius::Ends(w) => {
            let k = w * p.pitch_rad.cos() / p.focal_px;
            let d = p.distance_m + p.height_m * p.pitch_rad.tan();
            k * d / (1.0 + k * k).sqrt()
        }
        Radius::Fitted => q[2],
        Radius::Known(r) => r,
    };
    // Each point is read in the mean of three columns' profiles: the
    // arc's mean over them.
    let predict = |q: &[f64; 4], x: f64| {
        let p = camera(d_m, q[1], q[0], mpp, x0, principal_row);
        let a = outer(&p, q);
        super::plane::three_column_row(x, |x| side_row(&p, a, x, near)).map(|r| r + q[3] * (x - x0))
    };
    let free: Vec<usize> = match radius {
        Radius::Fitted => vec![0, 1, 2, 3],
        _ => vec![0, 1, 3],
    }
    .into_iter()
    .filter(|&j| !(hold_e && j == 1))
    .collect();
    let mut keep = vec![true; points.len()];
    let mut last: Option<(Vec<Vec<f64>>, Vec<f64>)> = None;
    for round in 0..30 {
        let mut jac = Vec::new();
        let mut res = Vec::new();
        let steps = [0.01, 1e-5, 1e-6 * q[2].max(1e-3), 1e-5];
        for (pt, k) in points.iter().zip(&keep) {
            if !k {
                continue;
            }
            let Some(r0) = predict(&q, pt[0]) else {
                continue;
            };
            let mut row = Vec::with_capacity(4);
            for &j in &free {
                let h = steps[j];
                let mut qp = q;
                qp[j] += h;
                let mut qm = q;
                qm[j] -= h;
                match (predict(&qp, pt[0]), predict(&qm, pt[0])) {
                    (Some(a), Some(b)) => row.push((a - b) / (2.0 * h)),
                    _ => break,
                }
            }
            if row.len() == free.len() {
                jac.push(row);
                res.push(pt[1] - r0);
            }
        }
        if res.len() < 8 {
            return None;
        }
        let (dq, _, _) = clamp::lstsq(&jac, &res)?;
        for (i, &j) in free.iter().enumerate() {
            q[j] += dq[i];
        }
        if !matches!(radius, Radius::Fitted) {
            q[2] = outer(&camera(d_m, q[1], q[0], mpp, x0, principal_row), &q);
        }
        if q[2] <= 0.0 || !q[1].is_finite() || q[1].abs() > 0.5 {
            return None;
        }
        let small = free
            .iter()
            .zip(&dq)
            .all(|(&j, d)| j == 3 || d.abs() < if j == 0 { 1e-6 } else { 1e-9 });
        if small || round == 29 {
            // Outliers: beyond 3.5 robust deviations (at least 0.25 px).
            let all: Vec<Option<f64>> = points
                .iter()
                .map(|pt| predict(&q, pt[0]).map(|r| pt[1] - r))
                .collect();
            let mut abs: Vec<f64> = all.iter().flatten().map(|r| r.abs()).collect();
            let cut = (3.5 * 1.4826 * quantile(&mut abs, 0.5)).max(0.25);
            let next: Vec<bool> = all
                .iter()
                .map(|r| r.is_some_and(|r| r.abs() <= cut))
                .collect();
            last = Some((jac, res));
            if next == keep {
                break;
            }
            keep = next;
        }
    }
    let (jac, res) = last?;
    let (_, cov, resid) = clamp::lstsq(&jac, &res)?;
    let infl = lag1_inflation(&resid);
    Some(Ring {
        row: Estimate {
            value: q[0],
            std: cov[0][0].sqrt() * infl,
        },
        elevation_rad: Estimate {
            value: q[1],
            std: if hold_e { 0.0 } else { cov[1][1].sqrt() * infl },
        },
        outer_radius_m: q[2],
    })
}

/// The camera of one round of the pinhole set-up: `d` m from the axis,
/// the scale `mpp` at the ring's centre, the axis's column `x0` and the
/// principal point's row.
pub(super) struct View {
    pub(super) d: f64,
    pub(super) mpp: f64,
    pub(super) x0: f64,
    pub(super) principal_row: f64,
}

/// Places the clamp ring's ellipse through the pinhole `at`: the ring
/// centre's row and the elevation from its far side ([`fit_ring`]). With
/// the ring's ends in the picture (a raised camera's elevation found from
/// them), its outer radius is the one of those ends. With the ends out of
/// the picture (`clamp.bend`), the outer radius is fitted too, from the
/// far side's shape, starting from the ellipse seen orthographically: its
/// top `v_top` and curvature `k` (`row = v_top + k x^2`) give, for an
/// outer radius `A` (started at 1.25 times the opening's), `sin e = 2 k A`
/// and the centre `v_top + A sin e`. Nothing to place on a level camera.
pub(super) fn place_ring(
    clamp: &mut Clamp,
    elevation_deg: &mut Option<Estimate>,
    at: &View,
    radius_m: f64,
) -> Result<(), TrackError> {
    let raised = elevation_deg.filter(|e| e.std > 0.0 && e.value > 2.0 * e.std);
    let (start, ends) = match (raised, clamp.half_width_below_px, clamp.bend) {
        (Some(e), Some(a_f), _) => {
            let start = [clamp.row.value, e.value.to_radians(), a_f * at.mpp];
            (start, Some(a_f))
        }
        // placed in an earlier round: from there
        (_, None, Some(_)) if elevation_deg.is_some() && clamp.half_width_px.is_some() => {
            let e = elevation_deg.map_or(0.0, |e| e.value.to_radians());
            let a_f = clamp.half_width_px.unwrap_or(0.0);
            ([clamp.row.value, e, a_f * at.mpp], None)
        }
        (_, None, Some(k)) => {
            let a_f = 1.25 * radius_m / at.mpp;
            let s = (2.0 * k.abs() * a_f).min(0.5);
            let centre = clamp.row.value + if clamp.near { -a_f * s } else { a_f * s };
            ([centre, s.asin(), a_f * at.mpp], None)
        }
        _ => return Ok(()),
    };
    let d = at.d;
    let near = clamp.near;
    // The face's front, or the dome's base (the opening's near half) at
    // the front's elevation when the front lies a flange's height lower.
    let mut on_base = clamp.on_base;
    let front = match (on_base, ends) {
        (true, None) => None,
        _ => {
            let points: Vec<[f64; 2]> = clamp
                .points
                .iter()
                .filter(|p| ends.is_none_or(|w| clamp::clear_of_ends(p[0] - at.x0, w)))
                .copied()
                .collect();
            let radius = ends.map_or(Radius::Fitted, Radius::Ends);
            fit_ring(&points, at, start, radius, near, false)
                // the ring's outer edge lies outside the opening
                .filter(|r| r.outer_radius_m > radius_m)
        }
    };
    let base = (near && !clamp.base_points.is_empty())
        .then(|| {
            let e = front.map_or(start[1], |f| f.elevation_rad.value);
            let start = [clamp.row.value, e, radius_m];
            let (points, hold) = (&clamp.base_points, front.is_some());
            fit_ring(points, at, start, Radius::Known(radius_m), true, hold)
        })
        .flatten()
        .map(|mut r| {
            if let Some(f) = front {
                r.elevation_rad = f.elevation_rad;
            }
            r.row.std = r.row.std.hypot(super::base::BASE_SHADE_PX);
            r
        });
    if let (Some(f), Some(b)) = (front, base) {
        on_base |= super::base::flange(f.row.value - b.row.value, f.row.std.hypot(b.row.std));
    }
    clamp.on_base = on_base;
    let r = if on_base { base } else { front };
    let r = r.ok_or_else(|| TrackError::NotFound {
        what: "the clamp ring's ellipse".into(),
        detail: format!(
            "its {} ({} columns) does not fit {} seen from {d} m",
            if on_base {
                "dome's base in front of the face"
            } else if near {
                "face's front"
            } else {
                "far side"
            },
            if on_base {
                clamp.base_points.len()
            } else {
                clamp.points.len()
            },
            if on_base {
                "the opening's circle"
            } else {
                "a circle wider than the opening"
            }
        ),
        keys: "clamp_row_px (the row of the clamp ring's centre) and elevation_deg",
        clamp_plane: true,
    })?;
    clamp.row = r.row;
    if ends.is_none() && !on_base {
        clamp.half_width_px = Some(r.outer_radius_m / at.mpp);
    }
    *elevation_deg = Some(Estimate {
        value: r.elevation_rad.value.to_degrees(),
        std: r.elevation_rad.std.to_degrees(),
    });
    Ok(())
}

/// The camera's horizontal distance from the axis, m, for a lens of focal
/// length `f_px` (px, from a calibration) that sees the ring's centre at
/// row `v0` with the scale `mpp` there (m per px), looking down at it at
/// `e` rad, the principal point at row `principal_row`: the inverse of
/// [`Pinhole::from_view`]'s scale `s = (D cos theta + H sin theta) / f`
/// with `H = D tan e` and the pitch `theta = e + atan((c_v - v0) / f)`,
/// `D = f s / (cos theta + tan e sin theta)`.
pub(super) fn distance_from_focal(f_px: f64, e: f64, v0: f64, mpp: f64, principal_row: f64) -> f64 {
    let theta = e + ((principal_row - v0) / f_px).atan();
    f_px * mpp / (theta.cos() + e.tan() * theta.sin())
}

/// The scale at the ring's centre, m per px, from the opening's half-width
/// `a_px` (its tangent points) for the camera `D` from the axis at the
/// elevation `e` with the centre at row `v0`: `a / a_px` times the
/// opening's scale factor, iterated (the factor depends on the focal
/// length, which depends on the scale).
pub(super) fn centre_scale(
    a_m: f64,
    a_px: f64,
    d_m: f64,
    e: f64,
    v0: f64,
    x0: f64,
    principal_row: f64,
) -> f64 {
    let mut s = a_m / a_px;
    for _ in 0..20 {
        let p = camera(d_m, e, v0, s, x0, principal_row);
        s = a_m / a_px * p.opening_scale_factor(a_m);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::init::plane::three_column_row;

    /// The far side's points projected from a circle of 2000 points (not
    /// through `circle_rows`) come back to the camera that drew them.
    #[test]
    fn the_ring_comes_back_from_its_far_side() {
        for (d, e_deg, a_outer) in [(0.25, 2.0, 0.047), (0.45, 3.0, 0.047), (1.0, 5.0, 0.05)] {
            let (x0, cv, mpp) = (400.0, 299.5, 1e-4);
            let e = f64::to_radians(e_deg);
            let v0 = 420.0;
            let p = camera(d, e, v0, mpp, x0, cv);
            // the far half of the circle, projected point by point
            let n = 20000;
            let far: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let phi =
                        -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / n as f64;
                    p.project([a_outer * phi.sin(), a_outer * phi.cos(), 0.0])
                })
                .collect();
            // columns beside the bubble (1.04-1.2 of the opening's 0.0375 m)
            let a_px = 0.0375 / mpp;
            let pts: Vec<[f64; 2]> = far
                .windows(2)
                .filter_map(|w| {
                    let dx = (w[0][0] - x0).abs();
                    (dx > 1.04 * a_px && dx < 1.2 * a_px && w[0][0].round() != w[1][0].round())
                        .then_some(w[0])
                })
                .collect();
            assert!(pts.len() > 20, "{}", pts.len());
            // with the ends' half-width: the widest projected point of the
            // whole circle (its tangent points lie in the near half)
            let half = (0..n)
                .map(|i| {
                    let phi = std::f64::consts::TAU * i as f64 / n as f64;
                    (p.project([a_outer * phi.sin(), a_outer * phi.cos(), 0.0])[0] - x0).abs()
                })
                .fold(0.0, f64::max);
            let at = View {
                d,
                mpp,
                x0,
                principal_row: cv,
            };
            let start = [v0 - 5.0, 0.5 * e, 0.04];
            let r = fit_ring(&pts, &at, start, Radius::Ends(half), false, false).unwrap();
            assert!((r.row.value - v0).abs() < 0.02, "{d} {e_deg}: {r:?}");
            assert!(
                (r.outer_radius_m - a_outer).abs() < 1e-5,
                "{d} {e_deg}: {r:?}"
            );
            // and without
            let r = fit_ring(&pts, &at, start, Radius::Fitted, false, false).unwrap();
            assert!((r.row.value - v0).abs() < 0.02, "{d} {e_deg}: {r:?}");
            assert!(
                (r.elevation_rad.value - e).abs() < 2e-4,
                "{d} {e_deg}: {r:?}"
            );
            assert!(
                (r.outer_radius_m - a_outer).abs() < 1e-4,
                "{d} {e_deg}: {r:?}"
            );
        }
    }

    /// A far side seen on one side only, beside the bubble out to the
    /// ring's end (a ring 1.25 times the opening, 0.64 m away, 2.7 degrees
    /// above it: the set-up of a sweep sequence whose other end is out of
    /// the picture), each column read as the clamp's search reads it (the
    /// arc's mean over three columns), its last columns pulled 0.3 px down
    /// towards the corner with the ring's side: with the corner's columns
    /// the centre's row comes out 2 px and 3 of its stated deviations off;
    /// left out, it comes back.
    #[test]
    fn a_one_sided_far_side_is_placed_clear_of_the_ring_s_end() {
        let (d, e, v0, x0, cv, mpp) =
            (0.638, 2.74f64.to_radians(), 321.34, 267.19, 299.5, 8.667e-5);
        let (a, outer) = (0.021924, 1.25 * 0.021924);
        let p = camera(d, e, v0, mpp, x0, cv);
        let w = crate::track::synth::pinhole::circle_half_width_px(&p, outer, 0.0);
        let a_px = a / mpp;
        let pts: Vec<[f64; 2]> = ((1.04 * a_px).ceil() as i64..=(w - 0.5).floor() as i64)
            .filter_map(|dx| {
                let x = x0 + dx as f64;
                let row = three_column_row(x, |x| side_row(&p, outer, x, false))?;
                let u = w - dx as f64;
                Some([x, row + if u < 4.0 { 0.3 * (1.0 - u / 4.0) } else { 0.0 }])
            })
            .collect();
        let at = View {
            d,
            mpp,
            x0,
            principal_row: cv,
        };
        let start = [v0 - 3.0, 0.8 * e, outer];
        let all = fit_ring(&pts, &at, start, Radius::Ends(w), false, false).unwrap();
        let clear: Vec<[f64; 2]> = pts
            .iter()
            .filter(|q| clamp::clear_of_ends(q[0] - x0, w))
            .copied()
            .collect();
        let clear = fit_ring(&clear, &at, start, Radius::Ends(w), false, false).unwrap();
        assert!(
            (all.row.value - v0).abs() > 1.0 && (all.row.value - v0).abs() > 2.5 * all.row.std,
            "with the corner: {all:?}"
        );
        assert!(
            (clear.row.value - v0).abs() < 0.01,
            "clear of it: {clear:?}"
        );
    }

    /// The three columns' mean of a parabola `k x^2` is `k x^2 + 2 k / 3`:
    /// a curving edge is read `row'' / 3` off its middle column's row; the
    /// arc is undefined past its end.
    #[test]
    fn a_curving_edge_is_read_as_its_three_columns_mean() {
        let k = 0.05;
        for x in [-30.0, 0.0, 7.0, 120.0] {
            let r = three_column_row(x, |u| Some(k * u * u)).unwrap();
            assert!((r - (k * x * x + 2.0 * k / 3.0)).abs() < 1e-12, "{x}: {r}");
        }
        let arc = |u: f64| (u.abs() <= 10.0).then(|| (100.0 - u * u).sqrt());
        assert!(three_column_row(9.5, arc).is_none());
        assert!(three_column_row(8.0, arc).is_some());
    }

    /// The scale comes back from the opening's tangent width.
    #[test]
    fn the_centre_scale_comes_back_from_the_opening() {
        let (d, e, v0, x0, cv, mpp) = (0.45, 0.05, 420.0, 400.0, 299.5, 1.1e-4);
        let p = camera(d, e, v0, mpp, x0, cv);
        // the widest projected point of the opening, 200 000 points
        let a = 0.0375;
        let w = (0..200_000)
            .map(|i| {
                let phi = std::f64::consts::TAU * i as f64 / 200_000.0;
                (p.project([a * phi.sin(), a * phi.cos(), 0.0])[0] - x0).abs()
            })
            .fold(0.0, f64::max);
        let s = centre_scale(a, w, d, e, v0, x0, cv);
        assert!((s / mpp - 1.0).abs() < 1e-8, "{s} vs {mpp}");
    }
}
