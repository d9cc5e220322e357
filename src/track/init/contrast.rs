//! Which steps across a column of the clamp's rows are edges and which are
//! noise, whatever the scene's light.
//!
//! Edges are located on light (the photo's grey levels through the
//! camera's inverted tone curve), but whether a step stands out is judged
//! in grey levels, where a camera's noise is nearly even: photon noise,
//! whose deviation grows as the square root of the light, comes out of an
//! sRGB-like curve (close to a 1/2.4 power) about level across grey
//! levels, and the read-out and the JPEG's rounding act on the grey levels
//! themselves. In light, the same step of 25 grey levels is 7 times
//! smaller on a dark wall (grey 45 to 20: 4.9 levels of light) than on a
//! light one (grey 190 to 165: 35 levels), and a floor of 8 levels of light
//! refused 45 of the init sweep's 77 clean light domes on a dark wall.
//!
//! The threshold is measured where it is used: the robust deviation of
//! the step over every row and column searched, most of which hold no
//! edge (the wall's texture, the noise and the JPEG's blocks all count),
//! times [`K_SIGMA`], and never under [`FLOOR_LEVELS`].

use super::*;
use crate::track::image::Tone;

/// Steps beyond this many robust deviations of the search window's steps
/// are edges: the largest of `R` steps of pure Gaussian noise exceeds `k`
/// deviations with a chance of about `R Phi(-k)`, under 1e-4 per column for
/// the at most 300 rows a column's search reads.
pub(super) const K_SIGMA: f64 = 5.0;

/// The smallest step, grey levels, that counts whatever the deviation: an
/// 8-bit photo's rounding moves a level by at most 1, a JPEG's 8x8 blocks
/// (quality 80-95) a level or two at their borders.
pub(super) const FLOOR_LEVELS: f64 = 3.0;

/// The step at row `j` of profile `p` (light): the mean of rows `j + 1`,
/// `j + 2` less that of rows `j - 1`, `j` (the column search's stencil).
pub(super) fn step_at(p: &dyn Fn(i64) -> f64, j: i64) -> f64 {
    0.5 * (p(j + 2) + p(j + 1) - p(j) - p(j - 1))
}

/// The strongest step of a profile (light) inside `lo..hi`, judged in
/// grey levels ([`step_at`]'s stencil on the encoded means): its position
/// and its value in light. A step of light would favour the light side of
/// a photo, whose noise in light is the largest: through an sRGB curve a
/// grey level at 180 is 8 times as much light as one at 30, and on a light
/// dome in front of a dark wall (noise 3-4 levels, blurred by 1.4 px and a
/// motion of up to 4 px) the noise inside the dome beat the dome's side
/// in 7 of 56 rows, which put the axis 12 px off.
pub(super) fn strongest_step(
    tone: Tone,
    p: &dyn Fn(i64) -> f64,
    lo: i64,
    hi: i64,
) -> Option<(i64, f64)> {
    let j = (lo..hi)
        .map(|j| (j, levels_at(tone, p, j)))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?
        .0;
    // Within the step found, its steepest row in light: where the edge's
    // location starts, as before levels chose the step (through the curve
    // the steepest row in levels lies up to a row towards the dark side).
    ((j - 2).max(lo)..(j + 3).min(hi))
        .map(|j| (j, step_at(p, j)))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
}

/// The smallest step that counts as an edge, in grey levels, and the
/// camera's tone curve to judge steps of light by.
#[derive(Debug, Clone, Copy)]
pub(super) struct Contrast {
    pub(super) tone: Tone,
    /// Grey levels.
    pub(super) min_levels: f64,
}

impl Contrast {
    /// Measured on the profiles `columns` over rows `rows` (each profile
    /// light, [`Plane::three_columns`]).
    pub(super) fn measured(
        tone: Tone,
        columns: &[&dyn Fn(i64) -> f64],
        rows: std::ops::Range<i64>,
    ) -> Contrast {
        let mut steps: Vec<f64> = columns
            .iter()
            .flat_map(|p| rows.clone().map(move |j| levels_at(tone, *p, j)))
            .collect();
        let sigma = robust_sd(&mut steps);
        Contrast {
            tone,
            min_levels: (K_SIGMA * sigma).max(FLOOR_LEVELS),
        }
    }

    /// Whether the step at row `j` of profile `p` (light) is an edge.
    pub(super) fn counts(&self, p: &dyn Fn(i64) -> f64, j: i64) -> bool {
        levels_at(self.tone, p, j).abs() >= self.min_levels
    }
}

/// The step at row `j` of profile `p` in grey levels (signed).
fn levels_at(tone: Tone, p: &dyn Fn(i64) -> f64, j: i64) -> f64 {
    let below = 0.5 * (p(j) + p(j - 1));
    let above = 0.5 * (p(j + 2) + p(j + 1));
    tone.encode(above) - tone.encode(below)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Response;

    #[test]
    fn encode_inverts_the_tone_curve() {
        let t = Tone::of(Response::Srgb);
        for v in [0u8, 1, 20, 45, 128, 254, 255] {
            assert!((t.encode(t.light(v)) - f64::from(v)).abs() < 1e-9, "{v}");
        }
        // between two levels: the closed-form curve's level within the
        // table's linear interpolation (under 0.01 level above grey 10)
        let l = 255.0 * Response::Srgb.to_linear(45.5 / 255.0);
        assert!((t.encode(l) - 45.5).abs() < 0.01);
        assert_eq!(Tone::LINEAR.encode(37.25), 37.25);
        assert_eq!(t.encode(-1.0), 0.0);
        assert_eq!(t.encode(300.0), 255.0);
    }

    #[test]
    fn a_dark_ring_on_a_dark_wall_counts_where_light_would_not() {
        // grey 45 above row 50, 20 below; the same 25 levels at 190 / 165
        let t = Tone::of(Response::Srgb);
        let light = |v: f64| 255.0 * Response::Srgb.to_linear(v / 255.0);
        let dark = move |j: i64| light(if j < 50 { 45.0 } else { 20.0 });
        let bright = move |j: i64| light(if j < 50 { 190.0 } else { 165.0 });
        let c = Contrast {
            tone: t,
            min_levels: 8.0,
        };
        assert!(c.counts(&dark, 49) && c.counts(&bright, 49));
        // in light the dark step is under a fifth of the bright one
        assert!(step_at(&dark, 49).abs() < 0.25 * step_at(&bright, 49).abs());
        assert!(!c.counts(&dark, 30));
    }

    #[test]
    fn the_threshold_follows_the_noise() {
        // a flat profile with a deterministic ripple of no period, `amp
        // sin(0.7 j^2)` (deviation amp / sqrt 2, that of its steps the
        // same): at 0.3 levels the floor holds; at 6 the threshold is about
        // 5 times 4.2
        let ripple = |amp: f64| move |j: i64| 100.0 + amp * (0.7 * (j * j) as f64).sin();
        let (small, large) = (ripple(0.3), ripple(6.0));
        let c = Contrast::measured(Tone::LINEAR, &[&small], 0..400);
        assert_eq!(c.min_levels, FLOOR_LEVELS);
        let c = Contrast::measured(Tone::LINEAR, &[&large], 0..400);
        assert!(
            c.min_levels > 12.0 && c.min_levels < 30.0,
            "{}",
            c.min_levels
        );
    }
}
