//! The files that `bulge fit` writes beside `material.toml`: the fitted
//! curve on a fine grid, the residual at every point, the comparison table
//! of `all`, a plain-text summary and (feature `plots`) the figure of the
//! data, the law and the residuals.

use std::path::{Path, PathBuf};

use crate::fit::data::Loaded;
use crate::fit::hyperelastic::{Equibiaxial, HyperFit, Kind};
use crate::fit::quartic::{self, PolyFit};
use crate::fit::{FitDetail, FitModel, FitSettings, FittedMaterial};
use crate::io::{CsvOut, fmt_num};
use crate::material::StrainMeasure;
#[cfg(feature = "plots")]
use crate::report::plot::{Figure, LegendPosition, Panel, Series};

/// The files of a fit, named after the material file: `<stem>_curve.csv`,
/// `<stem>_residuals.csv`, `<stem>_fit.svg`, `<stem>_fit.png`,
/// `<stem>_models.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct FitPaths {
    /// The material file.
    pub material: PathBuf,
    /// The fitted curve.
    pub curve: PathBuf,
    /// The residuals.
    pub residuals: PathBuf,
    /// The figure as SVG.
    pub svg: PathBuf,
    /// The figure as PNG.
    pub png: PathBuf,
    /// The comparison of every model (`all`).
    pub models: PathBuf,
}

impl FitPaths {
    /// The side files (every path but the material).
    pub fn sides(&self) -> [&Path; 5] {
        [
            &self.curve,
            &self.residuals,
            &self.svg,
            &self.png,
            &self.models,
        ]
    }

    /// The paths beside `material`.
    pub fn new(material: &Path) -> Self {
        let stem = material
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "material".into());
        let dir = material.parent().unwrap_or(Path::new(""));
        let f = |suffix: &str| dir.join(format!("{stem}{suffix}"));
        Self {
            material: material.to_path_buf(),
            curve: f("_curve.csv"),
            residuals: f("_residuals.csv"),
            svg: f("_fit.svg"),
            png: f("_fit.png"),
            models: f("_models.csv"),
        }
    }
}

/// Everything `bulge fit` writes besides the material, built in memory.
pub struct FitOutputs {
    /// The fitted curve on a grid of `samples` points (`<stem>_curve.csv`).
    pub curve: CsvOut,
    /// Data, fit and residual at every point (`<stem>_residuals.csv`).
    pub residuals: CsvOut,
    /// The comparison table of every model (`<stem>_models.csv`, `all` only).
    pub models: Option<CsvOut>,
    /// What was fitted and how well, for the terminal.
    pub summary: String,
    /// Data, law and residuals (`<stem>_fit.svg`, `<stem>_fit.png`).
    #[cfg(feature = "plots")]
    pub figure: Figure,
}

/// The outputs of a fit of `data` (named `input` in titles and messages)
/// with `samples` points on the curve (at least 2).
pub fn fit_outputs(
    fitted: &FittedMaterial,
    data: &Loaded,
    settings: &FitSettings,
    input: &str,
    samples: usize,
) -> FitOutputs {
    let samples = samples.max(2);
    match &fitted.detail {
        FitDetail::Quartic(fit) => {
            let degree = match fitted.model {
                FitModel::Quartic { degree } => degree,
                _ => fit.coefficients_pa.len() - 1,
            };
            quartic_outputs(fit, degree, data, settings, input, samples)
        }
        FitDetail::Hyper { fits, best } => hyper_outputs(fits, *best, data, input, samples),
    }
}

/// Stress display unit for data of magnitude `max`.
#[cfg(feature = "plots")]
fn stress_unit(max: f64) -> (f64, &'static str) {
    if max >= 1e5 {
        (1e-6, "MPa")
    } else {
        (1e-3, "kPa")
    }
}

fn stretch_of_strain(m: StrainMeasure, e: f64) -> f64 {
    match m {
        StrainMeasure::Engineering => 1.0 + e,
        StrainMeasure::Log => e.exp(),
    }
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

#[cfg(feature = "plots")]
fn file_name(p: &str) -> String {
    std::path::Path::new(p)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.to_string())
}

fn label_column(k: &Kind) -> String {
    k.label().replace('-', "_")
}

