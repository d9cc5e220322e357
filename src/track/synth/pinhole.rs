//! Photos drawn by a pinhole camera at a finite distance (`Look::
//! camera_distance_m`): the camera of [`crate::track::persp::Pinhole`],
//! `D` from the axis, looking down at the clamp ring's centre at the look's
//! elevation angle (`H = D tan e`), its principal point at the axis's column
//! and the picture's middle row, its focal length the one that gives the
//! scene's scale across the picture at the ring's centre.
//!
//! The dome, a body of revolution closed by its base disc, projects to the
//! union of the images of its latitude circles. The image column `x` is the
//! plane through the camera `X = k (depth)`, `k = (x - c_x) / f`, with
//! `depth = cos theta (Y + D) - sin theta (Z - H)`; it meets the circle of
//! radius `rho` at height `z` (`X = rho sin phi`, `Y = rho cos phi`) where
//! `rho sin phi - k rho cos theta cos phi = k (D cos theta - (z - H) sin
//! theta)`, two points or none, in closed form. The outline per column is
//! the highest and the lowest of these points over the latitudes; the
//! clamp fixture's top face is its outer circle (radius 1.25 a) the same way.

use super::draw::envelope;
use super::{Scene, Silhouette, densify};
use crate::track::persp::Pinhole;

impl Scene {
    /// The look's pinhole camera (`None`: orthographic).
    pub fn pinhole(&self) -> Option<Pinhole> {
        let d = self.look.camera_distance_m;
        (d > 0.0).then(|| {
            Pinhole::from_view(
                d,
                self.look.elevation_deg.to_radians(),
                self.clamp_row_px,
                self.metres_per_pixel,
                None,
                [self.axis_x_px, (self.height as f64 - 1.0) / 2.0],
            )
        })
    }
}

/// The rows (top, bottom) where image column `x` meets the image of the
/// circle of radius `rho` at height `z` around the axis, or `None`.
pub fn circle_rows(p: &Pinhole, rho: f64, z: f64, x: f64) -> Option<(f64, f64)> {
    let k = (x - p.principal_px[0]) / p.focal_px;
    let (s, c) = p.pitch_rad.sin_cos();
    let rhs = k * (p.distance_m * c - (z - p.height_m) * s);
    let (a, b) = (rho, -k * rho * c);
    let m = a.hypot(b);
    if m == 0.0 || rhs.abs() > m {
        return None;
    }
    let delta = b.atan2(a);
    let base = (rhs / m).asin();
    let row = |phi: f64| p.project([rho * phi.sin(), rho * phi.cos(), z])[1];
    let (r1, r2) = (row(base - delta), row(std::f64::consts::PI - base - delta));
    Some((r1.min(r2), r1.max(r2)))
}

/// Half the image width, px, of the circle of radius `rho` at height `z`
/// around the axis: `f rho / (cos theta sqrt(D_z^2 - rho^2))`, `D_z = D +
/// (H - z) tan theta` (the tangent points, as
/// [`Pinhole::opening_half_width_px`] at `z = 0`).
pub fn circle_half_width_px(p: &Pinhole, rho: f64, z: f64) -> f64 {
    let d = p.distance_m + (p.height_m - z) * p.pitch_rad.tan();
    p.focal_px * rho / (p.pitch_rad.cos() * (d * d - rho * rho).sqrt())
}

/// The silhouette's top on the axis's column, px: the grazing ray's row
/// (the lowest row of the meridian's points in the plane through the
/// camera and the axis).
pub fn top_row(p: &Pinhole, s: &Silhouette, mpp: f64) -> f64 {
    densify(s, 0.05 * mpp)
        .iter()
        .flat_map(|&(r, z)| [p.project([0.0, -r, z])[1], p.project([0.0, r, z])[1]])
        .fold(f64::INFINITY, f64::min)
}

/// The outline of the dome seen by the pinhole, a closed polygon in raster
/// coordinates (`x + 0.5`, `y + 0.5`): the upper envelope from left to
/// right, then the lower one back, at columns spaced as `cos(psi)` (at
/// most a quarter pixel of arc apart).
pub(super) fn outline_px(scene: &Scene, p: &Pinhole, s: &Silhouette) -> Vec<(f64, f64)> {
    let dense = densify(s, 0.5 * scene.metres_per_pixel);
    let half = dense
        .iter()
        .map(|&(r, z)| circle_half_width_px(p, r.abs(), z))
        .fold(0.0, f64::max);
    let n = ((std::f64::consts::PI * half * 4.0).ceil() as usize).max(64);
    let mut top = Vec::with_capacity(n + 1);
    let mut bottom = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let psi = std::f64::consts::PI * (1.0 - k as f64 / n as f64);
        let x = p.principal_px[0] + half * psi.cos();
        let Some((t, b)) = envelope(&dense, |r, z| circle_rows(p, r.abs(), z, x)) else {
            continue;
        };
        top.push((x + 0.5, t + 0.5));
        bottom.push((x + 0.5, b + 0.5));
    }
    top.extend(bottom.into_iter().rev());
    top
}

