//! The apex's stated error: the residual scatter inflated for its
//! correlation along the edge, the bias terms (one-sided columns, tails,
//! the spread of the two edge models: one error, the light near the edge,
//! read several ways, of which the largest is stated) and the strong-step
//! bound.

use super::*;

/// The columns each side of the axis that the mirror test needs
/// ([`sides_bias2`]).
pub(super) const MIRROR_MIN_SIDE: usize = 5;

/// Whether an even fit's columns `kept` (`u` from the axis) leave a side
/// with too few for the mirror test ([`MIRROR_MIN_SIDE`]): the fit then
/// sees one side only.
pub(super) fn one_sided(kept: &[(f64, f64)]) -> bool {
    side(kept, true).count().min(side(kept, false).count()) < MIRROR_MIN_SIDE
}

/// The columns of `kept` (`u` from the axis) left of the axis (`left`) or
/// right of it; a column on the axis is on neither side.
pub(super) fn side(kept: &[(f64, f64)], left: bool) -> impl Iterator<Item = (f64, f64)> + '_ {
    kept.iter()
        .copied()
        .filter(move |p| (p.0 < 0.0) == left && p.0 != 0.0)
}

/// The mirror test of an even fit about the axis: the apex row fitted on
/// each side alone (`u < 0`, `u > 0`, each the even parabola, at least
/// [`MIRROR_MIN_SIDE`] columns, [`side`]), whose difference `D` a
/// symmetric silhouette makes zero but a highlight or clutter on one side
/// does not. Returns the squared bias of
/// the joint apex this implies beyond the difference's own variance,
/// `max(0, (D^2 - var D) / 4)` (half the difference: the joint fit
/// shares the biased side's columns about equally), 0 when a side has too
/// few columns.
pub(super) fn sides_bias2(kept: &[(f64, f64)]) -> f64 {
    let apex_of = |left: bool| {
        let pts: Vec<(f64, f64)> = side(kept, left).collect();
        if pts.len() < MIRROR_MIN_SIDE {
            return None;
        }
        let f = parabola(&pts, true)?;
        Some((
            f.coef[0],
            f.cov[0][0] * lag1_inflation(&f.residuals(&pts)).powi(2),
        ))
    };
    match (apex_of(true), apex_of(false)) {
        (Some((a, va)), Some((b, vb))) => (((a - b).powi(2) - va - vb) / 4.0).max(0.0),
        _ => 0.0,
    }
}

/// How many distances [`tail_bias2`] tries, in steps of an eighth of the
/// edge fit's half-span out to half of it.
pub(super) const TAIL_REACHES: usize = 4;

