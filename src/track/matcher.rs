//! Locating the apex in one region: OpenCV's normalised cross-correlation
//! (TM_CCOEFF_NORMED), a 2-D quadratic fit of the score peak, and a local
//! edge fit at the apex.

use opencv::core::{Mat, MatTraitConst, MatTraitConstManual};
use opencv::imgproc;

use super::TrackError;
use super::image::Gray;

/// The best match of the template in a search window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Integer position of the template's top-left corner (what `minMaxLoc` gives), px.
    pub integer: [f64; 2],
    /// Sub-pixel position from a 2-D quadratic fit of the 3x3 scores around the peak, px.
    pub quadratic: [f64; 2],
    /// TM_CCOEFF_NORMED at the peak, in [-1, 1].
    pub score: f64,
}

/// Matches `templ` inside `img` restricted to the window `[x0, y0, w, h]`
/// (in `img` coordinates; the window is the set of pixels the template may
/// cover). Positions returned are of the template's top-left corner in `img`.
pub fn match_in_window(img: &Gray, templ: &Gray, win: [usize; 4]) -> Result<Match, TrackError> {
    let [x0, y0, w, h] = win;
    debug_assert!(w >= templ.width && h >= templ.height);
    let sub = img.crop(x0, y0, w, h);
    let a = sub.as_mat().map_err(cv)?;
    let t = templ.as_mat().map_err(cv)?;
    let mut res = Mat::default();
    imgproc::match_template_def(&a, &t, &mut res, imgproc::TM_CCOEFF_NORMED).map_err(cv)?;
    let (rw, rh) = (res.cols() as usize, res.rows() as usize);
    let s: &[f32] = res.data_typed::<f32>().map_err(cv)?;
    // A flat window gives NaN scores (zero variance): treat them as -1.
    let val = |x: usize, y: usize| {
        let v = s[y * rw + x];
        if v.is_finite() { f64::from(v) } else { -1.0 }
    };
    let (mut bx, mut by, mut best) = (0, 0, f64::NEG_INFINITY);
    for y in 0..rh {
        for x in 0..rw {
            let v = val(x, y);
            if v > best {
                best = v;
                bx = x;
                by = y;
            }
        }
    }
    let (dx, dy) = if bx > 0 && by > 0 && bx + 1 < rw && by + 1 < rh {
        let mut f = [[0.0; 3]; 3];
        for (j, row) in f.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = val(bx + i - 1, by + j - 1);
            }
        }
        quadratic_peak(&f)
    } else {
        (0.0, 0.0)
    };
    Ok(Match {
        integer: [(x0 + bx) as f64, (y0 + by) as f64],
        quadratic: [(x0 + bx) as f64 + dx, (y0 + by) as f64 + dy],
        score: best,
    })
}

/// Block average by an integer factor `f` (the image's last partial blocks
/// are dropped), rounded to the nearest grey level: OpenCV's area resize.
pub fn reduce(img: &Gray, f: usize) -> Result<Gray, TrackError> {
    let (w, h) = (img.width / f, img.height / f);
    let mut out = Gray {
        width: w,
        height: h,
        data: vec![0u8; w * h],
        tone: img.tone,
    };
    if w == 0 || h == 0 {
        return Ok(out);
    }
    let src = if img.width == w * f && img.height == h * f {
        std::borrow::Cow::Borrowed(img)
    } else {
        std::borrow::Cow::Owned(img.crop(0, 0, w * f, h * f))
    };
    let a = src.as_mat().map_err(cv)?;
    let mut dst = Mat::default();
    let size = opencv::core::Size::new(w as i32, h as i32);
    imgproc::resize(&a, &mut dst, size, 0.0, 0.0, imgproc::INTER_AREA).map_err(cv)?;
    out.data.copy_from_slice(dst.data_bytes().map_err(cv)?);
    Ok(out)
}

fn cv(e: opencv::Error) -> TrackError {
    TrackError::OpenCv(e.to_string())
}

/// Offset of the maximum of the least-squares quadratic through a 3x3 patch
/// `f[row][col]` centred on the integer peak. Falls back to separate 1-D
/// parabolas when the 2-D fit is not a proper maximum; clamped to +-0.5 px
/// (beyond that the integer peak was not the nearest one).
pub fn quadratic_peak(f: &[[f64; 3]; 3]) -> (f64, f64) {
    let col = |i: usize| f[0][i] + f[1][i] + f[2][i];
    let row = |j: usize| f[j][0] + f[j][1] + f[j][2];
    let gx = (col(2) - col(0)) / 6.0;
    let gy = (row(2) - row(0)) / 6.0;
    let hxx = (col(2) + col(0) - 2.0 * col(1)) / 3.0;
    let hyy = (row(2) + row(0) - 2.0 * row(1)) / 3.0;
    let hxy = (f[2][2] - f[2][0] - f[0][2] + f[0][0]) / 4.0;
    let det = hxx * hyy - hxy * hxy;
    let (mut ox, mut oy) = if hxx < 0.0 && det > 0.0 {
        ((-gx * hyy + gy * hxy) / det, (-gy * hxx + gx * hxy) / det)
    } else {
        (f64::NAN, f64::NAN)
    };
    if !(ox.is_finite() && oy.is_finite() && ox.abs() <= 1.0 && oy.abs() <= 1.0) {
        let para = |m: f64, c: f64, p: f64| {
            let d = m + p - 2.0 * c;
            if d < 0.0 { 0.5 * (m - p) / d } else { 0.0 }
        };
        ox = para(f[1][0], f[1][1], f[1][2]);
        oy = para(f[0][1], f[1][1], f[2][1]);
    }
    (ox.clamp(-0.5, 0.5), oy.clamp(-0.5, 0.5))
}

/// Result of the edge fit at the apex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeFit {
    /// Apex row (top of the fitted parabola), px, image coordinates of `img`.
    pub y: f64,
    /// Standard error of `y`, px: from the column residuals, inflated for
    /// their correlation along the edge (lag-1 autocorrelation).
    pub y_std: f64,
    /// Vertex column of the parabola, px.
    pub x_vertex: f64,
    /// Standard error of `x_vertex`, px (large on flat tops).
    pub x_std: f64,
    /// Edge curvature `d2y/dx2`, 1/px (positive for a dome seen from the side).
    pub curvature: f64,
    /// Standard error of `curvature`, 1/px.
    pub curvature_std: f64,
    /// Columns used by the centroid fit.
    pub columns: usize,
    /// RMS of the centroid fit's column residuals, px. Both are the
    /// centroids' also where the apex comes from the step model
    /// (`two_sided`), whose rows are noisier: the guards compare frames
    /// by them.
    pub rms: f64,
    /// Whether the rows come from the two-sided step model rather than the
    /// centroids: the test of the two found the dome side under the edge
    /// biasing the centroids (a highlight, texture).
    pub two_sided: bool,
    /// Whether, in the frame at the lowest pressure (no emptier frame shows
    /// the background behind its top), a quarter or more of the columns
    /// located show a line in the rows above their edge that the edge's
    /// location reads ([`line_above`]): clutter behind the bubble a few
    /// rows above its top, which pulls the edge by up to a pixel, or on
    /// which the edge was located instead of the top. Such a frame cannot
    /// be measured.
    pub clutter_on_top: bool,
}

/// Settings of the edge fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeSettings {
    /// Half-width of the fitted span of columns around the apex, px.
    pub half_span_px: usize,
    /// Half-height of the window in each column in which the edge is located, px.
    pub half_window_px: usize,
}

/// Edge row in one column: the centroid of the vertical intensity
/// differences `d_j = I(j+1) - I(j)` (at `j + 1/2`) inside a window of
/// half-height `hw` centred on the current estimate, with 1-px linear tapers
/// at its ends, iterated to a fixed point. For an area-sampled step the two
/// non-zero differences give the exact edge; under symmetric blur the
/// centred window keeps it unbiased. Returns the row and the step (sum of the
/// weighted differences, grey levels).
///
/// The row is located in light (the grey levels through the inverted tone
/// curve: a lens blurs light, so only there is the blurred step odd about
/// the edge); the step is the grey levels' (the tests that read the photo
/// against it, for lines, spots and clutter, compare grey levels, whose
/// noise is even across the range).
fn column_edge(img: &Gray, c: usize, start: f64, hw: f64) -> Option<(f64, f64)> {
    in_light(
        img,
        |j| img.light(c, j as usize),
        |j| f64::from(img.at(c, j as usize)),
        start,
        hw,
        true,
    )
}

/// The edge row of a profile located on its light `light`, with the step
/// of its grey levels `grey` there ([`column_edge`]).
fn in_light(
    img: &Gray,
    light: impl Fn(i64) -> f64,
    grey: impl Fn(i64) -> f64,
    start: f64,
    hw: f64,
    slopes: bool,
) -> Option<(f64, f64)> {
    let len = img.height as i64;
    let (e, step) = profile_edge_with(light, len, start, hw, slopes)?;
    if img.tone == crate::track::image::Tone::LINEAR {
        return Some((e, step));
    }
    let (_, step) = profile_edge_with(grey, len, e, hw, slopes)?;
    Some((e, step))
}

/// [`column_edge`] along any profile of `len` samples `px(0..len)`: a
/// column, a row, or an average of several.
pub(crate) fn profile_edge(
    px: impl Fn(i64) -> f64,
    len: i64,
    start: f64,
    hw: f64,
) -> Option<(f64, f64)> {
    profile_edge_with(px, len, start, hw, true)
}

/// [`profile_edge`], the background slopes on each side subtracted only
/// with `slopes`.
fn profile_edge_with(
    px: impl Fn(i64) -> f64,
    len: i64,
    start: f64,
    hw: f64,
    slopes: bool,
) -> Option<(f64, f64)> {
    let h = len;
    let mut e = start;
    let mut step = 0.0;
    for _ in 0..8 {
        let lo = (e - hw - 1.0).floor() as i64;
        let hi = (e + hw + 1.0).ceil() as i64;
        if lo - SLOPE_ROWS < 0 || hi + 1 + SLOPE_ROWS >= h {
            return None;
        }
        // Smooth shading and background texture add a slope to the
        // differences on each side of the edge; their lever arm about the
        // centre would bias the centroid, so they are subtracted. Each slope
        // is the minmod of two 3-row estimates, so that another edge nearby
        // (the clamp fixture under a flat bubble) is not taken for a slope.
        let half = SLOPE_ROWS / 2;
        let slope = |a: i64, b: i64, c: i64| {
            minmod((px(b) - px(a)) / half as f64, (px(c) - px(b)) / half as f64)
        };
        let (g_above, g_below) = if slopes {
            (
                slope(lo - SLOPE_ROWS, lo - half, lo),
                slope(hi + 1, hi + 1 + half, hi + 1 + SLOPE_ROWS),
            )
        } else {
            (0.0, 0.0)
        };
        // Differences of the edge's polarity only (the sign of their sum):
        // a highlight or texture inside the dome, or the far side of a
        // thin dark line behind it, brightens the other way and is left out.
        let mut diffs = [(0.0f64, 0.0f64, 0.0f64); 64];
        let mut m = 0;
        let mut total = 0.0;
        for j in lo..=hi {
            let y = j as f64 + 0.5;
            let w = (hw + 0.5 - (y - e).abs()).clamp(0.0, 1.0);
            if w == 0.0 || m == diffs.len() {
                continue;
            }
            let base = if y < e { g_above } else { g_below };
            let d = px(j + 1) - px(j) - base;
            diffs[m] = (y, w, d);
            m += 1;
            total += w * d;
        }
        let (mut sw, mut swy) = (0.0, 0.0);
        for &(y, w, d) in &diffs[..m] {
            if d * total > 0.0 {
                sw += w * d;
                swy += w * d * y;
            }
        }
        if sw == 0.0 {
            return None;
        }
        let next = swy / sw;
        if !next.is_finite() || (next - start).abs() > 2.0 * hw + 2.0 {
            return None;
        }
        let moved = (next - e).abs();
        e = next;
        step = sw;
        if moved < 1e-4 {
            break;
        }
    }
    Some((e, step))
}

