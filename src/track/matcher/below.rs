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

/// Whether the dome side under an edge at row `e` of column `c` reaches
/// the sensor's full scale (grey level 255) within the rows below the edge
/// that its location reads ([`rows_read_below`]): light added there (a
/// highlight) beyond what the sensor records is lost, so the differences
/// that the centroid and the slope below the edge sum there are not the
/// scene's, and the column's edge row is off by an amount nothing in the
/// photo measures.
pub(super) fn clipped_below(img: &Gray, c: usize, e: f64, hw: f64) -> bool {
    let (j0, j1) = rows_read_below(e, hw);
    let j1 = j1.min(img.height as i64 - 1);
    (j0.max(0)..=j1).any(|j| img.at(c, j as usize) == u8::MAX)
}

/// The share of an edge's step by which the dome side under it must turn
/// back towards the background for the column to count as turning back
/// ([`turns_back`]): its shift is then worked out ([`turn_back_shift`]),
/// and where a tenth of the kept columns turn, the rim's term is not read
/// and the step model is not tested.
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
/// the edge can cause, px, an estimate from the centroid's definition
/// ([`profile_edge`], in light; the light added taken as even in the row
/// between the edge and the turn's peak): the dome side rises beyond its
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

/// The corrected pull of [`overshoot_shift`] over the standard deviation
/// left in it, `sqrt(3)`: the light it adds lies between the edge and the
/// turn's peak, `p` px below it, and [`turn_back_shift`] takes its mean
/// offset as `p / 2` (a rise even in the row). Where in that range the
/// light lies is not read (a highlight's flank rises faster near its peak
/// than near the edge, or the other way), so the mean offset is taken as
/// evenly spread over `0..p`: its deviation is `p / sqrt(12)`, the
/// correction's `1 / sqrt(3)` of the correction.
pub(super) const OVERSHOOT_SPREAD: f64 = 1.732_050_807_568_877_2;

/// The correction of a column's centroid for light added under its edge,
/// px into the dome: [`turn_back_shift`] where the dome is lighter than
/// its background (`step > 0`, the grey levels rising into the dome) and
/// its side [`turns_back`], 0 elsewhere. On such a dome, light added under
/// the edge (a highlight) continues the step past the dome's own level
/// before it turns back, so the differences it adds have the step's
/// polarity and are summed: the pull that [`turn_back_shift`] works out
/// is there, into the dome. On a dome darker than its background the same
/// light turns the dome side towards the background instead: its
/// differences are against the step's polarity and left out, and it cuts
/// the step's lower tail short, which lifts the centroid; that shift is
/// not the one worked out, and it stays a term of the uncertainty only.
pub(super) fn overshoot_shift(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> f64 {
    if is_light_dome(step) && turns_back(img, c, e, hw, step) {
        turn_back_shift(img, c, e, hw, step)
    } else {
        0.0
    }
}

/// Whether an edge of step `step` (grey levels, positive where they rise
/// into the dome) bounds a dome lighter than its background, on which
/// [`overshoot_shift`] takes a highlight's pull off the edge row.
pub(super) fn is_light_dome(step: f64) -> bool {
    step > 0.0
}

/// The rows below an edge at row `e` (window half-height `hw`) over which
/// [`rim_tail`] reads the dome side: from the first row beyond the window
/// (and the step's blur) for twice the slope rows.
pub(super) fn rim_rows(e: f64, hw: f64) -> (i64, i64) {
    let j0 = (e + hw + 1.0).ceil() as i64;
    (j0, j0 + 2 * SLOPE_ROWS - 1)
}

/// How a dome's light varies near its outline, `d` px inside an outline
/// of radius of curvature `r` px, where the cosine of the angle between
/// the line of sight and the surface's normal is `t = sqrt(2 d / r)`. Each
/// is a factor `G(d)`, 1 at the outline and falling inwards; the dome side
/// reads `a + A G(d)`, with `A > 0` where it is lighter (for a dark dome,
/// darker for a light one) towards the outline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum RimShape {
    /// Light that is smooth across the outline, `G = 1 - t^2 = 1 - 2 d / r`:
    /// a highlight's flank, a shade across the dome or uneven light. It is
    /// linear in `d`, and the slope below the edge that a column's centroid
    /// subtracts removes it: it moves the centroid by nothing.
    Ramp,
    /// A matte (Lambertian) surface lit from about the camera's side: its
    /// light goes as the cosine between the light and the normal, `t`
    /// near the outline, so it falls short of its inner level by
    /// `G = 1 - t` (J. H. Lambert, "Photometria", 1760; B. K. P. Horn,
    /// "Robot Vision", MIT Press 1986, ch. 10).
    Matte,
    /// A glossy (dielectric) surface reflecting what lies behind its
    /// outline, the more the closer to grazing: Schlick's approximation
    /// of the Fresnel factor, `G = (1 - t)^5` (C. Schlick, "An inexpensive
    /// BRDF model for physically-based rendering", Computer Graphics Forum
    /// 13 (1994), doi:10.1111/1467-8659.1330233).
    Glossy,
}

