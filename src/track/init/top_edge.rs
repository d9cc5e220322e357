//! Step 3 of `bulge init`, its fit: the clamp ring's top edge through the
//! points found beside the bubble's base, as an ellipse through the ring's
//! ends (the camera's elevation fitted or given) or as a straight edge
//! checked for the bend of a raised camera, with the slope of a rolled
//! one.

use super::clamp::{Fit, OUTLIER_FLOOR_PX, clamp_not_found, clear_of_ends, robust_lstsq};
use super::plane::arc;
use super::*;

/// The ring's top edge fitted over the columns `pts` (`(d, row, step)`,
/// `d` from the axis): see [`fit_top_edge`].
pub(super) struct TopEdge {
    /// The row of the ring's centre (of the straight edge, or the bent
    /// edge's top, when no ellipse is placed), px.
    pub(super) row: Estimate,
    /// The sine of the elevation, when fitted.
    pub(super) sin_e: Option<Estimate>,
    /// The edge's slope across the photo (a rolled camera).
    pub(super) slope: Estimate,
    /// The edge found is the face's front (lowest at the axis).
    pub(super) near: bool,
    /// The bend `k` of a straight edge's fit `c + k d^2` taken as a far
    /// side to be placed through the pinhole.
    pub(super) bent: Option<f64>,
    /// An ellipse fitted or placed through the ends: its centre row and
    /// the sine it was fitted with, for reading the ends below it.
    pub(super) ellipse: Option<(f64, f64)>,
}