/// The squared bias of the apex row at `u_v` that the tail of a spot
/// beyond the columns left out for it (`out`, spotted or weakened: see
/// [`spot_below`] and [`strong_columns`]) puts into the kept columns
/// `pts`. A highlight's flank fades with distance: where it no longer
/// weakens the step enough for a column to be left out, it still lifts
/// the centroid; and where the spot lies beside the top, the columns next
/// to those left out are the ones nearest the apex. On 640x480 photos with
/// the highlight against one side of the top the kept columns 5-10 px
/// beyond it were 0.05-0.2 px high, and the even fit, which then sees one
/// side only, put the apex 0.12-0.16 px high at a stated 0.03 px (4.1-5.4
/// standard errors), where the step model was no better.
///
/// A Hausman test like the step model's ([`two_sided_refit`]): the
/// parabola is fitted again without the kept columns within a reach of
/// any left out, for reaches of an eighth, a quarter, three eighths and
/// half the half-span `span` ([`TAIL_REACHES`]; a spot's reach is not
/// known), as long as half the kept columns remain (and 8). Without a
/// bias the two fits differ by `D` of variance `var D = var(without) -
/// var(all)` (Hausman's identity, the same residual variance for both),
/// and the largest `D^2 - var D` over the reaches (not below 0) is
/// returned, a term of the apex row's variance (the largest of the terms
/// for the light near the edge is stated: `edge_fit_core`). Fits of fewer columns,
/// extrapolated to the apex, are so noisy that the largest excess would be
/// their noise: with 8 columns at the least, photos 0.01-0.14 px off were
/// given 0.4-2 px.
///
/// Where the fit sees one side of the axis only (`sees_one_side`: an even fit
/// whose mirror test cannot be made, [`one_sided`]), the columns beyond
/// the spot's reach may be too few for this test to tell a bias from
/// noise, and nothing else tests it: then at least `var D` at the
/// shortest reach is returned, so that the apex row's stated variance
/// becomes that of the fit without the columns next to those left out
/// (the apex stays the whole fit's). On a 640x480 photo with a cable
/// hiding the far side, one side's 19 columns, all within 20 px of the
/// spot, put the apex 0.156 px high at a stated 0.031 px; the fit without
/// the nearest agreed with it to 0.055 +- 0.062 px.
pub(super) fn tail_bias2(
    pts: &[(f64, f64)],
    out: &[f64],
    span: f64,
    u_v: f64,
    even: bool,
    sees_one_side: bool,
) -> f64 {
    if out.is_empty() {
        return 0.0;
    }
    let Some(all) = parabola(pts, even) else {
        return 0.0;
    };
    let s2 = all.s2 * lag1_inflation(&all.residuals(pts)).powi(2);
    let at = |f: &Parabola| f.coef[0] + f.coef[1] * u_v + f.coef[2] * u_v * u_v;
    let mut worst = 0.0f64;
    // `var D` at the shortest reach tested.
    let mut nearest = None;
    for k in 1..=TAIL_REACHES {
        let reach = span * k as f64 / (2 * TAIL_REACHES) as f64;
        let far: Vec<(f64, f64)> = pts
            .iter()
            .copied()
            .filter(|p| out.iter().all(|&o| (p.0 - o).abs() > reach))
            .collect();
        if far.len() == pts.len() {
            continue;
        }
        if far.len() < 8.max(pts.len() / 2) {
            break;
        }
        let Some(sub) = parabola(&far, even) else {
            break;
        };
        let d = at(&sub) - at(&all);
        let var_d = s2 * (sub.unscaled_var_at(u_v) - all.unscaled_var_at(u_v)).max(0.0);
        worst = worst.max(d * d - var_d);
        nearest.get_or_insert(var_d);
    }
    match nearest {
        Some(var_d) if sees_one_side => worst.max(var_d),
        _ => worst,
    }
}

/// How an edge fit is tested against the step model ([`two_sided_refit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum StepTest {
    /// A tenth of the columns or more were weakened (left out by
    /// [`strong_columns`] or [`spot_below`]): every kept column is tested,
    /// and the model's rows replace the centroids' where they differ.
    Switch,
    /// Fewer than a tenth of the columns were weakened, but they carry a
    /// tenth of the apex row's weight or more ([`weakened_apex_share`]):
    /// every kept column is tested, and the bias found widens the apex
    /// row's uncertainty; the centroids stay. Switching there too, on the
    /// tracker sweep's 250 + 250 sequences at the two smaller sizes, moved
    /// 38 dirty photos' apexes from 0.134 to 0.169 px RMS error.
    Bound,
}

/// What the test of the centroids against the step model says.
pub(super) enum TwoSided {
    /// The centroids are biased: the robust parabola through the model's
    /// rows and the columns it kept, and the edge-model term of its apex
    /// row, px^2: the squared half-difference of the two models at the
    /// apex beyond its variance, `max(0, D^2 - sd^2) / 4`. Two edge models
    /// that each fit their rows and disagree at the apex leave the apex
    /// anywhere in their spread: the step model's straight dome side is
    /// no more the truth under a highlight's curved flank than the
    /// centroid's flat one (a light dome with a highlight against its top,
    /// 800x600: step model 0.34 px off at a stated 0.05 px without it,
    /// 0.15 px with it).
    Model(Parabola, Vec<(f64, f64)>, f64),
    /// Not significantly: the squared difference at the apex beyond its
    /// variance, an estimate of the centroid apex's squared bias, px^2.
    Bias(f64),
}

