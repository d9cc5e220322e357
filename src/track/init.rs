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
//!    clamp plane. Its two sides are located row by row (sub-pixel) in the
//!    last photo a little above the plane, and a circle `w^2 + u^2 = 2 U u
//!    + k` (w the half-width, u the height above the plane) is fitted to
//!    them: near the rim the meridian is close to its osculating circle.
//!    From a raised camera the outline of a sphere is a circle of its
//!    radius centred on the projected centre `U = (h - R) cos e`, so
//!    `a^2 = k - U^2 tan^2 e` (level: `a^2 = k`, the circle's width at
//!    `u = 0`). The scale is `radius_m / a_px`.
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
use super::matcher::{Columns, EdgeSettings, edge_fit_in, lag1_inflation, profile_edge};
use super::synth::Layout;

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
    /// The camera's tone curve (edges are located in light).
    pub response: crate::camera::Response,
    /// The lens (`bulge calibrate`): the clamp row, the axis and the scale
    /// are given in the undistorted image (the region and the template stay
    /// the photo's), and the experiment file gets the lens.
    pub lens: Option<super::lens::Lens>,
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
    /// The bubble's axis, image column.
    pub axis_x_px: Estimate,
    /// The clamp plane (the clamp ring's centre from a raised camera), image row.
    pub clamp_row_px: Estimate,
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
    /// The silhouette's sides as located above the clamp plane.
    pub side_points_px: Vec<[f64; 2]>,
}

/// A grayscale image as floats.
struct Plane {
    w: usize,
    h: usize,
    v: Vec<f32>,
}

impl Plane {
    fn of(g: &Gray) -> Plane {
        Plane {
            w: g.width,
            h: g.height,
            v: g.data.iter().map(|&b| g.tone.light(b) as f32).collect(),
        }
    }

    #[inline]
    fn at(&self, x: usize, y: usize) -> f64 {
        f64::from(self.v[y * self.w + x])
    }

    /// The 3x3 mean (edges replicated).
    fn box3(&self) -> Plane {
        let (w, h) = (self.w, self.h);
        let mut tmp = vec![0f32; w * h];
        for y in 0..h {
            let r = &self.v[y * w..(y + 1) * w];
            for x in 0..w {
                let (a, b) = (x.saturating_sub(1), (x + 1).min(w - 1));
                tmp[y * w + x] = (r[a] + r[x] + r[b]) / 3.0;
            }
        }
        let mut out = vec![0f32; w * h];
        for y in 0..h {
            let (a, b) = (y.saturating_sub(1), (y + 1).min(h - 1));
            for x in 0..w {
                out[y * w + x] = (tmp[a * w + x] + tmp[y * w + x] + tmp[b * w + x]) / 3.0;
            }
        }
        Plane { w, h, v: out }
    }
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

/// Every `stride`-th value of an image-sized map.
fn sample(v: &[f32], stride: usize) -> Vec<f64> {
    v.iter()
        .step_by(stride.max(1))
        .map(|&x| f64::from(x))
        .collect()
}

/// The region the top of the bubble swept between two photos.
struct Swept {
    /// The band with its thin gaps closed, row-major.
    joined: Vec<bool>,
    /// Per row: the leftmost and rightmost column of the region.
    rows: Vec<Option<(usize, usize)>>,
    /// Per column: the top and bottom row of the region.
    cols: Vec<Option<(usize, usize)>>,
    /// Threshold and the difference's robust noise, grey levels.
    noise: f64,
}

/// The largest 8-connected region of `mask` (row-major `w x h`).
fn largest_region(mask: &[bool], w: usize, h: usize) -> Vec<usize> {
    let mut seen = vec![false; mask.len()];
    let mut best: Vec<usize> = Vec::new();
    let mut stack = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] || seen[start] {
            continue;
        }
        let mut region = Vec::new();
        seen[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            region.push(i);
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if mask[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        if region.len() > best.len() {
            best = region;
        }
    }
    best
}

/// The mask dilated by a square of half-side `r` (two running sums).
fn dilate(mask: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    let mut rows = vec![false; w * h];
    let mut sums = vec![0u32; w.max(h) + 1];
    for y in 0..h {
        for x in 0..w {
            sums[x + 1] = sums[x] + u32::from(mask[y * w + x]);
        }
        for x in 0..w {
            let (a, b) = (x.saturating_sub(r), (x + r + 1).min(w));
            rows[y * w + x] = sums[b] > sums[a];
        }
    }
    let mut out = vec![false; w * h];
    for x in 0..w {
        for y in 0..h {
            sums[y + 1] = sums[y] + u32::from(rows[y * w + x]);
        }
        for y in 0..h {
            let (a, b) = (y.saturating_sub(r), (y + r + 1).min(h));
            out[y * w + x] = sums[b] > sums[a];
        }
    }
    out
}

/// Step 1: what moved between the first and the last photo.
fn swept(first: &Plane, last: &Plane, names: [&Path; 2]) -> Result<Swept, TrackError> {
    let (w, h) = (first.w, first.h);
    let (f, l) = (first.box3(), last.box3());
    let stride = (w * h / 200_000).max(1);
    let mut ratios: Vec<f64> =
        f.v.iter()
            .zip(&l.v)
            .step_by(stride)
            .filter(|(a, _)| **a > 10.0)
            .map(|(a, b)| f64::from(*b / *a))
            .collect();
    let gain = quantile(&mut ratios, 0.5) as f32;
    let d: Vec<f32> = l.v.iter().zip(&f.v).map(|(b, a)| b - gain * a).collect();
    let mut s = sample(&d, stride);
    let med = quantile(&mut s, 0.5);
    let mut dev: Vec<f64> = s.iter().map(|v| (v - med).abs()).collect();
    let sigma = 1.4826 * quantile(&mut dev, 0.5);
    let mut mags: Vec<f64> = s.iter().map(|v| v.abs()).collect();
    let contrast = quantile(&mut mags, 0.995);
    let thr = (6.0 * sigma).max(0.35 * contrast).max(3.0);
    let sum: f64 = d
        .iter()
        .filter(|v| f64::from(v.abs()) > thr)
        .map(|&v| f64::from(v))
        .sum();
    let sign = sum.signum() as f32;
    let mask: Vec<bool> = d.iter().map(|&v| f64::from(v * sign) > thr).collect();
    // A cable or a shelf edge in front of the band's background cuts it
    // into pieces: the pieces a thin line apart are joined (the regions of
    // the mask dilated by a few px), and the band is the mask's pixels in
    // the largest of them.
    let reach = (0.006 * w.max(h) as f64).max(3.0).round() as usize;
    let joined = largest_region(&dilate(&mask, w, h, reach), w, h);
    let mut in_joined = vec![false; w * h];
    for &i in &joined {
        in_joined[i] = true;
    }
    let region: Vec<usize> = joined.iter().copied().filter(|&i| mask[i]).collect();
    let min_area = ((w * h) as f64 * 2e-4).max(30.0) as usize;
    if sum == 0.0 || region.len() < min_area {
        return Err(TrackError::NotFound {
            what: "the bubble".into(),
            detail: format!(
                "the first photo ({}) and the last ({}) do not differ beyond their noise ({:.1} grey levels) over more than {} px: the bubble does not grow in these photos",
                names[0].display(),
                names[1].display(),
                sigma,
                region.len()
            ),
            keys: "roi_px, template_rect_px, apex_in_template_px, clamp_row_px and metres_per_pixel",
        });
    }
    let mut rows = vec![None; h];
    let mut cols = vec![None; w];
    for &i in &region {
        let (x, y) = (i % w, i / w);
        let r: &mut Option<(usize, usize)> = &mut rows[y];
        *r = Some(r.map_or((x, x), |(a, b)| (a.min(x), b.max(x))));
        let c: &mut Option<(usize, usize)> = &mut cols[x];
        *c = Some(c.map_or((y, y), |(a, b)| (a.min(y), b.max(y))));
    }
    Ok(Swept {
        joined: in_joined,
        rows,
        cols,
        noise: sigma,
    })
}

/// A linear least-squares fit: coefficients, covariance, residuals.
type Fit = (Vec<f64>, Vec<Vec<f64>>, Vec<f64>);

/// A straight-line (or any linear) least-squares fit: the coefficients,
/// their covariance scaled by the residual variance, and the residuals.
fn lstsq(rows: &[Vec<f64>], y: &[f64]) -> Option<Fit> {
    let p = rows.first()?.len();
    let n = rows.len();
    if n <= p {
        return None;
    }
    let x = nalgebra::DMatrix::from_fn(n, p, |i, j| rows[i][j]);
    let yv = nalgebra::DVector::from_column_slice(y);
    let xtx = x.transpose() * &x;
    let inv = xtx.try_inverse()?;
    let coef = &inv * x.transpose() * &yv;
    let res: Vec<f64> = (0..n)
        .map(|i| y[i] - (0..p).map(|j| rows[i][j] * coef[j]).sum::<f64>())
        .collect();
    let rss: f64 = res.iter().map(|r| r * r).sum();
    let s2 = rss / (n - p) as f64;
    let cov = (0..p)
        .map(|i| (0..p).map(|j| inv[(i, j)] * s2).collect())
        .collect();
    Some((coef.iter().copied().collect(), cov, res))
}

/// [`lstsq`] leaving out, in up to four rounds, the points whose residual
/// exceeds 3.5 robust standard deviations (and `floor`); returns the fit
/// and which points were kept.
fn robust_lstsq(rows: &[Vec<f64>], y: &[f64], floor: f64) -> Option<(Fit, Vec<bool>)> {
    let mut keep = vec![true; y.len()];
    let mut fit = None;
    for _ in 0..4 {
        let (r, v): (Vec<Vec<f64>>, Vec<f64>) = rows
            .iter()
            .zip(y)
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|((r, v), _)| (r.clone(), *v))
            .unzip();
        let f = lstsq(&r, &v)?;
        let all: Vec<f64> = rows
            .iter()
            .zip(y)
            .map(|(r, v)| v - r.iter().zip(&f.0).map(|(a, b)| a * b).sum::<f64>())
            .collect();
        let mut abs: Vec<f64> = f.2.iter().map(|r| r.abs()).collect();
        let cut = (3.5 * 1.4826 * quantile(&mut abs, 0.5)).max(floor);
        let next: Vec<bool> = all.iter().map(|r| r.abs() <= cut).collect();
        fit = Some(f);
        if next == keep {
            break;
        }
        keep = next;
    }
    fit.map(|f| (f, keep))
}

