//! A pressure log by time (`time_s,pressure_pa`, a logger at its own rate)
//! and its linear interpolation at the frames' times.
//!
//! The camera and the logger keep their own clocks. `[pressure] offset_s`
//! aligns them: **logger time = frame time + `offset_s`** (the logger's clock
//! reads `offset_s` when the camera's reads 0; a logger started 0.4 s before
//! the camera has `offset_s = 0.4`).

use std::path::{Path, PathBuf};

use crate::io::{InputError, Table, fmt_short};

/// A pressure log: strictly increasing times, s, and pressures, Pa.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureLog {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// Logger times, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Pressures, Pa.
    pub pressure_pa: Vec<f64>,
}

/// A frame time outside the log's span.
#[derive(Debug, Clone, PartialEq)]
pub struct OutsideLog {
    /// The logger time asked for, s.
    pub logger_time_s: f64,
    /// The log's first time, s.
    pub first_s: f64,
    /// The log's last time, s.
    pub last_s: f64,
}

impl PressureLog {
    /// True when a table is a log by time: a `time_s` column and no `file`
    /// column (a table with `file` is joined per photo).
    pub fn is_time_log(t: &Table) -> bool {
        t.column_index("file").is_none() && t.column_index("time_s").is_some()
    }

    /// Reads a log by time from its table: columns `time_s` and
    /// `pressure_pa`, finite numbers, at least two rows, times strictly
    /// increasing (each refusal names the file, line and value).
    pub fn from_table(t: &Table) -> Result<Self, InputError> {
        let tc = t.require("time_s")?;
        let pc = t.require("pressure_pa")?;
        let mut time_s = Vec::with_capacity(t.len());
        let mut pressure_pa = Vec::with_capacity(t.len());
        for r in 0..t.len() {
            let ts = t.number(r, tc)?;
            let p = t.number(r, pc)?;
            if let Some(&prev) = time_s.last()
                && ts <= prev
            {
                return Err(t.error_at(
                    r,
                    "time_s",
                    format!(
                        "time_s = {} s is not after the previous row's {} s (line {}): the log's times must increase strictly; sort the log by time or remove the repeated row",
                        fmt_short(ts),
                        fmt_short(prev),
                        t.lines[r - 1]
                    ),
                ));
            }
            time_s.push(ts);
            pressure_pa.push(p);
        }
        if time_s.len() < 2 {
            return Err(InputError::file(
                &t.path,
                format!(
                    "a pressure log by time (columns time_s,pressure_pa) needs at least two rows to interpolate between; it has {}",
                    time_s.len()
                ),
            ));
        }
        Ok(PressureLog {
            path: t.path.clone(),
            time_s,
            pressure_pa,
        })
    }

    /// Reads a log by time from a CSV file.
    pub fn read(path: &Path) -> Result<Self, InputError> {
        Self::from_table(&Table::read(path)?)
    }

    /// The log's first and last time, s.
    pub fn span(&self) -> (f64, f64) {
        (self.time_s[0], self.time_s[self.time_s.len() - 1])
    }

    /// The pressure at logger time `t`, Pa, linearly interpolated between
    /// the two rows around it; a time outside the log's span is refused.
    pub fn at(&self, t: f64) -> Result<f64, OutsideLog> {
        let (first, last) = self.span();
        if !(t.is_finite() && t >= first && t <= last) {
            return Err(OutsideLog {
                logger_time_s: t,
                first_s: first,
                last_s: last,
            });
        }
        // the first row after t (t == last: the last interval)
        let k = self
            .time_s
            .partition_point(|&x| x <= t)
            .clamp(1, self.time_s.len() - 1);
        let (t0, t1) = (self.time_s[k - 1], self.time_s[k]);
        let (p0, p1) = (self.pressure_pa[k - 1], self.pressure_pa[k]);
        let w = (t - t0) / (t1 - t0);
        Ok(p0 + w * (p1 - p0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log(text: &str) -> Result<PressureLog, InputError> {
        PressureLog::from_table(&Table::parse(Path::new("log.csv"), text.as_bytes())?)
    }

    #[test]
    fn interpolates_linearly_inside_and_refuses_outside() {
        let l = log("time_s,pressure_pa\n0,100\n0.5,200\n1.5,600\n").unwrap();
        assert_eq!(l.at(0.0).unwrap(), 100.0);
        assert!((l.at(0.25).unwrap() - 150.0).abs() < 1e-12);
        assert!((l.at(1.0).unwrap() - 400.0).abs() < 1e-12);
        assert_eq!(l.at(1.5).unwrap(), 600.0);
        let e = l.at(1.6).unwrap_err();
        assert_eq!((e.first_s, e.last_s), (0.0, 1.5));
        assert!(l.at(-0.01).is_err());
        assert!(l.at(f64::NAN).is_err());
    }

    #[test]
    fn refuses_times_that_do_not_increase() {
        let e = log("time_s,pressure_pa\n0,100\n0.5,200\n0.5,300\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("log.csv"), "{e}");
        assert!(e.contains("line 4"), "{e}");
        assert!(
            e.contains("not after the previous row's 0.5 s (line 3)"),
            "{e}"
        );
        let e = log("time_s,pressure_pa\n1,100\n0.5,200\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 3") && e.contains("increase strictly"),
            "{e}"
        );
        let e = log("time_s,pressure_pa\n1,100\n").unwrap_err().to_string();
        assert!(e.contains("at least two rows"), "{e}");
    }

    /// A smooth ramp sampled at 7 Hz on a clock 0.4 s ahead of the frames':
    /// interpolated at the frames' times within the bound of linear
    /// interpolation, h^2/8 max|p''|; the offset taken with the wrong sign
    /// misses by far more.
    #[test]
    fn a_seven_hertz_log_with_an_offset_gives_each_frame_its_pressure() {
        let (rate, offset) = (7.0, 0.4);
        let p = |t: f64| 1000.0 + 400.0 * t + 100.0 * (std::f64::consts::PI * t).sin().powi(2);
        // p'' = 100 * 2 pi^2 cos(2 pi t), |p''| <= 200 pi^2
        let bound = (1.0f64 / rate).powi(2) / 8.0 * 200.0 * std::f64::consts::PI.powi(2);
        let mut text = String::from("time_s,pressure_pa\n");
        for j in 0..=80 {
            let tau = j as f64 / rate;
            text += &format!("{tau},{}\n", p(tau - offset));
        }
        let l = log(&text).unwrap();
        let mut worst: f64 = 0.0;
        let mut worst_wrong: f64 = 0.0;
        for k in 0..20 {
            let t = 0.5 * k as f64;
            worst = worst.max((l.at(t + offset).unwrap() - p(t)).abs());
            if let Ok(v) = l.at(t - offset) {
                worst_wrong = worst_wrong.max((v - p(t)).abs());
            }
        }
        assert!(worst <= bound, "error {worst} Pa > bound {bound} Pa");
        assert!(worst_wrong > 10.0 * bound, "wrong sign: {worst_wrong}");
    }
}
