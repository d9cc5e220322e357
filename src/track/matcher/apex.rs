//! The apex fit: the edge row of each column near the apex and a robust
//! parabola through them, in passes, with the choice between the
//! centroids and the two-sided step model.

use super::*;

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

/// The rows an edge fit is seeded at around row `y`: `y` itself, then rows
/// `step` apart, alternately below and above it, out to `reach` steps
/// (each column's search finds an edge within about the window's
/// half-height plus one of its start: that is the step).
pub(crate) fn seed_rows(y: f64, step: f64, reach: i32) -> impl Iterator<Item = f64> {
    std::iter::once(0)
        .chain((1..=reach).flat_map(|k| [k, -k]))
        .map(move |k| y + f64::from(k) * step)
}

/// The fewest columns the apex fit is made from: a parabola's three
/// coefficients and two more to judge its residual by.
pub(super) const FIT_MIN_COLUMNS: usize = 5;

/// Every how many columns the apex fit samples its span `x0 +- half_span`:
/// at most about 129 columns, wider spans (large photos) sampled.
pub(crate) fn span_stride(half_span: usize) -> usize {
    (half_span / 64).max(1)
}

/// How many columns the apex fit samples over a span `x0 +- half_span`
/// within the image ([`span_stride`]).
pub fn sampled_columns(half_span: usize) -> usize {
    2 * half_span / span_stride(half_span) + 1
}

