//! The spherical cap: its radius, half-angle and meridian arc length, and the
//! strain and pole stress they give, with the series that keep the flat limit exact.

/// Below this `x = H/a`, `g(x) - 1` and `g'(x)` are summed from their series.
const SERIES_LIMIT: f64 = 0.5;
/// Series terms are added until they fall below this share of the sum.
const SERIES_TOL: f64 = 1e-18;
/// At `x < 1/2` the series needs at most ~30 terms; this is a safe cap.
const SERIES_MAX_TERMS: usize = 100;

/// Coefficient `c_n = (-1)^(n-1) 2 / (4 n^2 - 1)` of `x^(2n)` in `g(x) - 1`.
pub(super) fn coeff(n: usize) -> f64 {
    let nf = n as f64;
    let c = 2.0 / (4.0 * nf * nf - 1.0);
    if n % 2 == 1 { c } else { -c }
}

/// Spherical-cap radius `R = (a^2 + H^2) / (2H)` (eqs 19, 20), m; infinite at
/// `H = 0`.
pub fn cap_radius(a: f64, h: f64) -> f64 {
    let x = h / a;
    0.5 * a * (x + 1.0 / x)
}

/// Half-angle of the cap seen from its centre, `theta = 2 atan(H/a)`, rad. Valid
/// on every branch (`theta > pi/2` past the hemisphere), unlike eqs 21-22's
/// `asin(2aH / (a^2 + H^2))`, which returns `pi - theta` when `H > a`.
pub fn cap_half_angle(a: f64, h: f64) -> f64 {
    2.0 * (h / a).atan()
}

/// `g(x) - 1`, the relative excess of the meridian arc over the diameter:
/// `s = 2a (1 + arc_excess(H/a))`. Series below `x = 1/2`, closed form above.
pub fn arc_excess(x: f64) -> f64 {
    if x < SERIES_LIMIT {
        let y = x * x;
        let mut sum = 0.0;
        let mut yn = 1.0;
        for n in 1..=SERIES_MAX_TERMS {
            yn *= y;
            let term = coeff(n) * yn;
            sum += term;
            if term.abs() <= SERIES_TOL * sum.abs() {
                break;
            }
        }
        sum
    } else {
        (x + 1.0 / x) * x.atan() - 1.0
    }
}

/// `g(x) = s / (2a) = (x + 1/x) atan x`, with `g(0) = 1`.
pub(super) fn arc_ratio(x: f64) -> f64 {
    1.0 + arc_excess(x)
}

/// `g'(x)`, the derivative of `s / (2a)` with respect to `x = H/a`.
pub(super) fn arc_ratio_slope(x: f64) -> f64 {
    if x < SERIES_LIMIT {
        // g'(x) = x * sum 2 n c_n y^(n-1)
        let y = x * x;
        let mut sum = 0.0;
        let mut yn1 = 1.0;
        for n in 1..=SERIES_MAX_TERMS {
            let term = 2.0 * n as f64 * coeff(n) * yn1;
            sum += term;
            if term.abs() <= SERIES_TOL * sum.abs() {
                break;
            }
            yn1 *= y;
        }
        x * sum
    } else {
        (1.0 - 1.0 / (x * x)) * x.atan() + 1.0 / x
    }
}

/// `g(x1) - g(x0)` for `0 <= x0 <= x1`, with `dx = x1 - x0` supplied by the
/// caller from the unrounded difference of the heights.
pub(super) fn arc_ratio_difference(x0: f64, x1: f64, dx: f64) -> f64 {
    if x1 < SERIES_LIMIT {
        // sum c_n (y1^n - y0^n) = (y1 - y0) sum c_n D_n,
        // D_n = sum_{k<n} y1^k y0^(n-1-k), D_1 = 1, D_{n+1} = y1 D_n + y0^n.
        let (y0, y1) = (x0 * x0, x1 * x1);
        let dy = dx * (x1 + x0);
        let mut sum = 0.0;
        let mut d = 1.0;
        let mut y0n = 1.0;
        for n in 1..=SERIES_MAX_TERMS {
            let term = coeff(n) * d;
            sum += term;
            if term.abs() <= SERIES_TOL * sum.abs() {
                break;
            }
            y0n *= y0;
            d = y1 * d + y0n;
        }
        dy * sum
    } else {
        arc_excess(x1) - arc_excess(x0)
    }
}

/// Meridian arc length of the cap `s = 2 R theta` (eqs 21, 22 with atan), m;
/// `s = 2a` at `H = 0`, accurate to rounding for every `H >= 0`.
pub fn arc_length(a: f64, h: f64) -> f64 {
    2.0 * a * arc_ratio(h / a)
}

/// Engineering strain `lambda - 1 = s1/s0 - 1` between the pre-bulge height
/// `h0` and the height `h >= h0` (eqs 21-24, sign corrected), computed without
/// cancellation.
pub fn engineering_strain(a: f64, h0: f64, h: f64) -> f64 {
    let (x0, x1) = (h0 / a, h / a);
    arc_ratio_difference(x0, x1, (h - h0) / a) / arc_ratio(x0)
}

/// Stretch `lambda = s1 / s0` (eq 23): the mean meridional stretch.
pub fn stretch(a: f64, h0: f64, h: f64) -> f64 {
    1.0 + engineering_strain(a, h0, h)
}

/// Pole stress `sigma = p R / (2t)` (eq 18), Pa; zero when `p = 0`.
pub fn pole_stress(p: f64, radius: f64, t: f64) -> f64 {
    if p == 0.0 {
        0.0
    } else {
        p * radius / (2.0 * t)
    }
}