/// Rows beyond the window on each side of [`profile_edge`] over which the
/// slope beside the edge is measured.
const SLOPE_ROWS: i64 = 6;

/// Rows on each side of the edge over which [`step_model_edge`] fits.
const MODEL_ROWS: i64 = 5;

/// Standard normal density and distribution function.
fn normal_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// The edge row of a profile from a model of the whole step, fitted by
/// Levenberg-Marquardt ([`crate::fit::lm`], the solver of the hyperelastic
/// fits) to the `2 MODEL_ROWS + 1` samples around `start`:
/// a straight background `B + g t` on one side (`t = row - edge`), a
/// straight dome side `B + C + (g + S) t` on the other, the step blurred by
/// a Gaussian of width `sigma` and each sample the mean over its pixel
/// (closed forms through `G(t) = t Phi(t/sigma) + sigma phi(t/sigma)` and
/// its integral). The six parameters `B, g, C, S, edge, sigma` are all
/// fitted. Unlike the centroid of [`profile_edge`], whose window takes a
/// slope of the dome side that starts at the edge (a highlight's flank
/// under the edge, texture) for part of the step, this model gives that
/// slope its own parameter; it pays with about 1.5-2 times the noise.
/// `None` when it does not converge, the blur comes out outside 0.3-4 px,
/// or the edge moves more than 1.5 px from `start`.
pub(crate) fn step_model_edge(px: impl Fn(i64) -> f64, len: i64, start: f64) -> Option<f64> {
    const N: usize = (2 * MODEL_ROWS + 1) as usize;
    let j0 = start.floor() as i64 - MODEL_ROWS;
    if j0 < 0 || j0 + N as i64 > len {
        return None;
    }
    let step = StepModel {
        rows: std::array::from_fn(|k| (j0 + k as i64) as f64),
        y: std::array::from_fn(|k| px(j0 + k as i64)),
    };
    // Start: the edge given, a blur of 1.2 px, the straight parts by linear
    // least squares there.
    let (e0, s0) = (start, 1.2);
    let mut x = nalgebra::DVector::from_vec(vec![0.0, 0.0, 0.0, 0.0, e0, s0]);
    let jac = step.jacobian_at(&x);
    let a = jac.columns(0, 4).into_owned();
    let lin = (a.transpose() * &a)
        .cholesky()?
        .solve(&(a.transpose() * nalgebra::DVector::from_column_slice(&step.y)));
    x.rows_mut(0, 4).copy_from(&lin);
    let fit = crate::fit::lm::minimize(step, x, 60).ok()?;
    let (e, sigma) = (fit.x[4], fit.x[5]);
    (e.is_finite() && (e - start).abs() <= 1.5 && (0.3..=4.0).contains(&sigma)).then_some(e)
}

/// The least-squares problem of [`step_model_edge`]: parameters `[B, g, C,
/// S, edge, sigma]`, residuals model minus samples.
struct StepModel {
    rows: [f64; (2 * MODEL_ROWS + 1) as usize],
    y: [f64; (2 * MODEL_ROWS + 1) as usize],
}

impl StepModel {
    /// Per sample: the model's value and its derivatives with respect to
    /// the six parameters.
    fn terms(&self, p: &[f64]) -> impl Iterator<Item = (f64, [f64; 6])> + '_ {
        let [b, g, c, s_ramp, e, s] = [p[0], p[1], p[2], p[3], p[4], p[5]];
        // The blurred unit step's and ramp's antiderivatives.
        let gg = move |t: f64| t * normal_cdf(t / s) + s * normal_pdf(t / s);
        let kk = move |t: f64| {
            0.5 * (t * t + s * s) * normal_cdf(t / s) + 0.5 * t * s * normal_pdf(t / s)
        };
        self.rows.iter().map(move |&j| {
            let t = j - e;
            let (lo, hi) = (t - 0.5, t + 0.5);
            let psi1 = gg(hi) - gg(lo);
            let psi2 = kk(hi) - kk(lo);
            let dcdf = normal_cdf(hi / s) - normal_cdf(lo / s);
            let dpdf = normal_pdf(hi / s) - normal_pdf(lo / s);
            (
                b + g * t + c * psi1 + s_ramp * psi2,
                [
                    1.0,
                    t,
                    psi1,
                    psi2,
                    -(g + c * dcdf + s_ramp * psi1),
                    c * dpdf + s_ramp * s * dcdf,
                ],
            )
        })
    }

    fn jacobian_at(&self, p: &nalgebra::DVector<f64>) -> nalgebra::DMatrix<f64> {
        let mut jac = nalgebra::DMatrix::zeros(self.rows.len(), 6);
        for (i, (_, d)) in self.terms(p.as_slice()).enumerate() {
            for (k, v) in d.into_iter().enumerate() {
                jac[(i, k)] = v;
            }
        }
        jac
    }
}

impl argmin::core::Operator for StepModel {
    type Param = nalgebra::DVector<f64>;
    type Output = nalgebra::DVector<f64>;
    fn apply(&self, p: &Self::Param) -> Result<Self::Output, argmin::core::Error> {
        // The blur's bounds, as non-finite residuals (the solver's way).
        if !(0.3..=4.0).contains(&p[5]) {
            return Ok(nalgebra::DVector::from_element(self.rows.len(), f64::NAN));
        }
        Ok(nalgebra::DVector::from_iterator(
            self.rows.len(),
            self.terms(p.as_slice())
                .zip(&self.y)
                .map(|((m, _), y)| m - y),
        ))
    }
}

impl argmin::core::Jacobian for StepModel {
    type Param = nalgebra::DVector<f64>;
    type Jacobian = nalgebra::DMatrix<f64>;
    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, argmin::core::Error> {
        Ok(self.jacobian_at(p))
    }
}

/// The edge rows found so far in the columns of one image, so that the
/// passes of the edge fit and the wider axis fit ([`axis_fit_in`]) locate each column once:
/// `column_edge` iterates to a fixed point, so a column already converged
/// within a pixel of a new start would converge to the same row again.
pub struct Columns<'a> {
    img: &'a Gray,
    hw: f64,
    found: Vec<Option<(f64, f64)>>,
    /// Per column, the centroid row the step model ([`step_model_edge`])
    /// started from and its row: the free edge fit and the fit on the axis
    /// test the same columns.
    model: Vec<Option<(f64, Option<f64>)>>,
    fullest: Option<&'a Gray>,
    emptiest: Option<&'a Gray>,
    /// This frame is the emptiest: see [`Extremes::is_emptiest`].
    is_emptiest: bool,
}

impl<'a> Columns<'a> {
    /// No column located yet; `half_window_px` as in [`EdgeSettings`].
    pub fn new(img: &'a Gray, half_window_px: usize) -> Self {
        Columns {
            img,
            hw: half_window_px.max(2) as f64,
            found: vec![None; img.width],
            model: vec![None; img.width],
            fullest: None,
            emptiest: None,
            is_emptiest: false,
        }
    }

    /// As [`Columns::new`], each edge checked against the same region in
    /// the frames where the bubble is largest (`extremes.fullest`, see
    /// [`below_is_dome`]) and smallest (`extremes.emptiest`, see
    /// [`above_is_background`]; against it too, static clutter above an
    /// edge cancels: [`Columns::without_clutter`]).
    pub fn with_extremes(img: &'a Gray, half_window_px: usize, extremes: Extremes<'a>) -> Self {
        let same = |f: &&Gray| (f.width, f.height) == (img.width, img.height);
        Columns {
            fullest: extremes.fullest.filter(same),
            emptiest: extremes.emptiest.filter(same),
            is_emptiest: extremes.is_emptiest,
            ..Columns::new(img, half_window_px)
        }
    }

    /// The image's width, px.
    pub fn width(&self) -> usize {
        self.img.width
    }

    /// The edge `(e, step)` of column `c` again where the emptiest frame
    /// shows clutter in the rows above it that the edge's location reads
    /// ([`clutter_in_window`]): then from the difference of
    /// this frame and the emptiest, in which static clutter cancels (the
    /// bubble covers it only below the edge). `None` when the emptiest
    /// frame shows clutter on both sides of the edge.
    fn without_clutter(&self, c: usize, e: f64, step: f64) -> Option<(f64, f64)> {
        let Some(f) = self.emptiest else {
            return Some((e, step));
        };
        match clutter_in_window(f, c, e, self.hw, step) {
            (false, _) => Some((e, step)),
            (true, true) => None,
            (true, false) => {
                let d = in_light(
                    self.img,
                    difference(self.img, f, c),
                    grey_difference(self.img, f, c),
                    e,
                    self.hw,
                    false,
                )?;
                (d.1 * step > 0.0 && d.1.abs() >= 0.5 * step.abs()).then_some(d)
            }
        }
    }

    /// The step model's edge row of column `c` from the centroid row `e`
    /// (located once per column and row); like the centroid, on the
    /// difference from the emptiest frame where that shows clutter above
    /// the edge ([`Columns::without_clutter`]).
    fn model_edge(&mut self, c: usize, e: f64) -> Option<f64> {
        if let Some((e0, m)) = self.model[c]
            && e0 == e
        {
            return m;
        }
        let (img, len) = (self.img, self.img.height as i64);
        let step = self.found[c].map_or(0.0, |f| f.1);
        let m = match self
            .emptiest
            .filter(|f| clutter_in_window(f, c, e, self.hw, step).0)
        {
            Some(f) => step_model_edge(difference(img, f, c), len, e),
            None => step_model_edge(|j| img.light(c, j as usize), len, e),
        };
        self.model[c] = Some((e, m));
        m
    }

    /// The edge row and step of column `c` starting from row `start`.
    fn edge(&mut self, c: usize, start: f64) -> Option<(f64, f64)> {
        if let Some((e, step)) = self.found[c]
            && (e - start).abs() < 1.0
        {
            return Some((e, step));
        }
        let r = column_edge(self.img, c, start, self.hw)
            .filter(|&(e, step)| {
                self.emptiest
                    .is_none_or(|f| !static_line_on_edge(self.img, f, c, e, self.hw, step))
            })
            .and_then(|(e, step)| self.without_clutter(c, e, step))
            .filter(|&(e, step)| {
                self.fullest
                    .is_none_or(|f| below_is_dome(self.img, f, c, e, step))
                    && self
                        .emptiest
                        .is_none_or(|f| above_is_background(self.img, f, c, e, step))
            });
        if r.is_some() {
            self.found[c] = r;
        }
        r
    }
}

/// Whether the edge found at row `e` of column `c` (step `step`) is the
/// upper border of a line behind the bubble (a cable, a shelf edge) that
/// the bubble's top touches, rather than the top itself: the two rows just
/// under the edge look as they do in the emptiest frame (within a quarter
/// of the step: what is dark there was there before the bubble reached
/// it), and further down, within the rows the edge's location reads, the
/// emptiest frame turns back to the background by half the step or more
/// where this frame shows the dome (so what the emptiest frame shows there
/// is a line, not its own dome under an edge in nearly the same place).
/// Where the dome's edge runs along such a line, dark against dark, it
/// cannot be seen in the column: its centroid sits on the line's upper
/// border, up to the line's width above the top, and the difference from
/// the emptiest frame on its lower border.
fn static_line_on_edge(img: &Gray, emptiest: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
    let h = img.height as i64;
    let j0 = (e + 0.5).ceil() as i64;
    let j1 = rows_read_below(e, hw).1.min(h - 2);
    if j0 < 0 || j0 + 2 > j1 || step == 0.0 {
        return false;
    }
    let pair = |f: &Gray, j: i64| 0.5 * (turned(f, c, step, j) + turned(f, c, step, j + 1));
    let under = (pair(img, j0) - pair(emptiest, j0)).abs();
    under <= 0.25 * step.abs()
        && (j0 + 2..j1).any(|j| pair(emptiest, j) - pair(img, j) >= 0.5 * step.abs())
}

/// Row `j` of column `c` of `img`, turned by the sign of an edge's step
/// `step` so that the dome side lies low and the background high.
fn turned(img: &Gray, c: usize, step: f64, j: i64) -> f64 {
    -step.signum() * f64::from(img.at(c, j as usize))
}

