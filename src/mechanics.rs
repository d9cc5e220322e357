//! Heights -> stress and strain (Tudruj et al. (2023), eqs 18-25), corrected where the
//! paper is wrong.
//!
//! A clamped disc of free radius `a` and initial thickness `t` bulges under the
//! gauge pressure `p` into a bubble whose apex stands at height `H` above the
//! clamp plane (`H = h + h0`, the paper's rise `h` plus the pre-bulge height
//! `h0`). The bubble is taken to be a spherical cap. With `x = H / a`:
//!
//! | quantity | formula | Tudruj et al. (2023) |
//! |---|---|---|
//! | cap radius | $R = (a^2 + H^2) / (2H) = \tfrac a2 (x + 1/x)$ | eqs 19, 20 |
//! | cap half-angle | $\theta = 2 \arctan(H/a)$ | eqs 21, 22 (corrected) |
//! | meridian arc length | $s = 2R\theta = 2a\, g(x)$, $g(x) = (x + 1/x)\arctan x$ | eqs 21, 22 |
//! | stretch | $\lambda = s_1 / s_0 = g(x_1) / g(x_0)$ | eq 23 |
//! | strain | $\varepsilon = \lambda - 1$ (engineering) or $\ln\lambda$ (log) | eq 24 (corrected) |
//! | pole stress | $\sigma = pR/(2t)$ | eq 18 |
//! | true stress | $\lambda\sigma$ (`paper`) or $\lambda^2\sigma$ (`incompressible`) | eq 25 |
//! | secant modulus | $(1-\nu) S/\varepsilon$ (`biaxial`) or $S/\varepsilon$ (`uniaxial`) | section 7 |
//!
//! where `x0 = h0/a` (pre-bulge, `s0`) and `x1 = H/a` (loaded, `s1`), and `S`
//! is the stress chosen by [`ModulusStress`].
//!
//! ## Where the paper is wrong, and what is done here
//!
//! * **The asin branch (eqs 21, 22).** The paper writes
//!   $\theta = \arcsin(2aH/(a^2+H^2))$. Since $\sin\theta = a/R$, this is right
//!   only up to the hemisphere (`H <= a`); past it `asin` returns `pi - theta`
//!   and the arc length *falls* as the bubble grows (at `H = 2a` it gives
//!   `s = 2.318 a`, shorter than the hemisphere's `pi a`, instead of `5.536 a`).
//!   `tan(theta/2) = H/a` holds on every branch, so [`cap_half_angle`] uses
//!   `theta = 2 atan(H/a)`.
//! * **The flat limit.** `s = (a^2+H^2)/H * theta` is `0/0` at `H = 0` and
//!   loses digits as `H -> 0`, and `lambda - 1` cancels catastrophically. Here
//!   `g(x) - 1` ([`arc_excess`]) is summed from its series for `x < 1/2`:
//!   $g(x) = (1 + x^2)\,\arctan(x)/x = 1 + \sum_{n\ge1} (-1)^{n-1}\frac{2x^{2n}}{4n^2-1}
//!   = 1 + \tfrac23 x^2 - \tfrac2{15}x^4 + \tfrac2{35}x^6 - \dots$
//!   (multiply $\arctan(x)/x = \sum (-1)^n x^{2n}/(2n+1)$ by $1 + x^2$; the
//!   coefficient of $x^{2n}$ is $(-1)^n[1/(2n+1) - 1/(2n-1)]$), so `s -> 2a`
//!   and the strain `(2/3) x^2` keeps full relative precision down to
//!   `H = 1e-150 a`.
//! * **The pre-bulged case.** With `h0 > 0` the strain is
//!   `(g(x1) - g(x0)) / g(x0)`; in the series range the difference is summed as
//!   `(x1^2 - x0^2) * sum c_n (x1^{2n} - x0^{2n}) / (x1^2 - x0^2)` with the
//!   divided differences built from positive terms and `x1 - x0 = (H - h0)/a`
//!   taken from the inputs, so no digits are lost when `H` is close to `h0`.
//!   Above `x = 1/2` the direct difference loses at most a factor
//!   `g / (x g') <= 4` over the problem's own conditioning.
//! * **Eq 24's sign.** `eps = 1 - lambda` is negative in tension; the strain
//!   here is `lambda - 1` (or `ln lambda`).
//! * **Eq 25's thickness.** `lambda * sigma` is the stress for a thickness
//!   `t / lambda`. An incompressible membrane stretched equibiaxially by
//!   `lambda` thins to `t / lambda^2`, so its Cauchy stress is
//!   `lambda^2 p R / (2t)` ([`TrueStress::Incompressible`]). The paper's form
//!   is kept as the default so that the paper's procedure can be reproduced.
//!   Read differently, `lambda * sigma` needs no thickness assumption at all:
//!   it is the nominal (first Piola-Kirchhoff) stress, the tension
//!   `lambda pR/2` per unit *reference* length over the initial thickness,
//!   which is what feeds the secant modulus by default ([`ModulusStress`]).
//! * **Mean versus pole stretch.** `lambda = s1/s0` is the mean meridional
//!   stretch; the pole, where eq 18 gives the stress, stretches more (for a
//!   neo-Hookean membrane at `h/a = 0.531`: mean 1.178, pole 1.20). Stress and
//!   strain are therefore not measured at the same material point; this is a
//!   property of the method, documented rather than corrected.
//!
//! ## Uncertainty
//!
//! Given a standard deviation `sigma_H` of the height, every derived quantity
//! `q(H)` gets `q_std = |dq/dH| sigma_H` (first-order propagation; pressure,
//! `a`, `t`, `nu` and `h0` are taken as exact). The derivatives are analytic:
//! `dR/dH = (1 - 1/x^2)/2`, `ds/dH = 2 g'(x)` with
//! `g'(x) = (1 - 1/x^2) atan x + 1/x` (series below `x = 1/2`), `dlambda/dH =
//! g'(x1) / (a g(x0))`, and the product and quotient rules for the rest.