/// The strongest step of a profile inside `lo..hi` (as the difference
/// `p(j + 1) - p(j)` smoothed over two samples each side, at `j + 1/2`):
/// its position and value.
fn strongest_step(p: &dyn Fn(i64) -> f64, lo: i64, hi: i64) -> Option<(i64, f64)> {
    (lo..hi)
        .map(|j| (j, 0.5 * (p(j + 2) + p(j + 1) - p(j) - p(j - 1))))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
}

/// The axis from the last photo's silhouette: the median midpoint of its
/// two sides, located to sub-pixel precision in the rows of the middle of
/// the swept band (where a side is steep), with its standard error.
fn refine_axis(last: &Plane, sw: &Swept, x0: f64, top: usize, bottom: usize) -> Option<(f64, f64)> {
    let w = last.w as i64;
    let span = (bottom - top) as f64;
    let rows = (top as f64 + 0.2 * span) as usize..=(top as f64 + 0.6 * span) as usize;
    let mut mids = Vec::new();
    for r in rows {
        let Some((l, rt)) = sw.rows[r] else { continue };
        let p = |x: i64| last.at(x.clamp(0, w - 1) as usize, r);
        let edge = |start: usize| profile_edge(p, w, start as f64, 3.0).map(|e| e.0);
        if let (Some(a), Some(b)) = (edge(l), edge(rt))
            && (a - l as f64).abs() < 3.0
            && (b - rt as f64).abs() < 3.0
        {
            mids.push(0.5 * (a + b));
        }
    }
    if mids.len() < 5 {
        return None;
    }
    let mut m = mids.clone();
    let med = quantile(&mut m, 0.5);
    if (med - x0).abs() > 3.0 {
        return None;
    }
    let mut dev: Vec<f64> = mids.iter().map(|v| (v - med).abs()).collect();
    let sd = 1.4826 * quantile(&mut dev, 0.5);
    Some((med, 1.2533 * sd.max(0.02) / (mids.len() as f64).sqrt()))
}

