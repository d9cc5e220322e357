//! The membrane equations of a clamped disc, their start off the axis, and
//! one shot from the pole to the clamp.
//!
//! Dimensionless radius `x = r / a` in `(0, 1]`, load `pi = p a / t` (Pa).
//! State `y = [l1 - 1, l2 - 1, psi, d]` with `d = depth below the pole / a`.
//! With the nominal stresses `P_i(l1, l2)` and `P_ij = dP_i/dl_j` (see
//! [`super::law`]):
//!
//! ```text
//! l2'  = (l1 cos psi - l2) / x
//! l1'  = (P2 cos psi - P1 - x P12 l2') / (x P11)          from d(x P1)/dx = P2 cos psi
//! psi' = (pi l1 l2 - P2 sin psi / x) / P1
//! d'   = l1 sin psi
//! ```
//!
//! Series at the pole (`l1 = l0 + A x^2`, `l2 = l0 + B x^2`,
//! `psi = k x + C x^3`, `d = l0 k x^2 / 2 + D x^4`), with `s = P1(l0, l0)`:
//!
//! ```text
//! k = pi l0^2 / (2 s)
//! (3 P11 - P21) A + (3 P12 - P22) B = -s k^2 / 2
//! A - 3 B = l0 k^2 / 2
//! 4 s C = pi l0 (A + B) + s k^3 / 6 - k (s1 + s2),  s1 = P11 A + P12 B,  s2 = P21 A + P22 B
//! D = (l0 C - l0 k^3 / 6 + A k) / 4
//! ```
//!
//! Near the pole the equations have a regular singular point whose other
//! solutions decay like `x^-2` (the difference `l1 - l2`) and `x^-1` (`psi`),
//! so the truncation error of the start is damped, not amplified; the start
//! radius `x0 = 1e-3 min(1, 1/k)` leaves a start error of order
//! `(k x0)^4 ~ 1e-12`.

use num_dual::DualNum;

use super::law::{Law, Stress};
use super::ode::{self, Settings};

/// Shots that fold the meridian back (`l2` below this) are over-curved; the
/// run is cut there instead of being followed into the axis.
const L2_FLOOR: f64 = 0.5;

/// The outcome of one shot.
#[derive(Debug, Clone, Copy)]
pub struct Shot {
    /// Whether the clamp was reached.
    pub complete: bool,
    /// Where the run ended: the share of the reference arc from the pole
    /// to the clamp.
    pub x_end: f64,
    /// State there.
    pub y: [f64; 4],
    /// RK steps (accepted + rejected).
    pub steps: usize,
}

impl Shot {
    /// Apex height over the radius, `h / a`.
    pub fn height(&self) -> f64 {
        self.y[3]
    }

    /// Scaled clamp residual `(l2(a) - 1) / (l0 - 1)`: `1` for a flat shot,
    /// `0` at a solution, negative when over-curved. A shot that stopped short
    /// of the clamp is scored below any shot that reached it.
    pub fn residual(&self, l0: f64) -> f64 {
        let d = l0 - 1.0;
        if self.complete {
            self.y[1] / d
        } else {
            (self.y[1].min(0.0) - (1.0 - self.x_end) - 1.0) / d
        }
    }
}

/// One point of the profile, dimensionless.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    pub x: f64,
    pub l1: f64,
    pub l2: f64,
    /// Meridian angle (read by the equilibrium test).
    #[cfg_attr(not(test), allow(dead_code))]
    pub psi: f64,
    pub d: f64,
}

/// The stress-free reference surface: the flat disc, or a spherical cap of
/// height `h0` over the clamp (a slack membrane). Dimensionless: the
/// reference arc length `xi` from the pole runs to `end`, the reference
/// radius is `rho0(xi) = sin(c xi) / c` with `c = a / R0` the cap's
/// curvature (`rho0 = xi`, `end = 1` for the flat disc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    /// `a / R0`, 0 for the flat disc.
    pub curvature: f64,
    /// Arc length from the pole to the clamp over `a`.
    pub end: f64,
}

impl Reference {
    /// The flat disc.
    pub const FLAT: Reference = Reference {
        curvature: 0.0,
        end: 1.0,
    };

    /// The spherical cap of height `h0_over_a` (the flat disc at 0).
    pub fn cap(h0_over_a: f64) -> Reference {
        if h0_over_a <= 0.0 {
            return Reference::FLAT;
        }
        // Dimensionless: the cap over a rim of radius 1.
        let r0 = crate::mechanics::cap_radius(1.0, h0_over_a);
        Reference {
            curvature: 1.0 / r0,
            end: r0 * crate::mechanics::cap_half_angle(1.0, h0_over_a),
        }
    }