/// The fixture's top face per column (its back and front edges: the outer
/// circle's rows, or the ring centre's row outside it), and its half-width,
/// px.
pub(super) fn fixture_rows(scene: &Scene, p: &Pinhole) -> (Vec<f64>, Vec<f64>, f64) {
    let outer = 1.25 * scene.radius_m;
    let c = scene.clamp_row_px;
    let (back, front) = (0..scene.width)
        .map(|x| circle_rows(p, outer, 0.0, x as f64).unwrap_or((c, c)))
        .unzip();
    (back, front, circle_half_width_px(p, outer, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form rows against 400 000 points of the circle projected.
    #[test]
    fn circle_rows_are_the_projected_circle_at_that_column() {
        let p = Pinhole::aimed(
            0.3,
            0.3 * 4f64.to_radians().tan(),
            0.01,
            2000.0,
            [321.0, 240.0],
        );
        let (rho, z) = (0.04, 0.012);
        for x in [321.0, 300.0, 250.0, 390.0] {
            let (t, b) = circle_rows(&p, rho, z, x).unwrap();
            let (mut bt, mut bb) = (f64::INFINITY, f64::NEG_INFINITY);
            let n = 400_000;
            let pts: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let phi = std::f64::consts::TAU * i as f64 / n as f64;
                    p.project([rho * phi.sin(), rho * phi.cos(), z])
                })
                .collect();
            for w in pts.windows(2) {
                let ([x0, y0], [x1, y1]) = (w[0], w[1]);
                if (x0 - x) * (x1 - x) <= 0.0 && x1 != x0 {
                    let y = y0 + (y1 - y0) * (x - x0) / (x1 - x0);
                    bt = bt.min(y);
                    bb = bb.max(y);
                }
            }
            assert!(
                (t - bt).abs() < 1e-6 && (b - bb).abs() < 1e-6,
                "{x}: {t} {b} vs {bt} {bb}"
            );
        }
        let w = circle_half_width_px(&p, rho, z);
        assert!(circle_rows(&p, rho, z, 321.0 + w - 1e-6).is_some());
        assert!(circle_rows(&p, rho, z, 321.0 + w + 1e-6).is_none());
    }

    /// The outline's top per column, the envelope of the sampled latitudes
    /// of a sphere (half a pixel of meridian apart, as the photos are
    /// drawn), against the sphere's image in closed form: the rays at the
    /// angle `alpha = asin(R / L)` from the one to its centre. A camera
    /// level with the clamp plane 0.25 m away, where each latitude is a
    /// thin ellipse and the samples alone leave a staircase inside the
    /// outline near its sides.
    #[test]
    fn the_outline_is_the_envelope_of_the_latitudes() {
        let (f, cx, cy) = (1280.0, 639.5, 479.5);
        let p = Pinhole::aimed(0.25, 0.0, 0.01, f, [cx, cy]);
        // A sphere of radius 0.03 m centred 0.012 m above the plane.
        let (r, z0) = (0.03f64, 0.012);
        let n = 4000;
        let sphere = Silhouette {
            rho_m: (0..=n)
                .map(|i| r * (std::f64::consts::PI * 0.7 * i as f64 / n as f64).sin())
                .collect(),
            z_m: (0..=n)
                .map(|i| z0 + r * (std::f64::consts::PI * 0.7 * i as f64 / n as f64).cos())
                .collect(),
        };
        let mpp = 0.25 / f;
        let dense = densify(&sphere, 0.5 * mpp);
        // The ray through (x, v): (X, c + U s, U c - s), X = (x - cx) / f,
        // U = (cy - v) / f; on the cone where its angle to the centre's
        // direction m = (0, D, z0 - H) / L is alpha.
        let (s, c) = p.pitch_rad.sin_cos();
        let (d, dz) = (p.distance_m, z0 - p.height_m);
        let l = d.hypot(dz);
        let cos2 = 1.0 - (r / l).powi(2);
        let top_row = |x: f64| {
            let xx = (x - cx) / f;
            // k(U) = (k0 + k1 U) / L against cos2 (X^2 + (c + U s)^2 +
            // (U c - s)^2) = cos2 (X^2 + 1 + U^2): a quadratic in U.
            let (k0, k1) = ((c * d - s * dz) / l, (s * d + c * dz) / l);
            let (qa, qb, qc) = (
                k1 * k1 - cos2,
                2.0 * k0 * k1,
                k0 * k0 - cos2 * (xx * xx + 1.0),
            );
            let disc = (qb * qb - 4.0 * qa * qc).sqrt();
            let u = [(-qb + disc) / (2.0 * qa), (-qb - disc) / (2.0 * qa)];
            cy - f * u[0].max(u[1])
        };
        let widest = circle_half_width_px(&p, r, z0);
        for share in [0.0, 0.5, 0.9, 0.99, 0.999] {
            let x = cx + share * widest;
            let (t, _) = envelope(&dense, |rho, z| circle_rows(&p, rho.abs(), z, x)).unwrap();
            let want = top_row(x);
            assert!((t - want).abs() < 2e-3, "{share}: {t} against {want}");
        }
    }
}