/// The ring's top edge through its points: an ellipse through the ring's
/// ends `half` (its elevation fitted, or given as `given_sin_e`), else a
/// straight edge checked for a bend that betrays a raised camera (taken
/// as a far side when the distance is known for a pinhole to place it).
/// `ambiguous` columns showed two strong steps ([`check_inliers`]).
pub(super) fn fit_top_edge(
    pts: &[(f64, f64, f64)],
    half: Option<f64>,
    given_sin_e: Option<f64>,
    ambiguous: usize,
    distance_known: bool,
) -> Result<TopEdge, TrackError> {
    let floor = OUTLIER_FLOOR_PX;
    // Each fit has a slope across the photo: a camera rolled about its
    // view axis sees the clamp's edge tilted (the row at the axis stays
    // the clamp ring's centre's).
    let mut near = false;
    let mut bent = None;
    let mut ellipse = None;
    let (row, sin_e, slope) = match (half, given_sin_e) {
        (Some(a_f), None) => {
            let used: Vec<&(f64, f64, f64)> =
                pts.iter().filter(|p| clear_of_ends(p.0, a_f)).collect();
            let x: Vec<Vec<f64>> = used
                .iter()
                .map(|p| vec![1.0, -arc(a_f, p.0), p.0])
                .collect();
            let y: Vec<f64> = used.iter().map(|p| p.1).collect();
            let (((coef, cov, res), keep), slope) =
                with_slope(&x, &y, floor).ok_or_else(|| few_columns(x.len(), Some(a_f)))?;
            ellipse = Some((coef[0], coef[1]));
            check_inliers(&keep, ambiguous)?;
            let infl = lag1_inflation(&res);
            let est = |i: usize| Estimate {
                value: coef[i],
                std: cov[i][i].sqrt() * infl,
            };
            // Lowest at the axis: the face's front (the same ellipse, its
            // centre the same row; a camera below the clamp plane would
            // not see the bubble's base past the ring's near edge).
            let mut sin_e = est(1);
            near = sin_e.value < -2.0 * sin_e.std;
            if near {
                sin_e.value = -sin_e.value;
            }
            (est(0), Some(sin_e), slope)
        }
        (_, Some(s)) if s != 0.0 => {
            let Some(a_f) = half else {
                return Err(clamp_not_found(
                    "the camera is raised (elevation given) but the clamp's ends are not in the picture, so its ellipse's centre cannot be placed".into(),
                ));
            };
            let used: Vec<&(f64, f64, f64)> =
                pts.iter().filter(|p| clear_of_ends(p.0, a_f)).collect();
            let x: Vec<Vec<f64>> = used.iter().map(|p| vec![1.0, p.0]).collect();
            let y: Vec<f64> = used.iter().map(|p| p.1 + s * arc(a_f, p.0)).collect();
            let (((coef, cov, res), keep), slope) =
                with_slope(&x, &y, floor).ok_or_else(|| few_columns(x.len(), Some(a_f)))?;
            ellipse = Some((coef[0], s));
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
            let (((coef, cov, res), keep), bent_slope) =
                with_slope(&x, &y, floor).ok_or_else(|| few_columns(x.len(), None))?;
            check_inliers(&keep, ambiguous)?;
            let dmax = pts.iter().map(|p| p.0.abs()).fold(0.0, f64::max);
            let bend = coef[1] * dmax * dmax;
            let bend_std = cov[1][1].sqrt() * dmax * dmax;
            let bends = given_sin_e.is_none() && bend.abs() > 1.0 && bend.abs() > 4.0 * bend_std;
            if bends && distance_known {
                // the far side of an ellipse seen from above (or its front,
                // bending down), to be placed through the pinhole: its top
                // (bottom) row the start
                bent = Some(coef[1]);
                near = coef[1] < 0.0;
                let top = Estimate {
                    value: coef[0],
                    std: cov[0][0].sqrt() * lag1_inflation(&res),
                };
                (top, None, bent_slope)
            } else if bends {
                return Err(TrackError::NotFound {
                    what: "the camera's elevation".into(),
                    detail: format!(
                        "the clamp's top edge bends by {bend:.1} px across the photo (a camera above the clamp plane sees the clamp as an ellipse), but the clamp's ends are not in the picture to place the ellipse"
                    ),
                    keys: "elevation_deg and clamp_row_px (the row of the clamp ring's centre)",
                    clamp_plane: true,
                });
            } else {
                let (kept_x, kept_y): (Vec<Vec<f64>>, Vec<f64>) = x
                    .iter()
                    .zip(&y)
                    .zip(&keep)
                    .filter(|(_, k)| **k)
                    .map(|((r, v), _)| (vec![r[0], r[2]], *v))
                    .unzip();
                let (((c, ccov, cres), _), slope) = with_slope(&kept_x, &kept_y, f64::INFINITY)
                    .ok_or_else(|| few_columns(kept_x.len(), None))?;
                // An elevation the bend cannot show, unless the camera is
                // said to be level: a far side bending by `b` over the
                // columns seen (`k d^2` at the outermost, `dmax`) is seen
                // from `s = 2 R k` above, and the ring's centre lies `s R =
                // 2 b (R / dmax)^2` below its top, `R >= dmax` the ring's
                // radius. The bend is within its noise, so not taken, but
                // its deviation is carried, at `R = dmax`: on the init
                // sweep a camera 0.6 degrees up with one end of the ring
                // seen put the row 0.77 px high at a stated 0.12 px (the
                // bend 2.5 +- 0.64 px, short of four deviations).
                let hidden = if given_sin_e.is_none() {
                    2.0 * bend_std * lag1_inflation(&res)
                } else {
                    0.0
                };
                let row = Estimate {
                    value: c[0],
                    std: (ccov[0][0].sqrt() * lag1_inflation(&cres)).hypot(hidden),
                };
                (row, None, slope)
            }
        }
    };
    Ok(TopEdge {
        row,
        sin_e,
        slope,
        near,
        bent,
        ellipse,
    })
}

/// Too few columns for a fit, said with what they are (`ends`: the half-width
/// between the ring's ends found, px).
fn few_columns(n: usize, ends: Option<f64>) -> TrackError {
    clamp_not_found(match ends {
        Some(a_f) => format!(
            "only {n} columns of the clamp's top edge lie between its ends, found {a_f:.0} px either side of the bubble's axis: the ends found may be other edges (a clamp hardly lighter or darker than the wall, or its ends outside the picture)"
        ),
        None => format!(
            "only {n} columns show the clamp's top edge beside the bubble's base: the clamp is hardly lighter or darker than the wall, hidden, or out of the picture"
        ),
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
        return Err(clamp_not_found(format!(
            "two candidate edges beside the bubble's base: only {kept} of {} columns agree on one, {ambiguous} show two strong edges",
            keep.len()
        )));
    }
    Ok(())
}
