//! The dome's axis from an even fit over a wide span, and the
//! least-squares parabolas (plain, even, robust) the fits share.

use super::*;

/// The bubble's axis column from the mirror symmetry of its top edge over a
/// wide span (`half_span_px` each side of the apex, clipped to the image):
/// the edge rows of the columns are fitted by the even model
/// `y = A + C (x - s)^2 + E (x - s)^4`, linear in `A, C, E`, and the axis `s`
/// minimises the residual sum of squares (golden-section search within
/// +-8 px of `near`, the axis known from the frames before, else of the
/// vertex: a highlight or clutter on one side of the top can pull the
/// vertex of the edge fit further than that). Flat tops pin the axis down
/// only through their far flanks, hence the wide span; the row is not taken
/// from this fit (the even model is biased at the apex by the higher terms
/// over a wide span). Returns the axis and its standard error, px. The
/// columns may be located already (by the edge fit of the same image).
pub fn axis_fit_in(
    cols: &mut Columns,
    apex: &EdgeFit,
    near: Option<f64>,
    half_span_px: usize,
) -> Option<(f64, f64)> {
    let w = cols.img.width as i64;
    let near = near.unwrap_or(apex.x_vertex);
    let xc = near.round() as i64;
    let k = 0.5 * apex.curvature.max(0.0);
    let span = half_span_px as i64;
    let mut located = Vec::new();
    // At most about 97 columns: wider spans are sampled (the axis is a
    // least-squares fit; more columns of the same edge add little).
    let stride = (span as usize).div_ceil(24).max(1);
    for c in (xc - span..=xc + span)
        .step_by(stride)
        .filter(|&c| c >= 0 && c < w)
    {
        let u = c as f64 - apex.x_vertex;
        if let Some((e, step)) = cols.edge(c as usize, apex.y + k * u * u) {
            located.push((c as f64, e, step));
        }
    }
    let mut pts: Vec<(f64, f64)> = strong_columns(&located, 9, 0.0)?
        .iter()
        .map(|l| (l.0, l.1))
        .collect();
    let scale = half_span_px.max(1) as f64;
    // Columns far off the even model (a cable or a shelf edge crossing the
    // flanks) are left out as in `robust_parabola`, and the axis found again.
    let mut s = golden_axis(&even_fit_rss(&pts, near, scale), near, 8.0);
    // A minimum on the search's border lies beyond it.
    if (s - near).abs() > 7.9 {
        return None;
    }
    for _ in 0..3 {
        let kept = within_biweight(&pts, &even_residuals(&pts, s, scale)?);
        if kept.len() == pts.len() || kept.len() < 9.max(pts.len() / 2) {
            break;
        }
        pts = kept;
        // Near the first axis: leaving out a few columns refines it, it
        // does not move it to another minimum.
        s = golden_axis(&even_fit_rss(&pts, near, scale), s, 2.0);
    }
    let rss = even_fit_rss(&pts, near, scale);
    if (s - near).abs() > 7.9 {
        return None;
    }
    // Standard error from the curvature of RSS(s): var = 2 sigma^2 / RSS''.
    let h = 0.05;
    let (r0, rp, rm) = (rss(s), rss(s + h), rss(s - h));
    let curv = (rp + rm - 2.0 * r0) / (h * h);
    let n = pts.len() as f64;
    let sigma2 = r0 / (n - 4.0).max(1.0);
    if curv.is_nan() || curv <= 0.0 {
        return None;
    }
    Some((s, (2.0 * sigma2 / curv).sqrt()))
}

/// The axis in `near +- half` px that minimises `rss` (golden-section
/// search).
pub(super) fn golden_axis(rss: &impl Fn(f64) -> f64, near: f64, half: f64) -> f64 {
    let (mut a, mut b) = (near - half, near + half);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (rss(c), rss(d));
    while b - a > 1e-4 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = rss(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = rss(d);
        }
    }
    0.5 * (a + b)
}

