//! The set-up of an experiment from its photos alone (`bulge init`): the
//! clamp plane, the bubble's axis, the apex in every photo, the region and
//! the template for tracking, the scale from the clamp opening and the
//! camera's elevation from the clamp's ellipse.
//!
//! The method uses what a bubble test has and a cluttered background has
//! not: the bubble grows, everything else stands still.
//!
//! 1. **What moves.** The last photo minus the first (each smoothed 3x3,
//!    the first scaled by the median ratio of the two, for a drifting
//!    exposure) is noise except where the bubble grew. Pixels beyond
//!    `max(6 sigma, 0.35 C, 3)` (sigma the difference's robust noise, `C`
//!    its 99.5th percentile) of the bubble's sign form regions; the largest
//!    is the band the top of the bubble swept. A shelf edge or a cable
//!    behind the bubble is the same in both photos and drops out.
//! 2. **Axis and apex track.** The band is mirror-symmetric about the
//!    bubble's axis: the axis is the median of the midpoints of its rows.
//!    On the axis (the mean of 7 columns), the band runs from the last
//!    photo's apex down to the first's; each photo's apex is where its
//!    profile turns from the first photo's (background) to the last's
//!    (bubble), `t = (p_k - p_first) / (p_last - p_first)` crossing 1/2.
//! 3. **Clamp plane.** Beside the bubble's base (columns 1.04-1.6 times the
//!    band's half-width from the axis) the clamp's top edge is the lowest
//!    strong horizontal edge near the band's lowest row, located to
//!    sub-pixel precision per column (the same centroid of differences as
//!    the tracker's edge fit). A camera raised by `e` sees the clamp's top
//!    face, a circle of radius `A` (its half-width in the photo, from its
//!    ends), as an ellipse: its back edge lies at `c - s sqrt(A^2 - d^2)`
//!    at a distance `d` from the axis, `s = sin e`, `c` the row of its
//!    centre (the clamp plane as `clamp_row_px` means it). A least-squares
//!    fit of `(c, s)` over the columns, with outliers beyond 3.5 robust
//!    standard deviations left out, gives both with standard errors; a
//!    level camera gives `s` within its noise of 0.
//! 4. **Scale from the clamp opening.** The silhouette is `2a` wide at the
//!    clamp plane. Its sides are located row by row (sub-pixel) in the last
//!    photo a little above the plane, and the squared half-width is fitted
//!    as a quadratic in the height above it (`init/scale.rs`: the outline of a
//!    conic meridian from any elevation). The scale is `radius_m / a_px`
//!    (through the pinhole when the camera's distance is known); read at
//!    the clamp row, it shares that row's error.
//! 5. **Template and region.** The template (30 % of `a` wide, at most a
//!    tenth of the photo, half as tall) is cut around the apex of the first
//!    photo whose template stays clear of the clamp, and the region covers
//!    every apex found with a template's margin, as `bulge synth` lays them
//!    out. The apex inside the template comes from the tracker's edge fit.
//!
//! What cannot be found is refused, naming it and the key of the
//! experiment file to set by hand ([`TrackError::NotFound`]): no bubble
//! (the photos do not change), a bubble cut by the photo's border, the
//! clamp plane out of the picture or two candidate edges for it, a curved
//! clamp edge whose ends are outside the picture.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::TrackError;
use super::image::{Gray, read_gray};
use super::matcher::{
    Columns, EdgeSettings, SLOPE_ROWS, edge_fit_in, lag1_inflation, profile_edge,
    profile_edge_with, seed_rows,
};
use super::synth::Layout;

mod about;
mod band;
mod base;
mod bubble;
mod clamp;
mod clip;
pub mod command;
mod contrast;
mod file;
mod frames;
mod meridian;
mod plane;
mod ring;
mod scale;
mod top_edge;

use bubble::{follow_side, refine_axis, shrinking_check, swept, top_below_band};
use clamp::{Clamp, find_clamp, robust_lstsq};
pub use file::Sources;
pub use frames::Frames;
use plane::Plane;
use scale::find_radius;