    /// The reference of a specimen (its `prebulge_height_m`).
    pub fn of(specimen: &crate::experiment::Specimen) -> Reference {
        Reference::cap(specimen.prebulge_height_m / specimen.radius_m)
    }

    /// `rho0(xi)` and its slope.
    #[inline]
    pub fn radius(&self, xi: f64) -> (f64, f64) {
        if self.curvature == 0.0 {
            (xi, 1.0)
        } else {
            let (s, c) = (self.curvature * xi).sin_cos();
            (s / self.curvature, c)
        }
    }

    /// Height of the reference surface above the clamp plane at `xi`, over `a`.
    pub fn height(&self, xi: f64) -> f64 {
        if self.curvature == 0.0 {
            0.0
        } else {
            let c = self.curvature;
            ((c * xi).cos() - (c * self.end).cos()) / c
        }
    }
}

/// A material on a disc.
#[derive(Debug, Clone)]
pub struct Membrane<'a> {
    pub law: Law<'a>,
    pub max_steps: usize,
    /// The stress-free reference surface.
    pub reference: Reference,
}

/// Pole expansion coefficients.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Series<T = f64> {
    l0: T,
    pub(crate) k: T,
    a: T,
    b: T,
    c: T,
    d: T,
}

impl<T: DualNum<f64> + Copy> Series<T> {
    pub(crate) fn at(&self, x: f64) -> [T; 4] {
        let x2 = x * x;
        [
            self.l0 - 1.0 + self.a * x2,
            self.l0 - 1.0 + self.b * x2,
            (self.k + self.c * x2) * x,
            (self.l0 * self.k * 0.5 + self.d * x2) * x2,
        ]
    }
}

