//! A pinhole camera at a finite distance from the bubble: where the
//! silhouette's top and the opening's sides appear, and the apex height
//! back from the top's image row (derived in docs/theory.md, section 10).
//!
//! Coordinates: `z` up the axis from the clamp plane, `y` horizontal away
//! from the camera, the clamp ring's centre at the origin. The camera's
//! centre is at `y = -D`, `z = H` in the plane `x = 0` through the axis, its
//! image rows are horizontal (no roll, no yaw) and its optical axis is
//! pitched down by `theta`. A ray through image row `v` then rises at
//! `atan((c_v - v) / f) - theta` above the horizontal.
//!
//! The silhouette's top is the ray tangent to the dome's meridian in the
//! plane through the camera and the axis (for a camera in that plane, the
//! outline is symmetric about the axis's image column, so its highest point
//! lies on it). Near its pole the dome is a sphere of radius `R` (the pole
//! is an umbilic point), and the upper tangent from the camera to that
//! circle is closed form: the centre `(0, h - R)` is seen at
//! `atan2(h - R - H, D)` and the circle subtends `asin(R / L)` around it,
//! `L` the distance to the centre.

/// A pinhole camera in the plane through the axis (see the module's
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pinhole {
    /// Horizontal distance from the axis to the camera's centre, m.
    pub distance_m: f64,
    /// Height of the camera's centre above the clamp plane, m.
    pub height_m: f64,
    /// Angle of the optical axis below the horizontal, rad.
    pub pitch_rad: f64,
    /// Focal length, px.
    pub focal_px: f64,
    /// Principal point `[column, row]`, px.
    pub principal_px: [f64; 2],
}

impl Pinhole {
    /// A camera at `distance_m` from the axis and `height_m` above the clamp
    /// plane, aimed at the point `aim_z_m` up the axis, its principal point
    /// at `principal_px`.
    pub fn aimed(
        distance_m: f64,
        height_m: f64,
        aim_z_m: f64,
        focal_px: f64,
        principal_px: [f64; 2],
    ) -> Self {
        Pinhole {
            distance_m,
            height_m,
            pitch_rad: (height_m - aim_z_m).atan2(distance_m),
            focal_px,
            principal_px,
        }
    }

    /// The camera set up from what the experiment file gives: its distance
    /// `distance_m` from the axis, the angle `elevation_rad` at which it
    /// looks down at the clamp ring's centre (`H = D tan e`), the image row
    /// `centre_row_px` of that centre, the scale `metres_per_pixel` at that
    /// centre (across the picture), and the principal point (from the lens
    /// calibration, or the picture's centre). The focal length (when not
    /// given) and the pitch follow: the ring's centre lies on the ray at
    /// `-e`, so `theta = e + atan((c_v - v0) / f)`, and the scale there is
    /// `(D cos theta + H sin theta) / f` m per px; solved by iteration.
    pub fn from_view(
        distance_m: f64,
        elevation_rad: f64,
        centre_row_px: f64,
        metres_per_pixel: f64,
        focal_px: Option<f64>,
        principal_px: [f64; 2],
    ) -> Self {
        let height_m = distance_m * elevation_rad.tan();
        let slant = distance_m.hypot(height_m);
        let mut f = focal_px.unwrap_or(slant / metres_per_pixel);
        let mut pitch = elevation_rad;
        for _ in 0..50 {
            pitch = elevation_rad + ((principal_px[1] - centre_row_px) / f).atan();
            if focal_px.is_some() {
                break;
            }
            let next = (distance_m * pitch.cos() + height_m * pitch.sin()) / metres_per_pixel;
            let done = (next - f).abs() < 1e-12 * f;
            f = next;
            if done {
                break;
            }
        }
        Pinhole {
            distance_m,
            height_m,
            pitch_rad: pitch,
            focal_px: f,
            principal_px,
        }
    }