/// Follows a side of the silhouette from row `r0` (column `x`) down, row
/// by row, while it stays a strong step moving outward (`dir` -1 left, +1
/// right) or straight down, over gaps of up to 6 rows (a cable crossing
/// it); returns where it ends: about the clamp plane and the opening's edge.
fn follow_side(img: &Plane, x: f64, r0: usize, dir: f64) -> Option<(f64, f64)> {
    let (w, h) = (img.w as i64, img.h);
    let mut x = x;
    let mut slope = 0.0;
    let mut last = None;
    let mut steps: Vec<f64> = Vec::new();
    let mut gap = 0;
    for r in r0..h.saturating_sub(8) {
        let p = |c: i64| img.at(c.clamp(0, w - 1) as usize, r);
        let pred = x + slope;
        let found = profile_edge(p, w, pred, 3.0).filter(|(e, st)| {
            let reference = if steps.len() >= 3 {
                let mut v = steps.clone();
                quantile(&mut v, 0.5)
            } else {
                st.abs()
            };
            (e - pred).abs() < 2.5 && (e - x) * dir > -1.0 && st.abs() > 0.5 * reference
        });
        // Beside the side, a step down the column that stays (not a thin
        // line crossing it) is the clamp's top edge: the side ends there.
        if let Some((e, _)) = found
            && steps.len() >= 3
        {
            let q = (e + dir * 5.0).round() as i64;
            let col = |y: usize| img.at(q.clamp(0, w - 1) as usize, y.min(h - 1));
            let reach = 12usize;
            let below = (r + 3..r + 3 + reach).map(col).sum::<f64>() / reach as f64;
            let above = (r.saturating_sub(4)..r.saturating_sub(1))
                .map(col)
                .sum::<f64>()
                / 3.0;
            let mut v = steps.clone();
            if (below - above).abs() > 0.5 * quantile(&mut v, 0.5) {
                last = Some((e, r as f64));
                break;
            }
        }
        match found {
            Some((e, st)) => {
                if steps.len() < 40 {
                    steps.push(st.abs());
                }
                slope = 0.7 * slope + 0.3 * (e - x);
                x = e;
                last = Some((e, r as f64));
                gap = 0;
            }
            None => {
                gap += 1;
                if gap > 6 {
                    break;
                }
                x = pred;
            }
        }
    }
    last
}

/// The clamp's top edge beside the bubble (step 3).
#[derive(Clone)]
struct Clamp {
    row: Estimate,
    sin_e: Option<Estimate>,
    /// The slope of the clamp's top edge, rows per column (a rolled
    /// camera): the row at the axis is `row`.
    slope: Estimate,
    half_width_px: Option<f64>,
    points: Vec<[f64; 2]>,
}

