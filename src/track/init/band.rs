//! The clamp ring's top edge when each column may show more than one step
//! of one polarity: the face's far side, its front and a flange's lower
//! edge below it are all steps the same way when the face is shaded
//! between the wall and the ring's side. Two rules, both from the ring's
//! geometry: its top edge is one curve across the columns (it does not
//! jump from one edge to another), and its far side bends as an ellipse's
//! top half does (highest at the axis).

use super::*;

/// One column's edge point: its offset from the axis `d`, px, its row and
/// its step (signed).
pub(super) type Point = (f64, f64, f64);

/// How far apart, px, two steps of one polarity must lie in one column to
/// be told apart as two edges (the column search's rule): also the most
/// an edge of the ring moves per column, which its ellipse exceeds only
/// within `s^2 R / 32` px of its ends (`s` the sine of the elevation, `R`
/// the ring's radius in px: under 0.2 px at 10 degrees and `R` = 200 px).
pub(super) const TWO_EDGES_PX: f64 = 4.0;

/// The fewest columns a run of points must hold to count as an edge: the
/// fewest the clamp's search asks of a whole edge. A shorter run is a
/// blemish that the robust fit leaves out.
const MIN_RUN: usize = 6;

/// Where the points found split between two edges: the rows of two runs
/// of at least [`MIN_RUN`] columns on one side of the axis, each one curve
/// (no neighbour more than [`TWO_EDGES_PX`] per column away), more than
/// [`TWO_EDGES_PX`] apart where they meet. Only the columns within
/// `within` px of the axis are read (the ring's half-width when its ends
/// were found: beyond them the steps are not the ring's).
///
/// Returns the column offset where the second run starts and the two
/// runs' rows there.
pub(super) fn jump(pts: &[Point], within: Option<f64>) -> Option<(f64, f64, f64)> {
    for side in [-1.0, 1.0] {
        let mut one: Vec<&Point> = pts
            .iter()
            .filter(|p| p.0 * side > 0.0 && within.is_none_or(|h| p.0.abs() < h - 1.5))
            .collect();
        one.sort_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
        // Each point joins the run it continues, else starts one.
        let mut runs: Vec<Vec<&Point>> = Vec::new();
        for p in one {
            let joins = runs.iter_mut().find(|r| {
                let q = r[r.len() - 1];
                (p.1 - q.1).abs() <= TWO_EDGES_PX * (p.0 - q.0).abs()
            });
            match joins {
                Some(r) => r.push(p),
                None => runs.push(vec![p]),
            }
        }
        let long: Vec<&Vec<&Point>> = runs.iter().filter(|r| r.len() >= MIN_RUN).collect();
        if let [first, second, ..] = long[..] {
            // where the later run starts, and the first's row nearest it
            let start = second[0];
            let near = first
                .iter()
                .min_by(|a, b| (a.0 - start.0).abs().total_cmp(&(b.0 - start.0).abs()))?;
            return Some((start.0, near.1, start.1));
        }
    }
    None
}

/// Whether points bend as an ellipse's top half does, the ring's far side
/// seen from above: `row = c + k d^2 + m d` with `k` positive beyond four
/// of its standard deviations (a shelf's edge behind the ring is
/// straight).
pub(super) fn bends_as_far_side(p: &[Point], floor: f64) -> bool {
    let x: Vec<Vec<f64>> = p.iter().map(|q| vec![1.0, q.0 * q.0, q.0]).collect();
    let y: Vec<f64> = p.iter().map(|q| q.1).collect();
    robust_lstsq(&x, &y, floor)
        .is_some_and(|((c, cov, res), _)| c[1] > 4.0 * cov[1][1].sqrt() * lag1_inflation(&res))
}