    /// Image point `[column, row]` of the point `(x, y, z)`, m.
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        let (s, c) = self.pitch_rad.sin_cos();
        let q = [p[0], p[1] + self.distance_m, p[2] - self.height_m];
        let depth = q[1] * c - q[2] * s;
        let up = q[1] * s + q[2] * c;
        [
            self.principal_px[0] + self.focal_px * q[0] / depth,
            self.principal_px[1] - self.focal_px * up / depth,
        ]
    }

    /// Angle above the horizontal of the ray through image row `row`, rad.
    pub fn ray_rise(&self, row: f64) -> f64 {
        ((self.principal_px[1] - row) / self.focal_px).atan() - self.pitch_rad
    }

    /// Image row of a ray rising at `rise` rad above the horizontal.
    pub fn row_of_rise(&self, rise: f64) -> f64 {
        self.principal_px[1] - self.focal_px * (rise + self.pitch_rad).tan()
    }

    /// Rise of the upper tangent from the camera to the circle of radius
    /// `r` centred `(y = 0, z = h - r)` in the plane through the axis: the
    /// pole's sphere of a dome of apex height `h`, rad.
    pub fn top_rise(&self, h: f64, r: f64) -> f64 {
        let dz = h - r - self.height_m;
        let l = self.distance_m.hypot(dz);
        dz.atan2(self.distance_m) + (r / l).min(1.0).asin()
    }

    /// Image row of the silhouette's top of a dome of apex height `h` whose
    /// pole's radius of curvature is `r`, px.
    pub fn top_row(&self, h: f64, r: f64) -> f64 {
        self.row_of_rise(self.top_rise(h, r))
    }

    /// The apex height, m, whose silhouette top is at image row `row`, the
    /// pole's radius of curvature `pole_radius(h)` (a function of the
    /// height: the spherical cap through the rim, or a measured one), over
    /// `0..h_max_m`. The tangent touches the pole's sphere at the polar
    /// angle equal to the ray's rise (towards the camera for a rising ray,
    /// beyond the pole for a falling one); while that point lies on the
    /// dome (within its cap's half-angle `2 atan(h / a)`, `a_m` the free
    /// radius) the rise grows with `h`: the highest sign change on a
    /// geometric grid down from `h_max_m`, then bisection. `None` when no
    /// such height gives the row (the top would be the ring's back).
    pub fn height_from_top_row(
        &self,
        row: f64,
        a_m: f64,
        h_max_m: f64,
        pole_radius: impl Fn(f64) -> f64,
    ) -> Option<f64> {
        let target = self.ray_rise(row);
        let on_dome = |h: f64| {
            let rise = self.top_rise(h, pole_radius(h));
            (rise.abs() < 2.0 * (h / a_m).atan()).then_some(rise - target)
        };
        let mut hi = h_max_m;
        if on_dome(hi)? < 0.0 {
            return None;
        }
        let mut lo = hi;
        loop {
            lo *= 0.97;
            if lo < 1e-6 * a_m {
                return None;
            }
            match on_dome(lo) {
                None => return None,
                Some(g) if g < 0.0 => break,
                Some(_) => hi = lo,
            }
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            match on_dome(mid) {
                Some(g) if g < 0.0 => lo = mid,
                _ => hi = mid,
            }
            if hi - lo < 1e-15 * h_max_m.max(1.0) {
                break;
            }
        }
        Some(0.5 * (lo + hi))
    }

    /// Half the horizontal extent, px, of the image of the circle of radius
    /// `a` in the clamp plane around the axis: its tangent points from the
    /// camera, not the ends of the diameter across the view. The circle's
    /// point at azimuth `phi` (`x = a sin phi`, `y = a cos phi`) is at
    /// depth `cos theta (a cos phi + D')`, `D' = D + H tan theta`, so the
    /// column's offset `f a sin phi / (cos theta (a cos phi + D'))` is
    /// largest at `cos phi = -a / D'`: `f a / (cos theta sqrt(D'^2 - a^2))`.
    pub fn opening_half_width_px(&self, a: f64) -> f64 {
        let d = self.distance_m + self.height_m * self.pitch_rad.tan();
        self.focal_px * a / (self.pitch_rad.cos() * (d * d - a * a).sqrt())
    }

    /// The scale across the picture at the clamp ring's centre, m per px:
    /// a short horizontal segment there is at depth `D cos theta + H sin
    /// theta`.
    pub fn centre_scale(&self) -> f64 {
        let (s, c) = self.pitch_rad.sin_cos();
        (self.distance_m * c + self.height_m * s) / self.focal_px
    }

    /// The scale at the ring's centre over the one a radius `a` gives from
    /// the opening's image width (`a / half-width`): a scale measured on the
    /// opening is this factor too small (`1 / sqrt(1 - a^2 / D^2)` for a
    /// level camera).
    pub fn opening_scale_factor(&self, a: f64) -> f64 {
        self.centre_scale() * self.opening_half_width_px(a) / a
    }
}

