//! The flags of `bulge stress` and their help.

use bulge::mechanics::{Modulus, ModulusStress, StrainMeasure, TrueStress};
use std::path::PathBuf;

/// Flags of `bulge stress`.
///
/// Example: `bulge stress heights.csv --experiment experiment.toml -o stress_strain.csv`
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Heights are apex heights above the clamp plane (the paper's h + h0), in metres; \
pressures are gauge pressures in pascals. Bad input exits with status 2 and writes nothing."
)]
pub struct Args {
    /// Heights CSV with columns `pressure_pa` (gauge pressure, Pa, >= 0) and
    /// `height_m` (apex height above the clamp plane, m, >= the pre-bulge
    /// height); an optional `height_std_m` column gives each height's standard
    /// deviation. Other columns (`frame`, `file`, ...) are copied to the output.
    pub heights: PathBuf,

    /// Output CSV (required, no default: bulge does not guess where to write;
    /// parent folders are created; written whole or not at all). When the
    /// experiment file gives standard deviations besides the heights'
    /// ([pressure] std_pa, relative_std; [specimen] thickness_std_m,
    /// radius_std_m; [calibration] metres_per_pixel_std, clamp_row_std_px),
    /// `<stem>_sources.csv` beside it gives every point's change for each
    /// input's error (the correlations those shared inputs make).
    #[arg(short = 'o', long = "output", value_name = "FILE.csv")]
    pub output: PathBuf,

    /// Experiment file whose `[specimen]` table gives `radius_m`,
    /// `thickness_m`, `poisson` and optionally `prebulge_height_m` (default 0).
    /// No default: either this or the specimen flags below.
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = ["radius_m", "thickness_m", "poisson", "prebulge_height_m"])]
    pub experiment: Option<PathBuf>,

    /// Free radius `a` of the clamped disc, m (> 0). Required without
    /// `--experiment`; no default (it sets every result).
    #[arg(
        long = "radius-m",
        value_name = "M",
        allow_hyphen_values = true,
        required_unless_present = "experiment"
    )]
    pub radius_m: Option<f64>,

    /// Initial thickness `t`, m (> 0). Required without `--experiment`; no
    /// default (the stress scales with 1/t).
    #[arg(
        long = "thickness-m",
        value_name = "M",
        allow_hyphen_values = true,
        required_unless_present = "experiment"
    )]
    pub thickness_m: Option<f64>,

    /// Poisson ratio `nu`, in [0, 0.5) (latex/rubber: 0.45-0.499). Required
    /// without `--experiment`; no default (it sets the biaxial modulus).
    #[arg(
        long,
        value_name = "NU",
        allow_hyphen_values = true,
        required_unless_present = "experiment"
    )]
    pub poisson: Option<f64>,

    /// Pre-bulge apex height `h0` at p = 0+, m (>= 0). Default 0: a disc
    /// clamped flat. Heights below it are refused.
    #[arg(
        long = "prebulge-height-m",
        value_name = "M",
        allow_hyphen_values = true
    )]
    pub prebulge_height_m: Option<f64>,

    /// Strain measure: `engineering` = lambda - 1 (Tudruj et al. (2023) eq 24 with its
    /// sign corrected) or `log` = ln lambda. Default engineering: it is what
    /// the paper's secant-modulus procedure (section 7) uses.
    #[arg(long, value_enum, default_value_t = StrainMeasure::Engineering)]
    pub strain: StrainMeasure,

    /// True stress: `paper` = lambda * pR/(2t) (eq 25, thickness t/lambda) or
    /// `incompressible` = lambda^2 * pR/(2t) (thickness t/lambda^2, the
    /// Cauchy stress of an incompressible membrane). Default paper, so that
    /// the paper's procedure is reproduced; `incompressible` is the physically
    /// consistent choice for rubber.
    #[arg(long = "true-stress", value_enum, default_value_t = TrueStress::Paper)]
    pub true_stress: TrueStress,

    /// Secant modulus: `biaxial` = (1 - nu) S / strain (equibiaxial plane
    /// stress at the pole, the paper's "2D case") or `uniaxial` = S / strain.
    /// Default biaxial: the pole of a bubble is in equibiaxial tension.
    #[arg(long, value_enum, default_value_t = Modulus::Biaxial)]
    pub modulus: Modulus,

    /// Stress S in the secant modulus: `nominal` = lambda * pR/(2t), the
    /// force per unit reference area (first Piola-Kirchhoff; the same number
    /// as eq 25), `stress` = pR/(2t) (eq 18, the `stress_pa` column), or `true` = the
    /// `--true-stress` value. Default nominal: the mass-spring models of
    /// `bulge simulate` carry forces on the reference mesh with stiffness
    /// proportional to E t (eqs 1, 10-17), so they reproduce the measured
    /// tension per reference length, lambda pR/2, with E = (1 - nu) *
    /// nominal / strain.
    #[arg(long = "modulus-stress", value_enum, default_value_t = ModulusStress::Nominal)]
    pub modulus_stress: ModulusStress,

    /// Standard deviation of every height, m (>= 0). Default none: no `*_std`
    /// columns unless the heights CSV has a `height_std_m` column. When given,
    /// it is propagated to first order (|dq/dH| * std) into `*_std` columns
    /// for every derived quantity. Refused together with a `height_std_m`
    /// column (one source of uncertainty, not a silent override).
    #[arg(long = "height-std-m", value_name = "M", allow_hyphen_values = true)]
    pub height_std_m: Option<f64>,
}