/// Column `c` of `img` less the same column of `emptiest`, as a profile
/// for [`profile_edge_with`] or [`step_model_edge`]: static clutter cancels.
fn difference<'i>(img: &'i Gray, emptiest: &'i Gray, c: usize) -> impl Fn(i64) -> f64 + 'i {
    move |j| img.light(c, j as usize) - emptiest.light(c, j as usize)
}

/// [`difference`] of the grey levels.
fn grey_difference<'i>(img: &'i Gray, emptiest: &'i Gray, c: usize) -> impl Fn(i64) -> f64 + 'i {
    move |j| f64::from(img.at(c, j as usize)) - f64::from(emptiest.at(c, j as usize))
}

/// The same region in the frames of a sequence where the bubble is largest
/// and smallest, each `None` for the frame itself (or when not decoded).
#[derive(Debug, Clone, Copy, Default)]
pub struct Extremes<'a> {
    /// The frame at the highest pressure.
    pub fullest: Option<&'a Gray>,
    /// The frame at the lowest pressure.
    pub emptiest: Option<&'a Gray>,
    /// This frame is the one at the lowest pressure. Nothing cancels
    /// clutter above its edge: see [`EdgeFit::clutter_on_top`].
    pub is_emptiest: bool,
}

/// Rows below the edge compared with the fullest frame, from this far
/// below the edge (beyond its blur), px.
const BELOW_FROM_PX: f64 = 2.5;
/// ... over this many rows.
const BELOW_ROWS: usize = 4;

/// Whether the rows just below an edge found at row `e` of column `c` are
/// the bubble's: the bubble only grows, so in the frame where it is
/// largest (`fullest`) the rows under any frame's true edge are bubble too
/// and look much the same, while under a line behind the bubble (a shelf
/// edge, a cable) that the edge fit took for the top they are background
/// in this frame and bubble in the fullest: they differ there by about the
/// whole contrast of the edge. Refused when the mean difference, in the
/// direction of the edge's step (`step`, the summed differences of
/// [`profile_edge`]), exceeds half of it. The shading of the dome and a
/// highlight differ between the frames too, but by a fraction of the
/// contrast. Rows outside the image pass.
fn below_is_dome(img: &Gray, fullest: &Gray, c: usize, e: f64, step: f64) -> bool {
    let j0 = (e + BELOW_FROM_PX).ceil() as usize;
    if j0 + BELOW_ROWS > img.height || step == 0.0 {
        return true;
    }
    let diff: f64 = (j0..j0 + BELOW_ROWS)
        .map(|j| f64::from(img.at(c, j)) - f64::from(fullest.at(c, j)))
        .sum::<f64>()
        / BELOW_ROWS as f64;
    // Under a false edge this frame shows background where the fullest
    // shows bubble: the difference has the sign of `-step`.
    -diff * step.signum() <= 0.5 * step.abs()
}

/// Rows above the edge compared with the emptiest frame, from this far
/// above the edge (beyond its blur), px; over [`BELOW_ROWS`] rows.
const ABOVE_FROM_PX: f64 = 3.5;

/// Whether the rows just above an edge found at row `e` of column `c` are
/// background: the bubble only grows, so in the frame where it is smallest
/// (`emptiest`) the rows above any frame's true edge are background too,
/// the same background (clutter and light stay put), while above an edge
/// inside the dome (the lower border of a broad highlight, which can step
/// down more than the bubble's own edge, or its upper border) this frame
/// shows the dome where the emptiest shows background. Refused when the
/// mean difference exceeds a quarter of the edge's step (on clean edges
/// it stays within a tenth). Rows outside the image pass.
fn above_is_background(img: &Gray, emptiest: &Gray, c: usize, e: f64, step: f64) -> bool {
    let j1 = (e - ABOVE_FROM_PX).floor();
    if j1 < BELOW_ROWS as f64 || step == 0.0 {
        return true;
    }
    let j1 = j1 as usize;
    let diff: f64 = (j1 + 1 - BELOW_ROWS..=j1)
        .map(|j| f64::from(img.at(c, j)) - f64::from(emptiest.at(c, j)))
        .sum::<f64>()
        / BELOW_ROWS as f64;
    // Above a false edge this frame shows the dome where the emptiest
    // shows background, darker or brighter (the upper border of a
    // highlight steps the other way from the bubble's edge).
    diff.abs() <= 0.25 * step.abs()
}

/// The difference between neighbouring rows, grey levels, beyond which a
/// column shows a line (clutter behind the bubble) rather than the
/// background's own gradient and noise: `max(15, 0.2 |step|)` for an edge
/// whose step is `step`.
fn line_limit(step: f64) -> f64 {
    15f64.max(0.2 * step.abs())
}

/// Whether column `c` of `img` shows a line between rows `a` and `b`
/// (pairs of neighbouring rows `j, j + 1` for `j` in `a..b`, clipped to
/// the image): a difference larger than `lim`.
fn line_in(img: &Gray, c: usize, a: i64, b: i64, lim: f64) -> bool {
    rows_apart_differ(img, c, (a, b), 1, lim)
}

/// Whether two rows `gap` apart, both within rows `a..=b` of column `c`
/// (clipped to the image), differ by more than `lim`.
fn rows_apart_differ(img: &Gray, c: usize, (a, b): (i64, i64), gap: i64, lim: f64) -> bool {
    let v = |j: i64| f64::from(img.at(c, j as usize));
    (a.max(0)..b.min(img.height as i64 - 1) + 1 - gap).any(|j| (v(j + gap) - v(j)).abs() > lim)
}

/// Whether the emptiest frame shows a line (clutter behind the bubble)
/// in the rows above row `e` of column `c` that the edge's location reads
/// (the edge window and the rows beyond it where the slope beside the
/// edge is measured), and in the rows of the window below it ([`line_in`],
/// [`line_limit`]). Below the edge the emptiest frame's own edge counts
/// as a line too, which is as it should be: its rows there are then no
/// clean background.
fn clutter_in_window(emptiest: &Gray, c: usize, e: f64, hw: f64, step: f64) -> (bool, bool) {
    let lim = line_limit(step);
    let lo = first_row_read_above(e, hw);
    let hi = (e + hw + 1.0).ceil() as i64;
    let mid = e.round() as i64;
    (
        line_in(emptiest, c, lo, mid - 1, lim),
        line_in(emptiest, c, mid + 1, hi + 1, lim),
    )
}

/// Whether column `c` of a frame with no emptier frame to compare with
/// shows a line in the rows above its edge at row `e` that the edge's
/// location reads (as [`clutter_in_window`]), up to [`ABOVE_FROM_PX`]
/// above the edge, beyond its own blur. Such a line, a few rows above a
/// flat top, pulls the edge by a good part of a pixel. Besides the
/// neighbouring rows of [`line_in`], rows two apart count here when they
/// differ by more than 1.5 times the limit: the flank of a faint blurred
/// cable (40 grey levels deep, blur 1.5 px) changes by less than the limit
/// a row, and one 8-12 rows above a 640x480 photo's first top had pulled
/// it 0.64 px up at 6 stated standard deviations. (Taken for the emptiest
/// frame's check of other frames as well, the same rule sent more columns
/// through the noisier difference from it, for a worse RMS.)
fn line_above(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
    let (a, b) = (
        first_row_read_above(e, hw),
        (e - ABOVE_FROM_PX).floor() as i64,
    );
    let lim = line_limit(step);
    line_in(img, c, a, b, lim) || rows_apart_differ(img, c, (a, b), 2, 1.5 * lim)
}

/// The first row above an edge at row `e` that [`profile_edge`] reads with
/// a window of half-height `hw`: the window, then the slope rows.
fn first_row_read_above(e: f64, hw: f64) -> i64 {
    (e - hw - 1.0).floor() as i64 - SLOPE_ROWS
}

/// Fits the top edge of a dome near `(x0, y0)` (image coordinates of `img`):
/// the edge row of each column of `x0 +- half_span` (`column_edge`), then
/// a least-squares parabola `y = A + B u + C u^2` (u = x - x0) through them;
/// the apex is its vertex. Passes: the second centres each column's window
/// on the first parabola, the third re-centres the span on the vertex when
/// the vertex is well determined. `None` when too few columns show an edge.
#[cfg(test)]
pub fn edge_fit(img: &Gray, x0: f64, y0: f64, s: EdgeSettings) -> Option<EdgeFit> {
    edge_fit_in(&mut Columns::new(img, s.half_window_px), x0, y0, 0.0, s)
}

/// [`edge_fit`] on columns some of which may be located already, the first
/// pass starting each column on the parabola of curvature `d2y/dx2 =
/// curvature` through `(x0, y0)` (the previous frame's, when tracking: the
/// second pass then finds most columns already converged).
pub fn edge_fit_in(
    cols: &mut Columns,
    x0: f64,
    y0: f64,
    curvature: f64,
    s: EdgeSettings,
) -> Option<EdgeFit> {
    edge_fit_core(cols, x0, y0, curvature, s, None)
}

/// The apex row on the bubble's axis: the edge fit of [`edge_fit_in`] with
/// its span centred on the axis column `axis.0` (standard error `axis.1`,
/// from [`axis_fit_in`]) and the even parabola `y = A + C (x - axis)^2`
/// (no linear term: the silhouette of an axisymmetric dome is mirror
/// symmetric about its axis). `apex` is the free fit of the same image,
/// which starts the columns' windows.
///
/// With the vertex column given, the columns on one side alone determine
/// the apex: a highlight or a line behind the bubble that spoils the other
/// side's columns (they are left out by their contrast) leaves a free
/// parabola's vertex, and so its apex row, poorly placed, while the even
/// one keeps most of its precision. The axis's own error is carried into
/// `y_std` (through `dA/ds` of the kept columns, which vanishes for columns
/// placed evenly about the axis); `x_vertex` and `x_std` are the axis's.
pub fn edge_fit_about(
    cols: &mut Columns,
    axis: (f64, f64),
    apex: &EdgeFit,
    s: EdgeSettings,
) -> Option<EdgeFit> {
    let u = axis.0 - apex.x_vertex;
    let y0 = apex.y + 0.5 * apex.curvature * u * u;
    edge_fit_core(cols, axis.0, y0, apex.curvature, s, Some(axis))
}

