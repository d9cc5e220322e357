//! The stress stage: heights -> stress and strain, the stress-free dome
//! height, and the shift of each point under each source of error.

use crate::experiment::Specimen;
use crate::fit::uncertainty::{SourceKind, Sources};
use crate::fit::{FitModel, inverse};
use crate::io::{CsvOut, InputError, Table, fmt_num};
use crate::mechanics::{self, CORR_COLUMNS, DERIVED_COLUMNS, Point, Row, STD_COLUMNS};

use super::*;

/// Output of the stress stage.
#[derive(Debug, Clone)]
pub struct StressOut {
    /// The measured points.
    pub points: Vec<Point>,
    /// Derived quantities per point.
    pub rows: Vec<Row>,
    /// Per point, how its values move for each input's error
    /// ([`crate::fit::uncertainty::point_shifts`]); empty without the
    /// experiment's standard deviations besides the heights'.
    pub shifts: Vec<PointShifts>,
}

/// How one point's derived values move for a one-standard-deviation error
/// of each input (see [`crate::fit::uncertainty::point_shifts`]).
pub type PointShifts = Vec<(SourceKind, mechanics::Derived)>;

/// Every point's [`PointShifts`] when `sources` has a standard deviation
/// (else none: the heights' own are in the `*_std` columns).
pub fn point_shifts(
    spec: &Specimen,
    opts: &mechanics::Options,
    points: &[Point],
    sources: &Sources,
) -> Result<Vec<PointShifts>, mechanics::StressError> {
    if *sources == Sources::default() {
        return Ok(Vec::new());
    }
    points
        .iter()
        .map(|p| crate::fit::uncertainty::point_shifts(spec, opts, p, sources))
        .collect()
}

/// Output column names of a shift table ([`shifts_csv`]), in the order of
/// [`DERIVED_COLUMNS`].
pub const SHIFT_COLUMNS: [&str; 7] = [
    "radius_shift_m",
    "arc_length_shift_m",
    "stretch_shift",
    "strain_shift",
    "stress_shift_pa",
    "true_stress_shift_pa",
    "secant_modulus_shift_pa",
];

/// The shift table of `bulge stress` and `bulge run`
/// (`stress_strain_sources.csv`): one row per point and input error,
/// `point` (1 for the first data row of `stress_strain.csv`),
/// `pressure_pa`, `height_m`, `source` (`height`, `pressure_noise`,
/// `pressure_gain`, `thickness`, `radius`, `scale`, `height_offset`,
/// `prebulge_height`) and
/// the signed change of every derived value for a one-standard-deviation
/// error of that source ([`SHIFT_COLUMNS`]). `None` when there are none.
pub fn shifts_csv(points: &[Point], shifts: &[PointShifts]) -> Option<CsvOut> {
    if shifts.is_empty() {
        return None;
    }
    let mut header = vec!["point", "pressure_pa", "height_m", "source"];
    header.extend(SHIFT_COLUMNS);
    let mut out = CsvOut::new(&header);
    for (i, (p, list)) in points.iter().zip(shifts).enumerate() {
        for (kind, d) in list {
            let name = match kind {
                SourceKind::Points => "height",
                k => k.name(),
            };
            let mut f = vec![
                (i + 1).to_string(),
                fmt_num(Some(p.pressure_pa)),
                fmt_num(Some(p.height_m)),
                name.to_string(),
            ];
            f.extend(d.to_array().into_iter().map(fmt_num));
            out.row(&f);
        }
    }
    Some(out)
}

