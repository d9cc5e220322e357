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
/// ([`rows_read_below`]; means of neighbouring rows, against the noise). A
/// broad highlight whose flank rises slowly from the edge does this
/// without turning away again within those rows, so [`spot_below`] does
/// not leave the column out; its rise cuts the lower tail of the blurred
/// step short and lifts the centroid (0.27 px on a drawn dome), which the
/// minmod slope below the edge misses where the flank turns within the
/// slope rows. A flat dome side stays within the noise.
pub(super) fn turns_back(img: &Gray, c: usize, e: f64, hw: f64, step: f64) -> bool {
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