/// The fit's apex, vertex, curvature and their standard errors, each
/// inflated for the residuals' correlation along the edge.
pub(super) fn summarise(
    fit: &Parabola,
    pts: &[(f64, f64)],
    centre: f64,
    lim: f64,
    two_sided: bool,
) -> EdgeFit {
    let [a, b, c] = fit.coef;
    let u_v = if c > 1e-9 {
        (-b / (2.0 * c)).clamp(-lim, lim)
    } else {
        0.0
    };
    // Delta method for the vertex column u_v = -B / (2C).
    let x_std = if c > 1e-9 {
        let g = [0.0, -1.0 / (2.0 * c), b / (2.0 * c * c)];
        quad_form(&fit.cov, &g).sqrt()
    } else {
        f64::INFINITY
    };
    let inflate = lag1_inflation(&fit.residuals(pts));
    // cov(y, 2 C) with y = A + B u_v + C u_v^2 (u_v held).
    let g = [1.0, u_v, u_v * u_v];
    let y_c = (0..3).map(|j| fit.cov[j][2] * g[j]).sum::<f64>();
    EdgeFit {
        y: a + b * u_v + c * u_v * u_v,
        y_std: fit.var_at(u_v).sqrt() * inflate,
        x_vertex: centre + u_v,
        x_std: x_std * inflate,
        curvature: 2.0 * c,
        curvature_std: 2.0 * fit.cov[2][2].max(0.0).sqrt() * inflate,
        y_curvature_cov: 2.0 * y_c * inflate * inflate,
        columns: pts.len(),
        rms: (fit.rss / pts.len() as f64).sqrt(),
        two_sided,
        clutter_on_top: false,
    }
}

/// Residual correlation along the edge: the factor `sqrt((1 + r) / (1 - r))`
/// of the lag-1 autocorrelation `r` (clamped to 0-0.9) by which standard
/// errors computed for independent residuals are too small.
pub(crate) fn lag1_inflation(res: &[f64]) -> f64 {
    let num: f64 = res.windows(2).map(|p| p[0] * p[1]).sum();
    let den: f64 = res.iter().map(|r| r * r).sum();
    let rho = if den > 0.0 {
        (num / den).clamp(0.0, 0.9)
    } else {
        0.0
    };
    ((1.0 + rho) / (1.0 - rho)).sqrt()
}

/// How far apart the two estimators may be on a clean edge, px, beyond
/// their noise: the centroid and the step model differ slightly in how they
/// treat pixel sampling and the blur's shape (on clean synthetic edges the
/// difference at the apex stays within about 0.01-0.04 px).
pub(super) const TWO_SIDED_MARGIN_PX: f64 = 0.02;

/// The share of the upper quartile's contrast below which an apex column
/// is left out ([`strong_columns`]).
pub(super) const UPPER_SHARE: f64 = 0.8;