/// Refuses a stripe lying on the edge found: a step of the other polarity
/// within the persistence window above it (so thin that the column
/// search's persistence rule took it for a line). Across most columns that is the ring's own flange lit
/// lighter (or darker) than both the wall and the ring's side, whose
/// upper edge would be the ring's top: the row cannot be told from a
/// stripe in front of the ring, so init says so rather than guess. From
/// a camera raised well above the ring the ring's top face itself shows
/// as a band beside the bubble (a path-traced scene 8.3 degrees above was
/// refused for a stripe 16 px tall at 1280x960; which band it was is not
/// established), so the message names that too.
pub(super) fn no_stripe(
    img: &Plane,
    x0: f64,
    pts: &[Point],
    reach: i64,
    contrast: &super::contrast::Contrast,
) -> Result<(), TrackError> {
    if let Some(g) = pts.first().map(|p| p.2.signum()) {
        let stripes: Vec<f64> = pts
            .iter()
            .filter_map(|&(d, e, _)| {
                let p = img.three_columns(x0.round() as i64 + d as i64);
                let top = (e.round() as i64 - 2 * reach).max(1);
                let (j, step) =
                    super::contrast::strongest_step(contrast.tone, &p, top, e.round() as i64 - 3)?;
                (step * g < 0.0 && contrast.counts(&p, j)).then_some(e - j as f64 - 1.5)
            })
            .collect();
        if stripes.len() * 5 >= pts.len() * 3 {
            let mut tall = stripes;
            return Err(super::clamp::clamp_not_found(format!(
                "a stripe about {:.0} px tall lies on the clamp's top edge in {} of {} columns (a flange lit unlike the wall and the ring's side, something in front of the ring, or the ring's top face itself seen from a camera raised beyond the 5 degrees init is measured on): its top or its bottom may be the clamp's edge",
                quantile(&mut tall, 0.5),
                tall.len(),
                pts.len()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn far_side(d: f64) -> f64 {
        // a ring of 350 px seen from 3 degrees, centre row 480
        480.0 - 0.052 * (350.0f64 * 350.0 - d * d).max(0.0).sqrt()
    }

    #[test]
    fn one_edge_with_a_blemish_is_one_curve() {
        let mut pts: Vec<Point> = (290..345)
            .flat_map(|d| {
                [
                    (-d as f64, far_side(d as f64), -60.0),
                    (d as f64, far_side(d as f64), -60.0),
                ]
            })
            .collect();
        // two columns crossed by something 15 px lower
        pts[10].1 += 15.0;
        pts[11].1 += 15.0;
        assert_eq!(jump(&pts, Some(350.0)), None);
        assert!(bends_as_far_side(&pts, 0.25));
    }

    #[test]
    fn the_far_side_then_a_flange_below_is_a_jump() {
        // the far side found near the axis, a flange's edge 20 px lower
        // towards the ends (where it comes into the rows searched)
        let pts: Vec<Point> = (290..349)
            .map(|d| {
                let d = d as f64;
                let row = if d < 335.0 {
                    far_side(d)
                } else {
                    2.0 * 480.0 - far_side(d) + 15.0
                };
                (-d, row, -60.0)
            })
            .collect();
        let (d, from, to) = jump(&pts, Some(350.0)).expect("two edges");
        assert_eq!(d, -335.0);
        assert!((from - far_side(334.0)).abs() < 1e-9);
        assert!(to - from > 15.0);
        // beyond the ring's ends the steps are not read
        assert_eq!(jump(&pts, Some(336.0)), None);
    }

    #[test]
    fn a_straight_edge_does_not_bend_as_a_far_side() {
        let pts: Vec<Point> = (290..345)
            .flat_map(|d| {
                // a shelf's edge, sloping a little, with the edge fit's noise
                let row = |d: f64| 470.0 + 0.01 * d + 0.05 * (1.7 * d).sin();
                [
                    (-d as f64, row(-d as f64), 60.0),
                    (d as f64, row(d as f64), 60.0),
                ]
            })
            .collect();
        assert!(!bends_as_far_side(&pts, 0.25));
    }
}