/// The passes of [`edge_fit_in`], or of [`edge_fit_about`] when `axis` is
/// given.
pub(super) fn edge_fit_core(
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
        let mut on_line = 0;
        for c in (xc - span..=xc + span)
            .step_by(span_stride(s.half_span_px))
            .filter(|&c| c >= 0 && c < w)
        {
            let u = c as f64 - centre;
            let start = coef[0] + coef[1] * u + coef[2] * u * u;
            if let Some((e, step)) = cols.edge(c as usize, start) {
                located.push((u, e, step));
            } else if cols.on_line[c as usize] {
                on_line += 1;
            }
        }
        // A static line behind the bubble along most of the top (three
        // times the columns that show the top itself, so that it hides
        // three quarters of it or more): the dome's edge runs along it,
        // dark against dark or light against light, and cannot be seen
        // there; the few columns left are the line's own border where the
        // test narrowly missed it (a dark dome grown up to a cable's row,
        // 640x480: 5 of 57 columns left, the apex 2.2 px high at a stated
        // 0.16 px). Nothing on this photo measures the top. The factor is
        // measured on the tracker sweep's 250 dirty sequences, not derived:
        // at 3 it refuses two photos there (that one, and one written 0.3
        // standard deviations off); at 1 it refused 19, 17 of them good.
        if on_line > 3 * located.len() {
            return None;
        }
        // Leave out the columns with a bright spot under the edge, or light
        // there beyond the sensor's range, where enough others remain.
        let clipped: Vec<bool> = located
            .iter()
            .map(|&(u, e, _)| clipped_below(cols.img, (u + centre).round() as usize, e, cols.hw))
            .collect();
        let unspotted: Vec<(f64, f64, f64)> = located
            .iter()
            .zip(&clipped)
            .filter(|&(&(u, e, step), &clip)| {
                !clip && !spot_below(cols.img, (u + centre).round() as usize, e, cols.hw, step)
            })
            .map(|(&l, _)| l)
            .collect();
        let enough = unspotted.len() >= SPOT_MIN_KEPT && 4 * unspotted.len() >= located.len();
        // Where too few are left for that, the columns with light beyond the
        // sensor's range are still left out while the fit's own least
        // ([`FIT_MIN_COLUMNS`]) remain: their rows are not measured at all (a lamp's
        // clipped image over most of a light dome's top, path-traced at
        // 1024x768: with them the first photo was refused for its
        // curvature, without them it is written 0.4 % low, within one of
        // its deviations).
        // (read only then: most fits have enough)
        let unclipped: Vec<(f64, f64, f64)>;
        let candidates = if enough {
            &unspotted
        } else {
            unclipped = located
                .iter()
                .zip(&clipped)
                .filter(|(_, clip)| !**clip)
                .map(|(&l, _)| l)
                .collect();
            if unclipped.len() >= FIT_MIN_COLUMNS {
                &unclipped
            } else {
                &located
            }
        };
        // Keep columns whose step has the dome's polarity and about the
        // contrast of most.
        let Some(strong) = strong_columns(candidates, FIT_MIN_COLUMNS, UPPER_SHARE) else {
            break;
        };
        // Each row less the pull of light added under a light dome's edge
        // ([`overshoot_shift`]).
        let pts: Vec<(f64, f64)> = strong
            .iter()
            .map(|&(u, e, step)| {
                let c = (u + centre).round() as usize;
                (u, e - overshoot_shift(cols.img, c, e, cols.hw, step))
            })
            .collect();
        let (fit, pts) = robust_parabola(&pts, even)?;
        coef = fit.coef;
        let r = summarise(&fit, &pts, centre, span as f64, false);
        last = Some((pts, centre, r.x_vertex - centre, strong, located));
        result = Some(r);
    }
    let (pts, centre, u_v, strong, located) = last?;
    // Something on the edge weakened a tenth of its columns or more, or
    // columns that carry a tenth of the apex row's weight
    // ([`weakened_apex_share`]): then (only, it costs) the rows are tested
    // against the step model. Not where the dome side turns back under a
    // tenth of the strong ones (a broad highlight's flank) and nothing
    // weakened them: the turn contradicts the model's straight dome side,
    // so the two models' difference there holds the model's own error,
    // not the centroids' bias (on the tracker sweep's 500 dirty sequences
    // it had no correlation with the apex row's error: -0.07 over 821
    // light domes, 0.19 over 190 dark ones), and the turn's term below
    // bounds that bias from the centroid's own arithmetic.
    // (tested once per column: the turn's shift below needs it too)
    let turns: Vec<bool> = strong
        .iter()
        .map(|&(u, e, step)| turns_back(cols.img, (u + centre).round() as usize, e, cols.hw, step))
        .collect();
    let turning = turns.iter().filter(|t| **t).count();
    let weakened = 10 * (located.len() - strong.len()) >= located.len();
    let turning_side = !weakened && 10 * turning >= strong.len();
    let test = if weakened {
        Some(StepTest::Switch)
    } else if turning_side {
        None
    } else if weakened_apex_share(&located, &strong, u_v) >= 0.1 {
        Some(StepTest::Bound)
    } else {
        None
    };
    let lined = |&&(u, e, step): &&(f64, f64, f64)| {
        line_above(cols.img, (u + centre).round() as usize, e, cols.hw, step)
    };
    let clutter_on_top =
        cols.is_emptiest && 4 * located.iter().filter(lined).count() >= located.len();
    // The step model is tested against the rows as located, before a light
    // dome's highlight was taken off them: the highlight pulls the step
    // model too (nearly as much, on the tracker sweep's light domes), so
    // against the corrected rows the difference would hold the correction,
    // not a bias the two models do not share.
    let located_rows: Vec<(f64, f64)> = pts
        .iter()
        .map(|&(u, y)| {
            strong
                .iter()
                .find(|l| l.0 == u)
                .map_or((u, y), |l| (u, l.1))
        })
        .collect();
    // The fit, its columns and the step model's term (px^2); the fit's
    // `y_std` is its statistical error alone until the terms below join it.
    let (r, kept, model2) =
        match test.and_then(|t| two_sided_refit(cols, &located_rows, centre, u_v, even, t)) {
            Some(TwoSided::Model(fit, kept, spread2)) => {
                let r = result?;
                let m = summarise(&fit, &kept, centre, span as f64, true);
                (
                    EdgeFit {
                        columns: r.columns,
                        rms: r.rms,
                        ..m
                    },
                    kept,
                    spread2,
                )
            }
            Some(TwoSided::Bias(b2)) => (result?, pts, b2),
            None => (result?, pts, 0.0),
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
    // Which strong columns the fit kept.
    let in_fit: Vec<bool> = strong
        .iter()
        .map(|l| kept.iter().any(|k| k.0 == l.0))
        .collect();
    // The kept columns whose dome side turns back under the edge (`true`)
    // or not.
    let kept_turning = |turning: bool| {
        strong
            .iter()
            .zip(&turns)
            .zip(&in_fit)
            .filter(move |((_, t), k)| **t == turning && **k)
            .map(|((&l, _), _)| l)
    };
    // Where the dome side turns back under the edge, the centroids' shift
    // that its rise can cause ([`turn_back_shift`]), carried to the apex
    // row by the fit itself: the parabola through each kept column's shift
    // (0 where the side does not turn back), at the apex column. The
    // shifts share their cause (one highlight's flank, read with one
    // assumption on where its light lies), so their errors move together
    // and add through the fit's weights; those weigh the columns near the
    // apex most and those at the span's ends against them (a parabola's
    // value at its vertex), so a highlight under the top moves the apex
    // row more than its shift's mean over the columns, and one on the
    // flanks less.
    let turn = {
        let shifts: Vec<(f64, f64)> = strong
            .iter()
            .zip(&turns)
            .zip(&in_fit)
            .filter(|(_, k)| **k)
            .map(|((&(u, e, step), &turns_here), _)| {
                if !turns_here {
                    return (u, 0.0);
                }
                let shift =
                    turn_back_shift(cols.img, (u + centre).round() as usize, e, cols.hw, step);
                // Taken off the centroids' rows: what is left of it (the
                // step model's rows, where they are the fit's, keep it).
                if is_light_dome(step) && !r.two_sided {
                    (u, shift / OVERSHOOT_SPREAD)
                } else {
                    (u, shift)
                }
            })
            .collect();
        if shifts.iter().all(|s| s.1 == 0.0) {
            0.0
        } else {
            let u_v = r.x_vertex - centre;
            parabola(&shifts, even).map_or(0.0, |f| {
                let [a, b, c] = f.coef;
                (a + b * u_v + c * u_v * u_v).powi(2)
            })
        }
    };
    // A rim ([`rim_bias`]) on the kept columns whose dome side does not
    // turn back, unless a tenth of them do (the turn's term then bounds
    // the light near the edge): the centroids' shift it implies, stated as
    // a bias bound (the apex is not moved: a shade or a highlight's flank
    // can look alike).
    // Where columns were left out for a spot, its halo over the kept ones
    // is a reflection too, which the step model's straight dome side does
    // not follow: two dirty dark domes of the sweep with a highlight
    // against the top were written at 4.2-4.5 deviations without it.
    let rim = if !turning_side {
        let quiet: Vec<(f64, f64, f64)> = kept_turning(false).collect();
        rim_bias(cols.img, &quiet, centre, cols.hw, 0.5 / coef[2])
    } else {
        0.0
    };
    // The step model's term, the spot's tail, the turning dome side's shift
    // and the rim's (and, on the axis, the mirror test below) each measure
    // one error: how the light on the dome side near the edge moves the
    // centroids off the outline. They read it from different columns and
    // rows, so several fire on one cause (a highlight against the top
    // weakens columns, leaves a tail and a halo, and lies on one side);
    // summed, that error was counted more than once, and the sweep's
    // dirty photos were over-stated (RMS(error / std) 0.81, 97.8 % within
    // 1.96 std, docs/track.md). The largest of them is the bound stated.
    // Where the rows are the centroids', the shift that leaving out the
    // differences against the edge's polarity gives them: a noisier or
    // textured side pulls the centroids towards it
    // ([`Columns::polarity_shift`]); its mean over the kept columns beyond
    // its own standard error. It is read from the same rows and a
    // highlight's light moves it too, so it joins the largest.
    let polarity = if r.two_sided {
        0.0
    } else {
        let shifts: Vec<f64> = strong
            .iter()
            .zip(&in_fit)
            .filter(|(_, k)| **k)
            .filter_map(|(&(u, e, step), _)| {
                cols.polarity_shift((u + centre).round() as usize, e, step)
            })
            .collect();
        mean_beyond_noise2(&shifts)
    };
    let light2 = [model2, tail, turn, rim * rim, polarity]
        .into_iter()
        .fold(0.0, f64::max);
    let stat2 = r.y_std * r.y_std;
    let r = EdgeFit {
        y_std: (stat2 + light2).sqrt(),
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
                y_std: (stat2 + (slope * s_std).powi(2) + light2.max(sides)).sqrt(),
                x_std: s_std,
                ..r
            }
        }
    })
}