fn find_clamp(
    img: &Plane,
    x0: f64,
    a0: f64,
    [y_low, base]: [f64; 2],
    noise: f64,
    given_sin_e: Option<f64>,
    lens: Option<&super::lens::Lens>,
) -> Result<Clamp, TrackError> {
    let (w, h) = (img.w as i64, img.h as i64);
    let lo_row = ((y_low - 0.3 * a0 - 4.0).floor() as i64).max(8);
    let hi_row = ((base.max(y_low) + 0.1 * a0 + 4.0).ceil() as i64).min(h - 12);
    let not_found = |detail: String| TrackError::NotFound {
        what: "the clamp plane".into(),
        detail,
        keys: "clamp_row_px",
    };
    if hi_row <= lo_row + 4 {
        return Err(not_found(format!(
            "the bubble's base (row {y_low:.0}) is at the photo's bottom border: the clamp is out of the picture"
        )));
    }
    let d_lo = (1.04 * a0 + 3.0).ceil() as i64;
    let d_hi = (1.6 * a0).floor() as i64;
    let min_step = (8.0f64).max(6.0 * noise);
    // One column: the lowest strong step of the polarity `sign` (or of the
    // strongest step's, when `None`) that is a step (the far side stays
    // different beyond a thin line's height), not a shelf edge or a cable;
    // and whether a second step almost as strong lies above it.
    let reach = (0.04 * a0).max(8.0) as i64;
    let column = |x: i64, sign: Option<f64>| -> Option<(f64, f64, bool)> {
        let xs = [x - 1, x, x + 1].map(|c| c as usize);
        let p = |j: i64| {
            let j = j.clamp(0, h - 1) as usize;
            xs.iter().map(|&c| img.at(c, j)).sum::<f64>() / 3.0
        };
        let mean = |a: i64, b: i64| (a..b).map(p).sum::<f64>() / (b - a) as f64;
        let steps: Vec<(i64, f64)> = (lo_row..hi_row)
            .map(|j| (j, 0.5 * (p(j + 2) + p(j + 1) - p(j) - p(j - 1))))
            .collect();
        let persistent = |r: i64, g: f64| {
            (mean(r + reach, r + 2 * reach) - mean(r - 2 * reach, r - reach)) * g.signum()
                >= 0.5 * g.abs()
        };
        let gmax = steps
            .iter()
            .filter(|s| sign.is_none_or(|g| s.1 * g > 0.0))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?
            .1;
        if gmax.abs() < min_step {
            return None;
        }
        let g = gmax.signum();
        let peaks: Vec<usize> = (1..steps.len().saturating_sub(1))
            .filter(|&i| {
                let v = steps[i].1 * g;
                v >= 0.5 * gmax.abs()
                    && v >= steps[i - 1].1 * g
                    && v >= steps[i + 1].1 * g
                    && persistent(steps[i].0, gmax)
            })
            .collect();
        let &lowest = peaks.last()?;
        let two = peaks
            .iter()
            .any(|&i| steps[lowest].0 - steps[i].0 > 4 && steps[i].1 * g >= 0.8 * gmax.abs());
        let (e, step) = profile_edge(p, h, steps[lowest].0 as f64 + 0.5, 3.0)?;
        Some((e, step, two))
    };
    let d_range = d_lo..=d_hi;
    let columns: Vec<(f64, i64)> = [-1i64, 1]
        .into_iter()
        .flat_map(|side| d_range.clone().map(move |d| (side, d)))
        .map(|(side, d)| ((side * d) as f64, x0.round() as i64 + side * d))
        .filter(|&(_, x)| x >= 2 && x < w - 2)
        .collect();
    let candidates = columns.len();
    // The clamp's polarity: that of the most columns' strongest step.
    let votes: f64 = columns
        .iter()
        .filter_map(|&(_, x)| column(x, None))
        .map(|c| c.1.signum())
        .sum();
    let sign = if votes >= 0.0 { 1.0 } else { -1.0 };
    let mut pts: Vec<(f64, f64, f64)> = Vec::new();
    let mut ambiguous = 0usize;
    for &(d, x) in &columns {
        if let Some((e, step, two)) = column(x, Some(sign)) {
            pts.push((d, e, step));
            ambiguous += usize::from(two);
        }
    }
    let needed = (candidates / 10).max(6);
    if pts.len() < needed {
        return Err(not_found(format!(
            "no horizontal edge beside the bubble's base (rows {lo_row}-{hi_row}, {} of {candidates} columns show one): the clamp is out of the picture or hidden",
            pts.len()
        )));
    }
    // The clamp's ends: from the rows just below its edge, the strongest
    // horizontal step on each side.
    let c_guess = {
        let mut rows: Vec<f64> = pts.iter().map(|p| p.1).collect();
        quantile(&mut rows, 0.9)
    };
    let r0 = (c_guess + 3.0).ceil() as i64;
    let r1 = (r0 + (0.04 * a0).clamp(4.0, 12.0) as i64).min(h - 1);
    let mut step_mags: Vec<f64> = pts.iter().map(|p| p.2.abs()).collect();
    let clamp_step = quantile(&mut step_mags, 0.5);
    let mut ends = [None, None];
    if r1 > r0 {
        let rows: Vec<usize> = (r0..=r1).map(|r| r as usize).collect();
        let q = |x: i64| {
            let x = x.clamp(0, w - 1) as usize;
            rows.iter().map(|&r| img.at(x, r)).sum::<f64>() / rows.len() as f64
        };
        for (k, side) in [-1i64, 1].into_iter().enumerate() {
            let a = x0 + side as f64 * 1.02 * a0;
            let b = x0 + side as f64 * 2.2 * a0;
            let (lo, hi) = if side < 0 { (b, a) } else { (a, b) };
            let (lo, hi) = ((lo.floor() as i64).max(8), (hi.ceil() as i64).min(w - 10));
            if hi <= lo + 2 {
                continue;
            }
            if let Some((j, g)) = strongest_step(&q, lo, hi)
                && g.abs() >= min_step.max(0.3 * clamp_step)
                && j > lo
                && j < hi - 1
                && let Some((e, _)) = profile_edge(q, w, j as f64 + 0.5, 3.0)
            {
                ends[k] = Some(e);
            }
        }
    }
    // Through the lens (when calibrated): the edge's points and the clamp's
    // ends in the undistorted image, as offsets from the axis's image (a
    // straight edge stays straight there; the photo's is bent by the lens).
    let (pts, ends) = super::lens::undistort_clamp(lens, x0, pts, ends, c_guess);
    // Both ends centred on the axis, or one end and the axis.
    let half = match ends {
        [Some(l), Some(r)] if ((l + r) / 2.0 - x0).abs() < 0.02 * a0 + 3.0 => Some((r - l) / 2.0),
        [Some(_), Some(_)] => None,
        [Some(e), None] | [None, Some(e)] => Some((e - x0).abs()),
        [None, None] => None,
    };
    let floor = 0.25;
    // Each fit has a slope across the photo: a camera rolled about its
    // view axis sees the clamp's edge tilted (the row at the axis stays
    // the clamp ring's centre's).
    let (row, sin_e, slope) = match (half, given_sin_e) {
        (Some(a_f), None) => {
            let used: Vec<&(f64, f64, f64)> =
                pts.iter().filter(|p| p.0.abs() < a_f - 1.5).collect();
            let x: Vec<Vec<f64>> = used
                .iter()
                .map(|p| vec![1.0, -(a_f * a_f - p.0 * p.0).max(0.0).sqrt(), p.0])
                .collect();
            let y: Vec<f64> = used.iter().map(|p| p.1).collect();
            let (((coef, cov, res), keep), slope) =
                with_slope(&x, &y, floor).ok_or_else(|| not_found("too few columns".into()))?;
            check_inliers(&keep, ambiguous)?;
            let infl = lag1_inflation(&res);
            let est = |i: usize| Estimate {
                value: coef[i],
                std: cov[i][i].sqrt() * infl,
            };
            (est(0), Some(est(1)), slope)
        }
        (_, Some(s)) if s != 0.0 => {
            let Some(a_f) = half else {
                return Err(not_found(
                    "the camera is raised (elevation given) but the clamp's ends are not in the picture, so its ellipse's centre cannot be placed".into(),
                ));
            };
            let used: Vec<&(f64, f64, f64)> =
                pts.iter().filter(|p| p.0.abs() < a_f - 1.5).collect();
            let x: Vec<Vec<f64>> = used.iter().map(|p| vec![1.0, p.0]).collect();
            let y: Vec<f64> = used
                .iter()
                .map(|p| p.1 + s * (a_f * a_f - p.0 * p.0).max(0.0).sqrt())
                .collect();
            let (((coef, cov, res), keep), slope) =
                with_slope(&x, &y, floor).ok_or_else(|| not_found("too few columns".into()))?;
            check_inliers(&keep, ambiguous)?;
            let row = Estimate {
                value: coef[0],
                std: cov[0][0].sqrt() * lag1_inflation(&res),
            };
            (row, None, slope)
        }
        _ => {
            // Level (or the ends unseen): a straight edge, checked for a
            // curvature that would betray a raised camera.
            let x: Vec<Vec<f64>> = pts.iter().map(|p| vec![1.0, p.0 * p.0, p.0]).collect();
            let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let (((coef, cov, _), keep), _) =
                with_slope(&x, &y, floor).ok_or_else(|| not_found("too few columns".into()))?;
            check_inliers(&keep, ambiguous)?;
            let dmax = pts.iter().map(|p| p.0.abs()).fold(0.0, f64::max);
            let bend = coef[1] * dmax * dmax;
            let bend_std = cov[1][1].sqrt() * dmax * dmax;
            if given_sin_e.is_none() && bend.abs() > 1.0 && bend.abs() > 4.0 * bend_std {
                return Err(TrackError::NotFound {
                    what: "the camera's elevation".into(),
                    detail: format!(
                        "the clamp's top edge bends by {bend:.1} px across the photo (a camera above the clamp plane sees the clamp as an ellipse), but the clamp's ends are not in the picture to place the ellipse"
                    ),
                    keys: "elevation_deg and clamp_row_px (the row of the clamp ring's centre)",
                });
            }
            let (kept_x, kept_y): (Vec<Vec<f64>>, Vec<f64>) = x
                .iter()
                .zip(&y)
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|((r, v), _)| (vec![r[0], r[2]], *v))
                .unzip();
            let (((c, ccov, cres), _), slope) = with_slope(&kept_x, &kept_y, f64::INFINITY)
                .ok_or_else(|| not_found("too few columns".into()))?;
            let row = Estimate {
                value: c[0],
                std: ccov[0][0].sqrt() * lag1_inflation(&cres),
            };
            (row, None, slope)
        }
    };
    Ok(Clamp {
        row,
        sin_e,
        slope,
        half_width_px: half,
        points: pts.iter().map(|p| [x0 + p.0, p.1]).collect(),
    })
}

