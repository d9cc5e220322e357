//! The pole's radius of curvature, which a camera above the clamp plane or
//! at a finite distance needs to turn the silhouette's top into the apex
//! height: the membrane's bounds on it ([`pole_flattening`]), a photo's own
//! outline, and the outlines of a sequence's photos pooled
//! ([`pooled_flattening`]).

/// The pole's radius of curvature of an inflated membrane over that of the
/// spherical cap through its rim with the same height, at the apex height
/// `h_over_a` (`h / a`): its mean and relative standard deviation, those
/// of a uniform spread between the bounds that hold for every law. A flat
/// clamped membrane's top is flatter than the cap. The exact axisymmetric
/// solutions (`cargo run --release --example pole_curvature -- --rows`:
/// neo-Hookean, Mooney-Rivlin with C2/C1 0.05-1, Yeoh, Ogden, Gent with
/// Jm 10-100, linear elastic and a quartic law, flat or slack, from small
/// heights to 0.97 of the limit pressure or a pole stretch of 3) give
/// 1.01-1.12 up to `h = 0.8 a`; beyond, the most strain-stiffening of
/// them (Gent, Jm 10) rises to 1.43 at `h = 1.83 a`, under `1.12 + 0.3 (h
/// / a - 0.8)` everywhere, which is continued beyond. A slack membrane near
/// its stress-free shape (a cap) gives about 1, the lower bound.
pub fn pole_flattening(h_over_a: f64) -> (f64, f64) {
    let lo = 1.0;
    let hi = 1.12 + 0.3 * (h_over_a - 0.8).max(0.0);
    let mean = 0.5 * (lo + hi);
    (mean, (hi - lo) / (12f64.sqrt() * mean))
}

/// How fast one membrane's flattening can change as it inflates: the
/// largest `|d ln F / d(h / a)|` of the exact solutions of
/// `--example pole_curvature -- --rows` (`max abs dR/d(h/a)` over the
/// flattening's inverse `R`) on taut membranes is 0.32, Gent with Jm 10
/// near its largest heights (0.226 / 0.70); the other laws 0.19 at most.
/// Slack membranes change faster while they leave their stress-free cap
/// (up to 2.5 over a few hundredths of `a`); there the pooled value's
/// scatter test widens it ([`pooled_flattening`]).
pub const FLATTENING_SLOPE: f64 = 0.32;

/// What is known of a photo's pole radius besides the membrane's bounds.
/// Each carries the covariance of its error with the apex row's, px: the
/// row and the outline's curvature come from one fit of the top edge,
/// and noise that lowers the fitted top also flattens it, so both move a
/// height the same way (a raised camera's height falls with a lower top
/// and with a larger pole radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PoleMeasure {
    /// The curvature of the outline at its top and its standard error, in
    /// the image's units (1/px), from the photo's own edge fit, and the
    /// covariance of the curvature with the apex row (px times 1/px).
    Outline(f64, f64, f64),
    /// The flattening itself (the pole's radius over the cap's through the
    /// rim), its relative standard deviation, pooled over the photos of a
    /// sequence ([`pooled_flattening`]), and the covariance of `ln F` with
    /// the apex row, px: the photo's own outline's, times its share of
    /// the pool.
    Flattening(f64, f64, f64),
}

impl PoleMeasure {
    /// The measure where it measures a dome: a positive value with a
    /// positive, finite deviation.
    pub fn usable(self) -> Option<Self> {
        let (PoleMeasure::Outline(v, s, _) | PoleMeasure::Flattening(v, s, _)) = self;
        (v > 0.0 && s.is_finite() && s > 0.0).then_some(self)
    }

    /// The outline's curvature and its standard error, 1/px, where this is
    /// a usable [`PoleMeasure::Outline`].
    pub fn outline(self) -> Option<(f64, f64)> {
        match self.usable()? {
            PoleMeasure::Outline(k, ks, _) => Some((k, ks)),
            PoleMeasure::Flattening(..) => None,
        }
    }

    /// The pole's curvature and its standard deviation that a usable
    /// [`PoleMeasure::Flattening`] gives a dome whose cap through the rim
    /// has radius `r_cap`: `1 / (F r_cap)`, relative deviation that of `F`.
    pub fn flattening_curvature(self, r_cap: f64) -> Option<(f64, f64)> {
        match self.usable()? {
            PoleMeasure::Flattening(f, rel, _) => Some((1.0 / (f * r_cap), rel / (f * r_cap))),
            PoleMeasure::Outline(..) => None,
        }
    }

    /// The covariance of the apex row's error with the relative error of
    /// the pole's curvature this measure gives, px (0 where unusable):
    /// `cov(y, k) / k` for an outline, `-cov(y, ln F)` for a flattening
    /// (the curvature is `1 / (F r_cap)`).
    pub fn row_cov(self) -> f64 {
        match self.usable() {
            Some(PoleMeasure::Outline(k, _, c)) => c / k,
            Some(PoleMeasure::Flattening(_, _, c)) => -c,
            None => 0.0,
        }
    }
}

/// The pole's curvature and its standard deviation: the inverse-variance
/// mean of the membrane's estimate, `1 / (F r_cap)` for a spherical cap of
/// radius `r_cap` through the rim with the dome's height `h_over_a` times
/// the free radius ([`pole_flattening`]'s mean `F`, with its relative
/// deviation), and, when given, one measured (value and standard
/// deviation, in the units of `1 / r_cap`); then the measured one's weight
/// in the mean (0 without one), which carries its errors into the mean.
pub(crate) fn pole_curvature_mean(
    r_cap: f64,
    h_over_a: f64,
    measured: Option<(f64, f64)>,
) -> (f64, f64, f64) {
    let (f, rel) = pole_flattening(h_over_a);
    let k_p = 1.0 / (f * r_cap);
    let w_p = (rel * k_p).powi(-2);
    let (k_m, w_m) = measured.map_or((0.0, 0.0), |(k, ks)| (k, 1.0 / (ks * ks)));
    (
        (k_p * w_p + k_m * w_m) / (w_p + w_m),
        (w_p + w_m).sqrt().recip(),
        w_m / (w_p + w_m),
    )
}