/// Which strain measure is written to `strain` and feeds the modulus: the
/// same measure the material's modulus law is a function of.
pub use crate::material::StrainMeasure;

use serde::{Deserialize, Serialize};

/// Which "true stress" is written to `true_stress_pa`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum TrueStress {
    /// `lambda * p R / (2t)`: Tudruj et al. (2023) eq 25 (thickness `t / lambda`).
    #[default]
    Paper,
    /// `lambda^2 * p R / (2t)`: incompressible equibiaxial thinning `t / lambda^2`.
    Incompressible,
}

/// Which secant modulus is written to `secant_modulus_pa`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Modulus {
    /// `(1 - nu) S / eps`: equibiaxial plane stress ("the 2D case" of section 7).
    #[default]
    Biaxial,
    /// `S / eps`: as if the pole were in uniaxial tension.
    Uniaxial,
}

/// Which stress `S` feeds the secant modulus.
///
/// The membrane tension at the pole is `N = pR/2` per unit *current* length.
/// Per unit *reference* length it is `lambda N` (a reference width `w0` is
/// now `lambda w0` wide), so the nominal (first Piola-Kirchhoff) stress is
/// `lambda p R / (2t)`: numerically eq 25, whatever the thickness does. The
/// mass-spring models carry their forces on the reference geometry with
/// stiffnesses proportional to `E t` (eqs 1, 10-17), i.e. they realise
/// `lambda N = E t eps / (1 - nu)` under equibiaxial strain; the modulus that
/// reproduces the measured tension is therefore `(1 - nu) lambda sigma / eps`,
/// the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ModulusStress {
    /// Nominal (first Piola-Kirchhoff) stress `lambda p R / (2t)`, force per
    /// reference area; equal to eq 25's value.
    #[default]
    Nominal,
    /// The `stress_pa` column: `sigma = p R / (2t)` of eq 18 (tension per
    /// current length over the initial thickness).
    Stress,
    /// The true stress chosen by `--true-stress` (`paper` or `incompressible`).
    True,
}

/// Kebab-case names of the conventions, as the command line and the settings
/// files spell them.
macro_rules! names {
    ($t:ty { $($v:ident => $n:literal),+ $(,)? }) => {
        impl $t {
            /// The name as settings files and the command line spell it.
            pub fn name(self) -> &'static str {
                match self { $(<$t>::$v => $n),+ }
            }
        }
    };
}

names!(TrueStress { Paper => "paper", Incompressible => "incompressible" });
names!(Modulus { Biaxial => "biaxial", Uniaxial => "uniaxial" });
names!(ModulusStress { Nominal => "nominal", Stress => "stress", True => "true" });

impl Modulus {
    /// `k` in `E = k S / eps`: `1 - nu` (biaxial) or 1 (uniaxial).
    pub fn factor(self, poisson: f64) -> f64 {
        match self {
            Modulus::Biaxial => 1.0 - poisson,
            Modulus::Uniaxial => 1.0,
        }
    }
}

/// The choices of the stress stage; `Default` is what `bulge stress` uses
/// without flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Options {
    /// Strain measure (default engineering).
    pub strain: StrainMeasure,
    /// True-stress convention (default `paper`, eq 25).
    pub true_stress: TrueStress,
    /// Secant modulus (default `biaxial`).
    pub modulus: Modulus,
    /// Stress feeding the modulus (default the nominal stress `lambda sigma`).
    pub modulus_stress: ModulusStress,
}

/// The disc: the subset of [`crate::experiment::Specimen`] used here.
pub use crate::experiment::Specimen;

/// One measured point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Gauge pressure, Pa (>= 0).
    pub pressure_pa: f64,
    /// Apex height above the clamp plane `H = h + h0`, m (>= h0).
    pub height_m: f64,
    /// Standard deviation of the height, m (>= 0), when known.
    pub height_std_m: Option<f64>,
}