/// [`robust_lstsq`] of the clamp's edge whose rows end with the column's
/// distance from the axis (the slope of a rolled camera's edge): the fit
/// with the slope when it is significant (beyond 4 standard deviations),
/// else the fit without it, and the slope measured either way.
fn with_slope(rows: &[Vec<f64>], y: &[f64], floor: f64) -> Option<((Fit, Vec<bool>), Estimate)> {
    let (fit, keep) = robust_lstsq(rows, y, floor)?;
    let k = rows.first()?.len() - 1;
    let slope = Estimate {
        value: fit.0[k],
        std: fit.1[k][k].sqrt() * lag1_inflation(&fit.2),
    };
    if slope.value.abs() > 4.0 * slope.std {
        return Some(((fit, keep), slope));
    }
    let level: Vec<Vec<f64>> = rows.iter().map(|r| r[..k].to_vec()).collect();
    Some((robust_lstsq(&level, y, floor)?, slope))
}

/// Refuses a clamp edge whose columns split between two edges.
fn check_inliers(keep: &[bool], ambiguous: usize) -> Result<(), TrackError> {
    let kept = keep.iter().filter(|k| **k).count();
    if (kept as f64) < 0.6 * keep.len() as f64 || ambiguous * 3 > keep.len() {
        return Err(TrackError::NotFound {
            what: "the clamp plane".into(),
            detail: format!(
                "two candidate edges beside the bubble's base: only {kept} of {} columns agree on one, {ambiguous} show two strong edges",
                keep.len()
            ),
            keys: "clamp_row_px",
        });
    }
    Ok(())
}

/// The largest roll of the camera about its view axis, degrees, that init
/// takes. The heights, measured along the photo's columns, and the scale,
/// from the silhouette's width along its rows, are then a few hundredths of
/// a per cent off; beyond about 1.5 degrees the apex moves sideways by more
/// than the tracker's guard on the axis allows as the bubble grows.
pub const MAX_ROLL_DEG: f64 = 1.0;

/// The relative standard deviation of the opening's width from the
/// meridian's shape near the rim (see [`find_radius`]).
const MODEL_REL: f64 = 8e-4;

/// Step 4: the silhouette's half-width at the clamp plane, px, with the
/// points located on its sides.
fn find_radius(
    last: &Plane,
    x0: f64,
    a0: f64,
    clamp: &Clamp,
    sin_e: f64,
) -> Result<(Estimate, Vec<[f64; 2]>), TrackError> {
    let (w, h) = (last.w as i64, last.h as i64);
    let c = clamp.row.value;
    // From a raised camera the clamp's top face (outer radius `A`) is seen
    // behind the rim: its back edge runs `sqrt(A^2 - x^2) sin e` above the
    // plane at `x` from the axis, so beside the opening (`x` about `a`) the
    // sides are seen from `sqrt(A^2 - a^2) sin e` up (0.75 a sin e for a
    // clamp 1.25 a wide, against `A sin e` on the axis: the shorter the
    // extrapolation to the plane below, the smaller its error).
    let above_face = clamp
        .half_width_px
        .map_or(0.0, |a_f| (a_f * a_f - a0 * a0).max(0.0).sqrt() * sin_e)
        + 3.0;
    let u0 = 6.0f64.max(0.03 * a0).max(above_face);
    let k = 14.0f64.max(0.15 * a0);
    let mut rows: Vec<(f64, [f64; 2])> = Vec::new();
    let r_top = (c - u0 - k).ceil() as i64;
    let r_bot = (c - u0).floor() as i64;
    for r in r_top.max(1)..=r_bot.min(h - 2) {
        let p = |x: i64| last.at(x.clamp(0, w - 1) as usize, r as usize);
        let mut xs = [f64::NAN; 2];
        for (i, side) in [-1.0f64, 1.0].into_iter().enumerate() {
            let a = x0 + side * 0.5 * a0;
            let b = x0 + side * (1.1 * a0 + 4.0);
            let (lo, hi) = if side < 0.0 { (b, a) } else { (a, b) };
            let (lo, hi) = ((lo.floor() as i64).max(8), (hi.ceil() as i64).min(w - 10));
            if hi <= lo + 2 {
                continue;
            }
            if let Some((j, _)) = strongest_step(&p, lo, hi)
                && let Some((e, _)) = profile_edge(p, w, j as f64 + 0.5, 3.0)
            {
                xs[i] = e;
            }
        }
        if xs.iter().all(|v| v.is_finite()) {
            rows.push((c - r as f64, xs));
        }
    }
    let mut pts = Vec::new();
    let mut sides = Vec::new();
    for (u, xs) in &rows {
        pts.push((*u, 0.5 * (xs[1] - xs[0])));
        let r = c - u;
        sides.push([xs[0], r]);
        sides.push([xs[1], r]);
    }
    if pts.len() < 5 {
        return Err(TrackError::NotFound {
            what: "the scale".into(),
            detail: format!(
                "the bubble's sides above the clamp plane (rows {r_top}-{r_bot}) were found in {} rows only",
                pts.len()
            ),
            keys: "metres_per_pixel (or points_px with distance_m), or give --metres-per-pixel",
        });
    }
    // The squared half-width, W^2 = A + B u + C u^2. Near its rim the
    // meridian is close to a conic about the axis, rho^2 = alpha + beta z +
    // gamma z^2 (exact for a sphere, gamma = -1; an inflated membrane is
    // flatter near its rim), and the outline of such a surface seen from the
    // elevation `e` (the envelope of its latitude ellipses) is again
    // quadratic in `u`, with a^2 = alpha = A - B^2 s^2 / (4 (1 + s^2 C)),
    // s = sin e. (A quadratic in the half-width itself, extrapolated to the
    // plane from 0.08 a, came out 0.3 % small on the exact neo-Hookean
    // bubble 0.53 a high, 11 % on one 0.26 a high.)
    let x: Vec<Vec<f64>> = pts.iter().map(|(u, _)| vec![1.0, *u, u * u]).collect();
    let y: Vec<f64> = pts.iter().map(|(_, hw)| hw * hw).collect();
    let ((coef, cov, res), _) = robust_lstsq(&x, &y, 0.1 * a0).ok_or(TrackError::NotFound {
        what: "the scale".into(),
        detail: "the bubble's sides near the clamp do not fit a smooth curve".into(),
        keys: "metres_per_pixel",
    })?;
    let [big_a, big_b, big_c] = [coef[0], coef[1], coef[2]];
    let s2 = sin_e * sin_e;
    let f = 1.0 + s2 * big_c;
    let alpha = big_a - big_b * big_b * s2 / (4.0 * f);
    if big_a <= 0.0 || f <= 0.0 || alpha <= 0.0 {
        return Err(TrackError::NotFound {
            what: "the scale".into(),
            detail: "the bubble's sides near the clamp do not close into an opening".into(),
            keys: "metres_per_pixel",
        });
    }
    let a = alpha.sqrt();
    let infl = lag1_inflation(&res);
    // d a / d (A, B, C).
    let g = [
        1.0,
        -big_b * s2 / (2.0 * f),
        big_b * big_b * s2 * s2 / (4.0 * f * f),
    ]
    .map(|v| v / (2.0 * a));
    let var_fit = super::matcher::quad_form(&cov, &g) * infl * infl;
    // A clamp row off by dc moves the plane along the sides:
    // d a / d c = B / (2 a (1 + s^2 C)).
    let var_row = (big_b / (2.0 * a * f)).powi(2) * clamp.row.std.powi(2);
    // The meridian departs from the conic over the fitted rows: on exact
    // neo-Hookean meridians (apex 0.26-0.53 a, rows from 0.03 a or 0.08 a
    // up, 0.15 a tall) the conic met the rim 0.01-0.07 % wide.
    let var_model = (MODEL_REL * a).powi(2);
    Ok((
        Estimate {
            value: a,
            std: (var_fit + var_row + var_model).sqrt(),
        },
        sides,
    ))
}

