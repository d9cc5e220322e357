//! Heights from the apexes found: each apex through the lens into the
//! undistorted image's pixels, the row the heights are measured from (the
//! clamp plane, or a reference photo's apex), and the camera's geometry (an
//! orthographic camera, level or raised by `e`: `Elevation::height_px`; or
//! a pinhole at a known distance: the ray tangent to the dome), each height
//! with its standard deviation.

use super::super::guards::pole_curvature;
use super::super::tracker::{Located, Tracker};
use super::super::{PoleMeasure, pole_flattening, pooled_flattening};
use super::*;

/// The rows of the frames located (`None`: skipped), from the region's
/// origin and the apex's place in the template (`(roi, apex_in_t)`) in a
/// photo of `size` px.
pub(super) fn rows(
    setup: &Setup,
    reference: &Frame,
    state: &Tracker,
    located: &[Option<Located>],
    (roi, apex_in_t): ([usize; 4], [f64; 2]),
    (width, height): (usize, usize),
) -> Result<Vec<FrameResult>, TrackError> {
    // Apex in image coordinates and its statistical uncertainty, px.
    let apex_of = |l: &Located| -> ([f64; 2], f64, [f64; 2], [f64; 2], Option<EdgeFit>) {
        let (off_x, off_y) = (roi[0] as f64, roi[1] as f64);
        let shift = |p: [f64; 2]| [p[0] + off_x, p[1] + off_y];
        let (apex, std) = state.apex(l);
        let int = [l.m.integer[0] + apex_in_t[0], l.m.integer[1] + apex_in_t[1]];
        let quad = [
            l.m.quadratic[0] + apex_in_t[0],
            l.m.quadratic[1] + apex_in_t[1],
        ];
        let edge = l.edge.map(|e| EdgeFit {
            y: e.y + off_y,
            x_vertex: e.x_vertex + off_x,
            ..e
        });
        // Through the lens (when calibrated): heights in the undistorted
        // image's pixels.
        let (apex, edge) = super::lens::undistort_tracked(setup.lens.as_ref(), shift(apex), edge);
        (apex, std, shift(int), shift(quad), edge)
    };
    let mpp = setup.calibration.metres_per_pixel;
    let (origin_row, origin_std, offset_m) = match setup.calibration.origin {
        HeightOrigin::ClampRow(r) => (r, 0.0, 0.0),
        HeightOrigin::Reference { prebulge_height_m } => {
            let l = located[setup.reference_frame].as_ref().ok_or_else(|| TrackError::Config {
                path: setup.experiment.clone(),
                message: format!(
                    "the reference frame {} ({}) was skipped as bad, and heights are measured from it (no clamp_row_px in [calibration]); choose another reference_frame or give clamp_row_px",
                    setup.reference_frame, reference.file
                ),
            })?;
            let (apex, std, ..) = apex_of(l);
            (apex[1], std, prebulge_height_m)
        }
    };
    let a_px = setup.calibration.elevation.map(|el| el.radius_m / mpp);
    // A camera above the clamp plane: the silhouette's top `t` px above the
    // clamp ring's centre becomes the apex height (and its deviation, with
    // the pole radius's), px.
    let elevated = |t: f64, t_std: f64, m: Option<PoleMeasure>| -> (f64, f64) {
        match (setup.calibration.elevation, a_px) {
            (Some(el), Some(a_px)) => el.height_and_std_px(t, t_std, m, a_px),
            _ => (t, t_std),
        }
    };
    // A pinhole camera at a known distance: heights through the ray tangent
    // to the dome. The principal point is the lens's (or the picture's
    // centre); the focal length is the one that gives the scale at the
    // ring's centre from that distance (the heights then share the scale's
    // error, as an orthographic camera's do).
    let pinhole = setup.calibration.camera_distance_m.map(|d| {
        let e = setup.calibration.elevation.map_or(0.0, |e| e.radians);
        let principal = match &setup.lens {
            Some(l) => [l.cx, l.cy],
            None => [(width as f64 - 1.0) / 2.0, (height as f64 - 1.0) / 2.0],
        };
        super::persp::Pinhole::from_view(d, e, origin_row, mpp, None, principal)
    });
    let a_m = setup.calibration.opening_radius_m;
    // The height, m, and its deviation of the apex at `row` (deviation
    // `std`), with what is known of the pole's radius.
    let height_of = |i: usize, row: f64, std: f64, m: Option<PoleMeasure>| match &pinhole {
        None => {
            let (h_px, h_std_px) = elevated(origin_row - row, std, m);
            Ok((h_px * mpp + offset_m, h_std_px * mpp))
        }
        Some(p) => p
            .membrane_height(row, std, a_m, m)
            .ok_or_else(|| not_a_dome(setup, i, row, p, origin_row)),
    };
    let half_span = state.edge_settings.half_span_px as f64;
    // The photo's own measure of the pole: the outline's curvature at the
    // top, corrected for the parabola's fit over the span (its deviation
    // and covariance with the row scaled alike).
    let outline = |e: &EdgeFit| {
        let k = pole_curvature(e.curvature, half_span);
        let g = k / e.curvature;
        PoleMeasure::Outline(k, e.curvature_std * g, e.y_curvature_cov * g)
    };
    let fitted: Vec<_> = located
        .iter()
        .enumerate()
        .filter_map(|(i, l)| l.as_ref().map(|l| (i, l, apex_of(l))))
        .collect();
    let std_of = |i: usize, std: f64| {
        let is_ref_frame = matches!(setup.calibration.origin, HeightOrigin::Reference { .. })
            && i == setup.reference_frame;
        if is_ref_frame {
            0.0
        } else {
            std.hypot(origin_std)
        }
    };
    // Where the camera's geometry needs the pole's radius, each photo's
    // from the outlines of all (one membrane, whose flattening changes
    // slowly with its height: `pooled_flattening`), from a first pass on
    // each photo's own outline.
    let pooled: Option<Vec<Option<(f64, f64, f64)>>> = if pinhole.is_some() || a_px.is_some() {
        let mut h_over_a = Vec::with_capacity(fitted.len());
        let mut measured = Vec::with_capacity(fitted.len());
        // cov(row, ln F) of each photo's own measure, px: `ln F` falls with
        // the curvature, by `rel / (ks / k)` of its relative error.
        let mut row_cov = Vec::with_capacity(fitted.len());
        for (i, _, (apex, std, _, _, edge)) in &fitted {
            let own = edge.as_ref().map(outline);
            let (h, _) = height_of(*i, apex[1], std_of(*i, *std), own)?;
            // The pole radius the outline implies, over the cap's at this
            // photo's height.
            let (h_a, flattening) = match &pinhole {
                Some(p) => {
                    let r_cap = super::persp::cap_radius(a_m, h);
                    let f = |k: f64, ks: f64| {
                        let r0 = pole_flattening(h / a_m).0 * r_cap;
                        let (r, rel) = p.pole_radius_from_outline(h, r0, 1.0 / k, ks / k);
                        (r / r_cap, rel)
                    };
                    (
                        h / a_m,
                        own.and_then(PoleMeasure::outline).map(|(k, ks)| f(k, ks)),
                    )
                }
                None => {
                    let (h_px, a_px) = ((h - offset_m) / mpp, a_px.unwrap_or(f64::NAN));
                    let r_cap = super::persp::cap_radius(a_px, h_px);
                    let f = |k: f64, ks: f64| (1.0 / (k * r_cap), ks / k);
                    (
                        h_px / a_px,
                        own.and_then(PoleMeasure::outline).map(|(k, ks)| f(k, ks)),
                    )
                }
            };
            h_over_a.push(h_a);
            measured.push(flattening);
            row_cov.push(match (own, flattening) {
                (Some(PoleMeasure::Outline(_, ks, c)), Some((_, rel))) if ks > 0.0 => -rel * c / ks,
                _ => 0.0,
            });
        }
        let pool = pooled_flattening(&h_over_a, &measured);
        Some(
            pool.into_iter()
                .zip(row_cov)
                .map(|(p, c)| p.map(|(f, rel, own)| (f, rel, own * c)))
                .collect(),
        )
    } else {
        None
    };
    let mut rows = Vec::with_capacity(located.len());
    for (n, (i, l, (apex, std, int, quad, edge))) in fitted.into_iter().enumerate() {
        let f = &setup.frames[i];
        let measure = match &pooled {
            Some(p) => p[n].map(|(v, rel, c)| PoleMeasure::Flattening(v, rel, c)),
            None => None,
        };
        let (height_m, height_std_m) = height_of(i, apex[1], std_of(i, std), measure)?;
        rows.push(FrameResult {
            frame: i,
            file: f.file.clone(),
            pressure_pa: f.pressure_pa,
            apex_x_px: apex[0],
            apex_y_px: apex[1],
            score: l.m.score,
            height_m,
            height_std_m,
            apex_y_std_px: std,
            apex_integer_px: int,
            apex_quadratic_px: quad,
            edge,
            time_s: f.time_s,
        });
    }
    if let HeightOrigin::ClampRow(clamp) = setup.calibration.origin {
        check_above_clamp(setup, clamp, &rows)?;
    }
    Ok(rows)
}