/// The stress-free dome height of a slack membrane (`prebulge_height_m =
/// "fit"`), m, and a sentence saying how it was found: first from the cap
/// formulas ([`crate::mechanics::prebulge::estimate`], a few per cent low),
/// then, with `settings.refine`, beside a Mooney-Rivlin law corrected to the
/// heights ([`inverse::refine_with_prebulge`]): two parameters follow rubber
/// well and are too few to make up for a wrong reference, where a quartic's
/// five absorb it (its rms height error is flat within 0.01 percentage
/// points over +-10 % of `h0`).
pub fn prebulge_stage(
    spec: &Specimen,
    settings: &Settings,
    points: Vec<Point>,
    relative: bool,
) -> Result<(f64, Option<f64>, String), PipelineError> {
    let est = crate::mechanics::prebulge::estimate(spec, &points, relative)
        .map_err(|e| PipelineError::Input(e.to_string()))?;
    // The cap estimate's own standard deviation, where it is determined.
    let cap_std = Some(est.std_m).filter(|s| s.is_finite() && *s > 0.0);
    let cap = format!(
        "prebulge_height_m from the cap formulas {:.4e} m (std {:.1e} m, {} points)",
        est.height_m, est.std_m, est.points
    );
    if !settings.refine {
        return Ok((
            est.height_m,
            cap_std,
            format!("{cap}; used as it is (no correction to the heights)"),
        ));
    }
    let at = Specimen {
        prebulge_height_m: est.height_m,
        ..*spec
    };
    let mr = Settings {
        fit: FitModel::Hyperelastic(crate::fit::hyperelastic::Kind::MooneyRivlin),
        refine: false,
        ..settings.clone()
    };
    let beside = || -> Result<(inverse::Refined, f64), PipelineError> {
        let stress = stress_stage(&at, &mr, shift(points.clone(), relative, est.height_m))?;
        let law = fit_stage(&at, &mr, &stress)?.material;
        Ok(inverse::refine_with_prebulge(
            &law,
            &at,
            &measured_heights(&points),
            &inverse::Options::default(),
            est.height_m,
            relative,
        )?)
    };
    match beside() {
        Ok((r, h0)) => {
            let rms = inverse::Refined::rms(&r.after).map_or(f64::NAN, |v| 100.0 * v);
            let std = r.prebulge_std_m;
            let pm = std.map_or_else(String::new, |s| format!(" +- {s:.1e}"));
            Ok((
                h0,
                std,
                format!(
                    "{cap}; beside a Mooney-Rivlin law corrected to the heights (rms {rms:.2} %): prebulge_height_m = {h0:.4e}{pm} m, used by stress, fit and simulate{}",
                    if std.is_some() {
                        " (its error carried to the law's intervals)"
                    } else {
                        ""
                    }
                ),
            ))
        }
        // The cap estimate stands, said with the reason.
        Err(e) => Ok((
            est.height_m,
            cap_std,
            format!("{cap}, used as it is: the search beside a Mooney-Rivlin law failed ({e})"),
        )),
    }
}

/// `points` with `h0` added to their heights when they are `relative` to a
/// reference photo of the stress-free dome.
pub fn shift(points: Vec<Point>, relative: bool, h0: f64) -> Vec<Point> {
    if !relative {
        return points;
    }
    points
        .into_iter()
        .map(|p| Point {
            height_m: p.height_m + h0,
            ..p
        })
        .collect()
}

/// Stage 2: heights -> stress and strain.
pub fn stress_stage(
    spec: &Specimen,
    settings: &Settings,
    points: Vec<Point>,
) -> Result<StressOut, PipelineError> {
    let rows = mechanics::stress_strain(spec, &settings.stress, &points)?;
    let shifts = point_shifts(spec, &settings.stress, &points, &settings.uncertainty)?;
    Ok(StressOut {
        points,
        rows,
        shifts,
    })
}

impl StressOut {
    /// `stress_strain.csv` in the columns of `bulge stress` (with `frame` and
    /// `file` first when given, and the `*_std` columns).
    pub fn csv(&self, labels: Option<&[(usize, String)]>) -> CsvOut {
        let mut header: Vec<&str> = Vec::new();
        if labels.is_some() {
            header.extend(["frame", "file"]);
        }
        header.extend(["pressure_pa", "height_m"]);
        header.extend(DERIVED_COLUMNS);
        header.push("height_std_m");
        header.extend(STD_COLUMNS);
        header.extend(CORR_COLUMNS);
        let mut out = CsvOut::new(&header);
        for (i, (p, r)) in self.points.iter().zip(&self.rows).enumerate() {
            let mut f = Vec::new();
            if let Some(l) = labels {
                f.push(l[i].0.to_string());
                f.push(l[i].1.clone());
            }
            f.push(fmt_num(Some(p.pressure_pa)));
            f.push(fmt_num(Some(p.height_m)));
            f.extend(r.value.to_array().into_iter().map(fmt_num));
            f.push(fmt_num(p.height_std_m));
            f.extend(
                r.std
                    .unwrap_or_default()
                    .to_array()
                    .into_iter()
                    .map(fmt_num),
            );
            f.extend(r.correlations().into_iter().map(fmt_num));
            out.row(&f);
        }
        out
    }
}