/// Refuses a series in which the bubble shrinks. On the axis, the rows
/// between the two photos' apexes show the wall in the photo with the
/// smaller bubble and the bubble in the other: if the first photo's light
/// there is the wall's (the rows above both apexes) the bubble grew; if the
/// last photo's is, it shrank (a deflation, or photos in reverse order),
/// and every apex init would place is the wrong photo's.
fn shrinking_check(
    first: &[f64],
    last: &[f64],
    wall_rows: &std::ops::Range<usize>,
    band: std::ops::RangeInclusive<usize>,
    names: [&Path; 2],
) -> Result<(), TrackError> {
    let median = |v: &mut Vec<f64>| quantile(v, 0.5);
    let wall = median(&mut first[wall_rows.clone()].to_vec());
    let off = |p: &[f64]| median(&mut band.clone().map(|r| (p[r] - wall).abs()).collect());
    let (off_first, off_last) = (off(first), off(last));
    // the wall's own spread above the apexes: the noise of this comparison
    let spread = median(&mut wall_rows.clone().map(|r| (first[r] - wall).abs()).collect());
    if off_first > 3.0 * off_last && off_first - off_last > 6.0 * spread.max(1e-3 * wall) {
        return Err(TrackError::Config {
            path: names[1].to_path_buf(),
            message: format!(
                "above the bubble's top this last photo shows the wall where the first ({}) shows the bubble: the bubble shrinks in this series (a deflation, or photos in reverse order); give the photos in the order of rising pressure (name them so, or use a glob that sorts them so)",
                names[0].display()
            ),
        });
    }
    Ok(())
}

/// Template size for a bubble of free radius `a_px` in a photo `width` px
/// wide: 30 % of `a` wide, at most a tenth of the width, at least 32 px,
/// even, half as tall.
pub fn template_size_for(a_px: f64, width: usize) -> (usize, usize) {
    let tw = (0.3 * a_px).min(0.1 * width as f64).max(32.0);
    let tw = ((tw / 2.0).round() as usize) * 2;
    (tw, tw / 2)
}

/// Where the frames of a test come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Frames {
    /// Photo files, in the order taken.
    Photos(Vec<PathBuf>),
    /// A video and the indices of the frames to use, in time order.
    Video {
        /// The video file.
        path: PathBuf,
        /// The frames to use.
        indices: Vec<usize>,
    },
}

