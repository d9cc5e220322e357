//! Which columns of which file feed which fit.
//!
//! Two kinds of input are recognised by their header:
//!
//! * **`stress_strain.csv` from `bulge stress`** (it has `secant_modulus_pa`):
//!   - the quartic takes `strain` and `secant_modulus_pa` as they are, so the
//!     law inherits the stress stage's choices (strain measure, which stress,
//!     biaxial or uniaxial modulus) and the simulator that reads it back with
//!     the same conventions gets the modulus that was measured. Rows with an
//!     empty modulus (zero strain) are skipped. The strain measure written to
//!     `material.toml` is recognised from the columns (`strain = stretch - 1`
//!     or `ln stretch`);
//!   - the hyperelastic models take `stretch` and `stress_pa` (`p R / 2 t`,
//!     eq 18, the membrane force per unit *undeformed* thickness), converted
//!     for an incompressible membrane: Cauchy `sigma = l^2 p R / 2 t`, nominal
//!     `P = l p R / 2 t`; Cauchy by default (the stress measure of the
//!     [`LoadOptions`] to change).
//!     `true_stress_pa` is not used because its meaning depends on the
//!     stress stage's true-stress convention (the paper's eq 25, `l p R/2t`,
//!     is for an incompressible membrane the *nominal* stress, not the true
//!     one), which the file does not record; `stress_pa` is unambiguous.
//!     Cauchy is the default because the residuals then weigh the points as
//!     the measured quantity (pressure times radius) does, up to the known
//!     factor `l^2`.
//!
//!     The stretch of `stress_strain.csv` is the mean meridional stretch of
//!     the cap (eq 23), which understates the pole stretch that the
//!     equibiaxial formulas assume (the exact neo-Hookean inflation gives 1.179 against 1.20 at
//!     h/a = 0.53): hyperelastic parameters from bubble data carry that bias.
//! * **raw equibiaxial data** `stretch` plus one stress column: `nominal_stress_pa`
//!   or `cauchy_stress_pa` (the measure follows from the name), or
//!   `stress_pa` with the stress measure of the [`LoadOptions`] saying which. The hyperelastic models
//!   are fitted in that measure. The quartic is fitted to the secant modulus
//!   `k sigma / eps` built from the Cauchy stress and the chosen strain
//!   (`k = 1 - nu` biaxial, `1` uniaxial), points at zero strain skipped.

use super::StressMeasure;
use super::hyperelastic::Equibiaxial;
use crate::io::{InputError, Table};
use crate::material::StrainMeasure;
use crate::mechanics::{Modulus, Row};

/// What the input file was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `stress_strain.csv` of `bulge stress`.
    StressStage,
    /// Raw `stretch` plus stress.
    Raw,
}

/// Choices that decide how a file is read.
#[derive(Debug, Clone, Copy)]
pub struct LoadOptions {
    /// Stress measure of the raw stress column, or of the hyperelastic fit
    /// for `stress_strain.csv`; `None` infers it.
    pub stress_measure: Option<StressMeasure>,
    /// Strain measure; `None` infers it (stress stage) or takes engineering.
    pub strain_measure: Option<StrainMeasure>,
    /// Poisson ratio for the raw-data secant modulus.
    pub poisson: f64,
    /// Modulus convention for the raw-data secant modulus.
    pub modulus: Modulus,
}

/// Validated data ready for the fits.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// Which kind of file.
    pub source: Source,
    /// Stretch and stress for the hyperelastic fits.
    pub equibiaxial: Equibiaxial,
    /// Name of the stress column used for the hyperelastic fits and how.
    pub stress_column: String,
    /// Strain of every row.
    pub strain: Vec<f64>,
    /// Secant modulus of every row (None at zero strain), Pa.
    pub modulus_pa: Vec<Option<f64>>,
    /// Its standard deviation where the input gives one, Pa.
    pub modulus_std_pa: Vec<Option<f64>>,
    /// How every row moves when its height rises by one standard
    /// deviation, where the input says (`bulge stress` with a height
    /// uncertainty): what weights the fits.
    pub shifts: Vec<Option<HeightShift>>,
    /// The strain measure of `strain`.
    pub strain_measure: StrainMeasure,
    /// 1-based file line of every row.
    pub lines: Vec<u64>,
}

