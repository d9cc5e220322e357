//! The decoding pipeline: photos decoded in parallel (rayon) over the
//! region only, matched in order by the [`super::tracker`] as they arrive.

use std::path::Path;

pub(super) use super::guards::Guard;
use super::image::{Decoded, Gray};
use super::matcher::{EdgeFit, EdgeSettings, Extremes};
use super::tracker::{Located, Tracker};
use super::*;
use crate::io::fmt_short;

/// The sequential half of [`track`]: the reference photo, the template, then
/// every frame's region in order from `rx`.
pub(super) fn match_frames(
    setup: &Setup,
    opts: &Options,
    tick: &(dyn Fn() + Sync),
    reference: &Frame,
    rx: std::sync::mpsc::Receiver<(usize, Result<Decoded, TrackError>)>,
) -> Result<Tracked, TrackError> {
    let n = setup.frames.len();
    // Decoded photos that arrived before their turn.
    let mut early = std::collections::BTreeMap::new();
    let mut take = |i: usize| -> Result<Decoded, TrackError> {
        if let Some(d) = early.remove(&i) {
            return d;
        }
        loop {
            match rx.recv() {
                Ok((k, d)) if k == i => return d,
                Ok((k, d)) => {
                    early.insert(k, d);
                }
                Err(_) => {
                    return Err(TrackError::OpenCv(format!(
                        "the decoding of photo {} stopped early",
                        setup.frames[i].path.display()
                    )));
                }
            }
        }
    };
    // Every crop is read through the camera's tone curve (edges in light).
    let tone = image::Tone::of(setup.response);
    let full = take(setup.reference_frame)?;
    let (width, height) = (full.width, full.height);
    // The reference arrives cropped to `reference_box` (or whole).
    let [bx, by] = match reference_box(setup) {
        Some(b) => [b[0], b[1]],
        None => [0, 0],
    };
    super::lens::check_size(setup.lens.as_ref(), &setup.experiment, width, height)?;
    let roi = check_rect(&reference.path, setup.roi, width, height)?;
    let templ: Gray = match &setup.template {
        TemplateSource::File(p) => image::read_gray(p, None)?.crop,
        TemplateSource::Rect(r) => {
            let [x, y, w, h] = check_rect(&reference.path, *r, width, height)?;
            full.crop.crop(x - bx, y - by, w, h)
        }
    };
    let ref_crop = full
        .crop
        .crop(roi[0] - bx, roi[1] - by, roi[2], roi[3])
        .with_tone(tone);
    // The frames where the bubble is largest (the highest pressure, the
    // last of equals) and smallest (the lowest, the first of equals),
    // decoded once more up front: every other frame's edge is checked
    // against them (`matcher::Columns::with_extremes`). Not for a video,
    // whose frames are read once in order.
    let by_pressure = |a: &usize, b: &usize| {
        setup.frames[*a]
            .pressure_pa
            .total_cmp(&setup.frames[*b].pressure_pa)
    };
    let fullest_frame = (0..n).max_by(by_pressure).unwrap_or(0);
    let emptiest_frame = (0..n).min_by(by_pressure).unwrap_or(0);
    let extreme = |k: usize| -> Option<Gray> {
        match (&setup.video, k == setup.reference_frame) {
            (None, false) => decode_frame(&setup.frames[k].path, Some(roi))
                .ok()
                .map(|d| d.crop.with_tone(tone)),
            (None, true) => Some(ref_crop.clone()),
            _ => None,
        }
    };
    let fullest = extreme(fullest_frame);
    let emptiest = extreme(emptiest_frame);
    drop(full);
    if templ.width > roi[2] || templ.height > roi[3] {
        return Err(TrackError::TemplateLargerThanRegion {
            experiment: setup.experiment.clone(),
            tw: templ.width,
            th: templ.height,
            roi: setup.roi,
        });
    }
    let (tmin, tmax) = templ
        .data
        .iter()
        .fold((255u8, 0u8), |(a, b), &v| (a.min(v), b.max(v)));
    if tmax <= tmin {
        return Err(TrackError::Config {
            path: setup.experiment.clone(),
            message: format!(
                "the template ({}x{} px) is uniform (grey level {tmin}): it must show the border between the bubble's top and the background",
                templ.width, templ.height
            ),
        });
    }
    let apex_in_t = setup.apex_in_template.unwrap_or([
        (templ.width as f64 - 1.0) / 2.0,
        (templ.height as f64 - 1.0) / 2.0,
    ]);
    check_apex_in_template(setup, apex_in_t, &templ)?;
    let edge_settings = EdgeSettings {
        half_span_px: opts.edge_span_px.unwrap_or(templ.width / 2).max(3),
        half_window_px: opts.edge_window_px,
    };
    let mut state = Tracker {
        templ: &templ,
        opts,
        edge_settings,
        apex_in_t,
        reduced: {
            // Coarse search on a template about 64-128 px wide; 32-64 px
            // when the edge fit refines (it needs only a seed within a few
            // px, and OpenCV's matching then costs a fraction of decoding).
            let min_width = if opts.refine == Refine::Edge { 32 } else { 64 };
            let mut f = 1;
            while templ.width / (2 * f) >= min_width && templ.height / (2 * f) >= 16 {
                f *= 2;
            }
            match f {
                1 => None,
                f => Some((f, matcher::reduce(&templ, f)?)),
            }
        },
        // A template cut from the reference photo says where the search
        // starts: no search of the whole region for the first frame.
        last: match &setup.template {
            TemplateSource::Rect(r) => {
                Some([(r[0] - roi[0] as i64) as f64, (r[1] - roi[1] as i64) as f64])
            }
            TemplateSource::File(_) => None,
        },
        prev: None,
        curvature: 0.0,
    };
    let mut located: Vec<Option<Located>> = Vec::with_capacity(n);
    let mut skipped = Vec::new();
    let mut warnings = Vec::new();
    let mut guard = Guard::new(
        match setup.calibration.origin {
            HeightOrigin::ClampRow(r) => Some(r - roi[1] as f64),
            HeightOrigin::Reference { .. } => None,
        },
        Some(setup.calibration.opening_radius_m / setup.calibration.metres_per_pixel),
        edge_settings.half_span_px,
        opts.refine == Refine::Edge,
    )
    .with_elevation(setup.calibration.elevation);
    let mut locate_time = 0.0;
    while located.len() < n {
        let i = located.len();
        let f = &setup.frames[i];
        let crop_owned;
        let crop: &Gray = if i == setup.reference_frame {
            &ref_crop
        } else {
            let dec = take(i)?;
            if (dec.width, dec.height) != (width, height) {
                return Err(TrackError::MixedSizes {
                    path: f.path.clone(),
                    width: dec.width,
                    height: dec.height,
                    reference: reference.path.clone(),
                    ref_width: width,
                    ref_height: height,
                });
            }
            crop_owned = dec.crop.with_tone(tone);
            &crop_owned
        };
        let t0 = std::time::Instant::now();
        let extremes = Extremes {
            fullest: fullest.as_ref().filter(|_| i != fullest_frame),
            emptiest: emptiest.as_ref().filter(|_| i != emptiest_frame),
            is_emptiest: i == emptiest_frame,
        };
        let loc = state.locate(crop, extremes)?;
        let low = loc.m.score < opts.min_score || !loc.m.score.is_finite();
        let score = loc.m.score;
        // A good score, then the plausibility guards; an implausible apex is
        // searched again near the position the frames before predict.
        let verdict = if low {
            Err(format!(
                "score {:.3} < {} {}",
                loc.m.score,
                crate::setting::Setting::MinScore,
                opts.min_score
            ))
        } else {
            let (apex, std) = state.apex(&loc);
            let x_std = state.apex_x_std(&loc);
            match guard.check(f.pressure_pa, apex, [x_std, std], loc.edge.as_ref()) {
                Ok(()) => Ok(loc),
                Err(why) => {
                    // Only the trend rule broken: kept with a warning when
                    // the search near the prediction finds nothing better.
                    let only_trend = why.is_trend();
                    let again = guard
                        .predict(f.pressure_pa)
                        .and_then(|pred| state.locate_at(crop, extremes, pred).transpose())
                        .transpose()?
                        .filter(|l| {
                            let (a, s) = state.apex(l);
                            if l.m.score < opts.min_score {
                                return false;
                            }
                            let xs = state.apex_x_std(l);
                            guard
                                .check(f.pressure_pa, a, [xs, s], l.edge.as_ref())
                                .is_ok()
                        });
                    match again {
                        Some(l) => Ok(l),
                        None if only_trend => {
                            warnings.push(format!(
                                "frame {i} ({}): {why}; kept, since no membrane law bounds the height's step between two photos (near the limit pressure the height grows without bound): check this photo's height, or add photos between it and the one before",
                                f.file
                            ));
                            Ok(loc)
                        }
                        None => Err(why.to_string()),
                    }
                }
            }
        };
        locate_time += t0.elapsed().as_secs_f64();
        match verdict {
            Err(why) => {
                if !opts.skip_bad_frames {
                    // a video names the frame in it too
                    let path = match f.video_frame {
                        Some(_) => format!("{} ({})", f.path.display(), f.file).into(),
                        None => f.path.clone(),
                    };
                    return Err(if low {
                        TrackError::LowScore {
                            path,
                            frame: i,
                            score,
                            min: opts.min_score,
                        }
                    } else {
                        TrackError::Implausible {
                            path,
                            frame: i,
                            why,
                        }
                    });
                }
                skipped.push(Skipped {
                    frame: i,
                    file: f.file.clone(),
                    score,
                    reason: why,
                });
                if low {
                    state.last = None;
                    state.prev = None;
                    state.curvature = 0.0;
                } else if let Some(pred) = guard.predict(f.pressure_pa) {
                    // The next search starts from where this apex should be.
                    state.prev = state.last;
                    state.last = Some([pred[0] - apex_in_t[0], pred[1] - apex_in_t[1]]);
                }
                located.push(None);
            }
            Ok(loc) => {
                // The next search starts from this frame's refined apex (the
                // template alone slides along a flat top).
                let (apex, std) = state.apex(&loc);
                let x_std = state.apex_x_std(&loc);
                guard.accept(f.pressure_pa, apex, [x_std, std], loc.edge.as_ref());
                state.prev = state.last;
                state.last = Some([apex[0] - apex_in_t[0], apex[1] - apex_in_t[1]]);
                state.curvature = loc.edge.map_or(0.0, |e| e.curvature);
                located.push(Some(loc));
            }
        }
        tick();
    }

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
    // A camera above the clamp plane: the silhouette's top `t` px above the
    // clamp ring's centre becomes the apex height (and its deviation, with
    // the curvature's), px.
    let elevated = |t: f64, e: Option<&EdgeFit>| -> (f64, f64) {
        match setup.calibration.elevation {
            None => (t, 0.0),
            Some(el) => el.height_px(
                t,
                e.map(|e| (e.curvature, e.curvature_std)),
                el.radius_m / mpp,
            ),
        }
    };
    let cos_e = setup.calibration.elevation.map_or(1.0, |e| e.radians.cos());
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
    let mut rows = Vec::with_capacity(n);
    for (i, l) in located.iter().enumerate() {
        let Some(l) = l else { continue };
        let f = &setup.frames[i];
        let (apex, std, int, quad, edge) = apex_of(l);
        let is_ref_frame = matches!(setup.calibration.origin, HeightOrigin::Reference { .. })
            && i == setup.reference_frame;
        let std_total = if is_ref_frame {
            0.0
        } else {
            std.hypot(origin_std)
        };
        let (height_m, height_std_m) = match &pinhole {
            None => {
                let (h_px, h_extra) = elevated(origin_row - apex[1], edge.as_ref());
                let h_std_px = (std_total / cos_e).hypot(h_extra);
                (h_px * mpp + offset_m, h_std_px * mpp)
            }
            Some(p) => p
                .membrane_height(apex[1], std_total, setup.calibration.opening_radius_m)
                .ok_or_else(|| TrackError::Config {
                    path: setup.experiment.clone(),
                    message: format!(
                        "the apex of frame {i} ({}) at row {:.2} is not the top of a dome up to 1.5 times the opening's radius seen by a camera {} m from the axis looking down at the clamp ring's centre (row {}) at {:.2} degrees: check [camera] distance_m, [calibration] elevation_deg and clamp_row_px",
                        f.file,
                        apex[1],
                        fmt_short(p.distance_m),
                        fmt_short(origin_row),
                        (p.height_m / p.distance_m).atan().to_degrees()
                    ),
                })?,
        };
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
    Ok(Tracked {
        rows,
        skipped,
        warnings,
        image_size: [width, height],
        locate_seconds: locate_time,
    })
}

/// The part of the reference photo tracking needs: the smallest rectangle
/// holding the region and the template's rectangle (`None`, the whole photo,
/// when either is not a rectangle of non-negative position and positive
/// size: the checks against the photo's size then name it). When the box
/// does not fit in the photo, neither does one of the two, which the same
/// checks report.
pub(super) fn reference_box(setup: &Setup) -> Option<[usize; 4]> {
    let valid = |r: [i64; 4]| r[0] >= 0 && r[1] >= 0 && r[2] > 0 && r[3] > 0;
    let mut b = setup.roi;
    if !valid(b) {
        return None;
    }
    if let TemplateSource::Rect(t) = setup.template {
        if !valid(t) {
            return None;
        }
        let x0 = b[0].min(t[0]);
        let y0 = b[1].min(t[1]);
        let x1 = (b[0] + b[2]).max(t[0] + t[2]);
        let y1 = (b[1] + b[3]).max(t[1] + t[3]);
        b = [x0, y0, x1 - x0, y1 - y0];
    }
    Some(b.map(|v| v as usize))
}

/// Reads one photo and crops the region (an empty crop when the region does
/// not fit: the size check against the reference photo then names the file).
pub(super) fn decode_frame(path: &Path, roi: Option<[usize; 4]>) -> Result<Decoded, TrackError> {
    let bytes = std::fs::read(path).map_err(|e| TrackError::Unreadable {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    image::decode_gray_lenient(path, &bytes, roi)
}

/// The apex's position in the template must lie on the template (pixel
/// centres from 0 to size - 1, half a pixel of slack at each border).
fn check_apex_in_template(setup: &Setup, apex: [f64; 2], templ: &Gray) -> Result<(), TrackError> {
    let inside = |v: f64, n: usize| v.is_finite() && (-0.5..=n as f64 - 0.5).contains(&v);
    if inside(apex[0], templ.width) && inside(apex[1], templ.height) {
        return Ok(());
    }
    Err(TrackError::Config {
        path: setup.experiment.clone(),
        message: format!(
            "[photos] apex_in_template_px = [{}, {}] lies outside the template ({}x{} px): it is the apex's position inside the template, counted from its top-left pixel; give x in 0..{} and y in 0..{}, or remove the key to take the template's centre",
            fmt_short(apex[0]),
            fmt_short(apex[1]),
            templ.width,
            templ.height,
            templ.width - 1,
            templ.height - 1
        ),
    })
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