/// The points of a heights table (`pressure_pa`, `height_m` and optionally
/// `height_std_m`, as `bulge track` writes it). `height_std_m` given here is
/// every point's standard deviation; refused beside a `height_std_m` column
/// (one source of uncertainty, not a silent override).
pub fn heights_points(table: &Table, height_std_m: Option<f64>) -> Result<Vec<Point>, InputError> {
    let p_col = table.require("pressure_pa")?;
    let h_col = table.require("height_m")?;
    let std_col = table.column_index("height_std_m");
    if let (Some(sd), Some(_)) = (height_std_m, std_col) {
        return Err(InputError::cell(
            &table.path,
            1,
            "height_std_m",
            format!(
                "a height standard deviation of {sd} m was given for every point and the file has a height_std_m column: drop one of them (one source of uncertainty)"
            ),
        )
        .about_setting("height_std_m"));
    }
    (0..table.len())
        .map(|r| {
            let height_std_m = match (height_std_m, std_col) {
                (Some(sd), _) => Some(sd),
                (None, Some(c)) if !table.cell(r, c).is_empty() => Some(table.number(r, c)?),
                _ => None,
            };
            Ok(Point {
                pressure_pa: table.number(r, p_col)?,
                height_m: table.number(r, h_col)?,
                height_std_m,
            })
        })
        .collect()
}

/// The stress stage's rows checked for what a user would not trust: a
/// derived value that is not finite (inputs beyond double precision, such
/// as a pressure of 1e308 Pa or a thickness of 1e-320 m) is refused with its
/// row (index into `points`) and column; a height below a millionth of the
/// radius gets a warning (its strain is at round-off level and its secant
/// modulus meaningless).
pub fn check_stress_rows(
    spec: &Specimen,
    points: &[Point],
    rows: &[Row],
) -> Result<Vec<String>, (usize, &'static str, String)> {
    let mut warnings = Vec::new();
    for (i, (p, r)) in points.iter().zip(rows).enumerate() {
        for (name, v) in DERIVED_COLUMNS.iter().zip(r.value.to_array()) {
            if let Some(v) = v
                && !v.is_finite()
            {
                return Err((
                    i,
                    name,
                    format!(
                        "{name} is {v} for pressure {} Pa and height {} m on a disc of radius {} m and thickness {} m: \
                         the numbers are beyond double precision; check the units (Pa, m)",
                        crate::io::fmt_short(p.pressure_pa),
                        crate::io::fmt_short(p.height_m),
                        crate::io::fmt_short(spec.radius_m),
                        crate::io::fmt_short(spec.thickness_m)
                    ),
                ));
            }
        }
        if p.height_m > 0.0 && p.height_m < 1e-6 * spec.radius_m {
            warnings.push(format!(
                "point {}: the height {} m is {} of the radius: its strain is at round-off level and its secant modulus ({} Pa) meaningless",
                i + 1,
                crate::io::fmt_short(p.height_m),
                crate::io::fmt_short(p.height_m / spec.radius_m),
                crate::io::fmt_short(r.value.secant_modulus_pa.unwrap_or(f64::NAN))
            ));
        }
    }
    Ok(warnings)
}