/// Derived quantities of one point (or their standard deviations). `None`
/// where the value is not a finite number: `radius_m` at `H = 0` (a flat disc
/// has an infinite radius) and `secant_modulus_pa` where the strain is zero.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Derived {
    /// Spherical-cap radius `R`, m.
    pub radius_m: Option<f64>,
    /// Meridian arc length `s1`, m.
    pub arc_length_m: Option<f64>,
    /// Stretch `lambda = s1 / s0`.
    pub stretch: Option<f64>,
    /// Strain (engineering or log).
    pub strain: Option<f64>,
    /// Pole stress `sigma = p R / (2t)`, Pa.
    pub stress_pa: Option<f64>,
    /// True stress (`paper` or `incompressible`), Pa.
    pub true_stress_pa: Option<f64>,
    /// Secant modulus, Pa.
    pub secant_modulus_pa: Option<f64>,
}

impl Derived {
    /// The values in output-column order.
    pub fn to_array(&self) -> [Option<f64>; 7] {
        [
            self.radius_m,
            self.arc_length_m,
            self.stretch,
            self.strain,
            self.stress_pa,
            self.true_stress_pa,
            self.secant_modulus_pa,
        ]
    }
}

/// Output column names of [`Derived`], in order.
pub const DERIVED_COLUMNS: [&str; 7] = [
    "radius_m",
    "arc_length_m",
    "stretch",
    "strain",
    "stress_pa",
    "true_stress_pa",
    "secant_modulus_pa",
];

/// Output column names of the standard deviations, in the order of
/// [`DERIVED_COLUMNS`] (unit last, as in `height_std_m`).
pub const STD_COLUMNS: [&str; 7] = [
    "radius_std_m",
    "arc_length_std_m",
    "stretch_std",
    "strain_std",
    "stress_std_pa",
    "true_stress_std_pa",
    "secant_modulus_std_pa",
];

/// The result for one point: values and, when a height uncertainty was
/// given, their standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// The derived values.
    pub value: Derived,
    /// Standard deviations (first-order propagation of `height_std_m`).
    pub std: Option<Derived>,
}

/// What is wrong with one point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PointError {
    /// A NaN or infinite input.
    #[error(
        "{column} = {value} is not a finite number: replace it with a measured value or drop the row"
    )]
    NotFinite {
        /// Input column name.
        column: &'static str,
        /// The value.
        value: f64,
    },
    /// Negative gauge pressure.
    #[error(
        "pressure_pa = {pressure_pa} is negative: bulge expects the gauge pressure that inflates the bubble (>= 0); fix the sign or the zero offset of the pressure log"
    )]
    NegativePressure {
        /// The pressure, Pa.
        pressure_pa: f64,
    },
    /// Height below the pre-bulge height.
    #[error(
        "height_m = {height_m} is below the pre-bulge height h0 = {prebulge_height_m} m: height_m is the apex height above the clamp plane (the paper's h + h0); add h0 to heights measured from the pre-bulged apex, or correct prebulge_height_m"
    )]
    BelowPrebulge {
        /// The height, m.
        height_m: f64,
        /// The pre-bulge height, m.
        prebulge_height_m: f64,
    },
    /// A flat disc under pressure (infinite radius, infinite stress).
    #[error(
        "height_m = 0 with pressure_pa = {pressure_pa} > 0: a flat membrane cannot carry pressure (its cap radius and stress are infinite); check the height zero (clamp plane) or drop the row"
    )]
    FlatUnderPressure {
        /// The pressure, Pa.
        pressure_pa: f64,
    },
    /// Negative height uncertainty.
    #[error("height_std_m = {value} is negative: a standard deviation is zero or positive")]
    NegativeHeightStd {
        /// The value, m.
        value: f64,
    },
}

impl PointError {
    /// The input column that holds the bad value.
    pub fn column(&self) -> &'static str {
        match self {
            PointError::NotFinite { column, .. } => column,
            PointError::NegativePressure { .. } | PointError::FlatUnderPressure { .. } => {
                "pressure_pa"
            }
            PointError::BelowPrebulge { .. } => "height_m",
            PointError::NegativeHeightStd { .. } => "height_std_m",
        }
    }
}

/// Why the stress stage refused its input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StressError {
    /// The specimen failed [`Specimen::validate`] (radius or thickness <= 0,
    /// Poisson ratio outside [0, 0.5), negative pre-bulge height).
    #[error("invalid specimen: {0}")]
    Specimen(#[from] crate::experiment::SpecimenError),
    /// One point is invalid; `index` is its 0-based position in the input.
    #[error("point {index}: {problem}")]
    Point {
        /// 0-based index of the point.
        index: usize,
        /// What is wrong.
        problem: PointError,
    },
}

/// Below this `x = H/a`, `g(x) - 1` and `g'(x)` are summed from their series.
const SERIES_LIMIT: f64 = 0.5;
/// Series terms are added until they fall below this share of the sum.
const SERIES_TOL: f64 = 1e-18;
/// At `x < 1/2` the series needs at most ~30 terms; this is a safe cap.
const SERIES_MAX_TERMS: usize = 100;

