//! Predictors for continuation over pressures: the first guess of a scene's
//! next equilibrium from the ones already solved.

use super::super::solve::Predictor;
use nalgebra::Point3;

use super::*;

/// First guesses for the elliptical and rectangular windows: at the first
/// pressure the flat window lifted to a bump of Hencky's centre height for
/// a disc of the window's smaller half-width (`1 - (x/a)^2 - (y/b)^2` on the
/// ellipse, `(1 - (x/a)^2)(1 - (y/b)^2)` on the rectangle), then the last
/// displacement scaled by `(p1 / p0)^(1/3)`.
pub struct WindowPredictor {
    /// Half-sizes along x and y, m (semi-axes, or half length and width).
    pub half_m: [f64; 2],
    /// A rectangle (else an ellipse).
    pub rectangle: bool,
    /// Small-strain modulus, Pa.
    pub young_pa: f64,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Poisson ratio.
    pub poisson: f64,
}

impl Predictor for WindowPredictor {
    fn predict(&self, rest: &[Point3<f64>], x: &mut [Point3<f64>], p0: f64, p1: f64) {
        let [a, b] = self.half_m;
        if p0 <= 0.0 {
            let r = a.min(b);
            let w0 =
                (hencky_k(self.poisson) * r * (p1 * r / (self.young_pa * self.thickness_m)).cbrt())
                    .min(r);
            for (xi, xr) in x.iter_mut().zip(rest) {
                let (u, v) = ((xr.x / a).powi(2), (xr.y / b).powi(2));
                let bump = if self.rectangle {
                    (1.0 - u) * (1.0 - v)
                } else {
                    1.0 - u - v
                };
                if bump > 1e-12 {
                    *xi = Point3::new(xr.x, xr.y, (w0 * bump).max(xr.z));
                }
            }
        } else {
            let s = (p1 / p0).cbrt();
            for (xi, xr) in x.iter_mut().zip(rest) {
                *xi = xr + (*xi - xr) * s;
            }
        }
    }
}

/// First guesses for the disc: Hencky's profile at the first pressure (or
/// a slack membrane's reference dome where that stands higher), then the
/// last displacement scaled by `(p1 / p0)^(1/3)` (membrane scaling).
pub struct DiscPredictor {
    /// Free radius, m.
    pub radius_m: f64,
    /// Small-strain modulus, Pa.
    pub young_pa: f64,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Poisson ratio.
    pub poisson: f64,
}

impl Predictor for DiscPredictor {
    fn predict(&self, rest: &[Point3<f64>], x: &mut [Point3<f64>], p0: f64, p1: f64) {
        let a = self.radius_m;
        if p0 <= 0.0 {
            let w0 =
                (hencky_k(self.poisson) * a * (p1 * a / (self.young_pa * self.thickness_m)).cbrt())
                    .min(a);
            for (xi, xr) in x.iter_mut().zip(rest) {
                let r2 = (xr.x * xr.x + xr.y * xr.y) / (a * a);
                // A slack membrane's reference dome where it stands higher
                // than Hencky's profile: a guess under the dome is nearer
                // the dome turned inside out than the inflated one.
                if r2 < 1.0 - 1e-12 {
                    *xi = Point3::new(xr.x, xr.y, (w0 * (1.0 - r2)).max(xr.z));
                }
            }
        } else {
            let s = (p1 / p0).cbrt();
            for (xi, xr) in x.iter_mut().zip(rest) {
                *xi = xr + (*xi - xr) * s;
            }
        }
    }
}