/// The passes of [`edge_fit_in`], or of [`edge_fit_about`] when `axis` is
/// given.
fn edge_fit_core(
    cols: &mut Columns,
    x0: f64,
    y0: f64,
    curvature: f64,
    s: EdgeSettings,
    axis: Option<(f64, f64)>,
) -> Option<EdgeFit> {
    let w = cols.img.width as i64;
    let span = s.half_span_px as i64;
    let mut centre = x0;
    let mut coef = [y0, 0.0, 0.5 * curvature];
    let even = axis.is_some();
    let mut result: Option<EdgeFit> = None;
    // The last pass's columns, span centre, vertex offset, and whether
    // something on the edge weakened its columns.
    let mut last = None;
    for pass in 0..3 {
        if pass == 2 {
            if axis.is_some() {
                break;
            }
            match result {
                Some(r) if r.x_std < 0.25 * span as f64 && (r.x_vertex - centre).abs() > 0.5 => {
                    let shift = r.x_vertex.round() - centre.round();
                    let u = shift;
                    coef = [
                        coef[0] + coef[1] * u + coef[2] * u * u,
                        coef[1] + 2.0 * coef[2] * u,
                        coef[2],
                    ];
                    centre += shift;
                }
                _ => break,
            }
        }
        let xc = centre.round() as i64;
        let mut located = Vec::with_capacity((2 * span + 1) as usize);
        // At most about 129 columns: wider spans (large photos) are sampled.
        let stride = (span as usize / 64).max(1);
        for c in (xc - span..=xc + span)
            .step_by(stride)
            .filter(|&c| c >= 0 && c < w)
        {
            let u = c as f64 - centre;
            let start = coef[0] + coef[1] * u + coef[2] * u * u;
            if let Some((e, step)) = cols.edge(c as usize, start) {
                located.push((u, e, step));
            }
        }
        // Leave out the columns with a bright spot under the edge, where
        // enough others remain.
        let unspotted: Vec<(f64, f64, f64)> = located
            .iter()
            .copied()
            .filter(|&(u, e, step)| {
                !spot_below(cols.img, (u + centre).round() as usize, e, cols.hw, step)
            })
            .collect();
        let enough = unspotted.len() >= SPOT_MIN_KEPT && 4 * unspotted.len() >= located.len();
        let candidates = if enough { &unspotted } else { &located };
        // Keep columns whose step has the dome's polarity and about the
        // contrast of most.
        let Some(strong) = strong_columns(candidates, 5, UPPER_SHARE) else {
            break;
        };
        let pts: Vec<(f64, f64)> = strong.iter().map(|l| (l.0, l.1)).collect();
        let (fit, pts) = robust_parabola(&pts, even)?;
        coef = fit.coef;
        let r = summarise(&fit, &pts, centre, span as f64, false);
        last = Some((pts, centre, r.x_vertex - centre, strong, located));
        result = Some(r);
    }
    let (pts, centre, u_v, strong, located) = last?;
    // Something on the edge weakened a tenth of its columns or more, or the
    // dome side turns back under a tenth of the strong ones (a broad
    // highlight's flank): then (only, it costs) the rows are tested
    // against the step model.
    let turning = || {
        strong
            .iter()
            .filter(|&&(u, e, step)| {
                turns_back(cols.img, (u + centre).round() as usize, e, cols.hw, step)
            })
            .count()
    };
    let test = if 10 * (located.len() - strong.len()) >= located.len() {
        Some(StepTest::Switch)
    } else if 10 * turning() >= strong.len() {
        Some(StepTest::Widen)
    } else {
        None
    };
    let lined = |&&(u, e, step): &&(f64, f64, f64)| {
        line_above(cols.img, (u + centre).round() as usize, e, cols.hw, step)
    };
    let clutter_on_top =
        cols.is_emptiest && 4 * located.iter().filter(lined).count() >= located.len();
    let (r, kept) = match test.and_then(|t| two_sided_refit(cols, &pts, centre, u_v, even, t)) {
        Some(TwoSided::Model(fit, kept, spread2)) => {
            let r = result?;
            let m = summarise(&fit, &kept, centre, span as f64, true);
            (
                EdgeFit {
                    columns: r.columns,
                    rms: r.rms,
                    y_std: (m.y_std * m.y_std + spread2).sqrt(),
                    ..m
                },
                kept,
            )
        }
        Some(TwoSided::Bias(b2)) => {
            let r = result?;
            (
                EdgeFit {
                    y_std: (r.y_std * r.y_std + b2).sqrt(),
                    ..r
                },
                pts,
            )
        }
        None => (result?, pts),
    };
    // Where columns were left out for a spot or a weakened step, the
    // spot's tail beyond them ([`tail_bias2`]).
    let tail = if test == Some(StepTest::Switch) {
        let out: Vec<f64> = located
            .iter()
            .filter(|l| !strong.iter().any(|s| s.0 == l.0))
            .map(|l| l.0)
            .collect();
        let sees_one_side = even && one_sided(&kept);
        tail_bias2(
            &kept,
            &out,
            span as f64,
            r.x_vertex - centre,
            even,
            sees_one_side,
        )
    } else {
        0.0
    };
    let r = EdgeFit {
        y_std: (r.y_std * r.y_std + tail).sqrt(),
        clutter_on_top,
        ..r
    };
    Some(match axis {
        None => r,
        Some((_, s_std)) => {
            // The axis's error through dA/ds (by refitting the kept columns
            // about a shifted axis), and the sides' disagreement.
            let h = 0.1;
            let at = |d: f64| {
                let shifted: Vec<(f64, f64)> = kept.iter().map(|&(u, y)| (u - d, y)).collect();
                parabola(&shifted, true).map(|f| f.coef[0])
            };
            let slope = match (at(h), at(-h)) {
                (Some(p), Some(m)) => (p - m) / (2.0 * h),
                _ => 0.0,
            };
            let sides = sides_bias2(&kept);
            EdgeFit {
                y_std: (r.y_std * r.y_std + (slope * s_std).powi(2) + sides).sqrt(),
                x_std: s_std,
                ..r
            }
        }
    })
}

/// The share of an edge's step by which the dome side under it must turn
/// back towards the background (and half of it away again) to count as a
/// bright spot ([`spot_below`]).
const SPOT_SHARE: f64 = 0.15;

/// The columns an edge fit keeps at the least when it leaves out those
/// with a spot under the edge (and a quarter of the columns located);
/// with fewer it keeps them all, as before the test.
const SPOT_MIN_KEPT: usize = 12;

/// Whether the dome side under an edge at row `e` of column `c` (step
/// `step`) shows a bright spot, a specular highlight: within the rows below
/// the edge that its location reads (from 1.5 px below, through the window
/// and the slope rows), it turns back towards the background by more than
/// [`SPOT_SHARE`] of the step and then away from it by half that again. A
/// spot's flank within the edge's blur cancels part of the step's lower
/// half and lifts the centroid: measured against the same 640x480 photo
/// drawn without the spot, 0.3-1.2 px over the 45 columns under it, and
/// 0.5-2.4 px once the slope below the edge (measured on the spot's lower
/// flank) is subtracted. A dome's shading turns that fast nowhere, nor
/// does a step down to the clamp (it does not turn back).
fn spot_below(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
    let (j0, j1) = rows_read_below(e, hw);
    let j1 = j1.min(img.height as i64 - 1);
    if j0 >= j1 || step == 0.0 {
        return false;
    }
    let v = |j: i64| turned(img, c, step, j);
    let lim = SPOT_SHARE * step.abs();
    let (mut low, mut rise, mut fell) = (f64::INFINITY, 0.0f64, false);
    let mut peak = f64::NEG_INFINITY;
    for j in j0..=j1 {
        let x = v(j);
        low = low.min(x);
        if x - low > rise {
            rise = x - low;
            peak = x;
        }
        if rise > lim && peak - x > 0.5 * lim {
            fell = true;
        }
    }
    rise > lim && fell
}

/// The share of an edge's step by which the dome side under it must turn
/// back towards the background for the edge to be tested against the step
/// model ([`turns_back`], [`StepTest::Widen`]).
const TURN_SHARE: f64 = 0.1;

/// The rows below an edge at row `e` (window half-height `hw`) that its
/// location reads, beyond its own blur: from 1.5 px below the edge through
/// the window and the slope rows; not clipped to the image.
fn rows_read_below(e: f64, hw: f64) -> (i64, i64) {
    (
        (e + 1.5).ceil() as i64,
        (e + hw + 1.0).ceil() as i64 + SLOPE_ROWS,
    )
}

/// Whether the dome side under an edge at row `e` of column `c` (step
/// `step`) turns back towards the background by more than [`TURN_SHARE`]
/// of the step within the rows below the edge that its location reads
/// ([`rows_read_below`]; means of neighbouring rows, against the noise). A
/// broad highlight whose flank rises slowly from the edge does this
/// without turning away again within those rows, so [`spot_below`] does
/// not leave the column out; its rise cuts the lower tail of the blurred
/// step short and lifts the centroid (0.27 px on a drawn dome), which the
/// minmod slope below the edge misses where the flank turns within the
/// slope rows. A flat dome side stays within the noise.
fn turns_back(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
    let (j0, j1) = rows_read_below(e, hw);
    let j1 = j1.min(img.height as i64 - 2);
    if j0 >= j1 || step == 0.0 {
        return false;
    }
    let v = |j: i64| 0.5 * (turned(img, c, step, j) + turned(img, c, step, j + 1));
    let mut low = f64::INFINITY;
    let mut rise = 0.0f64;
    for j in j0..j1 {
        let x = v(j);
        low = low.min(x);
        rise = rise.max(x - low);
    }
    rise > TURN_SHARE * step.abs()
}

/// The columns each side of the axis that the mirror test needs
/// ([`sides_bias2`]).
const MIRROR_MIN_SIDE: usize = 5;

/// Whether an even fit's columns `kept` (`u` from the axis) leave a side
/// with too few for the mirror test ([`MIRROR_MIN_SIDE`]): the fit then
/// sees one side only.
fn one_sided(kept: &[(f64, f64)]) -> bool {
    side(kept, true).count().min(side(kept, false).count()) < MIRROR_MIN_SIDE
}

/// The columns of `kept` (`u` from the axis) left of the axis (`left`) or
/// right of it; a column on the axis is on neither side.
fn side(kept: &[(f64, f64)], left: bool) -> impl Iterator<Item = (f64, f64)> + '_ {
    kept.iter()
        .copied()
        .filter(move |p| (p.0 < 0.0) == left && p.0 != 0.0)
}

/// The mirror test of an even fit about the axis: the apex row fitted on
/// each side alone (`u < 0`, `u > 0`, each the even parabola, at least
/// [`MIRROR_MIN_SIDE`] columns, [`side`]), whose difference `D` a
/// symmetric silhouette makes zero but a highlight or clutter on one side
/// does not. Returns the squared bias of
/// the joint apex this implies beyond the difference's own variance,
/// `max(0, (D^2 - var D) / 4)` (half the difference: the joint fit
/// shares the biased side's columns about equally), 0 when a side has too
/// few columns.
fn sides_bias2(kept: &[(f64, f64)]) -> f64 {
    let apex_of = |left: bool| {
        let pts: Vec<(f64, f64)> = side(kept, left).collect();
        if pts.len() < MIRROR_MIN_SIDE {
            return None;
        }
        let f = parabola(&pts, true)?;
        Some((
            f.coef[0],
            f.cov[0][0] * lag1_inflation(&f.residuals(&pts)).powi(2),
        ))
    };
    match (apex_of(true), apex_of(false)) {
        (Some((a, va)), Some((b, vb))) => (((a - b).powi(2) - va - vb) / 4.0).max(0.0),
        _ => 0.0,
    }
}

/// How many distances [`tail_bias2`] tries, in steps of an eighth of the
/// edge fit's half-span out to half of it.
const TAIL_REACHES: usize = 4;

/// The squared bias of the apex row at `u_v` that the tail of a spot
/// beyond the columns left out for it (`out`, spotted or weakened: see
/// [`spot_below`] and [`strong_columns`]) puts into the kept columns
/// `pts`. A highlight's flank fades with distance: where it no longer
/// weakens the step enough for a column to be left out, it still lifts
/// the centroid; and where the spot lies beside the top, the columns next
/// to those left out are the ones nearest the apex. On 640x480 photos with
/// the highlight against one side of the top the kept columns 5-10 px
/// beyond it were 0.05-0.2 px high, and the even fit, which then sees one
/// side only, put the apex 0.12-0.16 px high at a stated 0.03 px (4.1-5.4
/// standard errors), where the step model was no better.
///
/// A Hausman test like the step model's ([`two_sided_refit`]): the
/// parabola is fitted again without the kept columns within a reach of
/// any left out, for reaches of an eighth, a quarter, three eighths and
/// half the half-span `span` ([`TAIL_REACHES`]; a spot's reach is not
/// known), as long as half the kept columns remain (and 8). Without a
/// bias the two fits differ by `D` of variance `var D = var(without) -
/// var(all)` (Hausman's identity, the same residual variance for both),
/// and the largest `D^2 - var D` over the reaches (not below 0) is
/// returned, to be added to the apex row's variance. Fits of fewer columns,
/// extrapolated to the apex, are so noisy that the largest excess would be
/// their noise: with 8 columns at the least, photos 0.01-0.14 px off were
/// given 0.4-2 px.
///
/// Where the fit sees one side of the axis only (`sees_one_side`: an even fit
/// whose mirror test cannot be made, [`one_sided`]), the columns beyond
/// the spot's reach may be too few for this test to tell a bias from
/// noise, and nothing else tests it: then at least `var D` at the
/// shortest reach is returned, so that the apex row's stated variance
/// becomes that of the fit without the columns next to those left out
/// (the apex stays the whole fit's). On a 640x480 photo with a cable
/// hiding the far side, one side's 19 columns, all within 20 px of the
/// spot, put the apex 0.156 px high at a stated 0.031 px; the fit without
/// the nearest agreed with it to 0.055 +- 0.062 px.
fn tail_bias2(
    pts: &[(f64, f64)],
    out: &[f64],
    span: f64,
    u_v: f64,
    even: bool,
    sees_one_side: bool,
) -> f64 {
    if out.is_empty() {
        return 0.0;
    }
    let Some(all) = parabola(pts, even) else {
        return 0.0;
    };
    let s2 = all.s2 * lag1_inflation(&all.residuals(pts)).powi(2);
    let at = |f: &Parabola| f.coef[0] + f.coef[1] * u_v + f.coef[2] * u_v * u_v;
    let mut worst = 0.0f64;
    // `var D` at the shortest reach tested.
    let mut nearest = None;
    for k in 1..=TAIL_REACHES {
        let reach = span * k as f64 / (2 * TAIL_REACHES) as f64;
        let far: Vec<(f64, f64)> = pts
            .iter()
            .copied()
            .filter(|p| out.iter().all(|&o| (p.0 - o).abs() > reach))
            .collect();
        if far.len() == pts.len() {
            continue;
        }
        if far.len() < 8.max(pts.len() / 2) {
            break;
        }
        let Some(sub) = parabola(&far, even) else {
            break;
        };
        let d = at(&sub) - at(&all);
        let var_d = s2 * (sub.unscaled_var_at(u_v) - all.unscaled_var_at(u_v)).max(0.0);
        worst = worst.max(d * d - var_d);
        nearest.get_or_insert(var_d);
    }
    match nearest {
        Some(var_d) if sees_one_side => worst.max(var_d),
        _ => worst,
    }
}