/// The edge fit's bias that no residual shows, px, on the clamp row seen
/// from a raised camera ([`seen_raised`]): the apex's floor as measured on
/// the tracker sweep's clean photos before it was split by the columns
/// fitted and a JPEG's block boundaries ([`super::tracker::edge_floor_px`]);
/// those were measured on the dome's curved top, not on the ring's edge,
/// and are not carried to it. From a raised camera the edge is an
/// ellipse's side whose row the camera grid finds biased by up to a
/// deviation with this floor (cause not established); from a level one it
/// is straight, and there its rows' errors are 0.94-1.02 of the fit's own
/// deviation without it (60 framings at each of 0.25, 0.45 and 1 m), so it
/// is not added.
pub const CLAMP_FLOOR_PX: f64 = 0.015;

/// The photos show the camera above the clamp plane: an elevation given
/// above 0, or fitted beyond 2 of its deviations from 0 (a level edge's
/// fitted elevation is within them 95 % of the time).
fn seen_raised(elevation_deg: Option<Estimate>) -> bool {
    elevation_deg.is_some_and(|e| e.value.abs() > 2.0 * e.std)
}

/// A value found in the photos and its standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard deviation (0: given, not measured).
    pub std: f64,
}

/// What is given instead of found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Given {
    /// The scale, m per px.
    pub metres_per_pixel: Option<f64>,
    /// The camera's elevation above the clamp plane, degrees.
    pub elevation_deg: Option<f64>,
    /// The clamp plane's row at the bubble's axis (from a raised camera the
    /// clamp ring's centre), px in the photo, and its standard deviation:
    /// step 3 is not made, the camera is taken as not rolled, and its
    /// elevation is `elevation_deg` (level without it). For a scene whose
    /// clamp init does not find (a lit floor or a table's edge beside the
    /// ring, a camera raised beyond the range init's search is measured on).
    pub clamp_row_px: Option<Estimate>,
    /// The camera's tone curve (edges are located in light).
    pub response: crate::camera::Response,
    /// The lens (`bulge calibrate`): the clamp row, the axis and the scale
    /// are given in the undistorted image (the region and the template stay
    /// the photo's), and the experiment file gets the lens.
    pub lens: Option<super::lens::Lens>,
    /// A pinhole camera this far from the bubble's axis, m (`[camera]
    /// distance_m`): the clamp ring's far side is fitted as the image of a
    /// circle seen from it, and the scale at the ring's centre from the
    /// opening's tangent points ([`ring`](self)). `None`: orthographic.
    pub camera_distance_m: Option<f64>,
    /// Without `camera_distance_m`, find the distance from the lens's focal
    /// length and the scale ([`ring::distance_from_focal`]); `false`: the
    /// camera is taken as orthographic (a telecentric lens).
    pub distance_from_focal: bool,
}

/// Where the scale came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScaleSource {
    /// The silhouette's width at the clamp plane, `2a`.
    ClampOpening,
    /// Given.
    Given,
}