impl Frames {
    /// The number of frames.
    pub fn len(&self) -> usize {
        match self {
            Frames::Photos(p) => p.len(),
            Frames::Video { indices, .. } => indices.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The file that frame `i` is (or is in), for messages.
    pub fn path(&self, i: usize) -> &Path {
        match self {
            Frames::Photos(p) => &p[i],
            Frames::Video { path, .. } => path,
        }
    }

    /// Frame `i`, grayscale.
    fn gray(&self, i: usize) -> Result<Gray, TrackError> {
        match self {
            Frames::Photos(p) => Ok(read_gray(&p[i], None)?.crop),
            Frames::Video { path, indices } => {
                let bgr = super::video::read_frame_bgr(path, indices[i])?;
                let mut g = opencv::core::Mat::default();
                opencv::imgproc::cvt_color_def(&bgr, &mut g, opencv::imgproc::COLOR_BGR2GRAY)
                    .map_err(|e| TrackError::OpenCv(e.to_string()))?;
                use opencv::core::MatTraitConst;
                let whole = [0, 0, g.cols() as usize, g.rows() as usize];
                Ok(super::image::crop_mat(path, &g, whole)?.crop)
            }
        }
    }

    /// `f` of every frame (grayscale), in order: photos decoded in
    /// parallel, a video read once from start to end.
    fn map<T: Send>(
        &self,
        f: impl Fn(usize, Gray) -> Result<T, TrackError> + Sync,
    ) -> Result<Vec<T>, TrackError> {
        match self {
            Frames::Photos(p) => (0..p.len())
                .into_par_iter()
                .map(|i| f(i, read_gray(&p[i], None)?.crop))
                .collect(),
            Frames::Video { path, indices } => {
                let wanted: Vec<super::video::Wanted> = indices
                    .iter()
                    .enumerate()
                    .map(|(seq, &index)| super::video::Wanted {
                        seq,
                        index,
                        crop: None,
                        lenient: false,
                    })
                    .collect();
                let mut out = Vec::with_capacity(indices.len());
                let mut failed = None;
                super::video::read_frames(path, &wanted, |i, d| {
                    match d.and_then(|d| f(i, d.crop)) {
                        Ok(v) => out.push(v),
                        Err(e) => failed = Some(e),
                    }
                    failed.is_none()
                });
                match failed {
                    Some(e) => Err(e),
                    None => Ok(out),
                }
            }
        }
    }
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
        });
    }
    let y_top = on_axis.iter().map(|c| c.0).min().unwrap_or(0);
    // The band's first run down the axis (a highlight that moved leaves
    // another patch below it).
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
    let given_sin = given.elevation_deg.map(|e| e.to_radians().sin());
    let clamp = find_clamp(
        &mean,
        x0,
        a0,
        [y_low, base],
        sw.noise,
        given_sin,
        given.lens.as_ref(),
    )?;
    let roll_deg = Estimate {
        value: clamp.slope.value.atan().to_degrees(),
        std: (clamp.slope.std / (1.0 + clamp.slope.value.powi(2))).to_degrees(),
    };
    if roll_deg.value.abs() > MAX_ROLL_DEG + 4.0 * roll_deg.std {
        return Err(TrackError::NotFound {
            what: "a level clamp".into(),
            detail: format!(
                "the clamp's top edge slopes by {:.2} +- {:.2} degrees across the photos: the camera is rolled about its view axis (at most {MAX_ROLL_DEG} degree is taken: the tracker measures along the photo's columns, and beyond it the apex moves sideways as the bubble grows): level the camera or rotate the photos",
                roll_deg.value, roll_deg.std
            ),
            keys: "clamp_row_px (the clamp's row at the bubble's axis), metres_per_pixel, roi_px and template_rect_px",
        });
    }
    if clamp.row.value < y_low - 3.0 - clamp.half_width_px.map_or(0.0, |a| a * 0.1) {
        return Err(TrackError::NotFound {
            what: "the clamp plane".into(),
            detail: format!(
                "the edge found beside the bubble (row {:.1}) is above the lowest part of the bubble that moves (row {y_low:.0}): it is not the clamp",
                clamp.row.value
            ),
            keys: "clamp_row_px",
        });
    }
    let elevation_deg = match (given.elevation_deg, clamp.sin_e) {
        (Some(e), _) => Some(Estimate { value: e, std: 0.0 }),
        (None, Some(s)) => {
            let e = s.value.clamp(-1.0, 1.0).asin();
            Some(Estimate {
                value: e.to_degrees(),
                std: (s.std / e.cos()).to_degrees(),
            })
        }
        (None, None) => None,
    };
    let sin_e = elevation_deg.map_or(0.0, |e| e.value.max(0.0).to_radians().sin());

    // Step 4: the scale.
    let (radius_px, metres_per_pixel, scale_from, side_points_px) = match given.metres_per_pixel {
        Some(m) => (
            None,
            Estimate { value: m, std: 0.0 },
            ScaleSource::Given,
            Vec::new(),
        ),
        None => {
            // The sides are read in the photo's rows.
            let mut in_photo = clamp.clone();
            in_photo.row.value =
                super::lens::clamp_row_in_photo(given.lens.as_ref(), x0, clamp.row.value);
            let (a, sides) = find_radius(&pl, x0, a0, &in_photo, sin_e)?;
            let mpp = radius_m / a.value;
            (
                Some(a),
                Estimate {
                    value: mpp,
                    std: mpp * a.std / a.value,
                },
                ScaleSource::ClampOpening,
                sides,
            )
        }
    };

    // The axis: the mean midpoint of the sides where they were located.
    let axis_x_px = if side_points_px.len() >= 10 {
        let m: Vec<f64> = side_points_px
            .chunks(2)
            .map(|p| 0.5 * (p[0][0] + p[1][0]))
            .collect();
        let n = m.len() as f64;
        let mean = m.iter().sum::<f64>() / n;
        let var = m.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        Estimate {
            value: mean,
            std: (var / n).sqrt(),
        }
    } else {
        Estimate {
            value: x0,
            std: x0_std,
        }
    };

    // Step 5: template and region.
    let a_px = radius_px.map_or(radius_m / metres_per_pixel.value, |a| a.value);
    let (tw, th) = template_size_for(a_px, w);
    // The template stays clear of the clamp (its top face, from a raised
    // camera): on the first photo when the apex is at least 4 px above it
    // (the template is then raised so that its bottom stays clear, the apex
    // below its middle), else on the first photo whose apex is.
    let face = clamp.half_width_px.map_or(0.0, |a| a * sin_e);
    let clear = clamp.row.value - face - 2.0;
    let reference_frame = apexes_px
        .iter()
        .position(|p| p[1] <= clear - 4.0)
        .unwrap_or(apexes_px.len() - 1);
    let ref_img = match reference_frame {
        0 => first,
        k if k == n - 1 => last,
        k => frames.gray(k)?.with_tone(tone),
    };
    let guess = apexes_px[reference_frame];
    let mut cols = Columns::new(&ref_img, 3);
    let fit = edge_fit_in(
        &mut cols,
        guess[0],
        guess[1],
        0.0,
        EdgeSettings {
            half_span_px: tw / 2,
            half_window_px: 3,
        },
    );
    let reference_apex_px = match fit {
        Some(f) if (f.y - guess[1]).abs() < 3.0 => [guess[0], f.y],
        _ => guess,
    };
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
    let (mut axis_x_px, clamp_row_px, mut radius_px, mut metres_per_pixel) =
        (axis_x_px, clamp.row, radius_px, metres_per_pixel);
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
        axis_x_px,
        clamp_row_px,
        elevation_deg,
        roll_deg,
        clamp_half_width_px: clamp.half_width_px,
        radius_px,
        metres_per_pixel,
        scale_from,
        apexes_px: apexes,
        reference_frame,
        layout,
        reference_apex_px,
        outlines_px,
        clamp_points_px: clamp.points,
        side_points_px,
    })
}

/// Where the experiment file written by `bulge init` points.
#[derive(Debug, Clone, PartialEq)]
pub struct Sources {
    /// The photo folder, as the experiment file will name it (relative to
    /// it), or with `video` the video file.
    pub dir: String,
    /// The frames are a video's, every N-th (`dir` names the video).
    pub video_every: Option<usize>,
    /// The glob of the photos.
    pub glob: String,
    /// The number of photos.
    pub count: usize,
    /// The pressure CSV, relative to the experiment file.
    pub pressure_csv: Option<String>,
    /// Two points and their distance, when the scale is given that way.
    pub points: Option<([[f64; 2]; 2], f64)>,
}