/// How an edge fit is tested against the step model ([`two_sided_refit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum StepTest {
    /// A tenth of the columns or more were weakened (left out by
    /// [`strong_columns`] or [`spot_below`]): every kept column is tested,
    /// and the model's rows replace the centroids' where they differ.
    Switch,
    /// Only the dome side turns back under a tenth of the kept columns
    /// ([`turns_back`]): about [`WIDEN_COLUMNS`] of them are tested, and
    /// the bias found widens the apex row's uncertainty; the centroids
    /// stay. Switching there, on every column, took twice the time on
    /// glossy photos and added the model's noise where there was little
    /// bias to remove (100 glossy 1280x960 photos: 0.048 against 0.040 px).
    Widen,
}

/// The columns, evenly spread over the span, that [`StepTest::Widen`]
/// tests.
const WIDEN_COLUMNS: usize = 24;

/// What the test of the centroids against the step model says.
enum TwoSided {
    /// The centroids are biased: the robust parabola through the model's
    /// rows and the columns it kept, and the edge-model term of its apex
    /// row, px^2: the squared half-difference of the two models at the
    /// apex beyond its variance, `max(0, D^2 - sd^2) / 4`. Two edge models
    /// that each fit their rows and disagree at the apex leave the apex
    /// anywhere in their spread: the step model's straight dome side is
    /// no more the truth under a highlight's curved flank than the
    /// centroid's flat one (a light dome with a highlight against its top,
    /// 800x600: step model 0.34 px off at a stated 0.05 px without it,
    /// 0.15 px with it).
    Model(Parabola, Vec<(f64, f64)>, f64),
    /// Not significantly: the squared difference at the apex beyond its
    /// variance, an estimate of the centroid apex's squared bias, px^2.
    Bias(f64),
}

/// The fit's apex, vertex, curvature and their standard errors, each
/// inflated for the residuals' correlation along the edge.
fn summarise(
    fit: &Parabola,
    pts: &[(f64, f64)],
    centre: f64,
    lim: f64,
    two_sided: bool,
) -> EdgeFit {
    let [a, b, c] = fit.coef;
    let u_v = if c > 1e-9 {
        (-b / (2.0 * c)).clamp(-lim, lim)
    } else {
        0.0
    };
    // Delta method for the vertex column u_v = -B / (2C).
    let x_std = if c > 1e-9 {
        let g = [0.0, -1.0 / (2.0 * c), b / (2.0 * c * c)];
        quad_form(&fit.cov, &g).sqrt()
    } else {
        f64::INFINITY
    };
    let inflate = lag1_inflation(&fit.residuals(pts));
    EdgeFit {
        y: a + b * u_v + c * u_v * u_v,
        y_std: fit.var_at(u_v).sqrt() * inflate,
        x_vertex: centre + u_v,
        x_std: x_std * inflate,
        curvature: 2.0 * c,
        curvature_std: 2.0 * fit.cov[2][2].max(0.0).sqrt() * inflate,
        columns: pts.len(),
        rms: (fit.rss / pts.len() as f64).sqrt(),
        two_sided,
        clutter_on_top: false,
    }
}

/// Residual correlation along the edge: the factor `sqrt((1 + r) / (1 - r))`
/// of the lag-1 autocorrelation `r` (clamped to 0-0.9) by which standard
/// errors computed for independent residuals are too small.
pub(crate) fn lag1_inflation(res: &[f64]) -> f64 {
    let num: f64 = res.windows(2).map(|p| p[0] * p[1]).sum();
    let den: f64 = res.iter().map(|r| r * r).sum();
    let rho = if den > 0.0 {
        (num / den).clamp(0.0, 0.9)
    } else {
        0.0
    };
    ((1.0 + rho) / (1.0 - rho)).sqrt()
}

/// How far apart the two estimators may be on a clean edge, px, beyond
/// their noise: the centroid and the step model differ slightly in how they
/// treat pixel sampling and the blur's shape (on clean synthetic edges the
/// difference at the apex stays within about 0.01-0.04 px).
const TWO_SIDED_MARGIN_PX: f64 = 0.02;

/// The share of the upper quartile's contrast below which an apex column
/// is left out ([`strong_columns`]).
const UPPER_SHARE: f64 = 0.8;

/// A test of the centroid edge against the step model, in the manner of
/// Hausman's specification test (J. A. Hausman, "Specification tests in
/// econometrics", Econometrica 46, 1978, doi:10.2307/1913827): the
/// centroids ([`profile_edge`]) are the precise estimate, unbiased when the
/// dome side under the edge is flat; the step model ([`step_model_edge`])
/// stays unbiased when it is not, at more noise. Each column's difference
/// between the two is fitted by a parabola and evaluated at the apex
/// (`u_v`); its standard error comes from the differences' own scatter
/// (what the shared noise cancels from). By Hausman's identity that
/// variance, `sd^2`, is the step model's variance less the centroids', so
/// the centroids' squared bias `b^2`, estimated by `D^2 - sd^2`, costs more
/// than the step model's extra noise when `D^2 > 2 sd^2`. When the
/// difference exceeds sqrt(2) standard errors plus [`TWO_SIDED_MARGIN_PX`],
/// something under the edge (a highlight's flank, texture) biased the
/// centroids more than the step model's noise costs, and the robust
/// parabola through the step model's rows is returned instead (with
/// [`StepTest::Switch`] only). Below it, or with [`StepTest::Widen`], the
/// difference still estimates the centroids' bias on a frame where
/// something lies on the edge (the test is made only there): its square
/// beyond its variance, `max(0, D^2 - sd^2)` (unbiased for the squared
/// bias), is returned to be added to the apex row's variance.
fn two_sided_refit(
    cols: &mut Columns,
    pts: &[(f64, f64)],
    centre: f64,
    u_v: f64,
    even: bool,
    test: StepTest,
) -> Option<TwoSided> {
    let switch = test == StepTest::Switch;
    let every = if switch {
        1
    } else {
        (pts.len() / WIDEN_COLUMNS).max(1)
    };
    let mut model = Vec::with_capacity(pts.len());
    let mut diff = Vec::with_capacity(pts.len());
    for &(u, e) in pts.iter().step_by(every) {
        // `u` is a column minus `centre`, so rounding recovers the column.
        let c = (centre + u).round() as usize;
        if let Some(m) = cols.model_edge(c, e) {
            model.push((u, m));
            diff.push((u, m - e));
        }
    }
    if diff.len() < 8.max(pts.len() / (2 * every)) {
        return None;
    }
    let d = parabola(&diff, false)?;
    let sd = d.var_at(u_v).sqrt() * lag1_inflation(&d.residuals(&diff));
    let [a, b, c] = d.coef;
    let at_apex = a + b * u_v + c * u_v * u_v;
    if !switch || at_apex.abs() <= std::f64::consts::SQRT_2 * sd + TWO_SIDED_MARGIN_PX {
        return Some(TwoSided::Bias((at_apex * at_apex - sd * sd).max(0.0)));
    }
    let (fit, kept) = robust_parabola(&model, even)?;
    let spread2 = 0.25 * (at_apex * at_apex - sd * sd).max(0.0);
    Some(TwoSided::Model(fit, kept, spread2))
}

/// The located columns `(column, edge row, step)` whose step has the
/// dome's polarity (the sign of the summed steps) and at least a quarter of
/// the median contrast, and at least `upper_share` of the upper quartile's
/// contrast, and, of those, at most `1 / upper_share` of their lower
/// quartile's contrast; `None` when fewer than `min` remain.
///
/// The second bound is for the apex: the contrast of a matte dome against
/// its background changes slowly along the edge, so a column whose step is
/// markedly weaker than most has something added where it is measured: a
/// highlight on the dome against the edge, a dark line behind it. Such a
/// column's centroid is pulled off the edge, most by a highlight's flank
/// within the window (0.5-1.2 px on a 640x480 synthetic dome). A highlight
/// on a light dome (brighter than its background) makes the step markedly
/// stronger instead, and pulls the centroid into the dome the same way
/// (0.25-0.6 px on 640x480 and 800x600 photos): the third bound.
fn strong_columns(
    located: &[(f64, f64, f64)],
    min: usize,
    upper_share: f64,
) -> Option<Vec<(f64, f64, f64)>> {
    let sign = located.iter().map(|l| l.2).sum::<f64>().signum();
    let mut mags: Vec<f64> = located
        .iter()
        .map(|l| l.2 * sign)
        .filter(|m| *m > 0.0)
        .collect();
    if mags.len() < min {
        return None;
    }
    mags.sort_by(f64::total_cmp);
    let med = mags[mags.len() / 2];
    let upper = mags[3 * mags.len() / 4];
    let floor = (0.25 * med).max(upper_share * upper);
    // The same bound from the other side, among the columns above the
    // floor: a highlight adds light, which weakens the step of a dark dome
    // and strengthens that of a light one where it lies against the edge.
    let above: Vec<f64> = mags.iter().copied().filter(|m| *m > floor).collect();
    let ceiling = match above.get(above.len() / 4) {
        Some(&lower) => lower / upper_share,
        None => f64::INFINITY,
    };
    let pts: Vec<(f64, f64, f64)> = located
        .iter()
        .copied()
        .filter(|l| l.2 * sign > floor && l.2 * sign < ceiling)
        .collect();
    (pts.len() >= min).then_some(pts)
}

/// The smaller of two slopes of the same sign, else 0.
fn minmod(a: f64, b: f64) -> f64 {
    if a * b <= 0.0 {
        0.0
    } else if a.abs() < b.abs() {
        a
    } else {
        b
    }
}

