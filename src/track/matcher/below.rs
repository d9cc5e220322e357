//! The tests of the dome side under an edge: a bright spot (a highlight)
//! or a profile that turns back towards the background, which bias the
//! column's edge row.

use super::*;

/// The share of an edge's step by which the dome side under it must turn
/// back towards the background (and half of it away again) to count as a
/// bright spot ([`spot_below`]).
pub(super) const SPOT_SHARE: f64 = 0.15;

/// The columns an edge fit keeps at the least when it leaves out those
/// with a spot under the edge (and a quarter of the columns located);
/// with fewer it keeps them all, as before the test.
pub(super) const SPOT_MIN_KEPT: usize = 12;

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
pub(super) fn spot_below(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
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
pub(super) const TURN_SHARE: f64 = 0.1;

/// The rows below an edge at row `e` (window half-height `hw`) that its
/// location reads, beyond its own blur: from 1.5 px below the edge through
/// the window and the slope rows; not clipped to the image.
pub(super) fn rows_read_below(e: f64, hw: f64) -> (i64, i64) {
    (
        (e + 1.5).ceil() as i64,
        (e + hw + 1.0).ceil() as i64 + SLOPE_ROWS,
    )
}

/// Whether the dome side under an edge at row `e` of column `c` (step
/// `step`) turns back towards the background by more than [`TURN_SHARE`]
/// of the step within the rows below the edge that its location reads
/// ([`rows_read_below`]) and the slope rows' length beyond them (means of
/// neighbouring rows, against the noise). A broad highlight whose flank
/// rises slowly from the edge does this without turning away again within
/// those rows, so [`spot_below`] does not leave the column out; its rise
/// cuts the lower tail of the blurred step short and lifts the centroid
/// (0.27 px on a drawn dome), which the minmod slope below the edge misses
/// where the flank turns within the slope rows. A highlight whose flank
/// rises through the window and peaks within the slope rows pulls the
/// centroid into the dome while the slope subtracted there is flat; it
/// turns back beyond them, hence the further rows (on the tracker sweep's
/// light domes before a dark wall, 0.23-0.51 px at a stated 0.05-0.11 px
/// before they were read). A flat dome side stays within the noise.
pub(super) fn turns_back(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
    let grey = |j: i64| turned(img, c, step, j);
    turn_back(img, &grey, e, hw, step).is_some_and(|(rise, ..)| rise > TURN_SHARE * step.abs())
}

/// How far the dome side under an edge at row `e` (turned profile `v`:
/// the dome side low, [`turned`]) turns back towards the background within
/// the rows [`turns_back`] reads (means of neighbouring rows), the row
/// where it starts to (the highlight's peak), and the level it turns back
/// to: `None` where no row is read or the step is 0.
fn turn_back(
    img: &Gray,
    v: &dyn Fn(i64) -> f64,
    e: f64,
    hw: f64,
    step: f64,
) -> Option<(f64, f64, f64)> {
    let (j0, j1) = rows_read_below(e, hw);
    let j1 = (j1 + SLOPE_ROWS).min(img.height as i64 - 2);
    if j0 >= j1 || step == 0.0 {
        return None;
    }
    let pair = |j: i64| 0.5 * (v(j) + v(j + 1));
    let (mut low, mut low_at) = (f64::INFINITY, j0);
    let (mut rise, mut peak, mut back) = (0.0f64, j0 as f64, pair(j0));
    for j in j0..j1 {
        let x = pair(j);
        if x < low {
            (low, low_at) = (x, j);
        }
        if x - low > rise {
            (rise, peak, back) = (x - low, low_at as f64 + 0.5, x);
        }
    }
    Some((rise, peak, back))
}

/// The shift of a column's centroid that a dome side turning back under
/// the edge can cause, px, an upper estimate from the centroid's
/// definition ([`profile_edge`], in light): the dome side rises beyond its
/// own level by the turn's rise (a share `r` of the step from the
/// background, above the window, to the level it turns back to) up to the
/// peak `p` px below the edge before it falls back; the centroid sums only
/// the differences of the step's polarity, so that rise adds `r` of the
/// step's weight at offsets from the edge to the peak, within the window's
/// `hw + 1/2`: a lever arm of half of `min(p, hw + 1/2)`, and a shift of
/// `r arm / (1 + r)` into the dome. For a column that [`turns_back`]: a
/// turn within the noise (under [`TURN_SHARE`] of the step in grey levels)
/// counts as none, and the caller has tested it.
pub(super) fn turn_back_shift(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> f64 {
    let light = |j: i64| -step.signum() * img.light(c, j as usize);
    let above = first_row_read_above(e, hw) + SLOPE_ROWS;
    if above < 0 {
        return 0.0;
    }
    let background = 0.5 * (light(above) + light(above + 1));
    match turn_back(img, &light, e, hw, step) {
        Some((rise, peak, back)) if background - back > 0.0 => {
            let r = rise / (background - back);
            let arm = 0.5 * (peak - e).clamp(0.0, hw + 0.5);
            r * arm / (1.0 + r)
        }
        _ => 0.0,
    }
}

/// The rows below an edge at row `e` (window half-height `hw`) over which
/// [`rim_tail`] reads the dome side: from the first row beyond the window
/// (and the step's blur) for twice the slope rows.
pub(super) fn rim_rows(e: f64, hw: f64) -> (i64, i64) {
    let j0 = (e + hw + 1.0).ceil() as i64;
    (j0, j0 + 2 * SLOPE_ROWS - 1)
}

/// How much of a glossy surface's reflection of what lies behind its
/// outline it still shows `d` px inside an outline of radius of curvature
/// `r` px: Schlick's approximation of the Fresnel factor,
/// `(1 - cos(theta))^5`, with `cos(theta) = sqrt(2 d / r)` the cosine of the
/// angle between the line of sight and the surface's normal there (C.
/// Schlick, "An inexpensive BRDF model for physically-based rendering",
/// Computer Graphics Forum 13 (1994), doi:10.1111/1467-8659.1330233).
pub(super) fn rim_factor(d: f64, r: f64) -> f64 {
    (1.0 - (2.0 * d.max(0.0) / r).sqrt()).max(0.0).powi(5)
}

/// A glossy dome's rim under an edge at row `e` of column `c` (grey step
/// `step`), the outline's radius of curvature `r` px: the amplitude `A` of
/// `a + A rim_factor(d, r)` ([`rim_factor`]) fitted by least squares to
/// the dome side's light `d` px under the edge, over the rows
/// [`rim_rows`], as a share of the step in light (from the background just
/// above the window to the fit at the first row read); positive where the
/// dome side is lighter towards the outline as a glossy surface's is (for
/// a dark dome on a light wall; the opposite way round for a light dome).
/// A dielectric surface seen near grazing reflects what lies behind its
/// outline, the more the closer to grazing, so near the outline the dome
/// shows the background and falls away from it inwards. `None` where the
/// rows leave the image.
pub(super) fn rim_tail(img: &Gray, c: usize, e: f64, hw: f64, step: f64, r: f64) -> Option<f64> {
    let light = |j: i64| -step.signum() * img.light(c, j as usize);
    let (j0, j1) = rim_rows(e, hw);
    let above = first_row_read_above(e, hw) + SLOPE_ROWS;
    if above < 0 || j1 >= img.height as i64 || step == 0.0 || r.is_nan() || r <= 0.0 {
        return None;
    }
    let ys: Vec<f64> = (j0..=j1).map(light).collect();
    let d = |k: usize| (j0 + k as i64) as f64 - e;
    let (a, amp) = least_squares(&ys, |k| rim_factor(d(k), r))?;
    let background = 0.5 * (light(above) + light(above + 1));
    let s = background - (a + amp * rim_factor(d(0), r));
    (s > 0.0).then_some(amp / s)
}

/// The least-squares fit `y_k = a + b x(k)`: `(a, b)`, `None` where the
/// `x` do not vary.
fn least_squares(ys: &[f64], x: impl Fn(usize) -> f64) -> Option<(f64, f64)> {
    let n = ys.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for (k, &y) in ys.iter().enumerate() {
        let x = x(k);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let det = n * sxx - sx * sx;
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let b = (n * sxy - sx * sy) / det;
    Some(((sy - b * sx) / n, b))
}

/// The shift into the dome of a column's centroid (window half-height
/// `hw`) that a rim's tail `A rim_factor(d, r)` ([`rim_tail`], `A` a share
/// of the step) puts there: the tail's fall within the window's lower half
/// `L = hw + 1/2`, less the slope below the edge that the centroid
/// subtracts (the tail's, where that is read, about `hw + 6` px under the
/// edge), weighted by its offset from the edge:
/// `A (int_0^L G - L G(L) + G'(hw + 6) L^2 / 2)`, px, `G = rim_factor`.
pub(super) fn rim_shift(amp: f64, hw: f64, r: f64) -> f64 {
    let l = hw + 0.5;
    let g = |d: f64| rim_factor(d, r);
    // Simpson's rule on 64 intervals for the integral of G (smooth in
    // sqrt(d): substituted d = t^2).
    let m = 64;
    let st = l.sqrt() / m as f64;
    let f = |t: f64| g(t * t) * 2.0 * t;
    let mut int = f(0.0) + f(l.sqrt());
    for k in 1..m {
        int += f(k as f64 * st) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    int *= st / 3.0;
    let dg = hw + 6.0;
    let slope = (g(dg + 0.5) - g(dg - 0.5)).min(0.0);
    (amp * (int - l * g(l) + 0.5 * slope * l * l)).max(0.0)
}

/// The shift into the dome of the apex row that a glossy rim puts there,
/// px, which the caller adds to the apex row's deviation as a bias bound:
/// the mean of [`rim_tail`] over the columns `(u from centre, edge row,
/// step)`, where it lies beyond two of its standard errors (from the
/// columns' spread, at least 5 columns) towards the background, through
/// [`rim_shift`]; 0 otherwise, and where the outline's radius of curvature
/// `radius` px is not positive. On path-traced photos of a glossy dark dome
/// (rough plastic of roughness 0.1, 1280x960 at 0.25 m) it gave 0.20-0.28
/// px where the centroids were 0.18-0.31 px into the dome. A matte dark
/// dome lit from the front darkens towards its outline, away from a light
/// background, and it gives 0; a matte light dome on a dark wall darkens
/// towards the background, which pulls the centroids too (0.08-0.13 px on
/// such path-traced photos), and it gives 0.16-0.20 px.
pub(super) fn rim_bias(
    img: &Gray,
    columns: &[(f64, f64, f64)],
    centre: f64,
    hw: f64,
    radius: f64,
) -> f64 {
    let shares: Vec<f64> = columns
        .iter()
        .filter_map(|&(u, e, step)| {
            rim_tail(img, (u + centre).round() as usize, e, hw, step, radius)
        })
        .collect();
    let n = shares.len() as f64;
    if n < 5.0 {
        return 0.0;
    }
    let mean = shares.iter().sum::<f64>() / n;
    let var = shares.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (n - 1.0);
    if mean > 2.0 * (var / n).sqrt() {
        rim_shift(mean, hw, radius)
    } else {
        0.0
    }
}