fn quartic_outputs(
    fit: &PolyFit,
    degree: usize,
    data: &Loaded,
    set: &FitSettings,
    input: &str,
    samples: usize,
) -> FitOutputs {
    #![cfg_attr(not(feature = "plots"), allow(unused_variables, unused_mut))]
    let (strain, modulus) = data.modulus_points();
    let k = set.modulus.factor(set.poisson);
    let sm = data.strain_measure;
    let skipped = data.modulus_pa.iter().filter(|m| m.is_none()).count();
    // Curve on a grid; the stress the law implies is E eps / k.
    let [lo, hi] = fit.strain_range;
    let xs = grid(lo, hi, samples);
    let mut curve = CsvOut::new(&["stretch", "strain", "modulus_pa", "implied_stress_pa"]);
    let mut e_line = Vec::new();
    let mut s_line = Vec::new();
    for &e in &xs {
        let m = quartic::eval(&fit.coefficients_pa, e);
        let s = m * e / k;
        curve.row(&[
            fmt_num(Some(stretch_of_strain(sm, e))),
            fmt_num(Some(e)),
            fmt_num(Some(m)),
            fmt_num(Some(s)),
        ]);
        e_line.push((e, m));
        s_line.push((e, s));
    }
    let mut residuals = CsvOut::new(&[
        "line",
        "strain",
        "modulus_pa",
        "fit_modulus_pa",
        "residual_pa",
    ]);
    let used: Vec<usize> = (0..data.strain.len())
        .filter(|&i| data.modulus_pa[i].is_some())
        .collect();
    for (j, &i) in used.iter().enumerate() {
        residuals.row(&[
            data.lines[i].to_string(),
            fmt_num(Some(strain[j])),
            fmt_num(Some(modulus[j])),
            fmt_num(Some(modulus[j] - fit.residuals_pa[j])),
            fmt_num(Some(fit.residuals_pa[j])),
        ]);
    }

    #[cfg(feature = "plots")]
    let figure = {
        // Plot: modulus, implied stress, residuals.
        let emax = modulus.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (f, unit) = stress_unit(emax);
        let smax = strain
            .iter()
            .zip(&modulus)
            .fold(0.0f64, |m, (e, v)| m.max((v * e / k).abs()));
        let (fs, sunit) = stress_unit(smax);
        let sc =
            |pts: &[(f64, f64)], f: f64| pts.iter().map(|&(x, y)| (x, y * f)).collect::<Vec<_>>();
        let data_pts: Vec<(f64, f64)> =
            strain.iter().zip(&modulus).map(|(&e, &m)| (e, m)).collect();
        let mut data_series = Series::scatter("secant modulus (data)", sc(&data_pts, f));
        if data.modulus_std_pa.iter().any(Option::is_some) {
            let errs: Vec<f64> = used
                .iter()
                .map(|&i| data.modulus_std_pa[i].unwrap_or(f64::NAN) * f)
                .collect();
            data_series = data_series.with_errors(errs);
        }
        let strain_label = format!("{} strain (-)", sm.name());
        let p1 = Panel::new(&strain_label, format!("secant modulus E ({unit})"))
            .with(data_series)
            .with(Series::line(
                format!("E(eps), degree {}", degree),
                sc(&e_line, f),
            ))
            .legend(LegendPosition::UpperRight)
            .weight(2.0);
        let stress_pts: Vec<(f64, f64)> = strain
            .iter()
            .zip(&modulus)
            .map(|(&e, &m)| (e, m * e / k))
            .collect();
        let p2 = Panel::new(
            &strain_label,
            format!(
                "stress E eps / {} ({sunit})",
                if k == 1.0 {
                    "1".to_string()
                } else {
                    format!("(1 - {})", set.poisson)
                }
            ),
        )
        .with(Series::scatter("data", sc(&stress_pts, fs)))
        .with(Series::line("implied by the law", sc(&s_line, fs)))
        .weight(2.0);
        let res_pts: Vec<(f64, f64)> = strain
            .iter()
            .zip(&fit.residuals_pa)
            .map(|(&e, &r)| (e, r * f))
            .collect();
        let p3 = Panel::new(&strain_label, format!("residual ({unit})"))
            .with(Series::scatter("", res_pts).color(2))
            .zero_line()
            .weight(1.2);
        Figure::new(
            format!(
                "Secant modulus law, degree {} ({})",
                degree,
                file_name(input)
            ),
            vec![p1, p2, p3],
        )
        .size(900, 1000)
    };

    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} points ({} skipped at zero strain), {} strain, {} modulus\n",
        input,
        fit.stats.n,
        skipped,
        sm.name(),
        set.modulus.name()
    ));
    s.push_str(&format!(
        "E(eps) = sum c_k eps^k, degree {}, strain range [{:.6}, {:.6}]\n",
        degree, lo, hi
    ));
    for (i, c) in fit.coefficients_pa.iter().enumerate() {
        let se = fit
            .std_errors_pa
            .as_ref()
            .map(|s| format!(" +- {:.4e}", s[i]))
            .unwrap_or_default();
        s.push_str(&format!("  c{i} = {c:.6e} Pa{se}\n"));
    }
    s.push_str(&format!(
        "RMSE {:.4e} Pa, R^2 {:.6}, AIC {:.3}, condition number {:.3e} (scaled; {:.3e} unscaled)\n",
        fit.stats.rmse, fit.stats.r2, fit.stats.aic, fit.condition_scaled, fit.condition_raw
    ));
    s.push_str(&weighted_line(fit.chi2_per_dof));
    FitOutputs {
        curve,
        residuals,
        models: None,
        summary: s,
        #[cfg(feature = "plots")]
        figure,
    }
}