/// The signed change of one row's values when its height rises by one
/// standard deviation. The stretch, strain, stress and modulus of a row all
/// follow from one measured height at a known pressure, so their errors are
/// one vector: a point of the modulus curve moves along `(strain,
/// modulus_pa)`, not in the modulus alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightShift {
    /// Of the stretch.
    pub stretch: f64,
    /// Of the strain.
    pub strain: f64,
    /// Of the stress the hyperelastic models are fitted to
    /// ([`Loaded::equibiaxial`]), Pa.
    pub stress_pa: f64,
    /// Of the secant modulus, Pa (`None` at zero strain).
    pub modulus_pa: Option<f64>,
}

impl HeightShift {
    /// From the shifts of the stretch, strain, pole stress `s` and secant
    /// modulus of a row at stretch `l` and pole stress `sigma`, the stress
    /// converted as [`load`] converts it for an incompressible membrane
    /// (Cauchy `l^2 s`, nominal `l s`).
    fn of_stage(
        l: f64,
        sigma: f64,
        d: [f64; 3],
        d_modulus: Option<f64>,
        measure: StressMeasure,
    ) -> HeightShift {
        let [dl, de, ds] = d;
        let stress_pa = match measure {
            StressMeasure::Cauchy => 2.0 * l * sigma * dl + l * l * ds,
            StressMeasure::Nominal => sigma * dl + l * ds,
        };
        HeightShift {
            stretch: dl,
            strain: de,
            stress_pa,
            modulus_pa: d_modulus,
        }
    }
}

impl Loaded {
    /// The `(strain, modulus)` points the polynomial law is fitted to.
    pub fn modulus_points(&self) -> (Vec<f64>, Vec<f64>) {
        self.strain
            .iter()
            .zip(&self.modulus_pa)
            .filter_map(|(&e, m)| m.map(|m| (e, m)))
            .unzip()
    }
}

impl Loaded {
    /// The `(strain, modulus)` shifts of the points of [`Self::modulus_points`];
    /// `None` unless every one of them has its shift.
    pub fn modulus_shifts(&self) -> Option<Vec<(f64, f64)>> {
        self.modulus_pa
            .iter()
            .zip(&self.shifts)
            .filter(|(m, _)| m.is_some())
            .map(|(_, s)| s.and_then(|s| Some((s.strain, s.modulus_pa?))))
            .collect::<Option<Vec<_>>>()
            .filter(|v| moves(v))
    }

    /// The `(stretch, stress)` shifts of the hyperelastic fits' points;
    /// `None` unless every row has its shift.
    pub fn stress_shifts(&self) -> Option<Vec<(f64, f64)>> {
        self.shifts
            .iter()
            .map(|s| s.map(|s| (s.stretch, s.stress_pa)))
            .collect::<Option<Vec<_>>>()
            .filter(|v| moves(v))
    }
}

/// Whether any point moves with its height (all heights exact: nothing to
/// weight by).
fn moves(shifts: &[(f64, f64)]) -> bool {
    shifts.iter().any(|&(a, b)| a != 0.0 || b != 0.0)
}

/// Below this share of the median, an effective standard deviation is
/// raised to it: where a point's shift runs along the law, its own would be
/// near zero and one point would pull the fit to itself.
pub const EFFECTIVE_STD_FLOOR: f64 = 0.05;