/// `stress_strain.csv` of a heights table: its other columns carried
/// through first, then pressure and height as given, the derived values,
/// and (with an uncertainty) `height_std_m` when it was given for every
/// point (`std_given`) and the standard deviations.
pub fn stress_csv_of_table(
    table: &Table,
    points: &[Point],
    rows: &[Row],
    std_given: bool,
) -> Result<CsvOut, InputError> {
    let p_col = table.require("pressure_pa")?;
    let h_col = table.require("height_m")?;
    let carried: Vec<usize> = (0..table.headers.len())
        .filter(|&c| c != p_col && c != h_col)
        .collect();
    let with_std = points.iter().any(|p| p.height_std_m.is_some());
    let written = |name: &str| {
        DERIVED_COLUMNS.contains(&name)
            || (with_std
                && (STD_COLUMNS.contains(&name)
                    || CORR_COLUMNS.contains(&name)
                    || (std_given && name == "height_std_m")))
    };
    if let Some(&c) = carried.iter().find(|&&c| written(&table.headers[c])) {
        let name = &table.headers[c];
        return Err(InputError::cell(
            &table.path,
            1,
            name,
            format!(
                "the column `{name}` is one that bulge stress writes: rename or drop it in the input"
            ),
        ));
    }
    let mut header: Vec<&str> = carried.iter().map(|&c| table.headers[c].as_str()).collect();
    header.extend(["pressure_pa", "height_m"]);
    header.extend(DERIVED_COLUMNS);
    if with_std {
        if std_given {
            header.push("height_std_m");
        }
        header.extend(STD_COLUMNS);
        header.extend(CORR_COLUMNS);
    }
    let mut out = CsvOut::new(&header);
    for (r, row) in rows.iter().enumerate() {
        let mut fields: Vec<String> = carried
            .iter()
            .map(|&c| table.cell(r, c).to_string())
            .collect();
        fields.push(table.cell(r, p_col).to_string());
        fields.push(table.cell(r, h_col).to_string());
        fields.extend(row.value.to_array().into_iter().map(fmt_num));
        if with_std {
            if std_given {
                fields.push(fmt_num(points[r].height_std_m));
            }
            fields.extend(
                row.std
                    .unwrap_or_default()
                    .to_array()
                    .into_iter()
                    .map(fmt_num),
            );
            fields.extend(row.correlations().into_iter().map(fmt_num));
        }
        out.row(&fields);
    }
    Ok(out)
}

/// What `bulge stress` writes for a heights table: `stress_strain.csv`,
/// the shift table when the experiment states errors besides the heights',
/// and the warnings about points that cannot be trusted.
pub struct StressTables {
    /// `stress_strain.csv` ([`stress_csv_of_table`]).
    pub csv: CsvOut,
    /// `*_sources.csv` ([`shifts_csv`]); `None` without stated errors.
    pub sources_csv: Option<CsvOut>,
    /// Said, not refused: heights at round-off level.
    pub warnings: Vec<String>,
    /// Rows written.
    pub rows: usize,
    /// Whether the points have standard deviations (the `*_std` columns).
    pub with_std: bool,
}

/// Why a heights table gave no stress table.
#[derive(Debug, thiserror::Error)]
pub enum StressTableError {
    /// A cell, a column or the specimen refused: the message names the
    /// file, the line and the fix.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The formulas refused the specimen.
    #[error("invalid specimen: {0}")]
    Specimen(String),
    /// A point's shift under an input's error could not be computed.
    #[error("the change of a point under an input's error: {0}")]
    Shifts(mechanics::StressError),
}

impl crate::Refusal for StressTableError {
    fn is_bad_input(&self) -> bool {
        !matches!(self, StressTableError::Shifts(_))
    }
}

/// `bulge stress`: the points of a heights `table` (`height_std_m`, when
/// given, every point's standard deviation), their stress and strain under
/// `opts`, checked, as `stress_strain.csv`, with the shift of each point
/// under each of `sources`' errors. A bad cell is refused at its line.
pub fn stress_of_table(
    spec: &Specimen,
    opts: &mechanics::Options,
    table: &Table,
    height_std_m: Option<f64>,
    sources: &Sources,
) -> Result<StressTables, StressTableError> {
    let points = heights_points(table, height_std_m)?;
    let rows = mechanics::stress_strain(spec, opts, &points).map_err(|e| match e {
        mechanics::StressError::Point { index, problem } => {
            StressTableError::Input(table.error_at(index, problem.column(), problem.to_string()))
        }
        mechanics::StressError::Specimen(m) => StressTableError::Specimen(m.to_string()),
    })?;
    let warnings =
        check_stress_rows(spec, &points, &rows).map_err(|(i, col, m)| table.error_at(i, col, m))?;
    let csv = stress_csv_of_table(table, &points, &rows, height_std_m.is_some())?;
    let shifts = point_shifts(spec, opts, &points, sources).map_err(StressTableError::Shifts)?;
    Ok(StressTables {
        csv,
        sources_csv: shifts_csv(&points, &shifts),
        warnings,
        rows: rows.len(),
        with_std: points.iter().any(|p| p.height_std_m.is_some()),
    })
}