/// The bubble's axis column from the mirror symmetry of its top edge over a
/// wide span (`half_span_px` each side of the apex, clipped to the image):
/// the edge rows of the columns are fitted by the even model
/// `y = A + C (x - s)^2 + E (x - s)^4`, linear in `A, C, E`, and the axis `s`
/// minimises the residual sum of squares (golden-section search within
/// +-8 px of `near`, the axis known from the frames before, else of the
/// vertex: a highlight or clutter on one side of the top can pull the
/// vertex of the edge fit further than that). Flat tops pin the axis down
/// only through their far flanks, hence the wide span; the row is not taken
/// from this fit (the even model is biased at the apex by the higher terms
/// over a wide span). Returns the axis and its standard error, px. The
/// columns may be located already (by the edge fit of the same image).
pub fn axis_fit_in(
    cols: &mut Columns,
    apex: &EdgeFit,
    near: Option<f64>,
    half_span_px: usize,
) -> Option<(f64, f64)> {
    let w = cols.img.width as i64;
    let near = near.unwrap_or(apex.x_vertex);
    let xc = near.round() as i64;
    let k = 0.5 * apex.curvature.max(0.0);
    let span = half_span_px as i64;
    let mut located = Vec::new();
    // At most about 97 columns: wider spans are sampled (the axis is a
    // least-squares fit; more columns of the same edge add little).
    let stride = (span as usize).div_ceil(24).max(1);
    for c in (xc - span..=xc + span)
        .step_by(stride)
        .filter(|&c| c >= 0 && c < w)
    {
        let u = c as f64 - apex.x_vertex;
        if let Some((e, step)) = cols.edge(c as usize, apex.y + k * u * u) {
            located.push((c as f64, e, step));
        }
    }
    let mut pts: Vec<(f64, f64)> = strong_columns(&located, 9, 0.0)?
        .iter()
        .map(|l| (l.0, l.1))
        .collect();
    let scale = half_span_px.max(1) as f64;
    // Columns far off the even model (a cable or a shelf edge crossing the
    // flanks) are left out as in `robust_parabola`, and the axis found again.
    let mut s = golden_axis(&even_fit_rss(&pts, near, scale), near, 8.0);
    // A minimum on the search's border lies beyond it.
    if (s - near).abs() > 7.9 {
        return None;
    }
    for _ in 0..3 {
        let kept = within_biweight(&pts, &even_residuals(&pts, s, scale)?);
        if kept.len() == pts.len() || kept.len() < 9.max(pts.len() / 2) {
            break;
        }
        pts = kept;
        // Near the first axis: leaving out a few columns refines it, it
        // does not move it to another minimum.
        s = golden_axis(&even_fit_rss(&pts, near, scale), s, 2.0);
    }
    let rss = even_fit_rss(&pts, near, scale);
    if (s - near).abs() > 7.9 {
        return None;
    }
    // Standard error from the curvature of RSS(s): var = 2 sigma^2 / RSS''.
    let h = 0.05;
    let (r0, rp, rm) = (rss(s), rss(s + h), rss(s - h));
    let curv = (rp + rm - 2.0 * r0) / (h * h);
    let n = pts.len() as f64;
    let sigma2 = r0 / (n - 4.0).max(1.0);
    if curv.is_nan() || curv <= 0.0 {
        return None;
    }
    Some((s, (2.0 * sigma2 / curv).sqrt()))
}

/// The axis in `near +- half` px that minimises `rss` (golden-section
/// search).
fn golden_axis(rss: &impl Fn(f64) -> f64, near: f64, half: f64) -> f64 {
    let (mut a, mut b) = (near - half, near + half);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (rss(c), rss(d));
    while b - a > 1e-4 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = rss(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = rss(d);
        }
    }
    0.5 * (a + b)
}

/// The residuals of the least-squares fit of the even model of
/// [`even_fit_rss`] about the axis `s`.
fn even_residuals(pts: &[(f64, f64)], s: f64, scale: f64) -> Option<Vec<f64>> {
    let basis = |x: f64| {
        let v = ((x - s) / scale).powi(2);
        nalgebra::Vector3::new(1.0, v, v * v)
    };
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(x, y) in pts {
        let g = basis(x);
        ata += g * g.transpose();
        aty += g * y;
    }
    let c = ata.cholesky()?.solve(&aty);
    Some(pts.iter().map(|&(x, y)| y - basis(x).dot(&c)).collect())
}

/// `RSS(s)` of the least-squares fit of `y = A + C v + E v^2`, with
/// `v = ((x - s) / scale)^2`, to `pts`, for any axis `s`. Power sums of the
/// abscissa (centred on `centre`, divided by `scale`) are taken once, and
/// each evaluation expands `sum (t - u)^m` binomially: O(1) per `s`, where
/// refitting costs O(points) for each of the 30-odd evaluations of the
/// golden-section search.
fn even_fit_rss(pts: &[(f64, f64)], centre: f64, scale: f64) -> impl Fn(f64) -> f64 {
    let ym = pts.iter().map(|p| p.1).sum::<f64>() / pts.len().max(1) as f64;
    let (mut st, mut sty, mut syy) = ([0.0f64; 9], [0.0f64; 5], 0.0);
    for &(x, y) in pts {
        let (t, y) = ((x - centre) / scale, y - ym);
        let mut p = 1.0;
        for k in 0..9 {
            st[k] += p;
            if k < 5 {
                sty[k] += p * y;
            }
            p *= t;
        }
        syy += y * y;
    }
    // Binomial coefficients C(m, j), m <= 8.
    let mut binom = [[0.0f64; 9]; 9];
    for m in 0..9 {
        binom[m][0] = 1.0;
        for j in 1..=m {
            binom[m][j] = binom[m - 1][j - 1] + if j < m { binom[m - 1][j] } else { 0.0 };
        }
    }
    move |s: f64| {
        let u = (s - centre) / scale;
        let mut nu = [1.0f64; 9];
        for k in 1..9 {
            nu[k] = nu[k - 1] * -u;
        }
        // sum (t - u)^m and sum (t - u)^m y.
        let shifted = |sums: &[f64], m: usize| -> f64 {
            (0..=m)
                .map(|j| binom[m][j] * nu[m - j] * sums[j])
                .sum::<f64>()
        };
        let mm = |m: usize| shifted(&st, m);
        let ata = nalgebra::Matrix3::new(
            mm(0),
            mm(2),
            mm(4),
            mm(2),
            mm(4),
            mm(6),
            mm(4),
            mm(6),
            mm(8),
        );
        let aty = nalgebra::Vector3::new(shifted(&sty, 0), shifted(&sty, 2), shifted(&sty, 4));
        match ata.cholesky() {
            Some(ch) => (syy - ch.solve(&aty).dot(&aty)).max(0.0),
            None => f64::INFINITY,
        }
    }
}

/// `g^T M g` (clamped at 0), the variance of a linear combination `g` of
/// estimates whose covariance is `M`.
pub(crate) fn quad_form<R: AsRef<[f64]>>(m: &[R], g: &[f64]) -> f64 {
    let mut v = 0.0;
    for (gi, row) in g.iter().zip(m) {
        for (gj, mij) in g.iter().zip(row.as_ref()) {
            v += gi * mij * gj;
        }
    }
    v.max(0.0)
}

struct Parabola {
    coef: [f64; 3],
    /// (X^T X)^-1 scaled by the residual variance.
    cov: [[f64; 3]; 3],
    rss: f64,
    /// The residual variance, `rss` over the degrees of freedom (at least
    /// 1).
    s2: f64,
}

impl Parabola {
    fn var_at(&self, u: f64) -> f64 {
        quad_form(&self.cov, &[1.0, u, u * u])
    }

    /// [`Parabola::var_at`] without the residual variance: for comparing
    /// fits of the same points' subsets under one variance.
    fn unscaled_var_at(&self, u: f64) -> f64 {
        self.var_at(u) / self.s2.max(f64::MIN_POSITIVE)
    }

    /// `y - fit(u)` of each point.
    fn residuals(&self, pts: &[(f64, f64)]) -> Vec<f64> {
        let [a, b, c] = self.coef;
        pts.iter()
            .map(|&(u, y)| y - (a + b * u + c * u * u))
            .collect()
    }
}

