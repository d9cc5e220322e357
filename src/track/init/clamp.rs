//! Step 3 of `bulge init`: the clamp's top edge beside the bubble's base,
//! its row at the axis, the camera's elevation from its ellipse and the
//! roll from its slope; and the (robust) linear least squares it uses.

use super::base;
use super::contrast::Contrast;
use super::*;
use crate::track::image::Tone;

/// The clamp's top edge beside the bubble (step 3).
#[derive(Clone)]
pub(super) struct Clamp {
    pub(super) row: Estimate,
    pub(super) sin_e: Option<Estimate>,
    /// The slope of the clamp's top edge, rows per column (a rolled
    /// camera): the row at the axis is `row`.
    pub(super) slope: Estimate,
    pub(super) half_width_px: Option<f64>,
    /// The same from the ends read below the ellipse's centre row.
    pub(super) half_width_below_px: Option<f64>,
    /// The curvature of a top edge that bends but whose ends are out of
    /// the picture (`row = row_top + bend x^2`, rows per px^2), found with
    /// the camera's distance known: `row` is then the far side's top (the
    /// near side's bottom when `near`), and the pinhole places the ring's
    /// ellipse ([`super::ring::place_ring`]).
    pub(super) bend: Option<f64>,
    /// The edge found is the face's front, the near half of the ring's
    /// outer circle, not its far side: the face is as light as the wall
    /// behind the ring, so its far side shows no step. Told by the
    /// curvature's sign: from above the clamp plane the far side is
    /// highest at the axis and the front lowest.
    pub(super) near: bool,
    pub(super) points: Vec<[f64; 2]>,
    /// With `near`: the dome's base in front of the face (image column,
    /// row), the near half of the opening's circle, which places the
    /// clamp plane ([`base::dome_base`]); empty when it was not found.
    pub(super) base_points: Vec<[f64; 2]>,
    /// The clamp plane is placed on the dome's base: the face's front
    /// lies more than [`base::BASE_GAP_PX`] below where the base puts it (a
    /// flange), or the ring's ends are out of the picture.
    pub(super) on_base: bool,
    /// The edge was located on a step clipped at the sensor's ceiling: the
    /// distance, px, to the first row at the ceiling, which bounds how far
    /// towards the wall it was located ([`super::clip`]).
    pub(super) clipped_px: Option<f64>,
}

impl Clamp {
    /// The clamp plane given at `row` (at the axis `x0`, in the photo):
    /// not searched, so no edge, ends or roll; through a lens the row is
    /// carried into the undistorted image, as the rows found are. Every
    /// apex lies above the clamp plane and the plane lies in the photo: a
    /// row at or above the largest bubble's top (row `top`) or below the
    /// photo (`h` rows tall) is refused, as [`Clamp::checked`] refuses an
    /// edge found above the bubble's base.
    pub(super) fn given(
        row: Estimate,
        x0: f64,
        lens: Option<&super::super::lens::Lens>,
        top: f64,
        h: usize,
    ) -> Result<Clamp, TrackError> {
        if !(row.value > top && row.value < h as f64) {
            return Err(clamp_not_found(format!(
                "the clamp row given, {:.1}, is {} (the largest bubble's top is at row {top:.0}, the photo {h} rows tall): rows count down from the photo's top edge",
                row.value,
                if row.value <= top {
                    "above the largest bubble's top"
                } else {
                    "below the photo"
                },
            )));
        }
        let value = lens.map_or(row.value, |l| l.undistort([x0, row.value])[1]);
        Ok(Clamp {
            row: Estimate {
                value,
                std: row.std,
            },
            sin_e: None,
            slope: Estimate {
                value: 0.0,
                std: 0.0,
            },
            half_width_px: None,
            half_width_below_px: None,
            bend: None,
            near: false,
            points: Vec::new(),
            base_points: Vec::new(),
            on_base: false,
            clipped_px: None,
        })
    }