/// Everything found in the photos.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Photo size, px.
    pub width: usize,
    /// Photo size, px.
    pub height: usize,
    /// The camera's tone curve the photos were read through.
    pub response: crate::camera::Response,
    /// The lens given (copied into the experiment file's `[camera]`).
    pub lens: Option<super::lens::Lens>,
    /// The pinhole camera's distance from the axis, m, given or found from
    /// the lens's focal length (written into `[camera] distance_m`).
    pub camera_distance_m: Option<f64>,
    /// `camera_distance_m` was found from the lens's focal length and the
    /// scale, not given.
    pub camera_distance_from_focal: bool,
    /// The bubble's axis, image column.
    pub axis_x_px: Estimate,
    /// The clamp plane (the clamp ring's centre from a raised camera), image row.
    pub clamp_row_px: Estimate,
    /// `clamp_row_px` was given ([`Given::clamp_row_px`]), not found.
    pub clamp_row_given: bool,
    /// The camera's elevation above the clamp plane, degrees (`None`: the
    /// clamp's ends are outside the picture and its edge is straight: level).
    pub elevation_deg: Option<Estimate>,
    /// The camera's roll about its view axis, degrees: the slope of the
    /// clamp's top edge across the photo (positive when it descends to the
    /// right). At most [`MAX_ROLL_DEG`].
    pub roll_deg: Estimate,
    /// Half-width of the clamp's top face, px, when its ends are in the picture.
    pub clamp_half_width_px: Option<f64>,
    /// The free radius in px, from the silhouette at the clamp plane
    /// (`None` when the scale is given).
    pub radius_px: Option<Estimate>,
    /// The scale, m per px.
    pub metres_per_pixel: Estimate,
    /// Where the scale came from.
    pub scale_from: ScaleSource,
    /// The scale's relative change per px that the clamp row lies lower, 1/px: read on the
    /// opening at the clamp row, the scale shares the row's error (0 when the scale is given).
    pub scale_per_clamp_row: f64,
    /// The apex in every photo, image coordinates (about a pixel: the
    /// tracker measures it precisely).
    pub apexes_px: Vec<[f64; 2]>,
    /// The photo the template is cut from.
    pub reference_frame: usize,
    /// Region, template and the apex in it.
    pub layout: Layout,
    /// The apex of the reference photo (edge fit), image coordinates.
    pub reference_apex_px: [f64; 2],
    /// The top outline of the first and the last photo's silhouette (one
    /// point per column of the band), image coordinates.
    pub outlines_px: [Vec<[f64; 2]>; 2],
    /// The clamp's top edge as located, column by column.
    pub clamp_points_px: Vec<[f64; 2]>,
    /// The clamp's edge was located on a step clipped at the sensor's
    /// ceiling: how far past it, px, the ceiling is reached (the row's
    /// deviation includes this over `sqrt(3)`).
    pub clamp_clipped_px: Option<f64>,
    /// The silhouette's sides as located above the clamp plane.
    pub side_points_px: Vec<[f64; 2]>,
}

/// The `q`-quantile of a sample (sorted in place).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = ((v.len() - 1) as f64 * q).round() as usize;
    let (_, m, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    *m
}

/// The standard deviation of a sample read robustly: 1.4826 times the
/// median absolute deviation from the median (a normal sample's standard
/// deviation; the sample is reordered in place).
fn robust_sd(v: &mut [f64]) -> f64 {
    let med = quantile(v, 0.5);
    let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    1.4826 * quantile(&mut dev, 0.5)
}

/// Every `stride`-th value of an image-sized map.
fn sample(v: &[f32], stride: usize) -> Vec<f64> {
    v.iter()
        .step_by(stride.max(1))
        .map(|&x| f64::from(x))
        .collect()
}

/// The largest roll of the camera about its view axis, degrees, that init takes. The heights,
/// measured along the photo's columns, and the scale, from the silhouette's width along its rows,
/// are then a few hundredths of a per cent off; beyond about 1.5 degrees the apex moves sideways
/// by more than the tracker's guard on the axis allows as the bubble grows.
pub const MAX_ROLL_DEG: f64 = 1.0;

/// Template size for a bubble of free radius `a_px` in a photo `width` px
/// wide: 30 % of `a` wide, at most a tenth of the width, at least 32 px,
/// even, half as tall.
pub fn template_size_for(a_px: f64, width: usize) -> (usize, usize) {
    let tw = (0.3 * a_px).min(0.1 * width as f64).max(32.0);
    let tw = ((tw / 2.0).round() as usize) * 2;
    (tw, tw / 2)
}

/// Finds the set-up in a sequence of photos (in the order they were
/// taken: the bubble grows from the first to the last), `radius_m` the
/// specimen's free radius. See the module documentation.
pub fn find(photos: &[PathBuf], radius_m: f64, given: Given) -> Result<Found, TrackError> {
    find_in(&Frames::Photos(photos.to_vec()), radius_m, given)
}