/// The points whose residual `res` lies within Tukey's biweight cut-off,
/// 4.685 robust standard deviations (the scale from the median absolute
/// residual, at least 0.05 px).
fn within_biweight(pts: &[(f64, f64)], res: &[f64]) -> Vec<(f64, f64)> {
    let mut abs: Vec<f64> = res.iter().map(|r| r.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let scale = (1.4826 * abs[abs.len() / 2]).max(0.05);
    pts.iter()
        .zip(res)
        .filter(|(_, r)| r.abs() < 4.685 * scale)
        .map(|(p, _)| *p)
        .collect()
}

/// The least-squares parabola through the columns after those far off it
/// are left out: Tukey's biweight (c = 4.685 robust standard deviations,
/// the scale from the median absolute residual, at least 0.05 px) by
/// iteratively reweighted least squares, then a plain fit through the
/// columns of non-zero weight (so that its covariance is the usual one).
/// A cable or the corner of a shelf that crosses a few columns no longer
/// bends the apex. Returns the fit and the columns kept.
fn robust_parabola(pts: &[(f64, f64)], even: bool) -> Option<(Parabola, Vec<(f64, f64)>)> {
    let mut kept = pts.to_vec();
    let mut fit = parabola(&kept, even)?;
    for _ in 0..4 {
        let c = fit.coef;
        let res: Vec<f64> = pts
            .iter()
            .map(|&(u, y)| y - (c[0] + c[1] * u + c[2] * u * u))
            .collect();
        let next = within_biweight(pts, &res);
        if next.len() == kept.len() || next.len() < 5.max(pts.len() / 2) {
            break;
        }
        kept = next;
        fit = parabola(&kept, even)?;
    }
    Some((fit, kept))
}

/// The least-squares parabola `y = A + B u + C u^2` through `pts`; with
/// `even`, `B = 0` (its row and column of the covariance are zero).
fn parabola(pts: &[(f64, f64)], even: bool) -> Option<Parabola> {
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(u, y) in pts {
        let g = nalgebra::Vector3::new(1.0, if even { 0.0 } else { u }, u * u);
        ata += g * g.transpose();
        aty += g * y;
    }
    if even {
        // The linear term fixed at zero: a unit on the diagonal keeps the
        // system invertible, and its solution and covariance are zeroed.
        ata[(1, 1)] = 1.0;
    }
    let mut inv = ata.try_inverse()?;
    if even {
        for k in 0..3 {
            inv[(1, k)] = 0.0;
            inv[(k, 1)] = 0.0;
        }
    }
    let c = inv * aty;
    let rss: f64 = pts
        .iter()
        .map(|&(u, y)| {
            let r = y - (c[0] + c[1] * u + c[2] * u * u);
            r * r
        })
        .sum();
    let dof = (pts.len() as f64 - if even { 2.0 } else { 3.0 }).max(1.0);
    let s2 = rss / dof;
    let mut cov = [[0.0; 3]; 3];
    for (i, row) in cov.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = inv[(i, j)] * s2;
        }
    }
    Some(Parabola {
        coef: [c[0], c[1], c[2]],
        cov,
        rss,
        s2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_peak_recovers_offset_of_a_paraboloid() {
        let (px, py) = (0.3, -0.2);
        let mut f = [[0.0; 3]; 3];
        for (j, row) in f.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                let (x, y) = (i as f64 - 1.0, j as f64 - 1.0);
                *v = 1.0 - 0.2 * (x - px).powi(2) - 0.1 * (y - py).powi(2)
                    + 0.05 * (x - px) * (y - py);
            }
        }
        let (ox, oy) = quadratic_peak(&f);
        assert!(
            (ox - px).abs() < 1e-12 && (oy - py).abs() < 1e-12,
            "{ox} {oy}"
        );
    }

    #[test]
    fn reduce_is_the_rounded_block_mean() {
        let (w, h) = (37usize, 23usize);
        let img = Gray {
            width: w,
            height: h,
            data: (0..w * h).map(|i| ((i * 7919) % 251) as u8).collect(),
            tone: crate::track::image::Tone::LINEAR,
        };
        for f in [2usize, 3] {
            let r = reduce(&img, f).unwrap();
            assert_eq!((r.width, r.height), (w / f, h / f));
            for y in 0..h / f {
                for x in 0..w / f {
                    let mut sum = 0u32;
                    for j in 0..f {
                        for i in 0..f {
                            sum += u32::from(img.at(x * f + i, y * f + j));
                        }
                    }
                    let want = (f64::from(sum) / (f * f) as f64).round();
                    assert!(
                        (f64::from(r.at(x, y)) - want).abs() <= 0.5,
                        "f {f} ({x}, {y})"
                    );
                }
            }
        }
    }

    /// The O(1) evaluation of the even fit's RSS against refitting the
    /// points directly (SVD of the design matrix) at several axes.
    #[test]
    fn even_fit_rss_matches_a_direct_refit() {
        let pts: Vec<(f64, f64)> = (0..150)
            .map(|i| {
                let x = 100.0 + i as f64;
                let u = x - 173.4;
                (
                    x,
                    40.0 + 0.01 * u * u - 2e-7 * u.powi(4) + 0.3 * (i as f64 * 1.7).sin(),
                )
            })
            .collect();
        let rss = even_fit_rss(&pts, 175.0, 75.0);
        for s in [167.0, 171.2, 173.4, 175.0, 180.9] {
            let a = nalgebra::DMatrix::from_fn(pts.len(), 3, |r, c| {
                ((pts[r].0 - s) / 75.0).powi(2 * c as i32)
            });
            let y = nalgebra::DVector::from_iterator(pts.len(), pts.iter().map(|p| p.1));
            let coef = a.clone().svd(true, true).solve(&y, 1e-14).unwrap();
            let direct = (&y - &a * coef).norm_squared();
            let fast = rss(s);
            assert!(
                (fast - direct).abs() <= 1e-9 * direct.max(1.0),
                "s = {s}: {fast} vs {direct}"
            );
        }
    }

    /// A step blurred by a Gaussian and averaged over each pixel, built by
    /// numerical quadrature (not through the model's closed forms): 200
    /// above the edge, `60 + ramp (y - e)` below it.
    fn blurred_step(e: f64, sigma: f64, ramp: f64, len: usize) -> Vec<f64> {
        let f = |y: f64| if y < e { 200.0 } else { 60.0 + ramp * (y - e) };
        let (n_px, n_k) = (24, 3000);
        (0..len)
            .map(|j| {
                let mut acc = 0.0;
                let mut wsum = 0.0;
                for a in 0..n_px {
                    let y = j as f64 - 0.5 + (a as f64 + 0.5) / n_px as f64;
                    for b in 0..n_k {
                        let t = -6.0 * sigma + 12.0 * sigma * (b as f64 + 0.5) / n_k as f64;
                        let w = (-0.5 * (t / sigma).powi(2)).exp();
                        acc += w * f(y - t);
                        wsum += w;
                    }
                }
                acc / wsum
            })
            .collect()
    }

    /// The step model finds the edge of blurred, pixel-averaged steps to
    /// 0.01 px at blurs of 0.8-2.5 px and any sub-pixel position, also with
    /// a slope on the dome side that starts at the edge, which moves the
    /// centroid by more than 0.05 px.
    #[test]
    fn the_step_model_is_not_moved_by_a_slope_under_the_edge() {
        for sigma in [0.8, 1.5, 2.5] {
            for e in [20.0, 20.27, 20.5, 20.81] {
                for ramp in [0.0, 10.0] {
                    let p = blurred_step(e, sigma, ramp, 40);
                    let px = |j: i64| p[j as usize];
                    let m = step_model_edge(px, 40, e.round() + 0.3).unwrap();
                    assert!(
                        (m - e).abs() < 0.01,
                        "sigma {sigma} edge {e} ramp {ramp}: model {m}"
                    );
                    if ramp > 0.0 && sigma >= 1.5 {
                        let (c, _) = profile_edge(px, 40, e, 3.0).unwrap();
                        assert!(
                            (c - e).abs() > 0.05,
                            "sigma {sigma} edge {e}: centroid {c}, no bias to show"
                        );
                    }
                }
            }
        }
    }

    /// A dome with an area-sampled edge: rows covered by a parabola
    /// `y = y0 + k (x - xa)^2`, background 200 above, 60 below, integrated
    /// exactly per pixel (supersampled 64x in x, exact in y).
    #[test]
    fn edge_fit_finds_sub_pixel_apex() {
        let (w, h) = (80usize, 60usize);
        let (xa, y0, k) = (40.3, 25.37, 0.004);
        let mut data = vec![0u8; w * h];
        let mut fdata = vec![0.0f64; w * h];
        for x in 0..w {
            for sx in 0..64 {
                let xs = x as f64 - 0.5 + (sx as f64 + 0.5) / 64.0;
                let e = y0 + k * (xs - xa).powi(2);
                for y in 0..h {
                    // pixel y spans [y - 0.5, y + 0.5); below the edge is dome.
                    let cov = ((y as f64 + 0.5) - e).clamp(0.0, 1.0);
                    fdata[y * w + x] += cov / 64.0;
                }
            }
        }
        for (d, f) in data.iter_mut().zip(&fdata) {
            *d = (200.0 - 140.0 * f).round() as u8;
        }
        let img = Gray {
            width: w,
            height: h,
            data,
            tone: crate::track::image::Tone::LINEAR,
        };
        let fit = edge_fit(
            &img,
            40.0,
            25.0,
            EdgeSettings {
                half_span_px: 20,
                half_window_px: 6,
            },
        )
        .unwrap();
        assert!((fit.y - y0).abs() < 0.02, "apex row {} vs {y0}", fit.y);
        assert!(
            (fit.curvature - 2.0 * k).abs() < 1e-3,
            "curvature {}",
            fit.curvature
        );
    }

    /// A camera blurs light and then encodes it with its tone curve: the
    /// blurred step in light is odd about the edge, so its halfway level
    /// is on the edge; the encoded step is not. A dome edge (a dark dome,
    /// grey 72, on a light wall, grey 190, as encoded levels) blurred by a
    /// Gaussian of 1.5 px in light and written through the sRGB curve is
    /// found within 0.03 px when read back through the curve, and a fifth
    /// of a pixel off (towards the dark side) when its grey levels are
    /// taken for light.
    #[test]
    fn an_edge_written_through_the_srgb_curve_is_found_in_light() {
        use crate::camera::Response;
        let (w, h) = (90usize, 60usize);
        let (xa, y0, k) = (45.2, 28.63, 0.003);
        let srgb = Response::Srgb;
        let (wall, dome_l) = (srgb.to_linear(190.0 / 255.0), srgb.to_linear(72.0 / 255.0));
        let mut data = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut cov = 0.0;
                for sx in 0..8 {
                    let xs = x as f64 - 0.5 + (sx as f64 + 0.5) / 8.0;
                    let e = y0 + k * (xs - xa).powi(2);
                    for sy in 0..8 {
                        let ys = y as f64 - 0.5 + (sy as f64 + 0.5) / 8.0;
                        cov += normal_cdf((ys - e) / 1.5) / 64.0;
                    }
                }
                let light = wall + (dome_l - wall) * cov;
                data[y * w + x] = (255.0 * srgb.encode(light)).round() as u8;
            }
        }
        let settings = EdgeSettings {
            half_span_px: 20,
            half_window_px: 6,
        };
        let img = Gray::new(w, h, data);
        let as_pixels = edge_fit(&img, 45.0, 29.0, settings).unwrap();
        let img = img.with_tone(crate::track::image::Tone::of(srgb));
        let in_light = edge_fit(&img, 45.0, 29.0, settings).unwrap();
        assert!(
            (in_light.y - y0).abs() < 0.03,
            "in light: apex row {} vs {y0}",
            in_light.y
        );
        assert!(
            as_pixels.y - y0 > 0.15,
            "grey levels taken for light: apex row {} vs {y0}",
            as_pixels.y
        );
    }

    /// A dome's top edge `y0 + k (x - xa)^2` (background 200 above, dome 60
    /// below, blurred by a Gaussian of 1.5 px, each pixel the mean over its
    /// area) with `extra(x, y)` grey levels added.
    fn dome(
        (w, h): (usize, usize),
        (xa, y0, k): (f64, f64, f64),
        extra: impl Fn(f64, f64) -> f64,
    ) -> Gray {
        let mut data = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut cov = 0.0;
                for sx in 0..8 {
                    let xs = x as f64 - 0.5 + (sx as f64 + 0.5) / 8.0;
                    let e = y0 + k * (xs - xa).powi(2);
                    for sy in 0..8 {
                        let ys = y as f64 - 0.5 + (sy as f64 + 0.5) / 8.0;
                        cov += normal_cdf((ys - e) / 1.5) / 64.0;
                    }
                }
                let v = 200.0 - 140.0 * cov + extra(x as f64, y as f64);
                data[y * w + x] = v.round().clamp(0.0, 255.0) as u8;
            }
        }
        Gray {
            width: w,
            height: h,
            data,
            tone: crate::track::image::Tone::LINEAR,
        }
    }

    #[test]
    fn the_even_fit_on_the_axis_holds_the_apex_when_one_side_is_spoiled() {
        // A broad highlight on the dome just under the edge, left of the
        // axis (as a small light reflected off the pole's side): it
        // brightens the dome side of the columns there.
        let (xa, y0, k) = (60.4, 30.3, 0.006);
        let img = dome((120, 70), (xa, y0, k), |x, y| {
            let e = y0 + k * (x - xa).powi(2);
            if y + 0.5 > e {
                100.0
                    * (-0.5 * (((x - xa + 14.0) / 9.0).powi(2) + ((y - e - 4.0) / 2.5).powi(2)))
                        .exp()
            } else {
                0.0
            }
        });
        let s = EdgeSettings {
            half_span_px: 24,
            half_window_px: 3,
        };
        let mut cols = Columns::new(&img, s.half_window_px);
        let free = edge_fit_in(&mut cols, 58.0, 30.0, 2.0 * k, s).unwrap();
        // The scene spoils the free parabola (else the test shows nothing):
        // its apex comes out 0.19 px high, 8 of its standard errors; on the
        // axis 0.07 px, 3 of them.
        assert!(
            (free.y - y0).abs() > 0.1,
            "free fit apex ({}, {}) against ({xa}, {y0})",
            free.x_vertex,
            free.y
        );
        let on_axis = edge_fit_about(&mut cols, (xa, 0.1), &free, s).unwrap();
        assert!(
            (on_axis.y - y0).abs() < 0.1,
            "apex row {} +- {} against {y0}",
            on_axis.y,
            on_axis.y_std
        );
        assert!((on_axis.y - y0).abs() < 4.0 * on_axis.y_std.hypot(0.01));
        assert_eq!(on_axis.x_vertex, xa);
    }

    /// The edge fit of `img` from `(x0, y0)` with the starting curvature
    /// given, against the emptiest frame `emptiest` (half-window 3 px).
    fn fit_against_emptiest(
        img: &Gray,
        emptiest: &Gray,
        (x0, y0, curvature): (f64, f64, f64),
        s: EdgeSettings,
    ) -> Option<EdgeFit> {
        let extremes = Extremes {
            fullest: None,
            emptiest: Some(emptiest),
            is_emptiest: false,
        };
        edge_fit_in(
            &mut Columns::with_extremes(img, 3, extremes),
            x0,
            y0,
            curvature,
            s,
        )
    }

    #[test]
    fn a_static_line_above_the_edge_cancels_against_the_emptiest_frame() {
        // A dark line behind the bubble (a cable, 3 px wide) whose lower
        // border lies 2-3 px above the top edge, in this frame and in the
        // emptiest one, whose top is 15 px lower.
        let (xa, y0, k) = (60.2, 30.4, 0.004);
        // The line, blurred like the edge, seen where the dome (`top` its
        // edge) does not hide it.
        let line = |x: f64, y: f64, top: f64| {
            let on = normal_cdf((y - (y0 - 7.0)) / 1.5) - normal_cdf((y - (y0 - 3.0)) / 1.5);
            let seen = 1.0 - normal_cdf((y - top - k * (x - xa).powi(2)) / 1.5);
            -110.0 * on * seen
        };
        let img = dome((120, 80), (xa, y0, k), |x, y| line(x, y, y0));
        let emptiest = dome((120, 80), (xa, y0 + 15.0, k), |x, y| line(x, y, y0 + 15.0));
        let s = EdgeSettings {
            half_span_px: 24,
            half_window_px: 3,
        };
        let plain = edge_fit_in(&mut Columns::new(&img, 3), 60.0, 30.0, 2.0 * k, s);
        assert!(
            plain.is_none_or(|f| (f.y - y0).abs() > 0.1),
            "without the emptiest frame the line biases the edge: {plain:?}"
        );
        let fit = fit_against_emptiest(&img, &emptiest, (60.0, 30.0, 2.0 * k), s).unwrap();
        assert!((fit.y - y0).abs() < 0.05, "apex row {} against {y0}", fit.y);
    }

    #[test]
    fn a_line_along_the_top_is_left_out_not_taken_for_it() {
        // A dark line behind the bubble (a cable, 3 px wide, as dark as the
        // dome) across the apex: from 2 px above the top to 1 px below it,
        // so that the top runs along it, dark against dark, and the columns
        // near the apex show only the line's upper border. The emptiest
        // frame's top is 15 px lower.
        let (xa, y0, k) = (80.2, 30.4, 0.01);
        // The scene blurred: the whole line less its part the dome hides
        // (the edge taken as straight across the line, the blur linear).
        let band = |y: f64, a: f64, b: f64| normal_cdf((y - a) / 1.5) - normal_cdf((y - b) / 1.5);
        let (a, b) = (y0 - 2.0, y0 + 1.0);
        let line = |x: f64, y: f64, top: f64| {
            let t = top + k * (x - xa).powi(2);
            let hidden = if t < b { band(y, t.max(a), b) } else { 0.0 };
            -140.0 * (band(y, a, b) - hidden)
        };
        let img = dome((160, 80), (xa, y0, k), |x, y| line(x, y, y0));
        let emptiest = dome((160, 80), (xa, y0 + 15.0, k), |x, y| line(x, y, y0 + 15.0));
        let s = EdgeSettings {
            half_span_px: 40,
            half_window_px: 3,
        };
        let plain = edge_fit_in(&mut Columns::new(&img, 3), 80.0, 30.0, 2.0 * k, s).unwrap();
        assert!(
            y0 - plain.y > 1.0,
            "without the emptiest frame the edge sits on the line: {plain:?}"
        );
        // The apex column's edge is the line's upper border, and so known.
        let (e, step) = column_edge(&img, 80, y0, 3.0).unwrap();
        assert!(y0 - e > 1.0 && static_line_on_edge(&img, &emptiest, 80, e, 3.0, step));
        let fit = fit_against_emptiest(&img, &emptiest, (80.0, 30.0, 2.0 * k), s).unwrap();
        assert!(
            (fit.y - y0).abs() < 0.05 && (fit.y - y0).abs() < 4.0 * fit.y_std,
            "apex row {} +- {} against {y0}",
            fit.y,
            fit.y_std
        );
        // Without the line, an emptiest frame whose top lies only 1 px
        // lower shows its own dome under the edge, not a line: no column
        // is taken for one.
        let clean = dome((160, 80), (xa, y0, k), |_, _| 0.0);
        let close = dome((160, 80), (xa, y0 + 1.0, k), |_, _| 0.0);
        for c in 40..=120 {
            let t = y0 + k * (c as f64 - xa).powi(2);
            let (e, step) = column_edge(&clean, c, t, 3.0).unwrap();
            assert!(
                !static_line_on_edge(&clean, &close, c, e, 3.0, step),
                "column {c}"
            );
        }
    }

    #[test]
    fn a_broad_flank_under_the_edge_widens_the_apex_uncertainty() {
        // A broad highlight on the dome (40 grey levels, 8 px under the
        // top, 4 px high and 25 px wide in standard deviations) whose
        // upper flank rises slowly from the edge and turns within the
        // slope rows: no spot, no weakened column, but the centroids are
        // lifted.
        let (xa, y0, k) = (80.2, 30.4, 0.004);
        let glow = |x: f64, y: f64| {
            let on = normal_cdf((y - y0 - k * (x - xa).powi(2)) / 1.5);
            40.0 * on * (-0.5 * (((x - xa) / 25.0).powi(2) + ((y - y0 - 8.0) / 4.0).powi(2))).exp()
        };
        let img = dome((160, 80), (xa, y0, k), glow);
        let (e, step) = column_edge(&img, 80, y0, 3.0).unwrap();
        assert!(turns_back(&img, 80, e, 3.0, step) && !spot_below(&img, 80, e, 3.0, step));
        let s = EdgeSettings {
            half_span_px: 40,
            half_window_px: 3,
        };
        let fit = edge_fit_in(&mut Columns::new(&img, 3), 80.0, 30.0, 2.0 * k, s).unwrap();
        let err = fit.y - y0;
        assert!(
            err.abs() > 0.15 && err.abs() < 4.0 * fit.y_std,
            "apex row {err:+.3} px off, stated std {:.3} px",
            fit.y_std
        );
    }

    #[test]
    fn a_faint_blurred_line_above_the_top_is_found() {
        // One column: a background of 150 above a weak edge at row 40.3
        // (down to 90, blur 1.5 px), and a cable 60 grey levels dark and 3
        // px wide (40 after the blur) whose centre lies 8 px above the edge:
        // its flanks change by less than 15 grey levels a row, by more
        // than 22.5 over two.
        let column = |cable: f64| {
            let band =
                |y: f64, a: f64, b: f64| normal_cdf((y - a) / 1.5) - normal_cdf((y - b) / 1.5);
            let data = (0..60)
                .map(|j| {
                    let y = j as f64;
                    let v =
                        150.0 - 60.0 * normal_cdf((y - 40.3) / 1.5) - cable * band(y, 30.8, 33.8);
                    v.round() as u8
                })
                .collect();
            Gray {
                width: 1,
                height: 60,
                data,
                tone: crate::track::image::Tone::LINEAR,
            }
        };
        let with = column(60.0);
        let rows: Vec<i32> = (25..36).map(|j| i32::from(with.at(0, j))).collect();
        assert!(
            rows.windows(2).all(|w| (w[1] - w[0]).abs() <= 15),
            "{rows:?}"
        );
        let (e, step) = column_edge(&with, 0, 40.0, 3.0).unwrap();
        assert!(line_above(&with, 0, e, 3.0, step));
        let (e, step) = column_edge(&column(0.0), 0, 40.0, 3.0).unwrap();
        assert!(!line_above(&column(0.0), 0, e, 3.0, step));
    }

    #[test]
    fn a_spot_under_the_edge_is_told_from_shading_and_the_clamp() {
        // One column, 40 rows: background 200 above an edge at row 15.3,
        // a dome at 60 below it (blur 1.2 px), with what lies under it.
        let column = |under: &dyn Fn(f64) -> f64| {
            let p = blurred_step(15.3, 1.2, 0.0, 40);
            Gray {
                width: 1,
                height: 40,
                data: p
                    .iter()
                    .enumerate()
                    .map(|(j, v)| (v + under(j as f64)).round().clamp(0.0, 255.0) as u8)
                    .collect(),
                tone: crate::track::image::Tone::LINEAR,
            }
        };
        let found = |img: &Gray| {
            let (e, step) = column_edge(img, 0, 15.0, 3.0).unwrap();
            spot_below(img, 0, e, 3.0, step)
        };
        let below = |y: f64| if y > 15.3 { 1.0 } else { 0.0 };
        // A highlight 40 grey levels high (29 % of the step), 5 px under
        // the edge: a spot.
        let spot = |y: f64| 40.0 * (-0.5 * ((y - 20.3) / 1.5).powi(2)).exp() * below(y);
        assert!(found(&column(&spot)));
        // Half as high (14 %): below the share.
        assert!(!found(&column(&|y| 0.5 * spot(y))));
        // Shading that brightens steadily away from the edge (3 grey
        // levels a row) turns back but never away again.
        assert!(!found(&column(&|y| 3.0 * (y - 15.3).max(0.0))));
        // A brighter clamp fixture 6 px under a low top: a step, no spot.
        assert!(!found(&column(&|y| if y > 21.3 { 80.0 } else { 0.0 })));
    }

    #[test]
    fn the_mirror_test_measures_a_one_sided_shift() {
        // An even edge about the axis, the columns of one side lifted by
        // 0.4 px (a highlight's bias): the sides' apex rows differ by 0.4,
        // and half of it is the joint fit's bias; a symmetric edge has none.
        let edge = |lift: f64| -> Vec<(f64, f64)> {
            (-20..=20)
                .filter(|&u| u != 0)
                .map(|u| {
                    let u = f64::from(u);
                    (u, 30.0 + 0.005 * u * u - if u < 0.0 { lift } else { 0.0 })
                })
                .collect()
        };
        assert!(sides_bias2(&edge(0.0)).abs() < 1e-12);
        assert!((sides_bias2(&edge(0.4)) - 0.04).abs() < 1e-9);
        // Too few columns on one side: no test.
        let one_sided: Vec<(f64, f64)> = edge(0.4).into_iter().filter(|p| p.0 > -4.0).collect();
        assert_eq!(sides_bias2(&one_sided), 0.0);
    }

    #[test]
    fn the_tail_of_a_spot_beyond_the_columns_left_out_widens_the_apex_uncertainty() {
        // An even edge `y = 30 + 0.002 u^2` about the axis, its columns
        // left of u = 4 left out for a spot (located, but spotted or
        // weakened), the right side's kept with noise. The spot's tail lifts
        // the kept columns next to it, by `tail` px at u = 4, fading over
        // `fade` px (as on 640x480 photos with the highlight beside the
        // top, where the apex came out 0.12-0.16 px high at 4-5 standard
        // errors).
        let edge = |us: &[i32], tail: f64, fade: f64, noise: f64| -> Vec<(f64, f64)> {
            us.iter()
                .map(|&u| {
                    let u = f64::from(u);
                    let hash = ((((u as u64) * 2_654_435_761) >> 9) % 11) as f64;
                    let lift = tail * (-(u - 4.0) / fade).exp();
                    (u, 30.0 + 0.002 * u * u - lift + noise * (hash - 5.0) / 5.0)
                })
                .collect()
        };
        let apex = |pts: &[(f64, f64)]| {
            let f = parabola(pts, true).unwrap();
            let std = f.var_at(0.0).sqrt() * lag1_inflation(&f.residuals(pts));
            (f.coef[0] - 30.0, std)
        };
        let widened = |std: f64, term: f64| (std * std + term).sqrt();
        let out: Vec<f64> = (-16..4).map(f64::from).collect();
        let us: Vec<i32> = (4..=32).collect();
        // With the tail the fit alone puts the apex high, beyond 4 of its
        // standard errors (0.116 px at 0.027 px); the tail's term covers
        // it (0.055 px).
        let lifted = edge(&us, 0.2, 8.0, 0.02);
        let (err, std) = apex(&lifted);
        let tail = tail_bias2(&lifted, &out, 32.0, 0.0, true, false);
        assert!(
            err < -0.1 && err.abs() > 4.0 * std,
            "{err:+.3} px at {std:.3} px: the scene shows nothing"
        );
        assert!(
            err.abs() < 4.0 * widened(std, tail),
            "{err:+.3} px off, stated {:.3} px with the tail",
            widened(std, tail)
        );
        // Without it the term stays within the noise.
        let clean = edge(&us, 0.0, 8.0, 0.02);
        let (_, std) = apex(&clean);
        assert!(tail_bias2(&clean, &out, 32.0, 0.0, true, false) < std * std);
        // Nothing left out: no term.
        assert_eq!(tail_bias2(&lifted, &[], 32.0, 0.0, true, false), 0.0);

        // Fewer columns, all within the tail's reach, and one amid them
        // left out too (u = 9), as where a cable hides the far side: the
        // columns beyond the reach are too few to tell the tail from
        // noise, and the fit's error only covers it as the one side's
        // (0.111 px off at 0.018 px; 0.051 px as one side's).
        let us: Vec<i32> = (4..24).filter(|&u| u != 9).collect();
        let out: Vec<f64> = (-16..4).chain([9]).map(f64::from).collect();
        let pts = edge(&us, 0.12, 12.0, 0.06);
        let (err, std) = apex(&pts);
        let two = widened(std, tail_bias2(&pts, &out, 32.0, 0.0, true, false));
        let one = widened(std, tail_bias2(&pts, &out, 32.0, 0.0, true, true));
        assert!(
            err < -0.1 && err.abs() > 4.0 * two,
            "{err:+.3} px at {two:.3} px: the scene shows nothing"
        );
        assert!(
            err.abs() < 4.0 * one,
            "{err:+.3} px off, stated {one:.3} px as one side's"
        );
    }
}