    /// The camera's roll from the edge's slope and the elevation from the
    /// ellipse's sine (`given` when the elevation is given, degrees),
    /// refusing a roll beyond [`MAX_ROLL_DEG`] and an edge above the lowest
    /// part of the bubble that moves (row `y_low`): not the clamp.
    pub(super) fn checked(
        &self,
        y_low: f64,
        given: Option<f64>,
    ) -> Result<(Estimate, Option<Estimate>), TrackError> {
        let roll_deg = Estimate {
            value: self.slope.value.atan().to_degrees(),
            std: (self.slope.std / (1.0 + self.slope.value.powi(2))).to_degrees(),
        };
        if roll_deg.value.abs() > MAX_ROLL_DEG + 4.0 * roll_deg.std {
            return Err(TrackError::NotFound {
                what: "a level clamp".into(),
                detail: format!(
                    "the clamp's top edge slopes by {:.2} +- {:.2} degrees across the photos: either the camera is rolled about its view axis (at most {MAX_ROLL_DEG} degree is taken: the tracker measures along the photo's columns, and beyond it the apex moves sideways as the bubble grows): level the camera or rotate the photos; or the edge found is not the clamp's (something beside the bubble's base, or a clamp hardly lighter or darker than the wall)",
                    roll_deg.value, roll_deg.std
                ),
                keys: "clamp_row_px (the clamp's row at the bubble's axis), metres_per_pixel, roi_px and template_rect_px",
                clamp_plane: false,
            });
        }
        // (a far side placed through the pinhole is checked by its fit)
        // From a camera raised by `e` the dome's base in front of the ring
        // lies `a sin e` below the ring's centre, beyond the tenth of the
        // face's half-width (`A = k a`) allowed here once `sin e > 0.1 k +
        // 3 / a` (orthographic; a pinhole's nearer base lies lower still):
        // for a = 250 px from 6.5 degrees with a face no wider than the
        // opening, 8.5 with one 1.35 times as wide. The message says so.
        if self.bend.is_none()
            && self.row.value < y_low - 3.0 - self.half_width_px.map_or(0.0, |a| a * 0.1)
        {
            return Err(clamp_not_found(format!(
                "the edge found beside the bubble (row {:.1}) is above the lowest part of the bubble that moves (row {y_low:.0}): it is not the clamp, or the camera looks down from beyond the 5 degrees init is measured on (from about 6-9 degrees up the dome's base in front of the ring lies that far below the ring's centre)",
                self.row.value
            )));
        }
        let elevation_deg = match (given, self.sin_e) {
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
        Ok((roll_deg, elevation_deg))
    }
}

/// How far, px, from the ring's end (its outline's column) the face's far
/// side is left out of the ring's fit. Towards the end the far side curves
/// ever more sharply (its radius of curvature at the end is `s^2 A`, half
/// a pixel for a ring 316 px wide seen 2.4 degrees from above) and meets
/// the side's upright outline: within a blur's reach of that corner a
/// column's edge is pulled down (0.1-0.3 px in the last 2-4 columns), and
/// those columns fix the fit's end, where the ellipse's row changes the
/// fastest with the centre's and the elevation. With only one end in the
/// picture they decided the fit: on the init sweep's three worst such
/// set-ups the centre's row came out 2.0-6.4 px high at 3.1-3.4 of its
/// stated deviations, and 0.4-1.8 px off within 0.9 leaving out the last
/// 6 px. The mechanism is the blur's reach, but the value is chosen among
/// measured ones (1.5, 3, 6 and 12 px on the sweep's ten one-sided
/// set-ups; docs/track.md), not derived from the photo's own blur, which
/// init does not measure: 6 px is 2.2 standard deviations of the widest
/// blur the sweep draws (2.8 px: a Gaussian of 2 px, a defocus disc of
/// radius 3 px and a motion of 4 px together).
pub(super) const CORNER_PX: f64 = 6.0;

/// Whether a column `d` px from the axis lies clear of the corners of a
/// ring whose ends are `half` px either side of it ([`CORNER_PX`]).
pub(super) fn clear_of_ends(d: f64, half: f64) -> bool {
    d.abs() < half - CORNER_PX
}

/// One column's clamp edge: its row and step, whether a second step almost
/// as strong lies above it, and that step's row and step when located.
type ColumnEdge = (f64, f64, bool, Option<(f64, f64)>);

/// A linear least-squares fit: coefficients, covariance, residuals.
pub(super) type Fit = (Vec<f64>, Vec<Vec<f64>>, Vec<f64>);

/// A straight-line (or any linear) least-squares fit: the coefficients,
/// their covariance scaled by the residual variance, and the residuals.
pub(super) fn lstsq(rows: &[Vec<f64>], y: &[f64]) -> Option<Fit> {
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
pub(super) fn robust_lstsq(rows: &[Vec<f64>], y: &[f64], floor: f64) -> Option<(Fit, Vec<bool>)> {
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

/// What step 3 is told: the elevation's sine when given, and whether the
/// camera's distance is known (given, or to be found from a calibrated
/// lens), so that a pinhole can place a ring whose ends are out of the
/// picture.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hint {
    pub(super) sin_e: Option<f64>,
    pub(super) distance_known: bool,
    /// The light of the code value one below the largest: a step whose
    /// bright side reaches it is clipped ([`super::clip`]).
    pub(super) at_ceiling: f64,
    /// The camera's tone curve: steps are judged in grey levels
    /// ([`super::contrast`]).
    pub(super) tone: Tone,
}

/// Residuals of the ring's edge fits below a quarter pixel are never
/// outliers ([`robust_lstsq`]'s floor).
pub(super) const OUTLIER_FLOOR_PX: f64 = 0.25;

/// Step 3: the clamp ring in `img` (the photos' mean in the ring's rows)
/// about the axis column `x0`, `a0` the opening's half-width, px: each
/// column's lowest strong step beside the bubble's base (rows from the
/// swept band's lowest, `y_low`, and the sides' foot, `base`), the
/// polarity chosen by geometry ([`top_family`]), the ring's ends, the
/// edge fitted ([`super::top_edge::fit_top_edge`]); where the edge found
/// is the face's front, the dome's base checks it ([`base::dome_base`]).
pub(super) fn find_clamp(
    img: &Plane,
    x0: f64,
    a0: f64,
    [y_low, base]: [f64; 2],
    hint: Hint,
    lens: Option<&super::super::lens::Lens>,
) -> Result<Clamp, TrackError> {
    let given_sin_e = hint.sin_e;
    let (w, h) = (img.w as i64, img.h as i64);
    let lo_row = ((y_low - 0.3 * a0 - 4.0).floor() as i64).max(8);
    let hi_row = ((base.max(y_low) + 0.1 * a0 + 4.0).ceil() as i64).min(h - 12);
    if hi_row <= lo_row + 4 {
        return Err(clamp_not_found(format!(
            "the bubble's base (row {y_low:.0}) is at the photo's bottom border: the clamp is out of the picture"
        )));
    }
    let d_lo = (1.04 * a0 + 3.0).ceil() as i64;
    let d_hi = (1.6 * a0).floor() as i64;
    let d_range = d_lo..=d_hi;
    let columns: Vec<(f64, i64)> = [-1i64, 1]
        .into_iter()
        .flat_map(|side| d_range.clone().map(move |d| (side, d)))
        .map(|(side, d)| ((side * d) as f64, x0.round() as i64 + side * d))
        .filter(|&(_, x)| x >= 2 && x < w - 2)
        .collect();
    let contrast = {
        let profiles: Vec<_> = columns.iter().map(|&(_, x)| img.three_columns(x)).collect();
        let refs: Vec<&dyn Fn(i64) -> f64> = profiles.iter().map(|p| p as _).collect();
        Contrast::measured(hint.tone, &refs, lo_row..hi_row)
    };
    let floor = OUTLIER_FLOOR_PX;
    // One column: the lowest strong step of the polarity `sign` (or of the
    // strongest step's, when `None`) that is a step (the far side stays
    // different beyond a thin line's height), not a shelf edge or a cable;
    // and whether a second step almost as strong lies above it.
    let reach = (0.04 * a0).max(8.0) as i64;
    let column = |x: i64, sign: Option<f64>| -> Option<ColumnEdge> {
        let p = img.three_columns(x);
        let mean = |a: i64, b: i64| (a..b).map(&p).sum::<f64>() / (b - a) as f64;
        let steps: Vec<(i64, f64)> = (lo_row..hi_row)
            .map(|j| (j, super::contrast::step_at(&p, j)))
            .collect();
        let persistent = |r: i64, g: f64| {
            (mean(r + reach, r + 2 * reach) - mean(r - 2 * reach, r - reach)) * g.signum()
                >= 0.5 * g.abs()
        };
        let &(jmax, gmax) = steps
            .iter()
            .filter(|s| sign.is_none_or(|g| s.1 * g > 0.0))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
        let g = gmax.signum();
        if !contrast.counts(&p, jmax) {
            return None;
        }
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
        let upper = peaks
            .iter()
            .find(|&&i| steps[lowest].0 - steps[i].0 > 4 && steps[i].1 * g >= 0.8 * gmax.abs());
        let (e, step) = profile_edge(&p, h, steps[lowest].0 as f64 + 0.5, 3.0)?;
        let two = upper.is_some();
        // The upper step located with a window that stays off the lower
        // (its half-width at most half the gap less a row each side), and
        // the slope beside it measured only where the slope's rows clear
        // the lower step: towards the ring's ends a face's far side and
        // front converge, and with the usual window the front's step
        // pulled the far side's centroids 0.15-0.45 px towards it
        // (path-traced, 640x480: the ring's row 0.31 px high at a stated
        // 0.13 px, now 0.01 px).
        let upper = upper.and_then(|&i| {
            let gap = (steps[lowest].0 - steps[i].0) as f64;
            let hw = (0.5 * (gap - 2.0)).clamp(1.0, 3.0);
            let slopes = gap > hw + 1.0 + SLOPE_ROWS as f64;
            profile_edge_with(&p, h, steps[i].0 as f64 + 0.5, hw, slopes)
        });
        Some((e, step, two, upper))
    };
    let candidates = columns.len();
    let needed = (candidates / 10).max(6);
    // The ring's top edge, per polarity: each column's lowest strong step
    // of that polarity. A ring seen from above shows its top face as a
    // band between the face's far side (the ring's top edge, against the
    // background) and its front edge (against the ring's side); the face
    // may be lighter or darker than either, so the polarity is chosen by
    // geometry, not by which step is the stronger: see [`top_family`].
    // Each column read once per polarity (rising, falling).
    let read: [Vec<(f64, Option<ColumnEdge>)>; 2] = [1.0, -1.0].map(|sign| {
        columns
            .iter()
            .map(|&(d, x)| (d, column(x, Some(sign))))
            .collect()
    });
    let edges_of = |sign: f64| {
        read[usize::from(sign < 0.0)]
            .iter()
            .filter_map(|&(d, c)| Some((d, c?)))
    };
    let family = |sign: f64| {
        let mut pts: Vec<(f64, f64, f64)> = Vec::new();
        let mut ambiguous = 0usize;
        for (d, (e, step, two, _)) in edges_of(sign) {
            pts.push((d, e, step));
            ambiguous += usize::from(two);
        }
        (pts, ambiguous)
    };
    let (pts, ambiguous) = top_family([family(1.0), family(-1.0)], needed, floor);
    // Two steps of one polarity in most columns: a face shaded between the
    // wall and the ring's side shows its far side and its front as steps
    // the same way: the lower (each column's lowest) is the front, the
    // upper the far side, highest at the axis. When the upper steps bend
    // so (beyond four deviations of their curvature; a shelf's edge above
    // the ring is straight), the ring's top edge is the upper one, as for
    // a band of two polarities (path-traced at 640x480, 0.45 m, 2.6
    // degrees, a face of reflectance 0.2 between a wall of 0.55 and a side
    // of 0.12: 76 of 98 columns showed both, and init refused).
    let (pts, mut ambiguous) = match pts.first().map(|p| p.2.signum()) {
        Some(g) if ambiguous * 3 > pts.len() => {
            let upper: Vec<(f64, f64, f64)> = edges_of(g)
                .filter_map(|(d, (_, _, _, up))| up.map(|(e, step)| (d, e, step)))
                .collect();
            let up = upper.len() >= needed && super::band::bends_as_far_side(&upper, floor);
            if up { (upper, 0) } else { (pts, ambiguous) }
        }
        _ => (pts, ambiguous),
    };
    super::band::no_stripe(img, x0, &pts, reach, &contrast)?;
    if pts.len() < needed {
        return Err(clamp_not_found(format!(
            "no horizontal edge beside the bubble's base (rows {lo_row}-{hi_row}, {} of {candidates} columns show one): the clamp is out of the picture or hidden, or its top face is as light as the wall behind it and its front lies further below the clamp plane than a tenth of the opening's radius (a flange of the face's shade)",
            pts.len()
        )));
    }
    // The clamp's ends: from the rows just below its edge, the strongest
    // horizontal step on each side.
    let c_guess = {
        let mut rows: Vec<f64> = pts.iter().map(|p| p.1).collect();
        quantile(&mut rows, 0.9)
    };
    let mut step_mags: Vec<f64> = pts.iter().map(|p| p.2.abs()).collect();
    let clamp_step = quantile(&mut step_mags, 0.5);
    let rows_read = (0.04 * a0).clamp(4.0, 12.0) as i64;
    // Two ends mirrored about the axis.
    let centred = |l: f64, r: f64| ((l + r) / 2.0 - x0).abs() < 0.02 * a0 + 3.0;
    // The ends read from the rows starting at `r0`. An end's step is the
    // ring's side against the background, whose contrast owes nothing to
    // the face's: two ends mirrored about the axis are taken at the noise's
    // threshold, one end alone only when its step is as strong as 0.3 of
    // the face's (an edge in the background beyond the ring is not
    // mirrored). A side lit from the front darkens towards its outline,
    // close to the wall's shade: on path-traced photos (a light face on a
    // dark wall, 1024x768) its steps were half the 0.3, the ends were not
    // read, and the ring placed from its far side alone put the centre's
    // row 0.88 px high (0.10 px with the ends). Each end is looked for
    // beyond the innermost column where that side's far side was found
    // (the ring reaches at least so far), not from the opening's estimate
    // `a0` alone: `a0`, from the last photo's sides, can fall short of the
    // opening by a few per cent, and below the far side the bubble's own
    // outline then lay in the rows read (a light dome on a dark wall, `a0`
    // 2.5 % short: both ends found on the dome's outline and the set-up
    // refused).
    let inner = [-1.0, 1.0].map(|side: f64| {
        let on_side = pts.iter().filter(|p| p.0 * side > 0.0).map(|p| p.0.abs());
        on_side
            .min_by(f64::total_cmp)
            .map_or(1.02 * a0, |d| d.max(1.02 * a0))
    });
    let read_ends = |r0: i64| {
        let r1 = (r0 + rows_read).min(h - 1);
        let mut ends: [Option<(f64, f64)>; 2] = [None, None];
        if r1 <= r0 {
            return [None, None];
        }
        let rows: Vec<usize> = (r0..=r1).map(|r| r as usize).collect();
        let q = |x: i64| {
            let x = x.clamp(0, w - 1) as usize;
            rows.iter().map(|&r| img.at(x, r)).sum::<f64>() / rows.len() as f64
        };
        for (k, side) in [-1i64, 1].into_iter().enumerate() {
            let a = x0 + side as f64 * inner[k];
            let b = x0 + side as f64 * 2.2 * a0;
            let (lo, hi) = if side < 0 { (b, a) } else { (a, b) };
            let (lo, hi) = ((lo.floor() as i64).max(8), (hi.ceil() as i64).min(w - 10));
            if hi <= lo + 2 {
                continue;
            }
            if let Some((j, g)) = super::contrast::strongest_step(hint.tone, &q, lo, hi)
                && contrast.counts(&q, j)
                && j > lo
                && j < hi - 1
                && let Some((e, _)) = profile_edge(q, w, j as f64 + 0.5, 3.0)
            {
                ends[k] = Some((e, g.abs()));
            }
        }
        let mirrored = matches!(ends, [Some((l, _)), Some((r, _))] if centred(l, r));
        ends.map(|end| {
            end.filter(|&(_, g)| mirrored || g >= 0.3 * clamp_step)
                .map(|(e, _)| e)
        })
    };
    let r0 = (c_guess + 3.0).ceil() as i64;
    let ends = read_ends(r0);
    // Both ends centred on the axis, or one end and the axis.
    let half_of = |ends: [Option<f64>; 2]| match ends {
        [Some(l), Some(r)] if centred(l, r) => Some((r - l) / 2.0),
        [Some(_), Some(_)] => None,
        [Some(e), None] | [None, Some(e)] => Some((e - x0).abs()),
        [None, None] => None,
    };
    // The ring's top edge is one curve: each column's lowest step may be
    // the far side in some columns and, in others, an edge below it that
    // reaches into the rows searched only there (a flange's lower edge
    // below a face shaded between the wall and the ring's side, drawn so
    // by bulge synth: the plane was set 19 px low at a stated 3 px). The
    // upper step, where a column shows two, else the lowest, is then the
    // far side when it is one curve that bends as one; else init says so.
    let pts = match (super::band::jump(&pts, half_of(ends)), pts.first()) {
        (Some((d, from, to)), Some(first)) => {
            let g = first.2.signum();
            let upper: Vec<super::band::Point> = edges_of(g)
                .map(|(d, (e, step, _, up))| up.map_or((d, e, step), |(e, step)| (d, e, step)))
                .collect();
            if super::band::jump(&upper, half_of(ends)).is_none()
                && super::band::bends_as_far_side(&upper, floor)
            {
                ambiguous = 0;
                upper
            } else {
                return Err(clamp_not_found(format!(
                    "the clamp's top edge found jumps from row {from:.1} to {to:.1} at column {:.0}: two edges of the ring, each found in part of the columns (the face's far side, and its front or a flange's lower edge below it), and neither is one curve across the columns",
                    x0 + d
                )));
            }
        }
        _ => pts,
    };
    let clipped_px = super::clip::clipped_reach(img, x0, &pts, hint.at_ceiling);
    // Through the lens (when calibrated): the edge's points and the clamp's
    // ends in the undistorted image, as offsets from the axis's image (a
    // straight edge stays straight there; the photo's is bent by the lens).
    let (pts, ends) = super::super::lens::undistort_clamp(lens, x0, pts, ends, c_guess);
    let half = half_of(ends);
    // The ends read again below the ellipse's centre row `v0` when they
    // were read above it, for the ring's fit through a pinhole
    // (`ring::fit_ring`), which takes them as the tangent points of the
    // ring's outer circle: below that row the ring's outline is its side,
    // at the ring's full radius, while above it it is still the face's far
    // half, narrower (`a_f sqrt(1 - d^2 / (s a_f)^2)` at `d` rows above the
    // centre, `s` the sine of the elevation). Read above, the ends came out
    // 0.5-2 px in at 5 degrees, and the pinhole fit put the centre's row
    // 0.12-0.23 px high (0.01-0.03 px read below). The orthographic
    // ellipse keeps the ends as first read: on orthographically drawn
    // photos at 5 degrees the ends read below moved its row 0.01-0.04 px
    // low instead. The rows start where the face's near half lies 6 px
    // inside the ends, `s sqrt(12 a_f)` below the centre: just below it
    // the near half still reaches the ends, and a face lit lighter than
    // the wall weakens the side's step there (path-traced at 0.25 m and
    // 5.4 degrees, a face of reflectance 0.8 on a wall of 0.55: the ends
    // read from 3 rows below came out 0.7 px in, the centre's row 0.24 px
    // high). `None` when they need no new reading or are not found there.
    let ends_below = |v0: f64, s: f64, a_f: f64| {
        let from = (v0 + 1.0 + s.abs() * (12.0 * a_f).sqrt()).ceil() as i64;
        (from > r0)
            .then(|| {
                let ends = read_ends(from);
                let (_, ends) = super::super::lens::undistort_clamp(lens, x0, Vec::new(), ends, v0);
                half_of(ends)
            })
            .flatten()
    };
    let fit =
        super::top_edge::fit_top_edge(&pts, half, given_sin_e, ambiguous, hint.distance_known)?;
    let half_below = match (fit.ellipse, half) {
        (Some((v0, s)), Some(a_f)) => ends_below(v0, s, a_f).or(half),
        _ => None,
    };
    let (row, sin_e, slope, near, bent) = (fit.row, fit.sin_e, fit.slope, fit.near, fit.bent);
    // The face's front seen, not its far side: the dome's base, the
    // opening's near half in the clamp plane, checks that the front is the
    // face's and not a flange's lower edge (the face's shade below it),
    // which would put the plane the flange's height low ([`base::dome_base`]).
    let mut base_points = Vec::new();
    let mut on_base = false;
    let (mut row, mut sin_e) = (row, sin_e);
    if near && let Some(g) = pts.first().map(|p| p.2.signum()) {
        let front = |u: f64| match (half, bent) {
            (Some(a_f), None) => {
                let s = sin_e.map_or(0.0, |s| s.value);
                row.value + s * (a_f * a_f - u * u).max(0.0).sqrt() + slope.value * u
            }
            _ => row.value + bent.unwrap_or(0.0) * u * u + slope.value * u,
        };
        let found = base::dome_base(img, x0, a0, &front, g, &contrast);
        let (found, _) =
            super::super::lens::undistort_clamp(lens, x0, found, [None, None], row.value);
        // with the front's elevation when it is placed (the flange's
        // lower edge is the face's circle, lower), else fitted
        let held = bent.is_none().then_some(sin_e).flatten();
        if let Some((c, s)) = base::base_fit(&found, a0, held, floor) {
            base_points = found.iter().map(|p| [x0 + p.0, p.1]).collect();
            // (through a pinhole the two near halves are seen larger than
            // an ellipse: the pinhole decides, [`super::ring::place_ring`])
            on_base = bent.is_some()
                || !hint.distance_known && base::flange(row.value - c.value, row.std.hypot(c.std));
            if on_base {
                row = Estimate {
                    value: c.value,
                    std: c.std.hypot(base::BASE_SHADE_PX),
                };
                sin_e = Some(s);
            }
        }
    }
    Ok(Clamp {
        row,
        sin_e,
        slope,
        half_width_px: half,
        half_width_below_px: half_below,
        bend: bent,
        near,
        points: pts.iter().map(|p| [x0 + p.0, p.1]).collect(),
        base_points,
        on_base,
        clipped_px,
    })
}

/// The clamp plane not found, and why.
pub(super) fn clamp_not_found(detail: String) -> TrackError {
    TrackError::NotFound {
        what: "the clamp plane".into(),
        detail,
        keys: "clamp_row_px",
        clamp_plane: true,
    }
}

/// One polarity's edge points `(d, row, step)` and how many of its columns
/// show two strong steps of that polarity.
type Family = (Vec<(f64, f64, f64)>, usize);

/// The ring's top edge among the two polarities' edges (`[rising,
/// falling]`, each column's lowest strong step of that sign).
///
/// When only one polarity has an edge across enough columns, it is the
/// ring's. When both do, the two are the edges of one band across the
/// ring's top, and the ring's top edge is the upper one: the ring's outline
/// against the background is the topmost edge of the ring, whatever the
/// face's shade. Its far side and its front are the two halves of one
/// ellipse (`row -+ sin(e) sqrt(a_f^2 - d^2)`), so the band is thickest at
/// the axis and thins towards the ring's ends; a level camera sees a band
/// of constant thickness (the flange's front). A band that instead
/// thickens away from the axis (beyond four standard deviations of its
/// fitted curvature) is not the ring's: the upper edge is then something
/// behind the ring (a shelf's edge, straight, above a raised ring's curved
/// far side), and the lower edge is taken.
fn top_family([rising, falling]: [Family; 2], needed: usize, floor: f64) -> Family {
    let enough = |f: &Family| f.0.len() >= needed;
    // Without two edges to compare: the polarity seen in more columns.
    let larger = |r: Family, f: Family| if r.0.len() >= f.0.len() { r } else { f };
    if !(enough(&rising) && enough(&falling)) {
        return larger(rising, falling);
    }
    // The band's thickness in the columns where both polarities have an
    // edge: `lower - upper`, as a function of d^2, and the weaker of the
    // two steps.
    let pairs: Vec<(f64, f64, f64)> = rising
        .0
        .iter()
        .filter_map(|r| {
            let f = falling.0.iter().find(|f| f.0 == r.0)?;
            Some((r.0, f.1 - r.1, r.2.abs().min(f.2.abs())))
        })
        .collect();
    if pairs.len() < needed {
        return larger(rising, falling);
    }
    // Which polarity is the upper: each column votes with its weaker step.
    // Where one polarity's edge lies beyond the rows searched, that
    // column's strongest step of it is the wall's texture, at a random row
    // above or below the other edge; its vote is as weak as its step (a
    // light dome on a dark wall, the face darker than both: the face's
    // front, a step of 2.4 in light on the 0-255 scale, lay below the rows
    // searched in 16 of 32 columns, whose texture, 0.4-1.0, lay above the
    // far side and had tipped the median of the gaps).
    let vote: f64 = pairs.iter().map(|p| p.2 * p.1.signum()).sum();
    let rising_upper = vote > 0.0;
    let sign = if rising_upper { 1.0 } else { -1.0 };
    // The band's shape from the columns where the upper edge lies above
    // the lower: elsewhere the two are not one band's edges.
    let band: Vec<&(f64, f64, f64)> = pairs.iter().filter(|p| sign * p.1 > 0.0).collect();
    let rows: Vec<Vec<f64>> = band.iter().map(|p| vec![1.0, p.0 * p.0]).collect();
    let t: Vec<f64> = band.iter().map(|p| sign * p.1).collect();
    let thickens_outwards = band.len() >= needed
        && robust_lstsq(&rows, &t, floor)
            .is_some_and(|((c, cov, _), _)| c[1] > 0.0 && c[1] > 4.0 * cov[1][1].sqrt());
    match (rising_upper, thickens_outwards) {
        (true, false) | (false, true) => rising,
        (false, false) | (true, true) => falling,
    }
}