/// A test of the centroid edge against the step model, in the manner of
/// Hausman's specification test (J. A. Hausman, "Specification tests in
/// econometrics", Econometrica 46, 1978, doi:10.2307/1913827): the
/// centroids ([`profile_edge`]) are the precise estimate, unbiased when the
/// dome side under the edge is flat; the step model ([`step_model_edge`])
/// stays unbiased when it is not, at more noise. Each column's difference
/// between the two is fitted by a parabola and evaluated at the apex
/// (`u_v`); its standard error comes from the differences' own scatter
/// (what the shared noise cancels from). By Hausman's identity that
/// variance, `sd^2`, is the step model's variance less the centroids', so
/// the centroids' squared bias `b^2`, estimated by `D^2 - sd^2`, costs more
/// than the step model's extra noise when `D^2 > 2 sd^2`. When the
/// difference exceeds sqrt(2) standard errors plus [`TWO_SIDED_MARGIN_PX`],
/// something under the edge (a highlight's flank, texture) biased the
/// centroids more than the step model's noise costs, and the robust
/// parabola through the step model's rows is returned instead (with
/// [`StepTest::Switch`] only). Below it, or with [`StepTest::Bound`], the
/// difference still estimates the centroids' bias on a frame where
/// something lies on the edge (the test is made only there): its square
/// beyond its variance, `max(0, D^2 - sd^2)` (unbiased for the squared
/// bias), is returned as a term of the apex row's variance (the largest of
/// the terms for the light near the edge is stated: `edge_fit_core`).
pub(super) fn two_sided_refit(
    cols: &mut Columns,
    pts: &[(f64, f64)],
    centre: f64,
    u_v: f64,
    even: bool,
    test: StepTest,
) -> Option<TwoSided> {
    let switch = test == StepTest::Switch;
    let mut model = Vec::with_capacity(pts.len());
    let mut diff = Vec::with_capacity(pts.len());
    for &(u, e) in pts {
        // `u` is a column minus `centre`, so rounding recovers the column.
        let c = (centre + u).round() as usize;
        if let Some(m) = cols.model_edge(c, e) {
            model.push((u, m));
            diff.push((u, m - e));
        }
    }
    if diff.len() < 8.max(pts.len() / 2) {
        return None;
    }
    let d = parabola(&diff, false)?;
    let sd = d.var_at(u_v).sqrt() * lag1_inflation(&d.residuals(&diff));
    let [a, b, c] = d.coef;
    let at_apex = a + b * u_v + c * u_v * u_v;
    if !switch || at_apex.abs() <= std::f64::consts::SQRT_2 * sd + TWO_SIDED_MARGIN_PX {
        return Some(TwoSided::Bias((at_apex * at_apex - sd * sd).max(0.0)));
    }
    let (fit, kept) = robust_parabola(&model, even)?;
    let spread2 = 0.25 * (at_apex * at_apex - sd * sd).max(0.0);
    Some(TwoSided::Model(fit, kept, spread2))
}

/// The located columns `(column, edge row, step)` whose step has the
/// dome's polarity (the sign of the summed steps) and at least a quarter of
/// the median contrast, and at least `upper_share` of the upper quartile's
/// contrast, and, of those, at most `1 / upper_share` of their lower
/// quartile's contrast; `None` when fewer than `min` remain.
///
/// The second bound is for the apex: the contrast of a matte dome against
/// its background changes slowly along the edge, so a column whose step is
/// markedly weaker than most has something added where it is measured: a
/// highlight on the dome against the edge, a dark line behind it. Such a
/// column's centroid is pulled off the edge, most by a highlight's flank
/// within the window (0.5-1.2 px on a 640x480 synthetic dome). A highlight
/// on a light dome (brighter than its background) makes the step markedly
/// stronger instead, and pulls the centroid into the dome the same way
/// (0.25-0.6 px on 640x480 and 800x600 photos): the third bound.
pub(super) fn strong_columns(
    located: &[(f64, f64, f64)],
    min: usize,
    upper_share: f64,
) -> Option<Vec<(f64, f64, f64)>> {
    let sign = located.iter().map(|l| l.2).sum::<f64>().signum();
    let mut mags: Vec<f64> = located
        .iter()
        .map(|l| l.2 * sign)
        .filter(|m| *m > 0.0)
        .collect();
    if mags.len() < min {
        return None;
    }
    mags.sort_by(f64::total_cmp);
    let med = mags[mags.len() / 2];
    let upper = mags[3 * mags.len() / 4];
    let floor = (0.25 * med).max(upper_share * upper);
    // The same bound from the other side, among the columns above the
    // floor: a highlight adds light, which weakens the step of a dark dome
    // and strengthens that of a light one where it lies against the edge.
    let above: Vec<f64> = mags.iter().copied().filter(|m| *m > floor).collect();
    let ceiling = match above.get(above.len() / 4) {
        Some(&lower) => lower / upper_share,
        None => f64::INFINITY,
    };
    let pts: Vec<(f64, f64, f64)> = located
        .iter()
        .copied()
        .filter(|l| l.2 * sign > floor && l.2 * sign < ceiling)
        .collect();
    (pts.len() >= min).then_some(pts)
}