/// A TOML string literal.
fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

impl Found {
    /// The text of a commented experiment file: the specimen as given, the
    /// set-up as found, each found value with its standard deviation.
    pub fn experiment_toml(&self, specimen: &crate::experiment::Specimen, src: &Sources) -> String {
        let mut t = String::new();
        let l = &self.layout;
        t.push_str(&format!(
            "# Written by `bulge init` from {} photos ({}x{} px). Check init.png: every value below\n\
             # found in the photos is drawn there. A value followed by `_std` is its standard deviation.\n\
             # Image coordinates: the centre of the top-left pixel is (0, 0), y down.\n\n",
            src.count, self.width, self.height
        ));
        t.push_str(&format!(
            "[specimen]\nradius_m = {:?}\nthickness_m = {:?}\npoisson = {:?}\nprebulge_height_m = {:?}\n\n",
            specimen.radius_m, specimen.thickness_m, specimen.poisson, specimen.prebulge_height_m
        ));
        let [rx, ry, rw, rh] = l.roi_px;
        let [tx, ty, tw, th] = l.template_rect_px;
        let ymin = self
            .apexes_px
            .iter()
            .map(|a| a[1])
            .fold(f64::INFINITY, f64::min);
        let ymax = self
            .apexes_px
            .iter()
            .map(|a| a[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let source = match src.video_every {
            None => format!("dir = {}\nglob = {}\n", quoted(&src.dir), quoted(&src.glob)),
            Some(1) => format!("video = {}\n", quoted(&src.dir)),
            Some(k) => format!("video = {}\nevery = {k}\n", quoted(&src.dir)),
        };
        t.push_str(&format!(
            "[photos]\n{source}\
             # where the apex moves: {} apexes found on the axis (column {:.2} +- {:.2}), rows {:.0} to {:.0}, with a template's margin\n\
             roi_px = [{rx}, {ry}, {rw}, {rh}]\n\
             # cut from reference_frame (the first photo whose template stays clear of the clamp), around its apex\n\
             template_rect_px = [{tx}, {ty}, {tw}, {th}]\nreference_frame = {}\n\
             apex_in_template_px = [{:.3}, {:.3}]\n\n",
            self.apexes_px.len(),
            self.axis_x_px.value,
            self.axis_x_px.std,
            ymin,
            ymax,
            self.reference_frame,
            l.apex_in_template_px[0],
            l.apex_in_template_px[1],
        ));
        t.push_str(&format!(
            "[camera]\n# the tone curve from light to grey levels: edges are located in light\n\
             # (\"srgb\" for ordinary 8-bit photos, \"linear\" for raw ones, or a gamma)\n\
             response = {}\n{}\n",
            toml::Value::try_from(self.response).map_or_else(|_| quoted("srgb"), |v| v.to_string()),
            super::lens::lens_keys_toml(self.lens.as_ref()),
        ));
        t.push_str("[calibration]\n");
        match (&src.points, self.scale_from) {
            (Some((p, d)), _) => t.push_str(&format!(
                "# the scale, given: two points and their distance\npoints_px = [[{:?}, {:?}], [{:?}, {:?}]]\ndistance_m = {d:?}\n",
                p[0][0], p[0][1], p[1][0], p[1][1]
            )),
            (None, ScaleSource::Given) => t.push_str(&format!(
                "# the scale, given\nmetres_per_pixel = {:?}\n",
                self.metres_per_pixel.value
            )),
            (None, ScaleSource::ClampOpening) => {
                let a = self.radius_px.expect("measured radius");
                t.push_str(&format!(
                    "# the scale from the clamp opening: the silhouette is 2a = {:.3} +- {:.3} px wide at the clamp plane\n\
                     # ({} points on its sides); radius_m / a. It shares the radius's own error (radius_std_m).\n\
                     metres_per_pixel = {:.6e}\nmetres_per_pixel_std = {:.2e}\n",
                    2.0 * a.value,
                    2.0 * a.std,
                    self.side_points_px.len(),
                    self.metres_per_pixel.value,
                    self.metres_per_pixel.std
                ));
            }
        }
        let face = match self.clamp_half_width_px {
            Some(a) => format!(", the clamp {:.1} px wide", 2.0 * a),
            None => String::new(),
        };
        t.push_str(&format!(
            "# the clamp plane: the clamp's top edge beside the bubble, {} columns{face}\n\
             clamp_row_px = {:.4}\nclamp_row_std_px = {:.2e}\n",
            self.clamp_points_px.len(),
            self.clamp_row_px.value,
            self.clamp_row_px.std.max(1e-4),
        ));
        t.push_str(&format!(
            "# the camera's roll about its view axis: the clamp's edge slopes by {:.2} +- {:.2} degrees (at most {MAX_ROLL_DEG} is taken)\n",
            self.roll_deg.value, self.roll_deg.std
        ));
        match self.elevation_deg {
            Some(e) if e.std == 0.0 => t.push_str(&format!(
                "# the camera's elevation above the clamp plane, given\nelevation_deg = {:?}\n",
                e.value
            )),
            Some(e) if e.value.abs() > 2.0 * e.std && e.value > 0.05 => t.push_str(&format!(
                "# the camera is {:.2} +- {:.2} degrees above the clamp plane (from the clamp's ellipse): clamp_row_px is\n\
                 # the row of the clamp ring's centre, and the heights are corrected for the elevation\n\
                 elevation_deg = {:.3}\n",
                e.value, e.std, e.value
            )),
            Some(e) => t.push_str(&format!(
                "# the camera is level with the clamp plane: elevation {:.2} +- {:.2} degrees from the clamp's ellipse\n",
                e.value, e.std
            )),
            None => t.push_str(
                "# the camera is taken as level: the clamp's edge is straight and its ends are outside the picture\n",
            ),
        }
        t.push('\n');
        match &src.pressure_csv {
            Some(p) => t.push_str(&format!("[pressure]\ncsv = {}\n", quoted(p))),
            None => t.push_str(
                "# No pressure log was given: add one (columns file,pressure_pa, or a log by time)\n# [pressure]\n# csv = \"pressure.csv\"\n",
            ),
        }
        t
    }
}