/// The residuals of the least-squares fit of the even model of
/// [`even_fit_rss`] about the axis `s`.
pub(super) fn even_residuals(pts: &[(f64, f64)], s: f64, scale: f64) -> Option<Vec<f64>> {
    let basis = |x: f64| {
        let v = ((x - s) / scale).powi(2);
        nalgebra::Vector3::new(1.0, v, v * v)
    };
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(x, y) in pts {
        let g = basis(x);
        ata += g * g.transpose();
        aty += g * y;
    }
    let c = ata.cholesky()?.solve(&aty);
    Some(pts.iter().map(|&(x, y)| y - basis(x).dot(&c)).collect())
}

/// `RSS(s)` of the least-squares fit of `y = A + C v + E v^2`, with
/// `v = ((x - s) / scale)^2`, to `pts`, for any axis `s`. Power sums of the
/// abscissa (centred on `centre`, divided by `scale`) are taken once, and
/// each evaluation expands `sum (t - u)^m` binomially: O(1) per `s`, where
/// refitting costs O(points) for each of the 30-odd evaluations of the
/// golden-section search.
pub(super) fn even_fit_rss(pts: &[(f64, f64)], centre: f64, scale: f64) -> impl Fn(f64) -> f64 {
    let ym = pts.iter().map(|p| p.1).sum::<f64>() / pts.len().max(1) as f64;
    let (mut st, mut sty, mut syy) = ([0.0f64; 9], [0.0f64; 5], 0.0);
    for &(x, y) in pts {
        let (t, y) = ((x - centre) / scale, y - ym);
        let mut p = 1.0;
        for k in 0..9 {
            st[k] += p;
            if k < 5 {
                sty[k] += p * y;
            }
            p *= t;
        }
        syy += y * y;
    }
    // Binomial coefficients C(m, j), m <= 8.
    let mut binom = [[0.0f64; 9]; 9];
    for m in 0..9 {
        binom[m][0] = 1.0;
        for j in 1..=m {
            binom[m][j] = binom[m - 1][j - 1] + if j < m { binom[m - 1][j] } else { 0.0 };
        }
    }
    move |s: f64| {
        let u = (s - centre) / scale;
        let mut nu = [1.0f64; 9];
        for k in 1..9 {
            nu[k] = nu[k - 1] * -u;
        }
        // sum (t - u)^m and sum (t - u)^m y.
        let shifted = |sums: &[f64], m: usize| -> f64 {
            (0..=m)
                .map(|j| binom[m][j] * nu[m - j] * sums[j])
                .sum::<f64>()
        };
        let mm = |m: usize| shifted(&st, m);
        let ata = nalgebra::Matrix3::new(
            mm(0),
            mm(2),
            mm(4),
            mm(2),
            mm(4),
            mm(6),
            mm(4),
            mm(6),
            mm(8),
        );
        let aty = nalgebra::Vector3::new(shifted(&sty, 0), shifted(&sty, 2), shifted(&sty, 4));
        match ata.cholesky() {
            Some(ch) => (syy - ch.solve(&aty).dot(&aty)).max(0.0),
            None => f64::INFINITY,
        }
    }
}

/// `g^T M g` (clamped at 0), the variance of a linear combination `g` of
/// estimates whose covariance is `M`.
pub(crate) fn quad_form<R: AsRef<[f64]>>(m: &[R], g: &[f64]) -> f64 {
    let mut v = 0.0;
    for (gi, row) in g.iter().zip(m) {
        for (gj, mij) in g.iter().zip(row.as_ref()) {
            v += gi * mij * gj;
        }
    }
    v.max(0.0)
}

pub(super) struct Parabola {
    pub(super) coef: [f64; 3],
    /// (X^T X)^-1 scaled by the residual variance.
    pub(super) cov: [[f64; 3]; 3],
    pub(super) rss: f64,
    /// The residual variance, `rss` over the degrees of freedom (at least
    /// 1).
    pub(super) s2: f64,
}