/// The effective standard deviations of points `(x_i, y_i)` fitted by
/// `y = f(x)`, when each point moves by `(dx_i, dy_i)` for a one-standard-
/// deviation rise of its height: the residual `y - f(x)` moves by
/// `dy - f'(x) dx`, its size is the point's standard deviation (the
/// effective-variance method with fully correlated errors), raised to
/// [`EFFECTIVE_STD_FLOOR`] of the median. `slope` is `f'`.
pub fn effective_std(shifts: &[(f64, f64)], x: &[f64], slope: impl Fn(f64) -> f64) -> Vec<f64> {
    let raw: Vec<f64> = shifts
        .iter()
        .zip(x)
        .map(|(&(dx, dy), &x)| (dy - slope(x) * dx).abs())
        .collect();
    let mut sorted: Vec<f64> = raw.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let smallest = sorted.iter().copied().find(|&v| v > 0.0).unwrap_or(0.0);
    let floor = (EFFECTIVE_STD_FLOOR * median).max(smallest);
    raw.iter().map(|&v| v.max(floor)).collect()
}

impl Loaded {
    /// The stress stage's rows as fit data, as `bulge fit` reads the
    /// `stress_strain.csv` that `bulge stress` writes: the rows with a
    /// stretch above 1, a stress and a secant modulus, sorted by stretch
    /// with exact repeats merged (noise can put two frames at one height).
    /// The hyperelastic models see the Cauchy stress `lambda^2 p R / 2t` of
    /// an incompressible membrane. `lines` are the rows' lines in
    /// `stress_strain.csv` (header on line 1, in the stage's order).
    pub fn from_stress_rows(rows: &[Row], strain_measure: StrainMeasure) -> Loaded {
        type Kept = (f64, f64, f64, f64, Option<f64>, u64, Option<HeightShift>);
        let mut v: Vec<Kept> = rows
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                let d = &r.value;
                let (l, e, st, m) = (d.stretch?, d.strain?, d.stress_pa?, d.secant_modulus_pa?);
                let sd = r.std.and_then(|s| s.secant_modulus_pa);
                let shift = r.shift.and_then(|s| {
                    Some(HeightShift::of_stage(
                        l,
                        st,
                        [s.stretch?, s.strain?, s.stress_pa?],
                        s.secant_modulus_pa,
                        StressMeasure::Cauchy,
                    ))
                });
                (l > 1.0).then_some((l, e, st, m, sd, i as u64 + 2, shift))
            })
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v.dedup_by(|a, b| a.0 == b.0);
        Loaded {
            source: Source::StressStage,
            equibiaxial: Equibiaxial {
                stretch: v.iter().map(|r| r.0).collect(),
                stress_pa: v.iter().map(|r| r.0 * r.0 * r.2).collect(),
                measure: StressMeasure::Cauchy,
            },
            stress_column: "stretch^2 * stress_pa (Cauchy, incompressible)".into(),
            strain: v.iter().map(|r| r.1).collect(),
            modulus_pa: v.iter().map(|r| Some(r.3)).collect(),
            modulus_std_pa: v.iter().map(|r| r.4).collect(),
            shifts: v.iter().map(|r| r.6).collect(),
            strain_measure,
            lines: v.iter().map(|r| r.5).collect(),
        }
    }
}

/// Reads and validates a table (see the module docs).
pub fn load(t: &Table, opts: &LoadOptions) -> Result<Loaded, InputError> {
    let stretch = t.numbers("stretch")?;
    for (r, &l) in stretch.iter().enumerate() {
        if l <= 0.0 {
            return Err(t.error_at(
                r,
                "stretch",
                format!("stretch {l} is not positive: a stretch is deformed/undeformed length, > 0 (1 at rest); fix or drop the row"),
            ));
        }
        // An inflated membrane is stretched: equibiaxial compression of a
        // membrane buckles it, so a stretch below 1 is another test's data.
        if l < 1.0 {
            return Err(t.error_at(
                r,
                "stretch",
                format!("stretch {l} is below 1: that is compression, and an inflated membrane is only stretched (equibiaxial compression buckles a membrane); drop the compression rows, or give uniaxial compression at stretch l as equibiaxial tension at stretch 1/sqrt(l) (incompressible)"),
            ));
        }
    }
    increasing(t, &stretch, "stretch")?;
    if t.column_index("secant_modulus_pa").is_some() {
        load_stress_stage(t, stretch, opts)
    } else {
        load_raw(t, stretch, opts)
    }
}