/// [`find`] on photos or a video's frames.
pub fn find_in(frames: &Frames, radius_m: f64, given: Given) -> Result<Found, TrackError> {
    let n = frames.len();
    if n < 2 {
        return Err(TrackError::NotFound {
            what: "the bubble".into(),
            detail: format!(
                "{n} photo given: the bubble is found by what changes between the first and the last photo, so at least two are needed"
            ),
            keys: "roi_px, template_rect_px, clamp_row_px and metres_per_pixel",
            clamp_plane: false,
        });
    }
    let (first_path, last_path) = (frames.path(0), frames.path(n - 1));
    // Edges are located in light: every photo is read through the camera's
    // tone curve.
    let tone = super::image::Tone::of(given.response);
    let (first, last) = rayon::join(
        || frames.gray(0).map(|g| g.with_tone(tone)),
        || frames.gray(n - 1).map(|g| g.with_tone(tone)),
    );
    let (first, last) = (first?, last?);
    if (first.width, first.height) != (last.width, last.height) {
        return Err(TrackError::MixedSizes {
            path: last_path.to_path_buf(),
            width: last.width,
            height: last.height,
            reference: first_path.to_path_buf(),
            ref_width: first.width,
            ref_height: first.height,
        });
    }
    let (w, h) = (first.width, first.height);
    let (pf, pl) = (Plane::of(&first), Plane::of(&last));
    let sw = swept(&pf, &pl, [first_path, last_path])?;

    // Step 2: axis, apexes.
    let mids: Vec<f64> = sw
        .rows
        .iter()
        .flatten()
        .map(|&(a, b)| 0.5 * (a + b) as f64)
        .collect();
    let mut m = mids.clone();
    let x0 = quantile(&mut m, 0.5);
    let mut dev: Vec<f64> = mids.iter().map(|v| (v - x0).abs()).collect();
    let x0_std = 1.2533 * 1.4826 * quantile(&mut dev, 0.5).max(0.5) / (mids.len() as f64).sqrt();
    let (top, bottom) = {
        let ys: Vec<usize> = sw
            .rows
            .iter()
            .enumerate()
            .filter(|r| r.1.is_some())
            .map(|r| r.0)
            .collect();
        (ys[0], ys[ys.len() - 1])
    };
    let (left, right) = sw
        .rows
        .iter()
        .flatten()
        .fold((usize::MAX, 0), |(l, r), &(a, b)| (l.min(a), r.max(b)));
    let cut = |side: &str| TrackError::NotFound {
        what: "the whole bubble".into(),
        detail: format!(
            "the bubble is cut by the photo's {side} border in {} (it grows out of the picture)",
            last_path.display()
        ),
        keys: "roi_px and template_rect_px (or take the photos with the whole bubble in the frame)",
        clamp_plane: false,
    };
    if top == 0 {
        return Err(cut("top"));
    }
    if left == 0 {
        return Err(cut("left"));
    }
    if right + 1 >= w {
        return Err(cut("right"));
    }
    let (x0, x0_std) = refine_axis(&pl, &sw, x0, top, bottom).unwrap_or((x0, x0_std));
    // The swept band thins out towards the rim: the last photo's sides are
    // followed down from its middle to where they meet the clamp.
    let r_s = top + (bottom - top) * 3 / 5;
    let ends: Vec<(f64, f64)> = match sw.rows[r_s] {
        Some((l, r)) => [(l, -1.0), (r, 1.0)]
            .into_iter()
            .filter_map(|(x, dir)| follow_side(&pl, x as f64, r_s, dir))
            .collect(),
        None => Vec::new(),
    };
    let region_a = (x0 - left as f64).max(right as f64 - x0);
    let (a0, base) = if ends.len() == 2 {
        let a = ends.iter().map(|e| (e.0 - x0).abs()).sum::<f64>() / 2.0;
        let b = ends.iter().map(|e| e.1).fold(0.0, f64::max);
        (a.max(region_a), b.max(bottom as f64))
    } else {
        (region_a, bottom as f64)
    };
    let xi = x0.round() as usize;
    let band: Vec<usize> = (xi.saturating_sub(3)..=(xi + 3).min(w - 1)).collect();
    let on_axis: Vec<(usize, usize)> = band.iter().filter_map(|&c| sw.cols[c]).collect();
    if on_axis.is_empty() {
        return Err(TrackError::NotFound {
            what: "the bubble's apex".into(),
            detail: format!(
                "the region that changes between the first and last photo is not symmetric about a vertical axis (its middle, column {x0:.0}, does not change): is the camera upright?"
            ),
            keys: "roi_px, template_rect_px and apex_in_template_px",
            clamp_plane: false,
        });
    }
    let y_top = on_axis.iter().map(|c| c.0).min().unwrap_or(0);
    // The band's first run down the axis (a moved highlight leaves a patch below).
    let y_bot = {
        let mut y = y_top;
        while y + 1 < h && band.iter().any(|&c| sw.joined[(y + 1) * w + c]) {
            y += 1;
        }
        let cut = (0.006 * w.max(h) as f64).max(3.0).round() as usize;
        let inner = band
            .iter()
            .filter_map(|&c| sw.cols[c])
            .map(|c| c.1)
            .filter(|&b| b <= y)
            .max();
        inner.unwrap_or(y.saturating_sub(cut))
    };

    // Every photo's profile on the axis.
    let bw = band.len();
    // Decoded once each: the profile on the axis, and the rows where the
    // clamp is (static: their mean over every photo has less noise).
    let band_rows = {
        let reach = (0.04 * a0).max(8.0);
        let lo = (bottom as f64 - 0.3 * a0 - 16.0).floor().max(0.0) as usize;
        let hi = ((base + 0.1 * a0 + 2.0 * reach + 30.0).ceil() as usize).min(h);
        lo..hi
    };
    let per_photo: Vec<(Vec<f64>, Vec<f32>)> = frames.map(|i, d| {
        let d = d.with_tone(tone);
        if (d.width, d.height) != (w, h) {
            return Err(TrackError::MixedSizes {
                path: frames.path(i).to_path_buf(),
                width: d.width,
                height: d.height,
                reference: first_path.to_path_buf(),
                ref_width: w,
                ref_height: h,
            });
        }
        let profile = (0..h)
            .map(|y| band.iter().map(|&x| d.light(x, y)).sum::<f64>() / bw as f64)
            .collect();
        let rows = d.data[band_rows.start * w..band_rows.end * w]
            .iter()
            .map(|&v| tone.light(v) as f32)
            .collect();
        Ok((profile, rows))
    })?;
    let n_photos = per_photo.len() as f32;
    let mut clamp_rows = vec![0f32; band_rows.len() * w];
    for (_, rows) in &per_photo {
        for (a, v) in clamp_rows.iter_mut().zip(rows) {
            *a += v / n_photos;
        }
    }
    let profiles: Vec<Vec<f64>> = per_photo.into_iter().map(|p| p.0).collect();
    let bg_rows = 0..y_top.saturating_sub(5).max(1);
    let level = |p: &[f64]| {
        let mut v: Vec<f64> = p[bg_rows.clone()].to_vec();
        quantile(&mut v, 0.5).max(1.0)
    };
    let (p_first, p_last) = (&profiles[0], &profiles[profiles.len() - 1]);
    let l_first = level(p_first);
    let norm = |p: &[f64]| -> Vec<f64> {
        let g = l_first / level(p);
        p.iter().map(|v| v * g).collect()
    };
    let (nf, nl) = (norm(p_first), norm(p_last));
    shrinking_check(&nf, &nl, &bg_rows, y_top..=y_bot, [first_path, last_path])?;
    let r0 = y_top.saturating_sub(3);
    let r1 = (y_bot + 3).min(h - 1);
    let dens: Vec<f64> = (r0..=r1).map(|r| nl[r] - nf[r]).collect();
    let dmax = dens.iter().map(|d| d.abs()).fold(0.0, f64::max);
    let apexes_px: Vec<[f64; 2]> = profiles
        .iter()
        .map(|p| {
            let n = norm(p);
            let t: Vec<Option<f64>> = (r0..=r1)
                .zip(&dens)
                .map(|(r, &d)| (d.abs() > 0.35 * dmax).then(|| (n[r] - nf[r]) / d))
                .collect();
            let valid: Vec<(usize, f64)> = t
                .iter()
                .enumerate()
                .filter_map(|(i, v)| v.map(|v| (r0 + i, v)))
                .collect();
            let y = valid
                .windows(2)
                .find(|p| p[0].1 > 0.5 && p[1].1 > 0.5)
                .map(|p| p[0].0 as f64 + 0.5 - p[0].1.clamp(0.0, 1.0))
                .or_else(|| top_below_band(&n, bg_rows.clone(), y_bot, base as usize, sw.sign))
                .unwrap_or(y_bot as f64 + 0.5);
            [x0, y]
        })
        .collect();

    // Step 3: the clamp, on the mean of every photo in its rows (static
    // there), of the first and the last elsewhere.
    let mut mean = Plane {
        w,
        h,
        v: pf.v.iter().zip(&pl.v).map(|(a, b)| 0.5 * (a + b)).collect(),
    };
    mean.v[band_rows.start * w..band_rows.end * w].copy_from_slice(&clamp_rows);
    let y_low = bottom as f64;
    let hint = clamp::Hint {
        sin_e: given.elevation_deg.map(|e| e.to_radians().sin()),
        distance_known: given.camera_distance_m.is_some()
            || (given.lens.is_some() && given.distance_from_focal),
        at_ceiling: tone.light(254),
        tone,
    };
    let principal_row = given.lens.as_ref().map_or((h as f64 - 1.0) / 2.0, |l| l.cy);
    // Steps 3 and 4 read the ring and the opening about the axis `x0`: the
    // ring's ends are taken when they are mirrored about it, and the
    // pinhole is placed on it. The swept band's `x0` leans towards the
    // side a light from one side brightens, which the sides found in step
    // 4 do not; when their axis lies more than a pixel off `x0`, steps 3
    // and 4 are done again about it (a light dome lit from the left on a
    // dark wall: `x0` 25 px off, both ends found but not mirrored about
    // it, the ring placed from its far side alone 4.5 px low).
    let steps = about::Steps34 {
        mean: &mean,
        last: &pl,
        a0,
        rows: [y_low, base],
        hint,
        given,
        principal_row,
        radius_m,
        top: apexes_px.last().map_or(f64::NAN, |p| p[1]),
        tone,
        x0_std,
    };
    let mut r = steps.read(x0)?;
    if (r.axis_x_px.value - x0).abs() > 1.0 {
        r = steps.read(r.axis_x_px.value)?;
    }
    // The apex track on that axis: the swept band's midpoints, which gave step 2's
    // `x0`, lean towards the side that a light from one side brightens (its
    // difference crosses the threshold further out there): on the init
    // sweep a light dome lit from the right had its template 14 px left of
    // the axis, and the tracker found no edge on the first photo.
    let apexes_px: Vec<[f64; 2]> = apexes_px
        .iter()
        .map(|p| [r.axis_x_px.value, p[1]])
        .collect();

    // Step 5: template and region.
    let a_px = r
        .radius_px
        .map_or(radius_m / r.metres_per_pixel.value, |a| a.value);
    let (tw, th) = template_size_for(a_px, w);
    // The template stays clear of the clamp (its top face, from a raised
    // camera): on the first photo when the apex is at least 4 px above it
    // (the template is then raised so that its bottom stays clear, the apex
    // below its middle), else on the first photo whose apex is.
    let face = r.clamp.half_width_px.map_or(0.0, |a| a * r.sin_e);
    let clear = r.clamp.row.value - face - 2.0;
    let settings = EdgeSettings {
        half_span_px: tw / 2,
        half_window_px: 3,
    };
    // The apex row the edge fit finds within 3 px of photo `k`'s guess,
    // or of a row `reach` steps above or below it ([`seed_rows`]), the
    // nearest first.
    let step = settings.half_window_px as f64 + 1.0;
    let confirmed = |k: usize, reach: i32| -> Result<Option<[f64; 2]>, TrackError> {
        let own;
        let img = match k {
            0 => &first,
            k if k == n - 1 => &last,
            k => {
                own = frames.gray(k)?.with_tone(tone);
                &own
            }
        };
        let [x, y] = apexes_px[k];
        let mut cols = Columns::new(img, 3);
        Ok(seed_rows(y, step, reach).find_map(|g| {
            edge_fit_in(&mut cols, x, g, 0.0, settings)
                .filter(|f| (f.y - g).abs() < 3.0)
                .filter(|f| k != 0 || background_above(img, x, f.y, apexes_px[n - 1][1], tw))
                .map(|f| [x, f.y])
        }))
    };
    let mut reference_frame = apexes_px
        .iter()
        .position(|p| p[1] <= clear - 4.0)
        .unwrap_or(apexes_px.len() - 1);
    let mut reference_apex_px = confirmed(reference_frame, 0)?;
    // The first photo's guess is the swept band's lowest row on the axis
    // (nothing crosses there: step 2 of the module's doc), its top only where
    // the dome's light does not change as it grows. A glossy dome reflects
    // the wall near its outline, and that band moves out with it: on a
    // path-traced glossy light dome before a dark wall (800x600, 0.45 m)
    // the band reached 19 px into the first photo's dome, and the
    // template cut there had the tracker find no top on that photo. Where
    // no edge lies at that row, the template is cut from the next photo,
    // whose guess is a crossing. The same reflection moves that crossing
    // into the dome (6 px on that photo), so its edge is searched out to
    // half the template's height from it, as the tracker does.
    if reference_apex_px.is_none()
        && reference_frame == 0
        && n > 1
        && let Some(p) = confirmed(1, (0.5 * th as f64 / step).floor() as i32)?
    {
        reference_frame = 1;
        reference_apex_px = Some(p);
    }
    let reference_apex_px = reference_apex_px.unwrap_or(apexes_px[reference_frame]);
    let mut apexes = apexes_px.clone();
    apexes[reference_frame] = reference_apex_px;
    let mut layout = Layout::around(&apexes, reference_frame, (tw, th), (w, h));
    let ty = layout.template_rect_px[1];
    let lowest = (clear - th as f64).floor() as i64;
    if ty > lowest {
        let shift = ty - lowest;
        layout.template_rect_px[1] -= shift;
        layout.apex_in_template_px[1] += shift as f64;
    }

    let outlines_px = [
        sw.cols
            .iter()
            .enumerate()
            .filter_map(|(x, c)| c.map(|(_, b)| [x as f64, b as f64 + 0.5]))
            .filter(|p| p[1] < y_low - 1.0)
            .collect(),
        sw.cols
            .iter()
            .enumerate()
            .filter_map(|(x, c)| c.map(|(t, _)| [x as f64, t as f64 - 0.5]))
            .collect(),
    ];
    // Through the lens (when calibrated): the axis and the scale in the
    // undistorted image (the clamp row is already).
    let (mut axis_x_px, mut clamp_row_px, mut radius_px, mut metres_per_pixel) =
        (r.axis_x_px, r.clamp.row, r.radius_px, r.metres_per_pixel);
    // The ring's edge is located by the same centroid as the apex: the
    // edge fit's bias that no residual shows is added ([`CLAMP_FLOOR_PX`])
    // where the edge is an ellipse's side, from a camera the photos show
    // above the clamp plane.
    if given.clamp_row_px.is_none() && seen_raised(r.elevation_deg) {
        clamp_row_px.std = clamp_row_px.std.hypot(CLAMP_FLOOR_PX);
    }
    // a clipped face: the edge anywhere within `t` of where it was located
    if let Some(t) = r.clamp.clipped_px {
        clamp_row_px.std = clamp_row_px.std.hypot(t / 3f64.sqrt());
    }
    let (ax, a) = super::lens::undistort_opening(
        given.lens.as_ref(),
        axis_x_px.value,
        clamp_row_px.value,
        radius_px.map(|a| a.value),
    );
    axis_x_px.value = ax;
    if let (Some(r), Some(a)) = (radius_px.as_mut(), a) {
        let k = a / r.value;
        (r.value, r.std) = (a, r.std * k);
        (metres_per_pixel.value, metres_per_pixel.std) =
            (metres_per_pixel.value / k, metres_per_pixel.std / k);
    }
    Ok(Found {
        width: w,
        height: h,
        response: given.response,
        lens: given.lens,
        camera_distance_m: r.camera_distance_m,
        camera_distance_from_focal: r.focal_px.is_some(),
        axis_x_px,
        clamp_row_px,
        clamp_row_given: given.clamp_row_px.is_some(),
        elevation_deg: r.elevation_deg,
        roll_deg: r.roll_deg,
        clamp_half_width_px: r.clamp.half_width_px,
        radius_px,
        metres_per_pixel,
        scale_from: r.scale_from,
        scale_per_clamp_row: r.scale_per_clamp_row,
        apexes_px: apexes,
        reference_frame,
        layout,
        reference_apex_px,
        outlines_px,
        clamp_points_px: r.clamp.points,
        clamp_clipped_px: r.clamp.clipped_px,
        side_points_px: r.side_points_px,
    })
}

