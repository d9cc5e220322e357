//! The decoding pipeline: photos decoded in parallel (rayon) over the
//! region only, matched in order by the [`super::tracker`] as they arrive.
//! Here the reference photo, the template and the frames where the bubble
//! is largest and smallest are prepared and checked; `locate` locates every
//! frame with the plausibility guards, `heights` turns the apexes into
//! heights through the camera.

use std::path::Path;

pub(super) use super::guards::Guard;
use super::image::{Decoded, Gray};
use super::matcher::{EdgeFit, EdgeSettings, Extremes};
use super::tracker::Tracker;
use super::*;
use crate::io::fmt_short;

mod heights;
mod locate;

/// The decoded photos, taken in frame order as they arrive from the
/// decoders (a photo decoded before its turn waits in `early`).
pub(super) struct InOrder<'a> {
    setup: &'a Setup,
    rx: std::sync::mpsc::Receiver<(usize, Result<Decoded, TrackError>)>,
    early: std::collections::BTreeMap<usize, Result<Decoded, TrackError>>,
}

impl InOrder<'_> {
    /// Frame `i`'s photo, decoded.
    pub(super) fn take(&mut self, i: usize) -> Result<Decoded, TrackError> {
        if let Some(d) = self.early.remove(&i) {
            return d;
        }
        loop {
            match self.rx.recv() {
                Ok((k, d)) if k == i => return d,
                Ok((k, d)) => {
                    self.early.insert(k, d);
                }
                Err(_) => {
                    return Err(TrackError::OpenCv(format!(
                        "the decoding of photo {} stopped early",
                        self.setup.frames[i].path.display()
                    )));
                }
            }
        }
    }
}

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
    let mut arrivals = InOrder {
        setup,
        rx,
        early: std::collections::BTreeMap::new(),
    };
    // Every crop is read through the camera's tone curve (edges in light).
    let tone = image::Tone::of(setup.response);
    let full = arrivals.take(setup.reference_frame)?;
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
        blocks: match &setup.video {
            Some(_) => Blocks::Unknown,
            None => Blocks::of_photo(&setup.frames[setup.reference_frame].path),
        },
        origin_row_px: roi[1] as f64,
    };
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
    let shared = locate::Shared {
        reference,
        ref_crop: &ref_crop,
        size: (width, height),
        tone,
        fullest: (fullest_frame, fullest.as_ref()),
        emptiest: (emptiest_frame, emptiest.as_ref()),
        apex_in_t,
    };
    let locate::Outcome {
        located,
        skipped,
        warnings,
        seconds: locate_time,
    } = locate::every_frame(
        setup,
        opts,
        tick,
        &shared,
        &mut arrivals,
        &mut state,
        &mut guard,
    )?;

    let rows = heights::rows(
        setup,
        reference,
        &state,
        &located,
        (roi, apex_in_t),
        (width, height),
    )?;
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