impl Parabola {
    pub(super) fn var_at(&self, u: f64) -> f64 {
        quad_form(&self.cov, &[1.0, u, u * u])
    }

    /// [`Parabola::var_at`] without the residual variance: for comparing
    /// fits of the same points' subsets under one variance.
    pub(super) fn unscaled_var_at(&self, u: f64) -> f64 {
        self.var_at(u) / self.s2.max(f64::MIN_POSITIVE)
    }

    /// `y - fit(u)` of each point.
    pub(super) fn residuals(&self, pts: &[(f64, f64)]) -> Vec<f64> {
        let [a, b, c] = self.coef;
        pts.iter()
            .map(|&(u, y)| y - (a + b * u + c * u * u))
            .collect()
    }
}

/// The points whose residual `res` lies within Tukey's biweight cut-off,
/// 4.685 robust standard deviations (the scale from the median absolute
/// residual, at least 0.05 px).
pub(super) fn within_biweight(pts: &[(f64, f64)], res: &[f64]) -> Vec<(f64, f64)> {
    let mut abs: Vec<f64> = res.iter().map(|r| r.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let scale = (1.4826 * abs[abs.len() / 2]).max(0.05);
    pts.iter()
        .zip(res)
        .filter(|(_, r)| r.abs() < 4.685 * scale)
        .map(|(p, _)| *p)
        .collect()
}

/// The least-squares parabola through the columns after those far off it
/// are left out: Tukey's biweight (c = 4.685 robust standard deviations,
/// the scale from the median absolute residual, at least 0.05 px) by
/// iteratively reweighted least squares, then a plain fit through the
/// columns of non-zero weight (so that its covariance is the usual one).
/// A cable or the corner of a shelf that crosses a few columns no longer
/// bends the apex. Returns the fit and the columns kept.
pub(super) fn robust_parabola(
    pts: &[(f64, f64)],
    even: bool,
) -> Option<(Parabola, Vec<(f64, f64)>)> {
    let mut kept = pts.to_vec();
    let mut fit = parabola(&kept, even)?;
    for _ in 0..4 {
        let c = fit.coef;
        let res: Vec<f64> = pts
            .iter()
            .map(|&(u, y)| y - (c[0] + c[1] * u + c[2] * u * u))
            .collect();
        let next = within_biweight(pts, &res);
        if next.len() == kept.len() || next.len() < 5.max(pts.len() / 2) {
            break;
        }
        kept = next;
        fit = parabola(&kept, even)?;
    }
    Some((fit, kept))
}

/// The least-squares parabola `y = A + B u + C u^2` through `pts`; with
/// `even`, `B = 0` (its row and column of the covariance are zero).
pub(super) fn parabola(pts: &[(f64, f64)], even: bool) -> Option<Parabola> {
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(u, y) in pts {
        let g = nalgebra::Vector3::new(1.0, if even { 0.0 } else { u }, u * u);
        ata += g * g.transpose();
        aty += g * y;
    }
    if even {
        // The linear term fixed at zero: a unit on the diagonal keeps the
        // system invertible, and its solution and covariance are zeroed.
        ata[(1, 1)] = 1.0;
    }
    let mut inv = ata.try_inverse()?;
    if even {
        for k in 0..3 {
            inv[(1, k)] = 0.0;
            inv[(k, 1)] = 0.0;
        }
    }
    let c = inv * aty;
    let rss: f64 = pts
        .iter()
        .map(|&(u, y)| {
            let r = y - (c[0] + c[1] * u + c[2] * u * u);
            r * r
        })
        .sum();
    let dof = (pts.len() as f64 - if even { 2.0 } else { 3.0 }).max(1.0);
    let s2 = rss / dof;
    let mut cov = [[0.0; 3]; 3];
    for (i, row) in cov.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = inv[(i, j)] * s2;
        }
    }
    Some(Parabola {
        coef: [c[0], c[1], c[2]],
        cov,
        rss,
        s2,
    })
}
