//! The photos as light: a grayscale image read through the camera's tone
//! curve, as floats, and the profiles init's searches read from it.

use crate::track::image::Gray;

/// A grayscale image as floats.
pub(super) struct Plane {
    pub(super) w: usize,
    pub(super) h: usize,
    pub(super) v: Vec<f32>,
}

impl Plane {
    pub(super) fn of(g: &Gray) -> Plane {
        Plane {
            w: g.width,
            h: g.height,
            v: g.data.iter().map(|&b| g.tone.light(b) as f32).collect(),
        }
    }

    #[inline]
    pub(super) fn at(&self, x: usize, y: usize) -> f64 {
        f64::from(self.v[y * self.w + x])
    }

    /// The 3x3 mean (edges replicated).
    pub(super) fn box3(&self) -> Plane {
        let (w, h) = (self.w, self.h);
        let mut tmp = vec![0f32; w * h];
        for y in 0..h {
            let r = &self.v[y * w..(y + 1) * w];
            for x in 0..w {
                let (a, b) = (x.saturating_sub(1), (x + 1).min(w - 1));
                tmp[y * w + x] = (r[a] + r[x] + r[b]) / 3.0;
            }
        }
        let mut out = vec![0f32; w * h];
        for y in 0..h {
            let (a, b) = (y.saturating_sub(1), (y + 1).min(h - 1));
            for x in 0..w {
                out[y * w + x] = (tmp[a * w + x] + tmp[y * w + x] + tmp[b * w + x]) / 3.0;
            }
        }
        Plane { w, h, v: out }
    }

    /// Column `x` as a profile of rows: the mean of columns `x - 1..=x + 1`
    /// (clamped to the photo) at row `j` (clamped), the columns the clamp's
    /// search reads.
    pub(super) fn three_columns(&self, x: i64) -> impl Fn(i64) -> f64 + '_ {
        let xs = [x - 1, x, x + 1].map(|c| c.clamp(0, self.w as i64 - 1) as usize);
        move |j| {
            let j = j.clamp(0, self.h as i64 - 1) as usize;
            xs.iter().map(|&c| self.at(c, j)).sum::<f64>() / 3.0
        }
    }
}

/// The row that an edge located in [`Plane::three_columns`]'s profile of
/// column `x` reads, for an edge whose row is `row(x)`: the mean over the
/// three columns, `row(x) + row''(x) / 3` to second order. Where the edge
/// curves across the columns (an ellipse's arc towards its ends) the
/// profile's step lies that far from the middle column's; `None` where the
/// edge is not defined in one of them.
pub(super) fn three_column_row(x: f64, row: impl Fn(f64) -> Option<f64>) -> Option<f64> {
    Some((row(x - 1.0)? + row(x)? + row(x + 1.0)?) / 3.0)
}

/// The half-ellipse `sqrt(a^2 - d^2)` (0 beyond `a`) at the column `d`
/// from the axis as the clamp's search reads it: its mean over the three
/// columns of each profile ([`three_column_row`]).
pub(super) fn arc(a: f64, d: f64) -> f64 {
    three_column_row(d, |u| Some((a * a - u * u).max(0.0).sqrt())).unwrap_or(0.0)
}
