//! The options, inputs, outputs and errors of the stress stage.

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
    /// `f` applied to every value present.
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Derived {
        Derived {
            radius_m: self.radius_m.map(&f),
            arc_length_m: self.arc_length_m.map(&f),
            stretch: self.stretch.map(&f),
            strain: self.strain.map(&f),
            stress_pa: self.stress_pa.map(&f),
            true_stress_pa: self.true_stress_pa.map(&f),
            secant_modulus_pa: self.secant_modulus_pa.map(&f),
        }
    }

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
    /// The signed change of every value when the height rises by its
    /// standard deviation, `dq/dH height_std_m` (so `std` is its size).
    /// Every value of a row follows from the one measured height, so their
    /// errors are one vector: a fit of one value against another needs the
    /// signs, not only the sizes.
    pub shift: Option<Derived>,
}

impl Row {
    /// The correlations of the strain's error with the stress's and with
    /// the secant modulus's ([`CORR_COLUMNS`]): +1 or -1 (one source, the
    /// height), `None` without a shift or where a value is missing.
    pub fn correlations(&self) -> [Option<f64>; 2] {
        let Some(s) = &self.shift else {
            return [None, None];
        };
        // A zero shift (the flat start's strain, a stress at no
        // pressure) takes either sign: +1.
        let corr = |other: Option<f64>| match (s.strain, other) {
            (Some(e), Some(o)) if e != 0.0 && o != 0.0 => Some((e * o).signum()),
            (Some(_), Some(_)) => Some(1.0),
            _ => None,
        };
        [corr(s.stress_pa), corr(s.secant_modulus_pa)]
    }
}

/// Output column names of [`Row::correlations`]: the correlation of the
/// strain's error with the stress's and with the secant modulus's.
pub const CORR_COLUMNS: [&str; 2] = ["strain_stress_corr", "strain_modulus_corr"];

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
    /// A height that no membrane on this opening can reach: the cap's
    /// stretch above [`MAX_STRETCH`].
    #[error(
        "height_m = {height_m:e} over radius_m = {radius_m:e} gives the cap a stretch of {stretch:.3e}, above {max}: no membrane survives that (rubbers break below a stretch of about 8 in equibiaxial tension); check that radius_m is the opening's radius in metres and height_m is in metres",
        max = MAX_STRETCH
    )]
    BeyondAnyMembrane {
        /// The height, m.
        height_m: f64,
        /// The opening's radius, m.
        radius_m: f64,
        /// The stretch of the spherical cap.
        stretch: f64,
    },
}

/// The largest cap stretch the stress stage accepts. Natural rubber, the
/// most extensible of the membranes bulge tests, breaks in equibiaxial
/// tension at stretches of about 4.5-8 (Treloar's equibiaxial data reach
/// 4.9: L. R. G. Treloar, "Stress-strain data for vulcanised rubber under
/// various types of deformation", Trans. Faraday Soc. 40 (1944) 59-70,
/// doi:10.1039/TF9444000059); a stretch of 10 is a unit or radius mistake.
pub const MAX_STRETCH: f64 = 10.0;

impl PointError {
    /// The input column that holds the bad value.
    pub fn column(&self) -> &'static str {
        match self {
            PointError::NotFinite { column, .. } => column,
            PointError::NegativePressure { .. } | PointError::FlatUnderPressure { .. } => {
                "pressure_pa"
            }
            PointError::BelowPrebulge { .. } | PointError::BeyondAnyMembrane { .. } => "height_m",
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

impl crate::Refusal for StressError {
    /// A specimen or a point that the formulas refuse.
    fn is_bad_input(&self) -> bool {
        true
    }
}
