//! A ring face lit beyond the sensor's ceiling: the clamp's edge located on
//! a clipped step, and the deviation that adds to the clamp's row.
//!
//! A blurred step from the wall's light `W` to the face's `F` crosses its
//! middle `(W + F) / 2` at the edge. When `F` lies above what the sensor
//! can record, the photo shows the step cut at the ceiling `C`, and its
//! middle `(W + C) / 2` is crossed before the edge, on the wall's side. How
//! far before depends on `F`, which the photo no longer shows: the edge
//! lies between the crossing located and the first row at the ceiling as
//! long as the face is at most twice as far above the wall as the ceiling
//! (`F <= 2 C - W`, where the true middle is still below `C`). That
//! distance `t` is read in each column; the row's deviation gains
//! `t / sqrt(3)`, the RMS of a shift anywhere in `[0, t]`. On path-traced
//! photos of a face of reflectance 0.8 under a lamp (1024x768, 0.45 m,
//! 3.3 degrees, blur 1.2 px) the face's far side came out 0.45 px towards
//! the wall and the ring's centre row 0.60 px high, with `t` about 1.5 px.

use super::band::Point;
use super::*;

/// How many rows past the edge the step's bright side is read.
const REACH_ROWS: i64 = 8;

/// The distance, px, from the edge located to the first of two rows at the
/// ceiling on the step's bright side (the median over the clipped columns),
/// when at least half the columns of `pts` are clipped: a light at or
/// above `at_ceiling` (the light of the code value one below the largest).
pub(super) fn clipped_reach(img: &Plane, x0: f64, pts: &[Point], at_ceiling: f64) -> Option<f64> {
    let mut reach: Vec<f64> = pts
        .iter()
        .filter_map(|&(d, e, step)| {
            let p = img.three_columns((x0 + d).round() as i64);
            // the bright side: below the edge for a step that rises downwards
            let dir = if step > 0.0 { 1 } else { -1 };
            let from = e.round() as i64;
            (0..=REACH_ROWS)
                .map(|k| from + dir * k)
                .find(|&r| p(r) >= at_ceiling && p(r + dir) >= at_ceiling)
                .map(|r| (r as f64 - e).abs())
        })
        .collect();
    (reach.len() * 2 >= pts.len() && !reach.is_empty()).then(|| quantile(&mut reach, 0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A column image: rows above `edge` at the wall's light, below it a
    /// step to `face` blurred by a ramp 3 rows wide, cut at 255.
    fn plane(face: f64, edge: f64) -> Plane {
        let (w, h) = (9, 40);
        let v = (0..w * h)
            .map(|i| {
                let y = (i / w) as f64;
                let t = ((y - edge) / 3.0 + 0.5).clamp(0.0, 1.0);
                (100.0 + (face - 100.0) * t).min(255.0) as f32
            })
            .collect();
        Plane { w, h, v }
    }

    #[test]
    fn a_step_below_the_ceiling_is_not_clipped() {
        let img = plane(240.0, 20.0);
        let pts: Vec<Point> = (-3..=3).map(|d| (f64::from(d), 20.0, 40.0)).collect();
        assert_eq!(clipped_reach(&img, 4.0, &pts, 254.0), None);
    }

    #[test]
    fn a_clipped_step_reaches_the_ceiling_past_its_located_edge() {
        // the face twice as far above the wall as the ceiling (the bound):
        // the clipped step's middle (177.5) is crossed 0.75 rows before the
        // edge, where the true middle is the ceiling
        let img = plane(410.0, 20.0);
        let located = 19.25;
        let pts: Vec<Point> = (-3..=3).map(|d| (f64::from(d), located, 40.0)).collect();
        let t = clipped_reach(&img, 4.0, &pts, 254.0).expect("clipped");
        // the first row at the ceiling is the edge's own, 20
        assert!((t - (20.0 - located)).abs() < 1e-9, "{t}");
        // the true edge lies within [located, located + t]
        assert!(20.0 >= located && 20.0 <= located + t);
    }
}