impl RimShape {
    pub(super) const ALL: [RimShape; 3] = [RimShape::Ramp, RimShape::Matte, RimShape::Glossy];
}

/// The factor `G(d)` of a rim of shape `shape` `d` px inside an outline of
/// radius of curvature `r` px ([`RimShape`]).
pub(super) fn rim_factor(shape: RimShape, d: f64, r: f64) -> f64 {
    let t2 = 2.0 * d.max(0.0) / r;
    match shape {
        RimShape::Ramp => 1.0 - t2,
        RimShape::Matte => (1.0 - t2.sqrt()).max(0.0),
        RimShape::Glossy => (1.0 - t2.sqrt()).max(0.0).powi(5),
    }
}

/// A dome's rim of shape `shape` under an edge at row `e` of column `c`
/// (grey step `step`), the outline's radius of curvature `r` px: the
/// amplitude `A` of `a + A G(d)` ([`rim_factor`]) fitted by least squares
/// to the dome side's light `d` px under the edge, over the rows
/// [`rim_rows`], as a share of the step in light, and the fit's sum of
/// squared residuals in shares of the step. A lens's blur spreads the step
/// in light evenly about the edge, so its tail under the edge is the
/// mirror of its tail above: each row under the edge is read with the
/// light `d` px above it added, which cancels the tail of a blur wider
/// than the window and leaves the dome's own light (the step is the
/// background's mean over those rows above less the dome's fit at the
/// first row read). `A` is positive where the dome side is lighter towards
/// the outline (for a dark dome on a light wall; darker for a light dome).
/// `None` where the rows leave the image.
///
/// On a dome darker than its background the share is bounded by what a
/// rim can reflect: at most all the light behind the outline (the Fresnel
/// reflectance is at most 1), so its light at the outline comes at most up
/// to the background's, an amplitude `A` of at most the step `S` from the
/// dome's own level to the background. The share is `A` over the step at
/// the first row read, `S - A G0` (`G0` the rim's factor there), so it is
/// taken as `1 / (1 - G0)` at most: a fit beyond that has read noise over
/// a step that its own level there nearly cancels.
pub(super) fn rim_tail(
    img: &Gray,
    c: usize,
    e: f64,
    hw: f64,
    step: f64,
    r: f64,
    shape: RimShape,
) -> Option<(f64, f64)> {
    let light = |j: i64| -step.signum() * img.light(c, j as usize);
    let (j0, j1) = rim_rows(e, hw);
    let top = 2.0 * e - j1 as f64;
    if top < 0.0 || j1 >= img.height as i64 || step == 0.0 || r.is_nan() || r <= 0.0 {
        return None;
    }
    // The light at a row between two pixels' centres, linearly.
    let at = |y: f64| {
        let j = y.floor();
        let f = y - j;
        light(j as i64) * (1.0 - f) + light(j as i64 + 1) * f
    };
    let d = |k: usize| (j0 + k as i64) as f64 - e;
    let above: Vec<f64> = (0..=(j1 - j0) as usize).map(|k| at(e - d(k))).collect();
    let ys: Vec<f64> = above
        .iter()
        .enumerate()
        .map(|(k, b)| light(j0 + k as i64) + b)
        .collect();
    let g = |k: usize| rim_factor(shape, d(k), r);
    let (a, amp) = least_squares(&ys, g)?;
    let background = above.iter().sum::<f64>() / above.len() as f64;
    let s = 2.0 * background - (a + amp * g(0));
    if s <= 0.0 {
        return None;
    }
    let rss = ys
        .iter()
        .enumerate()
        .map(|(k, y)| (y - a - amp * g(k)).powi(2))
        .sum::<f64>();
    let share = amp / s;
    let g0 = g(0);
    let share = if is_light_dome(step) || g0 >= 1.0 {
        share
    } else {
        share.min(1.0 / (1.0 - g0))
    };
    Some((share, rss / (s * s)))
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
/// `hw`) that a rim's tail `A G(d)` of shape `shape` ([`rim_tail`], `A` a
/// share of the step) puts there: the tail's fall within the window's
/// lower half `L = hw + 1/2`, less the slope below the edge that the
/// centroid subtracts (the tail's, where that is read, about `hw + 6` px
/// under the edge), weighted by its offset from the edge:
/// `A (int_0^L G - L G(L) + G'(hw + 6) L^2 / 2)`, px. It is 0 for a
/// [`RimShape::Ramp`], whose slope is the same everywhere.
pub(super) fn rim_shift(shape: RimShape, amp: f64, hw: f64, r: f64) -> f64 {
    let l = hw + 0.5;
    let g = |d: f64| rim_factor(shape, d, r);
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

/// The shift into the dome of the apex row that a dome's rim puts there,
/// px, which the caller adds to the apex row's deviation as a bias bound.
/// The rim's shape ([`RimShape`]) is the one whose fits ([`rim_tail`])
/// leave the least squared residual summed over the columns `(u from
/// centre, edge row, step)`: the three have two parameters each, so the
/// sum compares them fairly, and the columns together tell a matte
/// dome's fall-off from a glossy one's where one column's noise cannot.
/// The shift is that shape's [`rim_shift`] of the mean amplitude over the
/// columns, where the mean lies beyond two of its standard errors (from
/// the columns' spread, at least 5 columns) towards the background; 0
/// otherwise, and where the outline's radius of curvature `radius` px is
/// not positive. On path-traced photos of a glossy dark dome (rough
/// plastic of roughness 0.1, 1280x960 at 0.25 m) the glossy shape gave
/// 0.21-0.29 px where the centroids were 0.18-0.31 px into the dome. A
/// matte dark dome lit from the front darkens towards its outline, away
/// from a light background, and it gives 0; a matte light dome on a dark
/// wall darkens towards the background, which pulls the centroids too
/// (0.08-0.13 px on such path-traced photos, where it gives 0-0.07 px;
/// 0.16-0.20 px with the glossy shape alone and the blur's tail unmirrored).
pub(super) fn rim_bias(
    img: &Gray,
    columns: &[(f64, f64, f64)],
    centre: f64,
    hw: f64,
    radius: f64,
) -> f64 {
    let fits = |shape: RimShape| -> Vec<(f64, f64)> {
        columns
            .iter()
            .filter_map(|&(u, e, step)| {
                rim_tail(
                    img,
                    (u + centre).round() as usize,
                    e,
                    hw,
                    step,
                    radius,
                    shape,
                )
            })
            .collect()
    };
    // A dome lighter than the background (its steps rise into it) is
    // darker towards its outline by any of the three shapes; one darker
    // than the background is lighter there only by what it reflects (a
    // matte surface darkens towards its outline whatever lies behind it),
    // so the glossy shape bounds it, a highlight at the outline included.
    let light_dome = 2 * columns.iter().filter(|c| c.2 > 0.0).count() > columns.len();
    let shapes: &[RimShape] = if light_dome {
        &RimShape::ALL
    } else {
        &[RimShape::Glossy]
    };
    let by_shape: Vec<(RimShape, Vec<(f64, f64)>)> = shapes.iter().map(|&s| (s, fits(s))).collect();
    // The shape whose fits leave the least squared residual; where the
    // shapes did not all fit the same columns (a fit that leaves no
    // contrast), the glossy one, whose shift is the largest.
    let n = by_shape[0].1.len();
    let same = by_shape.iter().all(|(_, f)| f.len() == n);
    let rss = |f: &[(f64, f64)]| f.iter().map(|x| x.1).sum::<f64>();
    let (shape, fit) = if same {
        by_shape
            .into_iter()
            .min_by(|a, b| rss(&a.1).total_cmp(&rss(&b.1)))
            .expect("one shape at least")
    } else {
        by_shape.into_iter().last().expect("one shape at least")
    };
    // Each column's share (on a dark dome bounded by [`rim_tail`]).
    let shares: Vec<f64> = fit.iter().map(|x| x.0).collect();
    let n = shares.len() as f64;
    if n < 5.0 {
        return 0.0;
    }
    let mean = shares.iter().sum::<f64>() / n;
    let var = shares.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (n - 1.0);
    if mean > 2.0 * (var / n).sqrt() {
        rim_shift(shape, mean, hw, radius)
    } else {
        0.0
    }
}