fn increasing(t: &Table, v: &[f64], col: &str) -> Result<(), InputError> {
    for r in 1..v.len() {
        if v[r] <= v[r - 1] {
            let what = if v[r] == v[r - 1] {
                "repeats"
            } else {
                "is smaller than"
            };
            return Err(t.error_at(
                r,
                col,
                format!(
                    "{col} {} {what} {} on line {}: the fit needs one row per {col}, in increasing order; \
                     sort the rows, and average or drop repeated points (unloading branches included)",
                    v[r],
                    v[r - 1],
                    t.lines[r - 1]
                ),
            ));
        }
    }
    Ok(())
}

fn load_stress_stage(
    t: &Table,
    stretch: Vec<f64>,
    opts: &LoadOptions,
) -> Result<Loaded, InputError> {
    let strain = t.numbers("strain")?;
    let stress = t.numbers("stress_pa")?;
    let modulus_pa = t
        .optional_numbers("secant_modulus_pa")?
        .expect("checked by the caller");
    increasing(t, &strain, "strain")?;
    let tol = |x: f64| 1e-6 * x.abs().max(1e-3);
    let matches = |m: StrainMeasure| {
        stretch
            .iter()
            .zip(&strain)
            .position(|(&l, &e)| (m.of_stretch(l) - e).abs() > tol(e))
    };
    let strain_measure = match opts.strain_measure {
        Some(m) => {
            if let Some(r) = matches(m) {
                return Err(t.error_at(
                    r,
                    "strain",
                    format!(
                        "strain {} is not the {} strain of stretch {} (that would be {}): \
                         leave the strain measure out to let bulge recognise it, or choose the other one",
                        strain[r],
                        measure_name(m),
                        stretch[r],
                        m.of_stretch(stretch[r])
                    ),
                )
                .about_setting("strain_measure"));
            }
            m
        }
        None => match (
            matches(StrainMeasure::Engineering),
            matches(StrainMeasure::Log),
        ) {
            (None, _) => StrainMeasure::Engineering,
            (Some(_), None) => StrainMeasure::Log,
            (Some(r), Some(_)) => {
                return Err(t.error_at(
                    r,
                    "strain",
                    format!(
                        "strain {} is neither stretch - 1 nor ln(stretch) for stretch {}: \
                         the modulus law needs to know its strain; regenerate the file with `bulge stress`",
                        strain[r], stretch[r]
                    ),
                ));
            }
        },
    };
    let measure = opts.stress_measure.unwrap_or(StressMeasure::Cauchy);
    let stress_pa = stretch
        .iter()
        .zip(&stress)
        .map(|(&l, &s)| match measure {
            StressMeasure::Cauchy => l * l * s,
            StressMeasure::Nominal => l * s,
        })
        .collect();
    let stress_column = match measure {
        StressMeasure::Cauchy => "stretch^2 * stress_pa (Cauchy, incompressible)",
        StressMeasure::Nominal => "stretch * stress_pa (nominal, incompressible)",
    };
    // `bulge stress` writes the uncertainty of `secant_modulus_pa` as
    // `secant_modulus_std_pa` (unit last).
    let modulus_std_pa = match t.optional_numbers("secant_modulus_std_pa")? {
        Some(v) => v,
        None => t
            .optional_numbers("secant_modulus_pa_std")?
            .unwrap_or_else(|| vec![None; strain.len()]),
    };
    let shifts = stage_shifts(t, &stretch, &stress, measure)?;
    Ok(Loaded {
        source: Source::StressStage,
        equibiaxial: Equibiaxial {
            stretch,
            stress_pa,
            measure,
        },
        stress_column: stress_column.into(),
        strain,
        modulus_pa,
        modulus_std_pa,
        shifts,
        strain_measure,
        lines: t.lines.clone(),
    })
}

