//! Step 4 of `bulge init`: the silhouette's half-width at the clamp plane,
//! px, from its sides located row by row just above it.

use super::*;

/// Step 4: the silhouette's half-width at the clamp plane, px, with the
/// points located on its sides.
/// The silhouette's half-width at the clamp plane found by [`find_radius`].
#[derive(Debug, Clone)]
pub(super) struct Opening {
    /// The half-width, px; its deviation leaves out the clamp row's, which
    /// moves it by [`Opening::per_clamp_row`].
    pub(super) a: Estimate,
    /// How much the half-width grows per px that the clamp row (the
    /// plane the sides are extrapolated to) lies lower: `d a / d c`.
    pub(super) per_clamp_row: f64,
    /// The points located on the sides, `[column, row]`.
    pub(super) sides: Vec<[f64; 2]>,
    /// The rows the sides were located in, as heights above the clamp row, px.
    pub(super) us: Vec<f64>,
    /// The squared half-width's quadratic `W^2 = A + B u + C u^2`.
    pub(super) coef: [f64; 3],
}

pub(super) fn find_radius(
    last: &Plane,
    x0: f64,
    a0: f64,
    clamp: &Clamp,
    sin_e: f64,
    tone: crate::track::image::Tone,
) -> Result<Opening, TrackError> {
    let (w, h) = (last.w as i64, last.h as i64);
    let c = clamp.row.value;
    // From a raised camera the clamp's top face (outer radius `A`) is seen
    // behind the rim: its back edge runs `sqrt(A^2 - x^2) sin e` above the
    // plane at `x` from the axis, so beside the opening (`x` about `a`) the
    // sides are seen from `sqrt(A^2 - a^2) sin e` up (0.75 a sin e for a
    // clamp 1.25 a wide, against `A sin e` on the axis: the shorter the
    // extrapolation to the plane below, the smaller its error).
    let above_face = clamp
        .half_width_px
        .map_or(0.0, |a_f| (a_f * a_f - a0 * a0).max(0.0).sqrt() * sin_e)
        + 3.0;
    let u0 = 6.0f64.max(0.03 * a0).max(above_face);
    let k = 14.0f64.max(0.15 * a0);
    // Each side is located with the edge window of half-width 3 px, and
    // again with 2 and 5 px: the edge models that all fit, whose spread in
    // the opening is stated (below).
    const WINDOWS: [f64; 3] = [3.0, 2.0, 5.0];
    let mut rows: Vec<(f64, [[f64; 3]; 2])> = Vec::new();
    let r_top = (c - u0 - k).ceil() as i64;
    let r_bot = (c - u0).floor() as i64;
    for r in r_top.max(1)..=r_bot.min(h - 2) {
        let p = |x: i64| last.at(x.clamp(0, w - 1) as usize, r as usize);
        let mut xs = [[f64::NAN; 3]; 2];
        for (i, side) in [-1.0f64, 1.0].into_iter().enumerate() {
            let a = x0 + side * 0.5 * a0;
            let b = x0 + side * (1.1 * a0 + 4.0);
            let (lo, hi) = if side < 0.0 { (b, a) } else { (a, b) };
            let (lo, hi) = ((lo.floor() as i64).max(8), (hi.ceil() as i64).min(w - 10));
            if hi <= lo + 2 {
                continue;
            }
            if let Some((j, _)) = super::contrast::strongest_step(tone, &p, lo, hi) {
                for (x, hw) in xs[i].iter_mut().zip(WINDOWS) {
                    *x = profile_edge(p, w, j as f64 + 0.5, hw).map_or(f64::NAN, |e| e.0);
                }
            }
        }
        if xs.iter().all(|v| v[0].is_finite()) {
            rows.push((c - r as f64, xs));
        }
    }
    let half_widths = |m: usize| -> Vec<(f64, f64)> {
        rows.iter()
            .map(|(u, xs)| (*u, 0.5 * (xs[1][m] - xs[0][m])))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let pts = half_widths(0);
    let mut sides = Vec::new();
    for (u, xs) in &rows {
        let r = c - u;
        sides.push([xs[0][0], r]);
        sides.push([xs[1][0], r]);
    }
    if pts.len() < 5 {
        return Err(TrackError::NotFound {
            what: "the scale".into(),
            detail: format!(
                "the bubble's sides above the clamp plane (rows {r_top}-{r_bot}) were found in {} rows only; or give the scale ({})",
                pts.len(),
                crate::setting::Setting::MetresPerPixel
            ),
            keys: "metres_per_pixel (or points_px with distance_m)",
            clamp_plane: false,
        });
    }
    let fit = opening_from_sides(&pts, sin_e, a0)?;
    let a = fit.a;
    // The scale's error through the clamp row and the row's own are one
    // error, which the heights carry together (`[calibration]
    // scale_per_clamp_row`).
    let per_clamp_row = per_clamp_row(&fit, sin_e);
    // The edge models' spread: the largest change of the opening between
    // the windows, less the part of it that is the windows' own noise
    // (counted already in the fit's variance), is a bound on the edge
    // model's error, stated as a uniform spread within it (variance
    // bound^2 / 3). On 20 framings per combination of the camera grid the
    // whole change, stated as one deviation, over-stated the heights of
    // cameras 3 degrees up by up to twice.
    let var_edge = (1..WINDOWS.len())
        .filter_map(|m| {
            let change = opening_from_sides(&half_widths(m), sin_e, a0).ok()?.a - a;
            Some((change * change - window_change_var(&rows, m, &fit, a0)).max(0.0))
        })
        .fold(0.0, f64::max)
        / 3.0;
    // The meridian departs from the conic over the fitted rows: that bias
    // and its deviation are the caller's ([`super::meridian::unbiased`]).
    Ok(Opening {
        a: Estimate {
            value: a,
            std: (fit.var + var_edge).sqrt(),
        },
        per_clamp_row,
        sides,
        us: pts.iter().map(|p| p.0).collect(),
        coef: fit.coef,
    })
}

/// The variance of the change of the opening between the edge window `m`
/// and the first (`rows`: `(u, [[left; windows], [right; windows]])`) that
/// the windows' own noise gives, px^2: the change is, to first order, the
/// fit's gradient `fit.grad` applied to the coefficients of the
/// row-by-row change of `W^2` fitted the same way, whose covariance comes
/// from that change's scatter about its quadratic (inflated for its lag-1
/// correlation). Two windows read the same pixels, so most of each row's
/// noise is common and cancels; what is left is the noise the windows do
/// not share. 0 when too few rows have both.
fn window_change_var(rows: &[(f64, [[f64; 3]; 2])], m: usize, fit: &SidesFit, a0: f64) -> f64 {
    let (x, y): (Vec<Vec<f64>>, Vec<f64>) = rows
        .iter()
        .filter_map(|(u, xs)| {
            let w = |k: usize| 0.5 * (xs[1][k] - xs[0][k]);
            let (w0, wm) = (w(0), w(m));
            (w0.is_finite() && wm.is_finite()).then(|| (vec![1.0, *u, u * u], wm * wm - w0 * w0))
        })
        .unzip();
    if y.len() < 5 {
        return 0.0;
    }
    match robust_lstsq(&x, &y, w2_floor(a0)) {
        Some(((_, cov, res), _)) => {
            let infl = lag1_inflation(&res);
            super::super::matcher::quad_form(&cov, &fit.grad) * infl * infl
        }
        None => 0.0,
    }
}

/// The least cut, px^2, under which [`robust_lstsq`] keeps every row of a
/// fit of the squared half-width `W^2` (or of its change between windows):
/// `0.1 a0`, a change of 0.05 px in `W` about `a0`.
fn w2_floor(a0: f64) -> f64 {
    0.1 * a0
}

/// The axis's column: the mean midpoint of the sides located in the same
/// rows (`[left, right]` pairs), with its standard error; `None` from
/// fewer than 5 rows.
pub(super) fn axis_from_sides(sides: &[[f64; 2]]) -> Option<Estimate> {
    if sides.len() < 10 {
        return None;
    }
    let m: Vec<f64> = sides.chunks(2).map(|p| 0.5 * (p[0][0] + p[1][0])).collect();
    let n = m.len() as f64;
    let mean = m.iter().sum::<f64>() / n;
    let var = m.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    Some(Estimate {
        value: mean,
        std: (var / n).sqrt(),
    })
}

/// How much the opening's half-width grows per px that the clamp row lies
/// lower, `d a / d c`. A row `dc` px lower moves the plane down the sides
/// and `u` (the height above it) up by `dc` at every row: the fit's `A`
/// and `B` become `A - B dc` and `B - 2 C dc`, so `d a^2 / d c = -B / (1 +
/// s^2 C)` ([`opening_from_sides`]'s `a^2`) and `d a / d c = -B / (2 a (1 +
/// s^2 C))`, `s = sin_e`.
pub(super) fn per_clamp_row(fit: &SidesFit, sin_e: f64) -> f64 {
    let [_, big_b, big_c] = fit.coef;
    -big_b / (2.0 * fit.a * (1.0 + sin_e * sin_e * big_c))
}

/// The fit of [`opening_from_sides`].
pub(super) struct SidesFit {
    /// The half-width at the plane, px.
    pub(super) a: f64,
    /// Its variance from the fit, px^2.
    pub(super) var: f64,
    /// `[A, B, C]` of `W^2 = A + B u + C u^2`.
    pub(super) coef: [f64; 3],
    /// The half-width's gradient with respect to `[A, B, C]`.
    pub(super) grad: [f64; 3],
}

/// The silhouette's half-width at the clamp plane from its half-widths
/// `(u, W)` at heights `u` above the clamp row (px), seen from the
/// elevation `asin(sin_e)` by an orthographic camera.
pub(super) fn opening_from_sides(
    pts: &[(f64, f64)],
    sin_e: f64,
    a0: f64,
) -> Result<SidesFit, TrackError> {
    // The squared half-width, W^2 = A + B u + C u^2. Near its rim the
    // meridian is close to a conic about the axis, rho^2 = alpha + beta z +
    // gamma z^2 (exact for a sphere, gamma = -1; an inflated membrane is
    // flatter near its rim), and the outline of such a surface seen from the
    // elevation `e` (the envelope of its latitude ellipses) is again
    // quadratic in `u`, with a^2 = alpha = A - B^2 s^2 / (4 (1 + s^2 C)),
    // s = sin e. (A quadratic in the half-width itself, extrapolated to the
    // plane from 0.08 a, came out 0.3 % small on the exact neo-Hookean
    // bubble 0.53 a high, 11 % on one 0.26 a high.)
    let x: Vec<Vec<f64>> = pts.iter().map(|(u, _)| vec![1.0, *u, u * u]).collect();
    let y: Vec<f64> = pts.iter().map(|(_, hw)| hw * hw).collect();
    let ((coef, cov, res), _) = robust_lstsq(&x, &y, w2_floor(a0)).ok_or(TrackError::NotFound {
        what: "the scale".into(),
        detail: "the bubble's sides near the clamp do not fit a smooth curve".into(),
        keys: "metres_per_pixel",
        clamp_plane: false,
    })?;
    let [big_a, big_b, big_c] = [coef[0], coef[1], coef[2]];
    let s2 = sin_e * sin_e;
    let f = 1.0 + s2 * big_c;
    let alpha = big_a - big_b * big_b * s2 / (4.0 * f);
    if big_a <= 0.0 || f <= 0.0 || alpha <= 0.0 {
        return Err(TrackError::NotFound {
            what: "the scale".into(),
            detail: "the bubble's sides near the clamp do not close into an opening".into(),
            keys: "metres_per_pixel",
            clamp_plane: false,
        });
    }
    let a = alpha.sqrt();
    let infl = lag1_inflation(&res);
    // d a / d (A, B, C).
    let g = [
        1.0,
        -big_b * s2 / (2.0 * f),
        big_b * big_b * s2 * s2 / (4.0 * f * f),
    ]
    .map(|v| v / (2.0 * a));
    let var_fit = super::super::matcher::quad_form(&cov, &g) * infl * infl;
    Ok(SidesFit {
        a,
        var: var_fit,
        coef: [big_a, big_b, big_c],
        grad: g,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere of radius `r` px whose centre lies `z0` px above the clamp
    /// plane, seen level: its outline's half-width at `u` above the plane
    /// is `sqrt(r^2 - (u - z0)^2)`, the opening `a = sqrt(r^2 - z0^2)`, and
    /// a plane `dc` lower cuts it at `sqrt(r^2 - (z0 + dc)^2)`: `d a / d c
    /// = -z0 / a` in closed form. From a raised camera, the opening's change
    /// when the sides are fitted again with the plane 0.5 px lower and
    /// higher (a finite difference of the whole fit).
    #[test]
    fn the_openings_change_with_the_clamp_row_is_the_spheres() {
        let (r, a0) = (300.0f64, 250.0);
        for z0 in [-150.0f64, -60.0, 40.0] {
            let sides = |shift: f64| -> Vec<(f64, f64)> {
                (0..20)
                    .map(|i| {
                        let u = 8.0 + i as f64;
                        (u + shift, (r * r - (u - z0).powi(2)).sqrt())
                    })
                    .collect()
            };
            let fit = opening_from_sides(&sides(0.0), 0.0, a0).unwrap();
            let a = (r * r - z0 * z0).sqrt();
            assert!((fit.a - a).abs() < 1e-6, "z0 {z0}: a {} for {a}", fit.a);
            let k = per_clamp_row(&fit, 0.0);
            assert!(
                (k + z0 / a).abs() < 1e-6,
                "z0 {z0}: d a / d c {k} for {}",
                -z0 / a
            );
            for e in [3f64, 5.0] {
                let s = e.to_radians().sin();
                let at = |shift: f64| opening_from_sides(&sides(shift), s, a0).unwrap();
                let fd = (at(0.5).a - at(-0.5).a) / 1.0;
                let k = per_clamp_row(&at(0.0), s);
                assert!(
                    (k - fd).abs() < 1e-3 * fd.abs().max(0.1),
                    "z0 {z0} e {e}: d a / d c {k} against {fd} refitted"
                );
            }
        }
    }
}