/// No dome up to `1.5 a` has its top at the apex's `row` of frame `i` from
/// the pinhole `p`: the camera's set-up is wrong.
fn not_a_dome(
    setup: &Setup,
    i: usize,
    row: f64,
    p: &super::persp::Pinhole,
    origin_row: f64,
) -> TrackError {
    TrackError::Config {
        path: setup.experiment.clone(),
        message: format!(
            "the apex of frame {i} ({}) at row {row:.2} is not the top of a dome up to 1.5 times the opening's radius seen by a camera {} m from the axis looking down at the clamp ring's centre (row {}) at {:.2} degrees: check [camera] distance_m, [calibration] elevation_deg and clamp_row_px",
            setup.frames[i].file,
            fmt_short(p.distance_m),
            fmt_short(origin_row),
            (p.height_m / p.distance_m).atan().to_degrees()
        ),
    }
}

/// A bubble's apex stands above the clamp plane: a frame whose apex lies
/// below the clamp row (rows grow downward) by more than three standard
/// deviations and a pixel means the clamp row is wrong, not a negative height.
fn check_above_clamp(setup: &Setup, clamp: f64, rows: &[FrameResult]) -> Result<(), TrackError> {
    let below = rows
        .iter()
        .find(|r| r.apex_y_px - clamp > 3.0 * r.apex_y_std_px + 1.0);
    let Some(r) = below else { return Ok(()) };
    Err(TrackError::Config {
        path: setup.experiment.clone(),
        message: format!(
            "[calibration] clamp_row_px = {} lies above the apex of frame {} ({}, apex at row {:.1}): its height would be {} m, below the clamp plane. The clamp row is the image row of the clamp plane, below the bubble's top (rows grow downward); measure it on a photo, or remove it to measure heights from the reference frame",
            fmt_short(clamp),
            r.frame,
            r.file,
            r.apex_y_px,
            fmt_short(r.height_m)
        ),
    })
}
