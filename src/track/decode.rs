//! The decoding pipeline: photos decoded in parallel (rayon) over the
//! region only, matched in order by the [`super::tracker`] as they arrive.

use std::path::Path;

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
    let mut guard = Guard::new(
        match setup.calibration.origin {
            HeightOrigin::ClampRow(r) => Some(r - roi[1] as f64),
            HeightOrigin::Reference { .. } => None,
        },
        Some(setup.calibration.opening_radius_m / setup.calibration.metres_per_pixel),
        edge_settings.half_span_px,
        opts.refine == Refine::Edge,
    );
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
                "score {:.3} < --min-score {}",
                loc.m.score, opts.min_score
            ))
        } else {
            let (apex, std) = state.apex(&loc);
            let x_std = state.apex_x_std(&loc);
            match guard.check(f.pressure_pa, apex, [x_std, std], loc.edge.as_ref()) {
                Ok(()) => Ok(loc),
                Err(why) => {
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
                    again.ok_or(why)
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
        let (h_px, h_extra) = elevated(origin_row - apex[1], edge.as_ref());
        let h_std_px = (std_total / cos_e).hypot(h_extra);
        rows.push(FrameResult {
            frame: i,
            file: f.file.clone(),
            pressure_pa: f.pressure_pa,
            apex_x_px: apex[0],
            apex_y_px: apex[1],
            score: l.m.score,
            height_m: h_px * mpp + offset_m,
            height_std_m: h_std_px * mpp,
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

/// The plausibility guards of the apex, frame by frame (region
/// coordinates): an apex stands above the clamp plane; it moves
/// continuously with the pressure (within a tolerance of the position
/// extrapolated from the last two accepted frames, linearly in pressure);
/// it does not go down while the pressure rises (nor up while it falls),
/// beyond its noise; and the columns of its edge agree with one another
/// about as well as in the frames before.
/// What the guards keep of an accepted frame.
#[derive(Debug, Clone, Copy)]
struct Accepted {
    /// Pressure, Pa.
    p: f64,
    /// Apex, px (region coordinates).
    apex: [f64; 2],
    /// Standard error of the apex column, px.
    x_std: f64,
    /// Standard error of the apex row, px.
    y_std: f64,
    /// The edge fit's residual RMS (px), curvature and its standard error
    /// (1/px), and columns.
    edge: Option<(f64, f64, f64, usize)>,
}

pub(super) struct Guard {
    /// The clamp plane's row in the region, px, when known.
    clamp_row: Option<f64>,
    /// The opening's radius, px, when known and finite.
    opening_px: Option<f64>,
    /// Half-width of the edge fit's span of columns, px.
    span: f64,
    /// The apex is the edge fit's (`--refine edge`): a frame without an
    /// edge has no measurement, only the template's match.
    edge_required: bool,
    /// The accepted frames.
    history: Vec<Accepted>,
}

impl Guard {
    pub(super) fn new(
        clamp_row: Option<f64>,
        opening_px: Option<f64>,
        span_px: usize,
        edge_required: bool,
    ) -> Self {
        Guard {
            clamp_row,
            opening_px: opening_px.filter(|a| a.is_finite() && *a > 0.0),
            span: span_px as f64,
            edge_required,
            history: Vec::new(),
        }
    }

    /// The apex predicted at pressure `p` from the last two accepted
    /// frames (the last one's when only one, or equal pressures).
    pub(super) fn predict(&self, p: f64) -> Option<[f64; 2]> {
        let n = self.history.len();
        let Accepted {
            p: p1, apex: a1, ..
        } = *self.history.last()?;
        if n < 2 {
            return Some(a1);
        }
        let Accepted {
            p: p0, apex: a0, ..
        } = self.history[n - 2];
        if (p1 - p0).abs() <= f64::EPSILON * p1.abs().max(1.0) {
            return Some(a1);
        }
        let t = (p - p1) / (p1 - p0);
        Some([a1[0], a1[1] + t * (a1[1] - a0[1])])
    }

    /// Why the apex `apex` (standard errors `[x_std, y_std]`, px) at
    /// pressure `p` is not plausible, if it is not.
    pub(super) fn check(
        &self,
        p: f64,
        apex: [f64; 2],
        stds: [f64; 2],
        edge: Option<&EdgeFit>,
    ) -> Result<(), String> {
        // The template's match alone is not the bubble's top: it may have
        // locked on a line behind the bubble that its own background shows.
        if self.edge_required && edge.is_none() {
            return Err("no edge of the bubble's top was found at the template's match: the template locked on something else, or the top is hidden".to_string());
        }
        if edge.is_some_and(|e| e.clutter_on_top) {
            return Err("a line behind the bubble (clutter) lies a few rows above the top in this photo at the lowest pressure, and no emptier photo shows the background there to tell the two apart: clear the background or add a photo at a lower pressure".to_string());
        }
        let [x_std, std] = stds;
        let y = apex[1];
        // The axis does not move: the apex column stays within its
        // uncertainty (and 3 px) of the last well-placed one.
        if let Some(&Accepted {
            apex: a1,
            x_std: xs1,
            ..
        }) = self.history.iter().rev().find(|h| h.x_std.is_finite())
            && x_std.is_finite()
        {
            let tol = 3.0 + 4.0 * x_std.hypot(xs1);
            if (apex[0] - a1[0]).abs() > tol {
                return Err(format!(
                    "the apex column moved from {:.1} to {:.1} px (tolerance {:.1} px), while the bubble's axis stays put: the edge found is not the bubble's top",
                    a1[0], apex[0], tol
                ));
            }
        }
        // (When the first frame's apex is below it too, the clamp row is
        // wrong, which the check after tracking reports.)
        if let Some(c) = self.clamp_row
            && y >= c
            && self.history.first().is_some_and(|h| h.apex[1] < c)
        {
            return Err(format!(
                "the apex found at row {:.1} is at or below the clamp plane ({:.1} in the region): the template locked on something else",
                y, c
            ));
        }
        // A dome's apex column is pinned down once the dome is curved; an
        // edge whose top is not (a straight shelf edge) is not the dome's.
        let placed: Vec<f64> = self.history.iter().map(|h| h.x_std).collect();
        if placed.len() >= 2
            && placed[placed.len() - 2..]
                .iter()
                .all(|&s| s < 0.25 * self.span)
            && (x_std >= 0.5 * self.span || x_std.is_nan())
        {
            return Err(format!(
                "the edge found has no apex (its top is flat over the {:.0} px span), while the frames before had one",
                2.0 * self.span
            ));
        }
        // The top of a dome `h` px high on an opening of radius `a` px is
        // curved about as a spherical cap through the rim, `2 h / (a^2 +
        // h^2)`: an inflated membrane's pole is flatter or sharper than the
        // cap by tens of percent, never by a factor of 2.5. A shelf edge or
        // a cable along the top is nearly straight. This needs no frame
        // before, so it also guards the reference frame.
        if let (Some(c), Some(a), Some(e)) = (self.clamp_row, self.opening_px, edge) {
            let h = c - y;
            if h > 2.0 {
                let cap = 2.0 * h / (a * a + h * h);
                // Where the cap's top sags by 1 px or more across the span,
                // the curvature must be measured to half the cap's at least,
                // and with no frame before (the reference frame) the dome
                // must be shown, not only not excluded: a line along the
                // top, or an edge inside the dome, gives a curvature with a
                // large error.
                let visible = 0.5 * cap * self.span * self.span >= 1.0;
                let shown = self.history.is_empty() && visible;
                let noise = if shown { -2.0 } else { 4.0 } * e.curvature_std;
                if visible && e.curvature_std > 0.5 * cap {
                    return Err(format!(
                        "the edge found does not show a dome's curvature ({:.2e} +- {:.2e} 1/px, against {:.2e} for a spherical cap {:.1} px high on an opening of radius {:.1} px): something other than the bubble's top was fitted",
                        e.curvature, e.curvature_std, cap, h, a
                    ));
                }
                if e.curvature < 0.4 * cap - noise || e.curvature > 2.5 * cap + noise.abs() {
                    return Err(format!(
                        "the edge's curvature {:.2e} 1/px is not that of a dome {:.1} px high on an opening of radius {:.1} px ({:.2e} for a spherical cap): the edge found is not the bubble's top (a shelf edge or a cable along it?)",
                        e.curvature, h, a, cap
                    ));
                }
            }
        }
        // The edge fit's own apex error: a dome's top fits a parabola about
        // equally well from frame to frame, while clutter or a highlight
        // pulled into the fit raises the error many times (needs only the
        // reference frame, so it also acts on the frame after it).
        let worst = self
            .history
            .iter()
            .map(|h| h.y_std)
            .filter(|s| s.is_finite())
            .fold(f64::NAN, f64::max);
        if worst.is_finite() && std.is_finite() && std > 8.0 * worst && std - worst > 0.1 {
            return Err(format!(
                "the apex row's standard error jumped to {:.2} px from at most {:.2} px in the frames before: something pulls the edge fit off the bubble's top",
                std, worst
            ));
        }
        let noise = 3.0 * std + 0.5;
        if let Some(&Accepted {
            p: p1, apex: a1, ..
        }) = self.history.last()
        {
            let dy = y - a1[1];
            if (p > p1 && dy > noise) || (p < p1 && dy < -noise) {
                return Err(format!(
                    "the apex moved {:+.2} px against the pressure ({} -> {} Pa; rows grow downward): the edge found is not the bubble's",
                    dy, p1, p
                ));
            }
        }
        if self.history.len() >= 2
            && let Some(pred) = self.predict(p)
        {
            let last = self.history[self.history.len() - 1].apex[1];
            let tol = 2.0 + (pred[1] - last).abs() + 4.0 * std;
            if (y - pred[1]).abs() > tol {
                return Err(format!(
                    "the apex jumped to row {:.1}, {:.1} px from where the frames before predict it ({:.1}; tolerance {:.1} px)",
                    y,
                    y - pred[1],
                    pred[1],
                    tol
                ));
            }
        }
        if let Some(e) = edge
            && let Some((c1, c1_std, h1)) = self.recent_curvature()
        {
            // The dome's curvature changes smoothly; a straight shelf edge
            // or a sagging cable does not follow it. With the clamp row, the
            // curvature per px of height (2 / (a^2 + h^2) on a spherical
            // cap, which changes by a third from h = 0.1 a to 0.6 a) is
            // compared, within 12 %, so that frames left out in between do
            // not matter.
            let jumped = match (self.clamp_row, h1) {
                (Some(c), Some(h1)) if c - y > 2.0 && h1 > 2.0 => {
                    let (k, k1) = (e.curvature / (c - y), c1 / h1);
                    let tol = 0.12 * k1.abs() + 4.0 * e.curvature_std.hypot(c1_std) / (c - y);
                    (k - k1).abs() > tol
                }
                // Without the clamp row the height is not known, and the
                // curvature of a slack or flat membrane can double from one
                // photo to the next: only a dome turned into a nearly
                // straight edge (or a much sharper one) is refused.
                _ => {
                    let noise = 4.0 * e.curvature_std.hypot(c1_std);
                    e.curvature < 0.5 * c1 - noise || e.curvature > 4.0 * c1 + noise
                }
            };
            if jumped {
                return Err(format!(
                    "the edge's curvature jumped from {:.2e} to {:.2e} 1/px: the edge found is not the bubble's",
                    c1, e.curvature
                ));
            }
        }
        if let Some(e) = edge {
            let mut cols: Vec<usize> = self
                .history
                .iter()
                .filter_map(|h| h.edge.map(|e| e.3))
                .collect();
            if cols.len() >= 2 {
                cols.sort_unstable();
                let typical = cols[cols.len() / 2];
                if (e.columns as f64) < 0.6 * typical as f64 {
                    return Err(format!(
                        "the edge is seen in {} columns against {} in the frames before: something hides the bubble's top",
                        e.columns, typical
                    ));
                }
            }
            // (The last three: the residual of a parabola grows with the
            // dome's curvature.)
            let mut rms: Vec<f64> = self
                .history
                .iter()
                .rev()
                .filter_map(|h| h.edge.map(|e| e.0))
                .take(3)
                .collect();
            if rms.len() >= 2 {
                rms.sort_by(f64::total_cmp);
                let typical = rms[rms.len() / 2];
                let bound = (1.6 * typical).max(typical + 0.08);
                if e.rms > bound {
                    return Err(format!(
                        "the edge's columns disagree (residual RMS {:.2} px against {:.2} px in the frames before): something crosses the bubble's top edge",
                        e.rms, typical
                    ));
                }
            }
        }
        Ok(())
    }

    /// Of the last three accepted frames with an edge fit, the one of
    /// median curvature per px of height (median curvature without the
    /// clamp row): its curvature, standard error and height above the
    /// clamp row, px.
    fn recent_curvature(&self) -> Option<(f64, f64, Option<f64>)> {
        let mut c: Vec<(f64, f64, Option<f64>)> = self
            .history
            .iter()
            .rev()
            .filter_map(|h| {
                h.edge
                    .map(|e| (e.1, e.2, self.clamp_row.map(|c| c - h.apex[1])))
            })
            .take(3)
            .collect();
        if c.is_empty() {
            return None;
        }
        let key = |v: &(f64, f64, Option<f64>)| match v.2 {
            Some(h) if h > 0.0 => v.0 / h,
            _ => v.0,
        };
        c.sort_by(|a, b| key(a).total_cmp(&key(b)));
        Some(c[c.len() / 2])
    }

    /// Records an accepted frame.
    pub(super) fn accept(
        &mut self,
        p: f64,
        apex: [f64; 2],
        stds: [f64; 2],
        edge: Option<&EdgeFit>,
    ) {
        self.history.push(Accepted {
            p,
            apex,
            x_std: stds[0],
            y_std: stds[1],
            edge: edge.map(|e| (e.rms, e.curvature, e.curvature_std, e.columns)),
        });
    }
}
