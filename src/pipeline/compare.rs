//! Simulated against measured heights: the comparison per pressure and the
//! verdict per model.

use crate::fit::inverse;
use crate::io::fmt_short;
use crate::mechanics::Point;
use crate::sim::springs::HeightModel;

use super::*;

/// One row of the comparison table (Tudruj et al. (2023), Table 3 layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Measured height, m (mean over frames at this pressure), if measured.
    pub measured_m: Option<f64>,
    /// Its standard deviation, m.
    pub measured_std_m: Option<f64>,
    /// Simulated height per model, in the order of [`RunOutput::runs`]
    /// (by model: [`RunOutput::rel_errors_of`]), m.
    pub simulated_m: Vec<Option<f64>>,
}

impl Comparison {
    /// Relative error `(simulated - measured) / measured` per model.
    pub fn rel_errors(&self) -> Vec<Option<f64>> {
        self.simulated_m
            .iter()
            .map(|s| match (s, self.measured_m) {
                (Some(s), Some(m)) if m != 0.0 => Some((s - m) / m),
                _ => None,
            })
            .collect()
    }
}

/// The comparison table: one row per simulated pressure.
pub fn compare(points: &[Point], runs: &[ModelRun], pressures: &[f64]) -> Vec<Comparison> {
    pressures
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let same: Vec<&Point> = points.iter().filter(|q| q.pressure_pa == p).collect();
            let n = same.len() as f64;
            let measured_m =
                (!same.is_empty()).then(|| same.iter().map(|q| q.height_m).sum::<f64>() / n);
            let measured_std_m = if same.is_empty() {
                None
            } else {
                let v: Option<Vec<f64>> = same.iter().map(|q| q.height_std_m).collect();
                v.map(|v| (v.iter().map(|s| s * s).sum::<f64>()).sqrt() / n)
            };
            Comparison {
                pressure_pa: p,
                measured_m,
                measured_std_m,
                simulated_m: runs
                    .iter()
                    .map(|r| r.points.get(i).and_then(|q| q.height_m))
                    .collect(),
            }
        })
        .collect()
}

/// How one model's heights stand against the measured ones within the
/// uncertainty: at each compared pressure `z = (h_model - h_measured) /
/// sd`, `sd` the standard deviation of that difference (the measured
/// height's own, and the corrected law's through the parameters'
/// covariance with the shared errors of both sides,
/// [`inverse::BandPoint::diff_std_m`]). The model is consistent when
/// every `|z|` stays below the two-sided 95 % bound for the largest of `n`
/// independent normals (Sidak's `Phi^-1(1 - (1 - 0.95^(1/n)) / 2)`: 1.96
/// for one pressure, 2.80 for ten), so that a model that is right passes
/// 95 % of the time however many pressures are compared (Z. Sidak,
/// "Rectangular confidence regions for the means of multivariate normal
/// distributions", JASA 62(318), 1967, doi:10.1080/01621459.1967.10482935).
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The model.
    pub model: HeightModel,
    /// Pressures compared.
    pub compared: usize,
    /// The largest `|z|` and its pressure, Pa.
    pub worst: Option<(f64, f64)>,
    /// The bound on `|z|`.
    pub bound: f64,
}

impl Verdict {
    /// Whether every compared height is within the bound (`None`: nothing
    /// compared).
    pub fn consistent(&self) -> Option<bool> {
        self.worst.map(|(z, _)| z <= self.bound)
    }

    /// "consistent within the uncertainty (largest |z| 1.3 of 2.80 allowed)"
    /// or "misses by 4.2 standard deviations at 3200 Pa".
    pub fn describe(&self) -> String {
        match self.worst {
            None => "no measured height with an uncertainty to compare".into(),
            Some((z, _)) if z <= self.bound => format!(
                "consistent within the uncertainty (largest |z| {z:.2} of {:.2} allowed over {} pressures)",
                self.bound, self.compared
            ),
            Some((z, p_pa)) => format!(
                "misses by {z:.1} standard deviations at {} Pa (allowed {:.2} over {} pressures)",
                fmt_short(p_pa),
                self.bound,
                self.compared
            ),
        }
    }
}

/// The verdict of every run against the measured heights (see [`Verdict`]);
/// `band` at the pressures of `rows`.
pub fn verdicts(
    rows: &[Comparison],
    runs: &[ModelRun],
    band: &[Option<inverse::BandPoint>],
) -> Vec<Verdict> {
    runs.iter()
        .enumerate()
        .map(|(k, r)| {
            let z: Vec<(f64, f64)> = rows
                .iter()
                .zip(band)
                .filter_map(|(c, b)| {
                    let (h, m, b) = (c.simulated_m.get(k).copied()??, c.measured_m?, (*b)?);
                    let sd = c.measured_std_m.unwrap_or(0.0).hypot(b.diff_std_m);
                    (sd > 0.0).then(|| ((h - m).abs() / sd, c.pressure_pa))
                })
                .collect();
            let n = z.len().max(1) as f64;
            let bound =
                crate::fit::uncertainty::normal_quantile(1.0 - 0.5 * (1.0 - 0.95f64.powf(1.0 / n)));
            Verdict {
                model: r.model,
                compared: z.len(),
                worst: z.into_iter().max_by(|a, b| a.0.total_cmp(&b.0)),
                bound,
            }
        })
        .collect()
}