impl Pinhole {
    /// The apex height of a membrane of free radius `a_m` from its
    /// silhouette's top at `row` (standard deviation `row_std`), m, with its
    /// standard deviation. The pole's curvature is the inverse-variance
    /// mean of two estimates: [`super::pole_flattening`] times the
    /// spherical cap's through the rim (with its deviation), and, when
    /// given, one `measured`: the edge fit's curvature at the top (value
    /// and standard error, 1/px, in the undistorted image) through
    /// [`Pinhole::pole_radius_from_outline`], or the flattening pooled over
    /// a sequence's photos ([`super::pooled_flattening`]).
    /// The row's deviation and the curvature's are carried through by
    /// central differences, joined by their covariance (the row and the
    /// outline come from one fit). `None` when no dome up to `1.5 a` has its top
    /// at that row.
    pub fn membrane_height(
        &self,
        row: f64,
        row_std: f64,
        a_m: f64,
        measured: Option<super::PoleMeasure>,
    ) -> Option<(f64, f64)> {
        use super::pole::pole_curvature_mean;
        // The pole's curvature, 1/m, its standard deviation and their
        // covariance with the row (px/m), at the height `h`: an outline's
        // relative error reaches the pole radius's times the ratio of their
        // relative deviations ([`Pinhole::pole_radius_from_outline`]).
        let pole = |h: f64| {
            let r_cap = cap_radius(a_m, h);
            let in_m = measured.and_then(|m| match m.outline() {
                Some((k, ks)) => {
                    let r0 = super::pole_flattening(h / a_m).0 * r_cap;
                    let (r, rel) = self.pole_radius_from_outline(h, r0, 1.0 / k, ks / k);
                    Some((1.0 / r, rel / r, rel / (ks / k)))
                }
                None => m.flattening_curvature(r_cap).map(|(k, ks)| (k, ks, 1.0)),
            });
            let (k, k_std, share) = pole_curvature_mean(r_cap, h / a_m, in_m.map(|m| (m.0, m.1)));
            let row_cov = measured.map_or(0.0, |m| m.row_cov());
            let cov = in_m.map_or(0.0, |(k_m, _, g)| share * k_m * g * row_cov);
            (k, k_std, cov)
        };
        let solve = |row: f64, sd: f64| {
            self.height_from_top_row(row, a_m, 1.5 * a_m, |h| {
                let (k, k_std, _) = pole(h);
                1.0 / (k + sd * k_std)
            })
        };
        let h = solve(row, 0.0)?;
        let dv = 0.05;
        let per_px = match (solve(row - dv, 0.0), solve(row + dv, 0.0)) {
            (Some(up), Some(down)) => (up - down) / (2.0 * dv),
            _ => 0.0,
        };
        let per_k = match (solve(row, -1.0), solve(row, 1.0)) {
            (Some(p), Some(m)) => 0.5 * (p - m),
            _ => 0.0,
        };
        // d h = -per_px d row - per_k / k_std d k: the row's and the
        // pole's parts joined by their covariance ([`super::PoleMeasure`]).
        let (_, k_std, cov) = pole(h);
        let cross = if k_std > 0.0 {
            2.0 * per_px * per_k / k_std * cov
        } else {
            0.0
        };
        let var = (per_px * row_std).powi(2) + per_k * per_k + cross;
        Some((h, var.max(0.0).sqrt()))
    }

