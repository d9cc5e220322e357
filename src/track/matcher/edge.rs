//! The edge in one column: the centroid of the intensity differences
//! (located in light, with the step of its grey levels) and the two-sided
//! step model of a blurred edge, and the apex fit's result and settings.

use super::*;

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
    /// Covariance of `y` and `curvature`, one fit's (px times 1/px):
    /// negative, noise that lowers the parabola's top flattens it. A
    /// height that needs the pole's radius reads both
    /// ([`crate::track::PoleMeasure`]).
    pub y_curvature_cov: f64,
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
pub(super) fn column_edge(img: &Gray, c: usize, start: f64, hw: f64) -> Option<(f64, f64)> {
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
pub(super) fn in_light(
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
pub(crate) fn profile_edge_with(
    px: impl Fn(i64) -> f64,
    len: i64,
    start: f64,
    hw: f64,
    slopes: bool,
) -> Option<(f64, f64)> {
    centroid_edge(px, len, start, hw, slopes, true)
}

/// [`profile_edge`] without leaving out the differences against the edge's
/// polarity: every difference in the window counts. Leaving them out keeps
/// a highlight or texture inside the dome from pulling the centroid, but
/// where the noise or texture differs on the two sides of the edge it also
/// leaves a bias: in a row whose difference is noise of deviation `s`
/// alone, the differences kept average `s / sqrt(2 pi)` of the step's sign
/// instead of 0, and their lever arm about the edge pulls the centroid
/// towards the noisier side by about `M (s_b - s_a) / (sqrt(2 pi) |step|)`,
/// `M` the window's summed distance from the edge on one side (about 5.5
/// rows for a half-height of 3): 0.03 px for a textured wall (1.4 grey
/// levels between rows) over a smooth dome on a step of 110. Without the
/// selection the noise averages to zero on each side. See
/// `Columns::polarity_shift`.
pub(crate) fn unselected_edge(
    px: impl Fn(i64) -> f64,
    len: i64,
    start: f64,
    hw: f64,
) -> Option<f64> {
    centroid_edge(px, len, start, hw, true, false).map(|(e, _)| e)
}

/// The centroid of [`profile_edge`], the differences against the edge's
/// polarity left out only with `select`.
fn centroid_edge(
    px: impl Fn(i64) -> f64,
    len: i64,
    start: f64,
    hw: f64,
    slopes: bool,
    select: bool,
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
        // is the minmod of two 3-row estimates and of the 2-row slope across
        // the window's end, so that another edge nearby (the clamp fixture
        // under a flat bubble) is not taken for a slope, nor the flank of a
        // blurred line that ends where the window begins (a slope holds
        // across the window's end; a line's flank does not).
        let half = SLOPE_ROWS / 2;
        let slope = |a: i64, b: i64, c: i64| {
            minmod((px(b) - px(a)) / half as f64, (px(c) - px(b)) / half as f64)
        };
        let (g_above, g_below) = if slopes {
            (
                minmod(
                    slope(lo - SLOPE_ROWS, lo - half, lo),
                    0.5 * (px(lo + 1) - px(lo - 1)),
                ),
                minmod(
                    slope(hi + 1, hi + 1 + half, hi + 1 + SLOPE_ROWS),
                    0.5 * (px(hi + 2) - px(hi)),
                ),
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
            if !select || d * total > 0.0 {
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
pub(crate) const SLOPE_ROWS: i64 = 6;

/// Rows on each side of the edge over which [`step_model_edge`] fits.
pub(super) const MODEL_ROWS: i64 = 5;

/// Standard normal density and distribution function.
pub(super) fn normal_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

pub(super) fn normal_cdf(x: f64) -> f64 {
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
pub(super) struct StepModel {
    pub(super) rows: [f64; (2 * MODEL_ROWS + 1) as usize],
    pub(super) y: [f64; (2 * MODEL_ROWS + 1) as usize],
}

impl StepModel {
    /// Per sample: the model's value and its derivatives with respect to
    /// the six parameters.
    pub(super) fn terms(&self, p: &[f64]) -> impl Iterator<Item = (f64, [f64; 6])> + '_ {
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

    pub(super) fn jacobian_at(&self, p: &nalgebra::DVector<f64>) -> nalgebra::DMatrix<f64> {
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