/// The share of the apex row's weight carried by the located columns that
/// [`strong_columns`] (or [`spot_below`]) left out: `sum |w_i|` over them
/// against over every located column, `w_i` the weight of column `i` in the
/// least-squares vertex row of the even parabola `y = A + B d^2` through
/// them all (`d = u - u_vertex`): `A = sum w_i y_i`, `w_i = (S4 - S2 d_i^2)
/// / (n S4 - S2^2)`, `S2 = sum d^2`, `S4 = sum d^4`. The columns next to the
/// vertex carry the most, those at about 0.77 of the span the least: a
/// highlight under the top weakens a few columns where the row is read
/// (a dirty 800x600 photo of the tracker sweep, seed 1000319's ninth:
/// 5 of 61 columns weakened, 12 % of the weight, the apex written 0.10 px
/// high at a stated 0.024 px, the step model's test not run).
pub(super) fn weakened_apex_share(
    located: &[(f64, f64, f64)],
    strong: &[(f64, f64, f64)],
    u_vertex: f64,
) -> f64 {
    let n = located.len() as f64;
    let (s2, s4) = located.iter().fold((0.0, 0.0), |(s2, s4), l| {
        let d2 = (l.0 - u_vertex).powi(2);
        (s2 + d2, s4 + d2 * d2)
    });
    let det = n * s4 - s2 * s2;
    if det.is_nan() || det <= 0.0 {
        return 0.0;
    }
    let (mut weak, mut all) = (0.0, 0.0);
    for l in located {
        let w = ((s4 - s2 * (l.0 - u_vertex).powi(2)) / det).abs();
        all += w;
        if !strong.iter().any(|s| s.0 == l.0) {
            weak += w;
        }
    }
    if all > 0.0 { weak / all } else { 0.0 }
}

/// The squared mean of per-column shifts beyond its variance, px^2:
/// `max(0, D^2 - sd^2)` (unbiased for the squared mean shift), `sd` the
/// mean's standard error from the shifts' scatter, inflated for their
/// correlation along the edge ([`lag1_inflation`]); 0 with fewer than 8.
pub(super) fn mean_beyond_noise2(shifts: &[f64]) -> f64 {
    if shifts.len() < 8 {
        return 0.0;
    }
    let n = shifts.len() as f64;
    let mean = shifts.iter().sum::<f64>() / n;
    let res: Vec<f64> = shifts.iter().map(|x| x - mean).collect();
    let var = res.iter().map(|r| r * r).sum::<f64>() / (n - 1.0);
    let sd2 = var / n * lag1_inflation(&res).powi(2);
    (mean * mean - sd2).max(0.0)
}