    /// The pole's radius of curvature, m, and its relative standard
    /// deviation, from the outline's radius of curvature at its top,
    /// `rho_px` px (relative standard error `rel`), for a dome of apex
    /// height `h` whose pole radius is first taken as `r0`. A sphere of
    /// radius `R` whose centre is `L` from the camera's centre is seen
    /// within the cone of half-angle `alpha = asin(R / L)`; the outline's
    /// radius of curvature where its tangent is horizontal is `f tan alpha`
    /// wherever the sphere lies in the picture (docs/theory.md), so `R = L
    /// rho / sqrt(f^2 + rho^2)`, `L` from the centre `(0, h - R)`: solved by
    /// iteration. The relative deviation follows `d ln R = d ln L + f^2 /
    /// (f^2 + rho^2) d ln rho`, where `L` moves with `R` itself: `d ln L =
    /// -(h - R - H) R / L^2 d ln R` (`H` the camera's height).
    pub fn pole_radius_from_outline(&self, h: f64, r0: f64, rho_px: f64, rel: f64) -> (f64, f64) {
        let f = self.focal_px;
        let mut r = r0;
        for _ in 0..20 {
            let l = self.distance_m.hypot(h - r - self.height_m);
            let next = l * rho_px / f.hypot(rho_px);
            let done = (next - r).abs() < 1e-12 * r0;
            r = next;
            if done {
                break;
            }
        }
        let z = h - r - self.height_m;
        let l2 = self.distance_m.powi(2) + z * z;
        (
            r,
            rel * f * f / (f * f + rho_px * rho_px) / (1.0 + z * r / l2),
        )
    }
}