/// The rows' [`HeightShift`]s from the standard deviations and the
/// correlations that `bulge stress` writes with a height uncertainty
/// (`stretch_std`, `strain_std`, `stress_std_pa`, `secant_modulus_std_pa`,
/// `strain_stress_corr`, `strain_modulus_corr`); none where a column or a
/// cell is missing. The stretch and strain rise with the height, so their
/// shifts are their standard deviations; the correlations give the stress's
/// and the modulus's signs.
fn stage_shifts(
    t: &Table,
    stretch: &[f64],
    stress: &[f64],
    measure: StressMeasure,
) -> Result<Vec<Option<HeightShift>>, InputError> {
    let none = || vec![None; stretch.len()];
    let mut cols = Vec::new();
    for name in [
        "stretch_std",
        "strain_std",
        "stress_std_pa",
        "strain_stress_corr",
        "secant_modulus_std_pa",
        "strain_modulus_corr",
    ] {
        match t.optional_numbers(name)? {
            Some(c) => cols.push(c),
            None => return Ok(none()),
        }
    }
    for (r, (a, b)) in cols[3].iter().zip(&cols[5]).enumerate() {
        for (name, c) in [("strain_stress_corr", a), ("strain_modulus_corr", b)] {
            if let Some(c) = c
                && !(-1.0..=1.0).contains(c)
            {
                return Err(t.error_at(
                    r,
                    name,
                    format!("{name} {c} is not a correlation (between -1 and 1): regenerate the file with `bulge stress`"),
                ));
            }
        }
    }
    Ok((0..stretch.len())
        .map(|r| {
            let (dl, de, sd_s, rho_s) = (cols[0][r]?, cols[1][r]?, cols[2][r]?, cols[3][r]?);
            let d_modulus = cols[4][r].zip(cols[5][r]).map(|(sd, rho)| sd * rho);
            Some(HeightShift::of_stage(
                stretch[r],
                stress[r],
                [dl, de, sd_s * rho_s],
                d_modulus,
                measure,
            ))
        })
        .collect())
}

fn measure_name(m: StrainMeasure) -> &'static str {
    match m {
        StrainMeasure::Engineering => "engineering",
        StrainMeasure::Log => "log",
    }
}