/// The smaller of two slopes of the same sign, else 0.
pub(super) fn minmod(a: f64, b: f64) -> f64 {
    if a * b <= 0.0 {
        0.0
    } else if a.abs() < b.abs() {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::{mean_beyond_noise2, weakened_apex_share};
    use crate::track::matcher::edge::{profile_edge, unselected_edge};
    use nalgebra::DMatrix;

    #[test]
    fn texture_on_one_side_pulls_the_selected_centroid_not_the_unselected() {
        // A sharp step at row 20.3 (area-sampled), a wall of 190 above with
        // a texture of deviation 1 grey level per row, a smooth dome of 82
        // below; 400 columns of independent texture (a fixed LCG).
        let mut state: u64 = 12345;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (edge, hw) = (20.3, 3.0);
        let (mut sel, mut all) = (Vec::new(), Vec::new());
        for _ in 0..400 {
            // Sum of 12 uniforms less 6: unit deviation.
            let texture: Vec<f64> = (0..40)
                .map(|_| (0..12).map(|_| uniform()).sum::<f64>() - 6.0)
                .collect();
            let px = |j: i64| {
                let f = (edge - (j as f64 - 0.5)).clamp(0.0, 1.0);
                f * (190.0 + texture[j as usize]) + (1.0 - f) * 82.0
            };
            sel.push(profile_edge(px, 40, 20.0, hw).unwrap().0 - edge);
            all.push(unselected_edge(px, 40, 20.0, hw).unwrap() - edge);
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        // The closed form: rows of noise alone above the edge (centres 0.5-
        // 3.5 rows above it, the outermost at the taper's weight 0.3) keep
        // differences of mean -s/sqrt(2 pi), s = sqrt(2) for a unit texture;
        // their lever arm over the step of -108 lifts the centroid.
        let lever = 0.5 + 1.5 + 2.5 + 0.3 * 3.5;
        let want = -lever * 2f64.sqrt() / (2.0 * std::f64::consts::PI).sqrt() / 108.0;
        let (s, a) = (mean(&sel), mean(&all));
        assert!(
            s < 0.0 && (s - want).abs() < 0.4 * want.abs(),
            "{s} vs {want}"
        );
        assert!(a.abs() < 0.2 * want.abs(), "unselected {a} against {want}");
        // The mean shift is found beyond its noise.
        let shifts: Vec<f64> = sel.iter().zip(&all).map(|(s, a)| s - a).collect();
        assert!(mean_beyond_noise2(&shifts).sqrt() > 0.6 * want.abs());
        assert_eq!(mean_beyond_noise2(&shifts[..7]), 0.0);
    }

    /// The weights of the vertex row `A` in the least-squares fit of
    /// `y = A + B d^2`, from the normal equations solved by nalgebra: the
    /// first row of `(X^T X)^-1 X^T`.
    fn weights(d: &[f64]) -> Vec<f64> {
        let x = DMatrix::from_fn(d.len(), 2, |i, j| if j == 0 { 1.0 } else { d[i] * d[i] });
        let xtx = (x.transpose() * &x)
            .try_inverse()
            .expect("two distinct |d|");
        let hat = xtx * x.transpose();
        (0..d.len()).map(|i| hat[(0, i)]).collect()
    }

    #[test]
    fn the_weakened_share_is_that_of_the_vertex_rows_weight() {
        // 61 columns about a vertex 0.4 px off the span's centre.
        let located: Vec<(f64, f64, f64)> = (-30..=30).map(|u| (u as f64, 0.0, -100.0)).collect();
        let d: Vec<f64> = located.iter().map(|l| l.0 - 0.4).collect();
        let w = weights(&d);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let share = |weak: &dyn Fn(f64) -> bool| {
            let strong: Vec<_> = located.iter().copied().filter(|l| !weak(l.0)).collect();
            let got = weakened_apex_share(&located, &strong, 0.4);
            let abs: f64 = w.iter().map(|w| w.abs()).sum();
            let want: f64 = d
                .iter()
                .zip(&w)
                .filter(|(d, _)| weak(**d + 0.4))
                .map(|(_, w)| w.abs())
                .sum::<f64>()
                / abs;
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
            got
        };
        assert_eq!(share(&|_| false), 0.0);
        assert!((share(&|_| true) - 1.0).abs() < 1e-12);
        // Five columns next to the vertex, 8 % of them: over a tenth of the
        // weight. The same five where the weight changes sign (about 0.77
        // of the half-span): almost none of it.
        assert!(share(&|u| (-3.0..=1.0).contains(&u)) > 0.1);
        assert!(share(&|u| (21.0..=25.0).contains(&u)) < 0.02);
    }
}