/// Each photo's flattening from every photo's measured one: the photos of
/// one sequence show one membrane, whose flattening changes with its
/// height by at most [`FLATTENING_SLOPE`] in `ln F` per `a`. Photo `i`'s is
/// the inverse-variance mean of `ln F_j` over the photos measured, each
/// with its own relative deviation and, in quadrature, that bound times
/// the heights' difference `|h_j - h_i| / a`; the mean's deviation is
/// widened by the scatter about it where the measurements disagree beyond
/// their deviations (the Birge ratio `sqrt(chi^2 / (n_eff - 1))`, with
/// `n_eff = (sum w)^2 / sum w^2` the effective number of photos). A photo
/// never measured gets the others' through the same weights; `None` where
/// no photo was measured. `h_over_a[i]` is photo `i`'s height over the
/// free radius, `measured[i]` its flattening and relative deviation.
/// Returns each photo's flattening, its relative deviation and the weight
/// of the photo's own measurement in it (0 when it has none), through
/// which the pool shares that measurement's errors.
pub fn pooled_flattening(
    h_over_a: &[f64],
    measured: &[Option<(f64, f64)>],
) -> Vec<Option<(f64, f64, f64)>> {
    let points: Vec<(usize, f64, f64, f64)> = h_over_a
        .iter()
        .zip(measured)
        .enumerate()
        .filter_map(|(i, (&h, m))| {
            m.filter(|(f, rel)| *f > 0.0 && f.is_finite() && *rel > 0.0 && rel.is_finite())
                .map(|(f, rel)| (i, h, f.ln(), rel))
        })
        .collect();
    h_over_a
        .iter()
        .enumerate()
        .map(|(i, &h)| {
            if points.is_empty() {
                return None;
            }
            let w: Vec<f64> = points
                .iter()
                .map(|&(_, hj, _, rel)| 1.0 / (rel * rel + (FLATTENING_SLOPE * (hj - h)).powi(2)))
                .collect();
            let sw: f64 = w.iter().sum();
            let mean = points.iter().zip(&w).map(|(p, w)| p.2 * w).sum::<f64>() / sw;
            let chi2: f64 = points
                .iter()
                .zip(&w)
                .map(|(p, w)| w * (p.2 - mean).powi(2))
                .sum();
            let own = points
                .iter()
                .zip(&w)
                .find(|(p, _)| p.0 == i)
                .map_or(0.0, |(_, w)| w / sw);
            let n_eff = sw * sw / w.iter().map(|w| w * w).sum::<f64>();
            let birge = if n_eff > 1.5 {
                (chi2 / (n_eff - 1.0)).max(1.0)
            } else {
                1.0
            };
            Some((mean.exp(), (birge / sw).sqrt(), own))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One measurement is returned as it is; two equal ones at one height
    /// halve the variance; a far photo counts through the slope bound
    /// alone: `1 / (rel^2 + (S dh)^2)`.
    #[test]
    fn the_pool_weighs_each_photo_by_its_deviation_and_the_heights_apart() {
        let one = pooled_flattening(&[0.3], &[Some((1.08, 0.02))]);
        let (f, rel, own) = one[0].unwrap();
        assert!((f - 1.08).abs() < 1e-12 && (rel - 0.02).abs() < 1e-12);
        assert_eq!(own, 1.0);

        let two = pooled_flattening(&[0.3, 0.3], &[Some((1.08, 0.02)), Some((1.08, 0.02))]);
        let (_, rel, own) = two[0].unwrap();
        assert!((rel - 0.02 / 2f64.sqrt()).abs() < 1e-12, "{rel}");
        assert!((own - 0.5).abs() < 1e-12, "{own}");

        // Photo 0 unmeasured at 0.2 a, photo 1 measured at 0.5 a: the
        // variance is the measurement's and the slope bound's over 0.3 a.
        let far = pooled_flattening(&[0.2, 0.5], &[None, Some((1.1, 0.01))]);
        let (f, rel, own) = far[0].unwrap();
        assert_eq!(own, 0.0);
        let want = (0.01f64.powi(2) + (FLATTENING_SLOPE * 0.3).powi(2)).sqrt();
        assert!(
            (f - 1.1).abs() < 1e-12 && (rel - want).abs() < 1e-12,
            "{rel} {want}"
        );
        assert_eq!(pooled_flattening(&[0.2], &[None]), vec![None]);
    }

    /// Measurements that disagree beyond their deviations widen the
    /// pooled deviation by their scatter: two photos at one height, 1.00
    /// and 1.10 at 1 % each, are 9.5 deviations apart, and the pooled
    /// deviation is half their difference in `ln F`, not 0.7 %.
    #[test]
    fn disagreeing_photos_widen_the_pool_by_their_scatter() {
        let p = pooled_flattening(&[0.4, 0.4], &[Some((1.0, 0.01)), Some((1.1, 0.01))]);
        let (f, rel, _) = p[0].unwrap();
        let half = 0.5 * 1.1f64.ln();
        assert!((f.ln() - half).abs() < 1e-12);
        assert!((rel - half).abs() < 1e-9, "{rel} against {half}");
    }
}