/// Coefficient `c_n = (-1)^(n-1) 2 / (4 n^2 - 1)` of `x^(2n)` in `g(x) - 1`.
fn coeff(n: usize) -> f64 {
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
fn arc_ratio(x: f64) -> f64 {
    1.0 + arc_excess(x)
}

/// `g'(x)`, the derivative of `s / (2a)` with respect to `x = H/a`.
fn arc_ratio_slope(x: f64) -> f64 {
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
fn arc_ratio_difference(x0: f64, x1: f64, dx: f64) -> f64 {
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

/// Checks one point against the specimen.
pub fn check_point(spec: &Specimen, pt: &Point) -> Result<(), PointError> {
    let finite = |column: &'static str, value: f64| {
        if value.is_finite() {
            Ok(())
        } else {
            Err(PointError::NotFinite { column, value })
        }
    };
    finite("pressure_pa", pt.pressure_pa)?;
    finite("height_m", pt.height_m)?;
    if let Some(sd) = pt.height_std_m {
        finite("height_std_m", sd)?;
        if sd < 0.0 {
            return Err(PointError::NegativeHeightStd { value: sd });
        }
    }
    if pt.pressure_pa < 0.0 {
        return Err(PointError::NegativePressure {
            pressure_pa: pt.pressure_pa,
        });
    }
    if pt.height_m < spec.prebulge_height_m {
        return Err(PointError::BelowPrebulge {
            height_m: pt.height_m,
            prebulge_height_m: spec.prebulge_height_m,
        });
    }
    if pt.height_m == 0.0 && pt.pressure_pa > 0.0 {
        return Err(PointError::FlatUnderPressure {
            pressure_pa: pt.pressure_pa,
        });
    }
    Ok(())
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Values and their derivatives with respect to `H` for one valid point.
fn evaluate(spec: &Specimen, opts: &Options, p: f64, h: f64) -> (Derived, Derived) {
    let a = spec.radius_m;
    let t = spec.thickness_m;
    let h0 = spec.prebulge_height_m;
    let (x0, x1) = (h0 / a, h / a);

    let radius = cap_radius(a, h);
    let d_radius = 0.5 * (1.0 - 1.0 / (x1 * x1));
    let s = arc_length(a, h);
    let d_s = 2.0 * arc_ratio_slope(x1);

    let g0 = arc_ratio(x0);
    let eps_eng = engineering_strain(a, h0, h);
    let lambda = 1.0 + eps_eng;
    let d_lambda = arc_ratio_slope(x1) / (a * g0);
    let (strain, d_strain) = match opts.strain {
        StrainMeasure::Engineering => (eps_eng, d_lambda),
        StrainMeasure::Log => (eps_eng.ln_1p(), d_lambda / lambda),
    };

    let sigma = pole_stress(p, radius, t);
    let d_sigma = if p == 0.0 {
        0.0
    } else {
        p / (2.0 * t) * d_radius
    };
    let (true_stress, d_true) = match opts.true_stress {
        TrueStress::Paper => (lambda * sigma, d_lambda * sigma + lambda * d_sigma),
        TrueStress::Incompressible => (
            lambda * lambda * sigma,
            2.0 * lambda * d_lambda * sigma + lambda * lambda * d_sigma,
        ),
    };
    let (sm, d_sm) = match opts.modulus_stress {
        ModulusStress::Nominal => (lambda * sigma, d_lambda * sigma + lambda * d_sigma),
        ModulusStress::Stress => (sigma, d_sigma),
        ModulusStress::True => (true_stress, d_true),
    };
    let k = match opts.modulus {
        Modulus::Biaxial => 1.0 - spec.poisson,
        Modulus::Uniaxial => 1.0,
    };
    let (modulus, d_modulus) = if strain > 0.0 {
        (
            Some(k * sm / strain),
            Some(k * (d_sm / strain - sm * d_strain / (strain * strain))),
        )
    } else {
        (None, None)
    };

    let value = Derived {
        radius_m: finite(radius),
        arc_length_m: Some(s),
        stretch: Some(lambda),
        strain: Some(strain),
        stress_pa: Some(sigma),
        true_stress_pa: Some(true_stress),
        secant_modulus_pa: modulus.and_then(finite),
    };
    let slope = Derived {
        radius_m: finite(d_radius),
        arc_length_m: Some(d_s),
        stretch: Some(d_lambda),
        strain: Some(d_strain),
        stress_pa: finite(d_sigma),
        true_stress_pa: finite(d_true),
        secant_modulus_pa: d_modulus.and_then(finite),
    };
    (value, slope)
}

/// Derivatives with respect to the height `H` (per metre) of every derived
/// quantity at one point; `None` where the value or derivative is infinite.
/// Exposed so that the propagation can be checked against finite differences.
pub fn height_derivatives(spec: &Specimen, opts: &Options, p: f64, h: f64) -> Derived {
    evaluate(spec, opts, p, h).1
}

/// The stress stage: one [`Row`] per input point, or the first refused input.
pub fn stress_strain(
    spec: &Specimen,
    opts: &Options,
    points: &[Point],
) -> Result<Vec<Row>, StressError> {
    spec.validate().map_err(StressError::Specimen)?;
    points
        .iter()
        .enumerate()
        .map(|(index, pt)| {
            check_point(spec, pt).map_err(|problem| StressError::Point { index, problem })?;
            let (value, slope) = evaluate(spec, opts, pt.pressure_pa, pt.height_m);
            let std = pt.height_std_m.map(|sd| {
                let f = |v: Option<f64>, d: Option<f64>| match (v, d) {
                    (Some(_), Some(d)) => finite(d.abs() * sd),
                    _ => None,
                };
                Derived {
                    radius_m: f(value.radius_m, slope.radius_m),
                    arc_length_m: f(value.arc_length_m, slope.arc_length_m),
                    stretch: f(value.stretch, slope.stretch),
                    strain: f(value.strain, slope.strain),
                    stress_pa: f(value.stress_pa, slope.stress_pa),
                    true_stress_pa: f(value.true_stress_pa, slope.true_stress_pa),
                    secant_modulus_pa: f(value.secant_modulus_pa, slope.secant_modulus_pa),
                }
            });
            Ok(Row { value, std })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    fn spec(a: f64, t: f64, nu: f64, h0: f64) -> Specimen {
        Specimen {
            radius_m: a,
            thickness_m: t,
            poisson: nu,
            prebulge_height_m: h0,
        }
    }

    fn one(s: &Specimen, o: &Options, p: f64, h: f64, sd: Option<f64>) -> Row {
        stress_strain(
            s,
            o,
            &[Point {
                pressure_pa: p,
                height_m: h,
                height_std_m: sd,
            }],
        )
        .expect("valid point")[0]
    }

    fn rel(got: f64, want: f64) -> f64 {
        if want == 0.0 {
            got.abs()
        } else {
            ((got - want) / want).abs()
        }
    }

    fn all_options() -> Vec<Options> {
        let mut v = Vec::new();
        for strain in [StrainMeasure::Engineering, StrainMeasure::Log] {
            for true_stress in [TrueStress::Paper, TrueStress::Incompressible] {
                for modulus in [Modulus::Biaxial, Modulus::Uniaxial] {
                    for modulus_stress in [
                        ModulusStress::Nominal,
                        ModulusStress::Stress,
                        ModulusStress::True,
                    ] {
                        v.push(Options {
                            strain,
                            true_stress,
                            modulus,
                            modulus_stress,
                        });
                    }
                }
            }
        }
        v
    }

    fn parse_opts(f: &[&str]) -> Options {
        Options {
            strain: match f[6] {
                "engineering" => StrainMeasure::Engineering,
                _ => StrainMeasure::Log,
            },
            true_stress: match f[7] {
                "paper" => TrueStress::Paper,
                _ => TrueStress::Incompressible,
            },
            modulus: match f[8] {
                "biaxial" => Modulus::Biaxial,
                _ => Modulus::Uniaxial,
            },
            modulus_stress: match f[9] {
                "nominal" => ModulusStress::Nominal,
                "stress" => ModulusStress::Stress,
                _ => ModulusStress::True,
            },
        }
    }

    /// Every value and every d/dH of every option against
    /// `fixtures/stress/reference.csv`, written by the independent 60-digit
    /// script `fixtures/stress/reference.py` (acos form, numerical derivatives).
    #[test]
    fn matches_independent_reference_script() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/stress/reference.csv");
        let text = std::fs::read_to_string(path).expect("reference.csv");
        let mut worst_value = (0.0_f64, String::new());
        let mut worst_slope = (0.0_f64, String::new());
        let mut rows = 0;
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            let num = |i: usize| f[i].parse::<f64>().expect("number");
            let opt = |i: usize| (!f[i].is_empty()).then(|| num(i));
            let s = spec(num(0), num(1), num(2), num(3));
            let o = parse_opts(&f);
            let (p, h) = (num(5), num(4));
            let got = one(&s, &o, p, h, None).value.to_array();
            let slope = height_derivatives(&s, &o, p, h).to_array();
            for k in 0..7 {
                let want = opt(10 + k);
                assert_eq!(
                    got[k].is_some(),
                    want.is_some(),
                    "{} presence: {line}",
                    DERIVED_COLUMNS[k]
                );
                if let (Some(g), Some(w)) = (got[k], want) {
                    let e = rel(g, w);
                    if e > worst_value.0 {
                        worst_value = (e, format!("{} in {line}", DERIVED_COLUMNS[k]));
                    }
                }
                if let (Some(g), Some(w)) = (slope[k], opt(17 + k)) {
                    // mp.diff of the acos form: compare against the scale of
                    // the value over the height, not a derivative that vanishes
                    // (dR/dH = 0 at the hemisphere).
                    let scale = w.abs().max(got[k].unwrap_or(0.0).abs() / h * 1e-3);
                    let e = (g - w).abs() / scale;
                    if e > worst_slope.0 {
                        worst_slope = (e, format!("d{}/dH in {line}", DERIVED_COLUMNS[k]));
                    }
                }
            }
            rows += 1;
        }
        assert_eq!(rows, 14 * 24, "every case under every option");
        eprintln!(
            "largest relative error, values: {:.3e} ({})",
            worst_value.0, worst_value.1
        );
        eprintln!(
            "largest relative error, d/dH:   {:.3e} ({})",
            worst_slope.0, worst_slope.1
        );
        assert!(worst_value.0 < 1e-14, "values: {worst_value:?}");
        assert!(worst_slope.0 < 1e-12, "derivatives: {worst_slope:?}");
    }

    /// Closed forms: the hemisphere `H = a` has `R = a`, `theta = pi/2`,
    /// `s = pi a`.
    #[test]
    fn hemisphere_closed_form() {
        for a in [1.0, 0.0375, 3.0e-3] {
            assert!(rel(cap_radius(a, a), a) < 1e-15);
            assert!(rel(cap_half_angle(a, a), PI / 2.0) < 1e-15);
            assert!(rel(arc_length(a, a), PI * a) < 1e-15);
            assert!(rel(stretch(a, 0.0, a), PI / 2.0) < 1e-15);
        }
    }

    /// Past the hemisphere (`H = 2a`): `R = 1.25 a`, `theta = 2 atan 2 =
    /// acos(-3/5)`, `s = 2.5 a theta`. The paper's asin form (eqs 21-22)
    /// returns `pi - theta` there: an arc of 2.318 a, shorter than the
    /// hemisphere's pi a although the bubble is twice as high.
    #[test]
    fn past_the_hemisphere_atan_not_asin() {
        let a = 0.0375;
        let h = 2.0 * a;
        let theta = (-0.6_f64).acos();
        assert!(rel(cap_radius(a, h), 1.25 * a) < 1e-15);
        assert!(rel(cap_half_angle(a, h), theta) < 1e-15);
        assert!(rel(arc_length(a, h), 2.5 * a * theta) < 1e-15);
        let asin_theta = (2.0 * a * h / (a * a + h * h)).asin();
        assert!(rel(asin_theta, PI - theta) < 4e-15, "asin gives pi - theta");
        let paper_s = (a * a + h * h) / h * asin_theta;
        assert!(rel(paper_s, 2.5 * a * (PI - theta)) < 4e-15);
        assert!(
            paper_s < arc_length(a, a),
            "eqs 21-22: shorter than the hemisphere's arc"
        );
        assert!(arc_length(a, h) > 2.7 * a);
    }

    /// Small-H series (derived in the module doc):
    /// `s / 2a = 1 + (2/3) x^2 - (2/15) x^4 + (2/35) x^6 - (2/63) x^8 + ...`.
    /// Truncation after x^8 leaves `(2/99) x^10`, below 1e-17 relative for
    /// `x <= 1e-2`. The naive `(a^2+H^2)/H asin(...) / 2a - 1` is shown to fail.
    #[test]
    fn flat_limit_series() {
        let a = 0.0375;
        assert_eq!(arc_length(a, 0.0), 2.0 * a);
        assert_eq!(stretch(a, 0.0, 0.0), 1.0);
        for x in [1e-2, 1e-3, 1e-5, 1e-8, 1e-12, 1e-150] {
            let y = x * x;
            let series = y * (2.0 / 3.0 - y * (2.0 / 15.0 - y * (2.0 / 35.0 - y * 2.0 / 63.0)));
            let h = x * a;
            assert!(
                rel(engineering_strain(a, 0.0, h), series) < 4e-16,
                "x = {x}"
            );
            assert!(rel(arc_excess(x), series) < 4e-16, "x = {x}");
            assert!(rel(arc_length(a, h), 2.0 * a * (1.0 + series)) < 2e-16);
        }
        // The paper's form in floating point at x = 1e-8: all digits lost.
        let (x, h) = (1e-8, 1e-8 * a);
        let naive = (a * a + h * h) / h * (2.0 * a * h / (a * a + h * h)).asin() / (2.0 * a) - 1.0;
        let exact = 2.0 / 3.0 * x * x;
        assert!(rel(naive, exact) > 0.5, "naive {naive} vs {exact}");
    }

    /// A pre-bulged case by hand (a = 1, h0 = 0.1, H = 0.5, 15-digit values
    /// of atan): g(0.1) = 10.1 atan 0.1 = 10.1 * 0.0996686524911620
    /// = 1.00665339016074, g(0.5) = 2.5 atan 0.5 = 2.5 * 0.463647609000806
    /// = 1.15911902250202, lambda = 1.15145792368209.
    #[test]
    fn prebulged_by_hand() {
        let lambda = 1.159_119_022_502_02 / 1.006_653_390_160_74;
        assert!(rel(stretch(1.0, 0.1, 0.5), lambda) < 1e-13);
        assert!(rel(stretch(1.0, 0.1, 0.5), 1.151_457_923_682_09) < 1e-13);
        // s0 from h0 by the paper's eq 21 (asin is right below the hemisphere).
        let (a, h0) = (1.0_f64, 0.1_f64);
        let s0 = (a * a + h0 * h0) / h0 * (2.0 * a * h0 / (a * a + h0 * h0)).asin();
        assert!(rel(arc_length(a, h0), s0) < 1e-14);
        // At the pre-bulge height itself: stretch 1, strain 0, modulus empty.
        let s = spec(1.0, 1e-3, 0.45, 0.1);
        let r = one(&s, &Options::default(), 0.0, 0.1, Some(1e-4));
        assert_eq!(r.value.stretch, Some(1.0));
        assert_eq!(r.value.strain, Some(0.0));
        assert_eq!(r.value.secant_modulus_pa, None);
        assert_eq!(r.std.unwrap().secant_modulus_pa, None);
    }

    /// The exact inflation (Adkins & Rivlin 1952): for a neo-Hookean membrane at h/a = 0.53098 (pole
    /// stretch 1.20) the mean stretch s1/s0 is 1.179.
    #[test]
    fn mean_stretch_understates_pole_stretch() {
        let lambda = stretch(1.0, 0.0, 0.53098);
        assert!((lambda - 1.179).abs() < 1e-3, "{lambda}");
        assert!(lambda < 1.20);
    }

    /// Every option: the relations between them hold exactly (to rounding).
    #[test]
    fn every_option() {
        let s = spec(0.0375, 0.00035, 0.45, 0.002);
        let (p, h) = (5000.0, 0.03);
        let base = one(&s, &Options::default(), p, h, None).value;
        let lambda = base.stretch.unwrap();
        let eps = base.strain.unwrap();
        let sigma = base.stress_pa.unwrap();
        assert!(rel(sigma, p * cap_radius(0.0375, h) / (2.0 * 0.00035)) < 1e-15);
        assert!(rel(base.true_stress_pa.unwrap(), lambda * sigma) < 1e-15);
        assert!(rel(base.secant_modulus_pa.unwrap(), 0.55 * lambda * sigma / eps) < 1e-15);
        for o in all_options() {
            let v = one(&s, &o, p, h, None).value;
            let strain = match o.strain {
                StrainMeasure::Engineering => eps,
                StrainMeasure::Log => lambda.ln(),
            };
            let t = match o.true_stress {
                TrueStress::Paper => lambda * sigma,
                TrueStress::Incompressible => lambda * lambda * sigma,
            };
            let sm = match o.modulus_stress {
                ModulusStress::Nominal => lambda * sigma,
                ModulusStress::Stress => sigma,
                ModulusStress::True => t,
            };
            let k = match o.modulus {
                Modulus::Biaxial => 0.55,
                Modulus::Uniaxial => 1.0,
            };
            assert!(rel(v.strain.unwrap(), strain) < 1e-15, "{o:?}");
            assert!(rel(v.true_stress_pa.unwrap(), t) < 1e-15, "{o:?}");
            assert!(
                rel(v.secant_modulus_pa.unwrap(), k * sm / strain) < 1e-14,
                "{o:?}"
            );
            assert_eq!(v.stress_pa, base.stress_pa);
            assert_eq!(v.radius_m, base.radius_m);
            assert_eq!(v.arc_length_m, base.arc_length_m);
        }
    }

    /// The flat start: no radius (infinite), zero stress, zero strain, no
    /// modulus, and nothing that is NaN or infinite.
    #[test]
    fn flat_zero_pressure_row() {
        let s = spec(0.0375, 0.00035, 0.45, 0.0);
        for o in all_options() {
            let r = one(&s, &o, 0.0, 0.0, Some(1e-5));
            let v = r.value;
            assert_eq!(v.radius_m, None);
            assert_eq!(v.arc_length_m, Some(0.075));
            assert_eq!(
                (v.strain, v.stress_pa, v.true_stress_pa),
                (Some(0.0), Some(0.0), Some(0.0))
            );
            assert_eq!(v.secant_modulus_pa, None);
            let sd = r.std.unwrap();
            assert_eq!(sd.radius_m, None);
            assert_eq!(sd.stress_pa, Some(0.0));
            for x in sd.to_array().into_iter().flatten() {
                assert!(x.is_finite());
            }
        }
    }

    /// `q_std = |dq/dH| sigma_H` against central finite differences of the
    /// values themselves, for every option, on both sides of the hemisphere,
    /// near the flat start and pre-bulged. Step `d = 1e-5 H`: truncation
    /// O(d^2) ~ 1e-10 relative, rounding O(eps / 1e-5) ~ 1e-11.
    #[test]
    fn uncertainty_matches_finite_differences() {
        let sd = 1e-4;
        let mut worst: f64 = 0.0;
        for (h0, h, p) in [
            (0.0, 0.004, 100.0),
            (0.0, 0.02, 3000.0),
            (0.0, 0.0375, 6000.0),
            (0.0, 0.07, 8000.0),
            (0.003, 0.01, 1000.0),
            (0.003, 0.05, 7000.0),
        ] {
            let s = spec(0.0375, 0.00035, 0.45, h0);
            for o in all_options() {
                let r = one(&s, &o, p, h, Some(sd));
                let d = 1e-5 * h;
                let up = one(&s, &o, p, h + d, None).value.to_array();
                let dn = one(&s, &o, p, h - d, None).value.to_array();
                let got = r.std.unwrap().to_array();
                let val = r.value.to_array();
                for k in 0..7 {
                    let fd = (up[k].unwrap() - dn[k].unwrap()) / (2.0 * d) * sd;
                    // scale: the derivative itself, or for a vanishing one
                    // (dR/dH at the hemisphere) the value over the height
                    let scale = fd.abs().max(val[k].unwrap().abs() / h * sd * 1e-3);
                    let e = (got[k].unwrap() - fd.abs()).abs() / scale;
                    worst = worst.max(e);
                    assert!(
                        e < 1e-7,
                        "{} {o:?} h0={h0} H={h}: {} vs {fd}",
                        STD_COLUMNS[k],
                        got[k].unwrap()
                    );
                }
            }
        }
        eprintln!("uncertainty vs finite differences: largest relative difference {worst:.2e}");
    }

    #[test]
    fn refused_points() {
        let s = spec(0.0375, 0.00035, 0.45, 0.002);
        let o = Options::default();
        let pt = |p: f64, h: f64, sd: Option<f64>| Point {
            pressure_pa: p,
            height_m: h,
            height_std_m: sd,
        };
        let err = |pts: &[Point]| stress_strain(&s, &o, pts).unwrap_err();
        let e = err(&[pt(10.0, 0.01, None), pt(-1.0, 0.01, None)]);
        assert_eq!(
            e,
            StressError::Point {
                index: 1,
                problem: PointError::NegativePressure { pressure_pa: -1.0 }
            }
        );
        let StressError::Point { problem, .. } = err(&[pt(10.0, 0.001, None)]) else {
            panic!("expected a point error")
        };
        assert_eq!(problem.column(), "height_m");
        assert!(
            problem
                .to_string()
                .contains("below the pre-bulge height h0 = 0.002")
        );
        let StressError::Point { problem, .. } = err(&[pt(f64::NAN, 0.01, None)]) else {
            panic!("expected a point error")
        };
        assert_eq!(problem.column(), "pressure_pa");
        let StressError::Point { problem, .. } = err(&[pt(1.0, 0.01, Some(-1e-5))]) else {
            panic!("expected a point error")
        };
        assert_eq!(problem.column(), "height_std_m");
        let flat = spec(0.0375, 0.00035, 0.45, 0.0);
        assert!(matches!(
            stress_strain(&flat, &o, &[pt(5.0, 0.0, None)]),
            Err(StressError::Point {
                problem: PointError::FlatUnderPressure { .. },
                ..
            })
        ));
        for bad in [
            spec(0.0, 0.00035, 0.45, 0.0),
            spec(0.0375, -1e-3, 0.45, 0.0),
            spec(0.0375, 0.00035, 0.5, 0.0),
            spec(0.0375, 0.00035, -0.1, 0.0),
        ] {
            assert!(matches!(
                stress_strain(&bad, &o, &[pt(1.0, 0.01, None)]),
                Err(StressError::Specimen(_))
            ));
        }
    }

    proptest! {
        /// Invariants: s >= 2a, R >= a, stretch >= 1 and increasing with H,
        /// log strain <= engineering strain, ds/dH >= 0.
        #[test]
        fn invariants(a in 1e-3f64..1.0, x0 in 0.0f64..1.5, dx1 in 0.0f64..3.0, frac in 0.0f64..1.0) {
            let h0 = x0 * a;
            let h2 = h0 + dx1 * a;
            let h1 = h0 + frac * (h2 - h0);
            prop_assert!(arc_length(a, h1) >= 2.0 * a);
            if h1 > 0.0 {
                prop_assert!(cap_radius(a, h1) >= a * (1.0 - 1e-15));
            }
            let (l1, l2) = (stretch(a, h0, h1), stretch(a, h0, h2));
            prop_assert!(l1 >= 1.0);
            prop_assert!(l2 >= l1, "{} {}", l1, l2);
            let eps = engineering_strain(a, h0, h2);
            prop_assert!(eps.ln_1p() <= eps);
            prop_assert!(arc_ratio_slope(h1 / a) >= 0.0);
        }

        /// The series and closed forms agree where they meet (x = 1/2), and
        /// the divided difference agrees with the plain difference when the
        /// heights are far apart.
        #[test]
        fn branches_agree(x in 0.3f64..0.7, x0 in 0.0f64..0.2) {
            let y = x * x;
            let closed = (x + 1.0 / x) * x.atan() - 1.0;
            prop_assert!(rel(arc_excess(x), closed) < 1e-14);
            let slope_closed = (1.0 - 1.0 / y) * x.atan() + 1.0 / x;
            prop_assert!(rel(arc_ratio_slope(x), slope_closed) < 1e-13);
            let x1 = x0 + 0.25;
            let diff = arc_ratio_difference(x0, x1, 0.25);
            prop_assert!(rel(diff, arc_excess(x1) - arc_excess(x0)) < 1e-13);
        }
    }
}