fn load_raw(t: &Table, stretch: Vec<f64>, opts: &LoadOptions) -> Result<Loaded, InputError> {
    let has = |c: &str| t.column_index(c).is_some();
    let (column, measure) = match opts.stress_measure {
        Some(m) => {
            let named = format!("{}_stress_pa", m.name());
            if has(&named) {
                (named, m)
            } else if has("stress_pa") {
                ("stress_pa".to_string(), m)
            } else {
                return Err(InputError::cell(
                    &t.path,
                    1,
                    &named,
                    format!(
                        "no stress column: expected `{named}` or `stress_pa` next to `stretch` (found: {})",
                        t.headers.join(", ")
                    ),
                ));
            }
        }
        None => match (has("nominal_stress_pa"), has("cauchy_stress_pa")) {
            (true, false) => ("nominal_stress_pa".to_string(), StressMeasure::Nominal),
            (false, true) => ("cauchy_stress_pa".to_string(), StressMeasure::Cauchy),
            (true, true) => {
                return Err(InputError::file(
                    &t.path,
                    "both `nominal_stress_pa` and `cauchy_stress_pa` are present: choose the stress measure to fit",
                )
                .about_setting("stress_measure"));
            }
            (false, false) => {
                return Err(InputError::file(
                    &t.path,
                    format!(
                        "no stress column: expected `nominal_stress_pa` or `cauchy_stress_pa` (or `stress_pa` with \
                         the stress measure, nominal or cauchy, chosen), or a `stress_strain.csv` from `bulge stress` (found: {})",
                        t.headers.join(", ")
                    ),
                )
                .about_setting("stress_measure"));
            }
        },
    };
    let stress_pa = t.numbers(&column)?;
    let strain_measure = opts.strain_measure.unwrap_or_default();
    let strain: Vec<f64> = stretch
        .iter()
        .map(|&l| strain_measure.of_stretch(l))
        .collect();
    let k = opts.modulus.factor(opts.poisson);
    let modulus_pa = stretch
        .iter()
        .zip(&stress_pa)
        .zip(&strain)
        .map(|((&l, &s), &e)| {
            let cauchy = match measure {
                StressMeasure::Cauchy => s,
                StressMeasure::Nominal => l * s,
            };
            (e != 0.0).then(|| k * cauchy / e)
        })
        .collect();
    let modulus_std_pa = vec![None; strain.len()];
    let shifts = vec![None; strain.len()];
    Ok(Loaded {
        source: Source::Raw,
        equibiaxial: Equibiaxial {
            stretch,
            stress_pa,
            measure,
        },
        stress_column: column,
        strain,
        modulus_pa,
        modulus_std_pa,
        shifts,
        strain_measure,
        lines: t.lines.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn opts() -> LoadOptions {
        LoadOptions {
            stress_measure: None,
            strain_measure: None,
            poisson: 0.45,
            modulus: Modulus::Biaxial,
        }
    }

    #[test]
    fn stress_stage_columns_and_strain_measure() {
        let csv = "pressure_pa,height_m,radius_m,arc_length_m,stretch,strain,stress_pa,true_stress_pa,secant_modulus_pa\n\
                   0,0,,0.075,1,0,0,0,\n\
                   1000,0.01,0.08,0.077,1.1,0.09531017980432493,100000,120000,577000\n\
                   2000,0.02,0.05,0.08,1.2,0.1823215567939546,200000,280000,603000\n";
        let t = Table::parse(Path::new("s.csv"), csv.as_bytes()).unwrap();
        let d = load(&t, &opts()).unwrap();
        assert_eq!(d.source, Source::StressStage);
        assert_eq!(d.strain_measure, StrainMeasure::Log);
        assert_eq!(d.equibiaxial.measure, StressMeasure::Cauchy);
        assert!((d.equibiaxial.stress_pa[2] - 1.44 * 200000.0).abs() < 1e-6);
        let (e, m) = d.modulus_points();
        assert_eq!(e.len(), 2);
        assert_eq!(m, vec![577000.0, 603000.0]);
    }

    #[test]
    fn raw_measure_from_column_name_and_errors_located() {
        let t = Table::parse(
            Path::new("r.csv"),
            b"stretch,nominal_stress_pa\n1,0\n1.5,2\n2,3\n",
        )
        .unwrap();
        let d = load(&t, &opts()).unwrap();
        assert_eq!(d.equibiaxial.measure, StressMeasure::Nominal);
        // Secant modulus from Cauchy stress: 0.55 * 1.5 * 2 / 0.5.
        assert!((d.modulus_pa[1].unwrap() - 3.3).abs() < 1e-12);
        assert!(d.modulus_pa[0].is_none());
        let t = Table::parse(
            Path::new("r.csv"),
            b"stretch,nominal_stress_pa\n1,0\n1.5,2\n1.5,3\n",
        )
        .unwrap();
        let e = load(&t, &opts()).unwrap_err().to_string();
        assert!(e.contains("r.csv, line 4") && e.contains("repeats"), "{e}");
        let t = Table::parse(
            Path::new("r.csv"),
            b"stretch,nominal_stress_pa\n1.2,0\n1.1,2\n",
        )
        .unwrap();
        let e = load(&t, &opts()).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("smaller"), "{e}");
        let t = Table::parse(
            Path::new("r.csv"),
            b"stretch,nominal_stress_pa\n1,0\n0.9,2\n",
        )
        .unwrap();
        let e = load(&t, &opts()).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("compression"), "{e}");
        let t = Table::parse(
            Path::new("r.csv"),
            b"stretch,nominal_stress_pa\n-1,0\n0.9,2\n",
        )
        .unwrap();
        let e = load(&t, &opts()).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("not positive"), "{e}");
        let t = Table::parse(Path::new("r.csv"), b"stretch,stress_pa\n1,0\n1.2,2\n").unwrap();
        let e = load(&t, &opts()).unwrap_err().to_string();
        assert!(e.contains("stress measure"), "{e}");
    }
}