/// The pole's radius of curvature of the spherical cap of base radius `a`
/// and height `h`: `(a^2 + h^2) / (2 h)`.
pub fn cap_radius(a: f64, h: f64) -> f64 {
    (a * a + h * h) / (2.0 * h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(d: f64, up_deg: f64, aim: f64) -> Pinhole {
        Pinhole::aimed(
            d,
            d * up_deg.to_radians().tan(),
            aim,
            3000.0,
            [640.0, 480.0],
        )
    }

    /// The closed-form top against the highest image point of 20001 points
    /// on the whole sphere (not only its meridian) through the projection.
    #[test]
    fn the_top_is_the_highest_projected_point_of_the_pole_sphere() {
        let a = 0.0375;
        for (d, up, aim) in [
            (0.25, 0.0, 0.02),
            (0.45, 4.0, 0.0),
            (1.0, 5.0, 0.01),
            (0.3, 3.0, 0.03),
        ] {
            let c = cam(d, up, aim);
            for h in [0.005, 0.015, 0.03] {
                let r = cap_radius(a, h);
                let mut best = f64::INFINITY;
                let n = 400;
                for i in 0..=n {
                    // polar angle from the top, azimuth (dense near the top)
                    let t = 0.6 * (i as f64 / n as f64);
                    for j in 0..50 {
                        let az = std::f64::consts::TAU * j as f64 / 50.0;
                        let p = [
                            r * t.sin() * az.cos(),
                            r * t.sin() * az.sin(),
                            h - r + r * t.cos(),
                        ];
                        best = best.min(c.project(p)[1]);
                    }
                }
                // and finely along the meridian, both sides of the pole
                for i in 0..=400_000 {
                    let t = 0.4 * (i as f64 / 200_000.0 - 1.0);
                    best = best.min(c.project([0.0, -r * t.sin(), h - r + r * t.cos()])[1]);
                }
                let closed = c.top_row(h, r);
                assert!(
                    (closed - best).abs() < 1e-6,
                    "D {d} up {up} h {h}: {closed} vs {best}"
                );
                // and it is above (a smaller row than) the pole's own image
                assert!(closed < c.project([0.0, 0.0, h])[1]);
            }
        }
    }

    #[test]
    fn the_height_comes_back_from_the_top_row() {
        let a = 0.0375;
        for (d, up, aim) in [(0.25, 0.0, 0.02), (0.45, 4.0, 0.0), (1.0, 5.0, 0.01)] {
            let c = cam(d, up, aim);
            for h in [0.003, 0.01, 0.02, 0.04] {
                let row = c.top_row(h, cap_radius(a, h));
                let back = c
                    .height_from_top_row(row, a, 2.0 * a, |h| cap_radius(a, h))
                    .unwrap();
                assert!((back - h).abs() < 1e-12, "{back} vs {h}");
            }
        }
    }

    /// The pole's radius back from the outline's curvature at its top: the
    /// image of a sphere's tangent circle (its points projected), a
    /// parabola fitted to those within 2 px of the top's column.
    #[test]
    fn the_pole_radius_comes_back_from_the_outline_curvature() {
        for (d, up, aim) in [(0.25, 0.0, 0.02), (0.45, 4.0, 0.0), (1.0, 5.0, 0.01)] {
            let c = cam(d, up, aim);
            for (h, r) in [(0.01, 0.08), (0.02, 0.045), (0.035, 0.04)] {
                // The tangent circle: in the plane normal to the camera's
                // direction, `r^2 / l` from the centre towards it, of radius
                // `r sqrt(l^2 - r^2) / l`.
                let centre = [0.0, 0.0, h - r];
                let cam_pt = [0.0, -c.distance_m, c.height_m];
                let v: Vec<f64> = (0..3).map(|i| cam_pt[i] - centre[i]).collect();
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let n = [v[0] / l, v[1] / l, v[2] / l];
                let e1 = [1.0, 0.0, 0.0];
                let e2 = [
                    n[1] * e1[2] - n[2] * e1[1],
                    n[2] * e1[0] - n[0] * e1[2],
                    n[0] * e1[1] - n[1] * e1[0],
                ];
                let (off, rad) = (r * r / l, r * (l * l - r * r).sqrt() / l);
                let pts: Vec<[f64; 2]> = (0..200_000)
                    .map(|i| {
                        let t = std::f64::consts::TAU * i as f64 / 200_000.0;
                        let p: Vec<f64> = (0..3)
                            .map(|k| {
                                centre[k] + off * n[k] + rad * (t.cos() * e1[k] + t.sin() * e2[k])
                            })
                            .collect();
                        c.project([p[0], p[1], p[2]])
                    })
                    .collect();
                let top = pts.iter().fold(
                    [0.0, f64::INFINITY],
                    |b, p| if p[1] < b[1] { *p } else { b },
                );
                // Least squares y - y0 = k (x - x0)^2 over the points near the top.
                let (mut sxx, mut sxy) = (0.0, 0.0);
                for p in pts
                    .iter()
                    .filter(|p| (p[0] - top[0]).abs() < 2.0 && p[1] < top[1] + 1.0)
                {
                    let q = (p[0] - top[0]).powi(2);
                    sxx += q * q;
                    sxy += q * (p[1] - top[1]);
                }
                let rho = 1.0 / (2.0 * sxy / sxx);
                let (back, _) = c.pole_radius_from_outline(h, 1.1 * r, rho, 0.0);
                assert!((back / r - 1.0).abs() < 1e-4, "{d} {up}: {back} vs {r}");
            }
        }
    }

    /// The row's and the outline's errors joined through a pinhole: their
    /// covariance adds `2 (d h / d row) (d h / d k) cov(row, k)` to the
    /// height's variance, against its first-order changes with the row and
    /// with the measured curvature (central differences of the solved
    /// height), within 1 % (the pole's radius of the membrane's bounds
    /// moves with the height solved for, which the term leaves out).
    #[test]
    fn the_row_and_the_outline_of_one_fit_join_their_errors() {
        use crate::track::PoleMeasure;
        let a = 0.0375;
        for (d, up, aim) in [(0.25, 0.0, 0.02), (0.45, 4.0, 0.0), (1.0, 5.0, 0.01)] {
            let c = cam(d, up, aim);
            let h = 0.015;
            let row = c.top_row(h, 1.08 * cap_radius(a, h));
            // the outline's curvature, 1/px, from the pole radius over the
            // focal length at about the distance
            let k = d / (1.08 * cap_radius(a, h) * c.focal_px);
            let (sd, ks) = (0.03, 0.02 * k);
            let cov = -0.6 * sd * ks;
            let at = |row: f64, k: f64, cov: f64| {
                c.membrane_height(row, sd, a, Some(PoleMeasure::Outline(k, ks, cov)))
                    .unwrap()
            };
            let got = at(row, k, cov).1.powi(2) - at(row, k, 0.0).1.powi(2);
            let (dr, dk) = (1e-3, 1e-6 * k);
            let per_row = (at(row + dr, k, 0.0).0 - at(row - dr, k, 0.0).0) / (2.0 * dr);
            let per_k = (at(row, k + dk, 0.0).0 - at(row, k - dk, 0.0).0) / (2.0 * dk);
            let cross = 2.0 * per_row * per_k * cov;
            assert!(cross > 0.0, "{d} m {up} deg: {cross}");
            assert!(
                (got / cross - 1.0).abs() < 0.01,
                "{d} m {up} deg: {got} against {cross}"
            );
        }
    }

    /// The tangent-point width against 2 million points of the circle.
    #[test]
    fn the_opening_width_is_the_widest_projected_point_of_the_circle() {
        let a = 0.0375;
        for (d, up, aim) in [(0.25, 0.0, 0.0), (0.45, 4.0, 0.02), (1.0, 5.0, 0.01)] {
            let c = cam(d, up, aim);
            let mut best: f64 = 0.0;
            for i in 0..2_000_000 {
                let az = std::f64::consts::TAU * i as f64 / 2_000_000.0;
                let x = c.project([a * az.sin(), a * az.cos(), 0.0])[0] - c.principal_px[0];
                best = best.max(x.abs());
            }
            let closed = c.opening_half_width_px(a);
            assert!((closed - best).abs() < 1e-6, "{closed} vs {best}");
        }
        // a level camera: 1 / sqrt(1 - a^2 / D^2)
        let c = Pinhole::aimed(0.45, 0.0, 0.0, 3000.0, [640.0, 480.0]);
        let k = 1.0 / (1.0 - (a / 0.45_f64).powi(2)).sqrt();
        assert!((c.opening_scale_factor(a) - k).abs() < 1e-12);
    }

    /// `from_view` finds the camera back from its centre row, scale and
    /// elevation (the focal length unknown).
    #[test]
    fn the_camera_comes_back_from_the_view_of_the_ring_centre() {
        for (d, up, aim) in [(0.25, 0.0, 0.02), (0.45, 4.0, 0.0), (1.0, 5.0, 0.04)] {
            let c = cam(d, up, aim);
            let v0 = c.project([0.0, 0.0, 0.0])[1];
            let e = (c.height_m / c.distance_m).atan();
            let back = Pinhole::from_view(d, e, v0, c.centre_scale(), None, c.principal_px);
            assert!(
                (back.focal_px - c.focal_px).abs() < 1e-6 * c.focal_px,
                "{back:?}"
            );
            assert!((back.pitch_rad - c.pitch_rad).abs() < 1e-9);
            assert!((back.height_m - c.height_m).abs() < 1e-12);
        }
    }
}
