//! The dome's base in front of the clamp ring's face (part of step 3 of
//! `bulge init`): where the membrane is clamped, the near half of the
//! opening's circle in the clamp plane. When a raised camera sees only the
//! face's front, the base tells the face's front from a flange's lower
//! edge below it (the face's shade, which looks the same), and places the
//! clamp plane when the front is a flange's.

use super::clamp::robust_lstsq;
use super::*;

/// How far, px, the face's front may lie below the clamp plane that the
/// dome's base gives before it is taken for a flange's lower edge. The
/// base is read against the face, which the dome shades where they meet:
/// on path-traced photos of a dark dome on a light face (0.45 m, 2.6
/// degrees, 1280x960) its points came out 0.16 px low on average (0.05-0.4
/// px by column), the plane fitted on them 0.38 px low, while the front
/// put it within 0.02 px.
pub(super) const BASE_GAP_PX: f64 = 1.0;

/// Whether the face's front lying `gap` px below the clamp plane that the
/// dome's base gives (the two with deviation `std`) is a flange's.
pub(super) fn flange(gap: f64, std: f64) -> bool {
    gap > BASE_GAP_PX + 4.0 * std
}

/// The standard deviation, px, of the clamp plane placed on the dome's
/// base for the dome's shade on the face beside it: the base's points came
/// out 0.16 px low on average on the path-traced photos of
/// [`BASE_GAP_PX`], the plane 0.16 px low with the front's elevation held.
pub(super) const BASE_SHADE_PX: f64 = 0.2;

/// The dome's base in front of the ring's face, seen from above when only
/// the face's front shows (`front(u)`, its row `u` px from the axis, a step
/// of sign `g` going down): the membrane is clamped at the opening, so its
/// base is the near half of the opening's circle in the clamp plane, below
/// which the face shows down to its front (or to a flange's lower edge of
/// the face's shade, which looks the same). Per column within 0.85 of the
/// opening's half-width `a0`, the two lowest strong steps down to the
/// front: the lowest of sign `g` is the front, the one above it the base,
/// located to sub-pixel with a window that stays off the front. Returns
/// `(u, row, step)`.
pub(super) fn dome_base(
    img: &Plane,
    x0: f64,
    a0: f64,
    front: &dyn Fn(f64) -> f64,
    g: f64,
    contrast: &super::contrast::Contrast,
) -> Vec<(f64, f64, f64)> {
    let (w, h) = (img.w as i64, img.h as i64);
    let reach = (0.3 * a0).max(12.0) as i64;
    let half = (0.85 * a0) as i64;
    (-half..=half)
        .filter_map(|u| {
            let x = x0.round() as i64 + u;
            if x < 2 || x >= w - 2 {
                return None;
            }
            let p = img.three_columns(x);
            let end = (front(u as f64).round() as i64 + 6).min(h - 3);
            let start = (end - reach).max(2);
            if end <= start + 4 {
                return None;
            }
            let steps: Vec<(i64, f64)> = (start..end)
                .map(|j| (j, super::contrast::step_at(&p, j)))
                .collect();
            let &(jmax, gmax) = steps
                .iter()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
            let gmax = gmax.abs();
            if !contrast.counts(&p, jmax) {
                return None;
            }
            let peak = |i: usize| {
                let v = steps[i].1;
                v.abs() >= 0.3 * gmax
                    && contrast.counts(&p, steps[i].0)
                    && v * steps[i - 1].1.signum() >= 0.0
                    && v.abs() >= steps[i - 1].1.abs()
                    && v.abs() >= steps[i + 1].1.abs()
            };
            let mut peaks = (1..steps.len() - 1).rev().filter(|&i| peak(i));
            let f = peaks.next()?;
            if steps[f].1 * g <= 0.0 {
                return None;
            }
            let b = peaks.next()?;
            let gap = (steps[f].0 - steps[b].0) as f64;
            let hw = (0.5 * gap - 0.5).min(3.0);
            if hw < 1.5 {
                return None;
            }
            let (e, step) = profile_edge(&p, h, steps[b].0 as f64 + 0.5, hw)?;
            ((e - (steps[b].0 as f64 + 0.5)).abs() < 1.5).then_some((u as f64, e, step))
        })
        .collect()
}

/// The clamp plane's row at the axis and the elevation's sine from the
/// dome's base (`(u, row, _)`, [`dome_base`]): the near half of the
/// opening's circle, `row = c + s sqrt(a0^2 - u^2)` with the roll's slope,
/// fitted robustly, the sine `held` when given. `a0` is the opening's
/// half-width read from the last photo's sides before the scale is
/// measured; the change of `c` when it is 1 % off is added to the row's
/// deviation. `None` on fewer than a third of the columns or a base that
/// does not bend down.
pub(super) fn base_fit(
    pts: &[(f64, f64, f64)],
    a0: f64,
    held: Option<Estimate>,
    floor: f64,
) -> Option<(Estimate, Estimate)> {
    if (pts.len() as f64) < 0.3 * 1.7 * a0 {
        return None;
    }
    let fit = |a: f64| {
        let x: Vec<Vec<f64>> = pts
            .iter()
            .map(|p| {
                let q = super::plane::arc(a, p.0);
                match held {
                    Some(_) => vec![1.0, p.0],
                    None => vec![1.0, q, p.0],
                }
            })
            .collect();
        let y: Vec<f64> = pts
            .iter()
            .map(|p| p.1 - held.map_or(0.0, |s| s.value * super::plane::arc(a, p.0)))
            .collect();
        robust_lstsq(&x, &y, floor)
    };
    let ((coef, cov, res), _) = fit(a0)?;
    let ((c_wide, _, _), _) = fit(1.01 * a0)?;
    let infl = lag1_inflation(&res);
    let s = match held {
        Some(s) => s,
        None => Estimate {
            value: coef[1],
            std: cov[1][1].sqrt() * infl,
        },
    };
    if s.value <= 4.0 * s.std {
        return None;
    }
    let row = Estimate {
        value: coef[0],
        std: (cov[0][0] * infl * infl + (c_wide[0] - coef[0]).powi(2)).sqrt(),
    };
    Some((row, s))
}