impl Membrane<'_> {
    #[inline]
    fn rhs(&self, pi: f64, x: f64, y: &[f64; 4]) -> Option<[f64; 4]> {
        self.rhs_with(self.law.params(), pi, x, y)
    }

    /// The right-hand side with the law's parameters `th`, in any dual
    /// number type (the plain solve is `f64`; the sensitivities carry
    /// derivatives with respect to the pole stretch and the parameters).
    #[inline]
    pub(crate) fn rhs_with<T: DualNum<f64> + Copy>(
        &self,
        th: &[T],
        pi: f64,
        x: f64,
        y: &[T; 4],
    ) -> Option<[T; 4]> {
        let (l1, l2, psi) = (y[0] + 1.0, y[1] + 1.0, y[2]);
        let Stress { p, dp } = self.law.stress_with(th, l1, l2)?;
        if !(p[0].re() > 0.0 && dp[0][0].re() > 0.0) {
            // No meridional tension or no meridional stiffness: wrinkling or
            // loss of ellipticity; outside the membrane's domain.
            return None;
        }
        let (s, c) = psi.sin_cos();
        // d(rho0 l2)/dxi = l1 cos psi, d(rho0 P1)/dxi = P2 cos psi.
        let (r, dr) = self.reference.radius(x);
        let dl2 = (l1 * c - l2 * dr) / r;
        let dl1 = (p[1] * c - p[0] * dr - dp[0][1] * dl2 * r) / (dp[0][0] * r);
        let dpsi = (l1 * l2 * pi - p[1] * s / r) / p[0];
        let dd = l1 * s;
        Some([dl1, dl2, dpsi, dd])
    }

    fn series(&self, l0: f64, pi: f64) -> Option<Series> {
        self.series_with(self.law.params(), l0, pi)
    }

    /// The pole expansion with the law's parameters `th` (see
    /// [`Membrane::rhs_with`]).
    pub(crate) fn series_with<T: DualNum<f64> + Copy>(
        &self,
        th: &[T],
        l0: T,
        pi: f64,
    ) -> Option<Series<T>> {
        let Stress { p, dp } = self.law.stress_with(th, l0, l0)?;
        let s = p[0];
        if s.re().is_nan() || s.re() <= 0.0 {
            return None;
        }
        let k = l0 * l0 * pi / (s * 2.0);
        // The reference's curvature c enters through rho0 = xi - c^2 xi^3 / 6:
        // [3P11 - P21, 3P12 - P22; 1, -3] [A; B] = [-s q/2; l0 q/2], q = k^2 - c^2
        let c2 = self.reference.curvature * self.reference.curvature;
        let q = k * k - c2;
        let (m11, m12, m21, m22) = (
            dp[0][0] * 3.0 - dp[1][0],
            dp[0][1] * 3.0 - dp[1][1],
            1.0,
            -3.0,
        );
        let (r1, r2) = (-s * q * 0.5, l0 * q * 0.5);
        let det = m11 * m22 - m12 * m21;
        if det.re() == 0.0 || !det.re().is_finite() {
            return None;
        }
        let a = (r1 * m22 - m12 * r2) / det;
        let b = (m11 * r2 - r1 * m21) / det;
        let s1 = dp[0][0] * a + dp[0][1] * b;
        let s2 = dp[1][0] * a + dp[1][1] * b;
        let c = (l0 * (a + b) * pi + s * k * k * k / 6.0 - s * k * c2 / 6.0 - k * (s1 + s2))
            / (s * 4.0);
        let d = (l0 * c - l0 * k * k * k / 6.0 + a * k) / 4.0;
        Some(Series { l0, k, a, b, c, d })
    }

    /// Integrates from the pole to the clamp for pole stretch `l0 > 1` and
    /// load `pi = p a / t`. `outputs` (increasing, in `(0, 1]`, shares of the
    /// reference arc from the pole to the clamp) are recorded into `profile`
    /// when given, each with its reference radius as `x`.
    pub fn shoot(
        &self,
        l0: f64,
        pi: f64,
        rtol: f64,
        outputs: &[f64],
        mut profile: Option<&mut Vec<Point>>,
    ) -> Shot {
        let failed = Shot {
            complete: false,
            x_end: 0.0,
            y: [l0 - 1.0, l0 - 1.0, 0.0, 0.0],
            steps: 0,
        };
        let Some(ser) = self.series(l0, pi) else {
            return failed;
        };
        let x0 = 1e-3 * (1.0f64).min(1.0 / ser.k.max(1e-300));
        let y0 = ser.at(x0);
        let delta = l0 - 1.0;
        let ps = ser.k.max(1e-300);
        let settings = Settings {
            rtol,
            atol: [rtol * delta, rtol * delta, rtol * ps, rtol * ps],
            h0: x0,
            h_min: 1e-13,
            max_steps: self.max_steps,
            norm_dims: 4,
        };
        let end = self.reference.end;
        let push = |profile: &mut Option<&mut Vec<Point>>, xi: f64, y: &[f64; 4]| {
            if let Some(v) = profile.as_deref_mut() {
                v.push(Point {
                    x: self.reference.radius(xi).0,
                    l1: 1.0 + y[0],
                    l2: 1.0 + y[1],
                    psi: y[2],
                    d: y[3],
                });
            }
        };
        // Outputs inside the start radius come from the series.
        let outputs: Vec<f64> = outputs.iter().map(|f| f * end).collect();
        let split = outputs.partition_point(|&x| x <= x0);
        for &x in &outputs[..split] {
            let y = if x == 0.0 {
                [delta, delta, 0.0, 0.0]
            } else {
                ser.at(x)
            };
            push(&mut profile, x, &y);
        }
        let out = ode::integrate(
            |x, y| self.rhs(pi, x, y),
            x0,
            y0,
            end,
            &settings,
            |_, y| 1.0 + y[1] < L2_FLOOR || y[2].abs() > 2.0 * std::f64::consts::PI,
            &outputs[split..],
            |x, y| push(&mut profile, x, y),
        );
        Shot {
            complete: out.stopped.is_none() && out.x >= end,
            x_end: out.x / end,
            y: out.y,
            steps: out.accepted + out.rejected,
        }
    }

    /// Whether the last run ended for lack of steps (reported, not scored).
    pub fn out_of_steps(&self, shot: &Shot) -> bool {
        !shot.complete && shot.steps >= self.max_steps
    }

    /// Pressure estimate for a pole stretch: a spherical cap of uniform
    /// equibiaxial stretch `l0` and the same arc length, `sin th / th = 1/l0`,
    /// `pi = 2 P1(l0, l0) sin th / l0`.
    pub fn cap_estimate(&self, l0: f64) -> Option<f64> {
        let s = self.law.stress(l0, l0)?.p[0];
        let target = 1.0 / l0;
        let mut th = (6.0 * (l0 - 1.0)).sqrt().min(3.0);
        for _ in 0..50 {
            let f = th.sin() / th - target;
            let df = (th * th.cos() - th.sin()) / (th * th);
            let step = f / df;
            th = (th - step).clamp(1e-8, std::f64::consts::PI - 1e-3);
            if step.abs() < 1e-12 {
                break;
            }
        }
        let pi = 2.0 * s * th.sin() / l0;
        (pi.is_finite() && pi > 0.0).then_some(pi)
    }

    /// Reason a run stopped, for messages.
    pub fn describe(shot: &Shot) -> String {
        format!(
            "the integration stopped at r/a = {:.4} (l1 = {:.4}, l2 = {:.4}, psi = {:.4} rad)",
            shot.x_end,
            1.0 + shot.y[0],
            1.0 + shot.y[1],
            shot.y[2]
        )
    }
}