/// Whether the edge at row `e` of `img` (about column `x`, over half the
/// template's width `tw`) has the background above it, as the top of a
/// bubble has: the rows just above it look like those above the largest
/// dome's top (row `y_top`, the swept band's top, where every photo shows
/// the background), within half the edge's step (the midpoint between the
/// two sides' levels). On a path-traced glossy light dome at 1280x960
/// seen 4.5 degrees from above, the first photo's dome brightened slowly
/// from its top (80 grey levels over 50 rows) and the band's lowest row
/// lay 38 px inside it, where the edge fit found that ramp: the rows above
/// it were the dome's (on the axis, about 130 grey levels over the wall,
/// against a step of about 15). Half the step is the midpoint between the
/// two sides' levels: nearer the wall than the dome. The rows read start
/// one beyond the edge window's half-height (3) from the edge, where its
/// blurred step has ended; their count (6 by the edge, 8 above the top)
/// and the columns (half the template's width) are chosen, not derived.
/// On the init sweep (250 clean and 100 dirty sequences) the rule turned
/// down 4 edges found on a first photo and left its table the same to
/// every printed digit.
fn background_above(img: &Gray, x: f64, e: f64, y_top: f64, tw: usize) -> bool {
    let q = (tw / 4).max(2) as i64;
    let (w, h) = (img.width as i64, img.height as i64);
    let level = |r0: f64, r1: f64| -> Option<f64> {
        let (r0, r1) = (r0.floor() as i64, r1.ceil() as i64);
        if r0 < 0 || r1 >= h || r1 <= r0 {
            return None;
        }
        let mut means: Vec<f64> = (x as i64 - q..=x as i64 + q)
            .filter(|c| (0..w).contains(c))
            .map(|c| {
                (r0..r1)
                    .map(|r| img.light(c as usize, r as usize))
                    .sum::<f64>()
                    / (r1 - r0) as f64
            })
            .collect();
        if means.is_empty() {
            return None;
        }
        means.sort_by(f64::total_cmp);
        Some(means[means.len() / 2])
    };
    match (
        level(y_top - 12.0, y_top - 4.0),
        level(e - 10.0, e - 4.0),
        level(e + 4.0, e + 10.0),
    ) {
        (Some(wall), Some(above), Some(below)) => {
            (above - wall).abs() <= 0.5 * (below - above).abs()
        }
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clamp_floor_is_for_a_camera_the_photos_show_raised() {
        let e = |value, std| Some(Estimate { value, std });
        // level: said so, fitted within its noise, or a straight edge
        assert!(!seen_raised(e(0.0, 0.0)));
        assert!(!seen_raised(e(0.05, 0.04)));
        assert!(!seen_raised(e(-0.07, 0.04)));
        assert!(!seen_raised(None));
        // raised: given, or fitted beyond 2 of its deviations
        assert!(seen_raised(e(3.0, 0.0)));
        assert!(seen_raised(e(0.3, 0.05)));
    }
}