/// The summary's line on the weights of a weighted fit (nothing for an
/// unweighted one).
fn weighted_line(chi2_per_dof: Option<f64>) -> String {
    chi2_per_dof.map_or_else(String::new, |c| {
        format!(
            "weighted by each point's uncertainty carried from its height's: chi2 / dof {c:.3} (about 1 when the law and the heights' standard deviations hold)\n"
        )
    })
}

fn hyper_outputs(
    fits: &[HyperFit],
    best: usize,
    src: &Loaded,
    input: &str,
    samples: usize,
) -> FitOutputs {
    #![cfg_attr(not(feature = "plots"), allow(unused_variables))]
    let data: &Equibiaxial = &src.equibiaxial;
    let measure = data.measure.name();
    let chosen = &fits[best];
    // Curve on a grid from min(1, l_min) to l_max.
    let lo = data.stretch.iter().copied().fold(1.0f64, f64::min);
    let hi = data.stretch[data.stretch.len() - 1];
    let ls = grid(lo, hi, samples);
    let curve = if fits.len() == 1 {
        let h = chosen.model.hyperelastic().expect("hyperelastic");
        let mut c = CsvOut::new(&["stretch", "nominal_stress_pa", "cauchy_stress_pa"]);
        for &l in &ls {
            c.row(&[
                fmt_num(Some(l)),
                fmt_num(Some(h.equibiaxial_nominal(l) + 0.0)),
                fmt_num(Some(h.equibiaxial_cauchy(l) + 0.0)),
            ]);
        }
        c
    } else {
        let mut header = vec!["stretch".to_string()];
        header.extend(
            fits.iter()
                .map(|f| format!("{}_{measure}_stress_pa", label_column(&f.kind))),
        );
        let mut c = CsvOut::new(&header);
        for &l in &ls {
            let mut row = vec![fmt_num(Some(l))];
            row.extend(
                fits.iter()
                    .map(|f| fmt_num(Some(data.predict(&f.model, l) + 0.0))),
            );
            c.row(&row);
        }
        c
    };
    let mut header = vec![
        "line".to_string(),
        "stretch".into(),
        format!("{measure}_stress_pa"),
    ];
    for f in fits {
        header.push(format!("{}_residual_pa", label_column(&f.kind)));
    }
    let mut residuals = CsvOut::new(&header);
    for i in 0..data.stretch.len() {
        let mut row = vec![
            src.lines[i].to_string(),
            fmt_num(Some(data.stretch[i])),
            fmt_num(Some(data.stress_pa[i])),
        ];
        row.extend(fits.iter().map(|f| fmt_num(Some(f.residuals_pa[i]))));
        residuals.row(&row);
    }

    // Comparison table.
    let models = (fits.len() > 1).then(|| {
        let mut c = CsvOut::new(&[
            "model",
            "parameters",
            "points",
            "rmse_pa",
            "r2",
            "aic",
            "aicc",
            "drucker_stable",
            "selected",
            "values",
        ]);
        for (i, f) in fits.iter().enumerate() {
            c.row(&[
                f.kind.label(),
                f.kind.n_params().to_string(),
                f.stats.n.to_string(),
                fmt_num(Some(f.stats.rmse)),
                fmt_num(Some(f.stats.r2)),
                fmt_num(Some(f.stats.aic)),
                fmt_num(f.stats.aicc),
                f.drucker.stable.to_string(),
                (i == best).to_string(),
                f.params
                    .iter()
                    .map(|p| format!("{}={}", p.name, p.value))
                    .collect::<Vec<_>>()
                    .join(" "),
            ]);
        }
        c
    });

    #[cfg(feature = "plots")]
    let figure = {
        // Plot.
        let smax = data.stress_pa.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (f, unit) = stress_unit(smax);
        let rmax = fits
            .iter()
            .flat_map(|f| f.residuals_pa.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let (fr, runit) = stress_unit(rmax * 10.0);
        let pts: Vec<(f64, f64)> = data
            .stretch
            .iter()
            .zip(&data.stress_pa)
            .map(|(&l, &s)| (l, s * f))
            .collect();
        let mut p1 = Panel::new(
            "equibiaxial stretch (-)",
            format!("{measure} stress ({unit})"),
        )
        .with(Series::scatter("data", pts).color(0))
        .weight(2.0);
        let mut p2 = Panel::new(
            "equibiaxial stretch (-)",
            format!("residual, data - model ({runit})"),
        )
        .zero_line();
        for (k, fit) in fits.iter().enumerate() {
            let line: Vec<(f64, f64)> = ls
                .iter()
                .map(|&l| (l, data.predict(&fit.model, l) * f))
                .collect();
            let name = format!(
                "{} (RMSE {:.3} {unit})",
                fit.kind.label(),
                fit.stats.rmse * f
            );
            p1 = p1.with(Series::line(name, line).color(k + 1));
            let res: Vec<(f64, f64)> = data
                .stretch
                .iter()
                .zip(&fit.residuals_pa)
                .map(|(&l, &r)| (l, r * fr))
                .collect();
            p2 = p2.with(
                Series::scatter(
                    if fits.len() > 1 {
                        String::new()
                    } else {
                        fit.kind.label()
                    },
                    res,
                )
                .color(k + 1),
            );
        }
        let title = if fits.len() == 1 {
            format!(
                "{} fit, equibiaxial ({})",
                chosen.kind.label(),
                file_name(input)
            )
        } else {
            format!("Hyperelastic models, equibiaxial ({})", file_name(input))
        };
        Figure::new(title, vec![p1, p2]).size(900, 800)
    };

    let mut s = String::new();
    s.push_str(&format!(
        "{}: {} points, fitted in {measure} stress ({})\n",
        input,
        data.stretch.len(),
        src.stress_column
    ));
    if fits.len() > 1 {
        s.push_str(&format!(
            "{:<14} {:>2} {:>12} {:>9} {:>9} {:>9} {:>8}\n",
            "model", "k", "RMSE (Pa)", "R^2", "AIC", "AICc", "Drucker"
        ));
        for (i, f) in fits.iter().enumerate() {
            s.push_str(&format!(
                "{:<14} {:>2} {:>12.1} {:>9.6} {:>9.2} {:>9} {:>8}{}\n",
                f.kind.label(),
                f.kind.n_params(),
                f.stats.rmse,
                f.stats.r2,
                f.stats.aic,
                f.stats
                    .aicc
                    .map(|a| format!("{a:.2}"))
                    .unwrap_or_else(|| "-".into()),
                if f.drucker.stable {
                    "stable"
                } else {
                    "UNSTABLE"
                },
                if i == best {
                    "  <- selected (lowest AICc, stable)"
                } else {
                    ""
                }
            ));
        }
    }
    s.push_str(&format!("{}:\n", chosen.kind.label()));
    for p in &chosen.params {
        let se = p
            .std_error
            .map(|e| format!(" +- {e:.4e}"))
            .unwrap_or_default();
        s.push_str(&format!("  {} = {:.6e}{se}\n", p.name, p.value));
    }
    s.push_str(&format!(
        "RMSE {:.4e} Pa, R^2 {:.6}, AIC {:.3}, Drucker-stable over stretch [{:.3}, {:.3}]: {} ({} starts, {} LM iterations)\n",
        chosen.stats.rmse,
        chosen.stats.r2,
        chosen.stats.aic,
        chosen.drucker.range[0],
        chosen.drucker.range[1],
        if chosen.drucker.stable { "yes" } else { "no" },
        chosen.starts,
        chosen.iterations
    ));
    s.push_str(&weighted_line(chosen.chi2_per_dof));
    FitOutputs {
        curve,
        residuals,
        models,
        summary: s,
        #[cfg(feature = "plots")]
        figure,
    }
}
