//! Measured heights as the input of a run (`[heights]` in the experiment
//! file, in place of `[photos]`): a laser gauge's or a 3D digital image
//! correlation's apex heights, one row per pressure stage.
//!
//! ```toml
//! [heights]
//! csv = "heights.csv"     # columns pressure_pa, height_m, optional height_std_m
//! origin = "reference"    # "clamp" (default): above the clamp plane;
//!                         # "reference": above a stress-free (slack, domed) state
//! ```
//!
//! The file is checked as a whole before any stage runs: every error names
//! the file, the line, the value and the fix (a missing column, pressures
//! not increasing, a negative height, heights that look like millimetres).

use std::path::Path;

use crate::experiment::{Experiment, HeightsOrigin};
use crate::io::{InputError, Table};
use crate::mechanics::Point;

/// The measured points of a `[heights]` file and what they are measured
/// from.
#[derive(Debug, Clone, PartialEq)]
pub struct Heights {
    /// One point per row, in the file's order (pressures increasing).
    pub points: Vec<Point>,
    /// Above a stress-free reference state (the apex stands at `h + h0`)
    /// rather than above the clamp plane.
    pub relative: bool,
}

/// The points of the experiment's `[heights]` file, checked; `None` when the
/// experiment has no `[heights]`.
pub fn of_experiment(exp: &Experiment) -> Option<Result<Heights, InputError>> {
    let cfg = exp.heights.as_ref()?;
    let path = exp.resolve(&cfg.csv);
    let relative = cfg.origin == HeightsOrigin::Reference;
    Some(read(&path, exp.specimen.radius_m, relative))
}

/// Reads and checks a heights file for a specimen of free radius `radius_m`.
pub fn read(path: &Path, radius_m: f64, relative: bool) -> Result<Heights, InputError> {
    let table = Table::read(path)?;
    let points = crate::pipeline::heights_points(&table, None)?;
    check(&table, &points, radius_m, relative)?;
    Ok(Heights { points, relative })
}

/// The checks of [`read`] on points read from `table` (row `i` of the
/// points is row `i` of the table).
pub fn check(
    table: &Table,
    points: &[Point],
    radius_m: f64,
    relative: bool,
) -> Result<(), InputError> {
    let origin = if relative {
        "the reference state"
    } else {
        "the clamp plane"
    };
    if points.len() < 2 {
        return Err(InputError::file(
            &table.path,
            format!(
                "{} row(s) of pressure_pa,height_m: a run needs at least 2 (one per pressure stage)",
                points.len()
            ),
        ));
    }
    for (i, p) in points.iter().enumerate() {
        if p.pressure_pa < 0.0 {
            return Err(table.error_at(
                i,
                "pressure_pa",
                format!(
                    "pressure {} Pa is negative: give the inflation pressure above ambient, in Pa",
                    p.pressure_pa
                ),
            ));
        }
        if p.height_m < 0.0 {
            return Err(table.error_at(
                i,
                "height_m",
                format!(
                    "height {} m is negative: heights are measured upward from {origin}; flip the sign of the column if the gauge counts downward",
                    p.height_m
                ),
            ));
        }
        if p.height_m > radius_m {
            return Err(table.error_at(
                i,
                "height_m",
                format!(
                    "height {} m is above the specimen's radius {} m: heights must be in metres (divide millimetres by 1000)",
                    p.height_m, radius_m
                ),
            ));
        }
        if let Some(sd) = p.height_std_m
            && (sd.is_nan() || sd < 0.0)
        {
            return Err(table.error_at(
                i,
                "height_std_m",
                format!("height_std_m = {sd} must be zero or positive (a standard deviation, m)"),
            ));
        }
        if i > 0 && p.pressure_pa <= points[i - 1].pressure_pa {
            return Err(table.error_at(
                i,
                "pressure_pa",
                format!(
                    "pressure {} Pa does not increase on the previous row's {} Pa: give the loading branch only, one row per stage, in increasing pressure (leave unloading stages out)",
                    p.pressure_pa,
                    points[i - 1].pressure_pa
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str, relative: bool) -> Result<Heights, InputError> {
        let path = Path::new("h.csv");
        let table = Table::parse(path, text.as_bytes())?;
        let points = crate::pipeline::heights_points(&table, None)?;
        check(&table, &points, 0.1, relative)?;
        Ok(Heights { points, relative })
    }

    #[test]
    fn a_good_file_is_read_with_its_std() {
        let h = read_text(
            "pressure_pa,height_m,height_std_m\n100,0.01,1e-5\n200,0.012,\n",
            true,
        )
        .unwrap();
        assert_eq!(h.points.len(), 2);
        assert_eq!(h.points[0].height_std_m, Some(1e-5));
        assert_eq!(h.points[1].height_std_m, None);
    }

    #[test]
    fn bad_files_are_refused_with_line_value_and_fix() {
        let cases = [
            ("pressure_pa,h\n1,0.01\n2,0.02\n", "height_m"),
            (
                "pressure_pa,height_m\n100,0.01\n90,0.02\n",
                "does not increase",
            ),
            ("pressure_pa,height_m\n100,-0.01\n200,0.02\n", "negative"),
            ("pressure_pa,height_m\n100,10\n200,12\n", "millimetres"),
            ("pressure_pa,height_m\n100,0.01\n", "at least 2"),
        ];
        for (text, want) in cases {
            let e = read_text(text, false).unwrap_err().to_string();
            assert!(e.contains(want), "{text:?}: {e}");
            assert!(e.contains("h.csv"), "{e}");
        }
        let e = read_text("pressure_pa,height_m\n100,0.01\n90,0.02\n", false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3") && e.contains("90"), "{e}");
    }
}
