//! The report's figures, built on [`super::plot`]: height against pressure
//! (measured with error bars, each model as a line, and the relative error
//! per model below), and the fit (stress against strain with the law, the
//! secant modulus `E(eps)` with the law, residuals of the points' own fit);
//! with the correction to the heights, both laws.

use super::plot::{Figure, LegendPosition, Panel, Series};
use crate::fit::FitDetail;
use crate::fit::inverse::BandPoint;
use crate::fit::quartic;
use crate::material::{Model, StrainMeasure};
use crate::mechanics::Point;
use crate::pipeline::{Comparison, FitOut, ModelRun};
use crate::sim::HeightModel;

/// Height against pressure (kPa, mm), and the relative error per model;
/// with `band`, the corrected law's 95 % band (its bounds dotted, above as
/// heights, below as relative to the law).
pub fn heights(
    points: &[Point],
    runs: &[ModelRun],
    rows: &[Comparison],
    band: Option<&[Option<BandPoint>]>,
) -> Figure {
    let measured: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.pressure_pa * 1e-3, p.height_m * 1e3))
        .collect();
    let errs: Vec<f64> = points
        .iter()
        .map(|p| p.height_std_m.unwrap_or(0.0) * 1e3)
        .collect();
    let mut top = Panel::new("pressure (kPa)", "apex height (mm)")
        .with(
            Series::scatter("measured (error bars: height_std_m)", measured)
                .with_errors(errs)
                .color(0),
        )
        .legend(LegendPosition::LowerRight)
        .weight(2.0);
    let mut bottom = Panel::new("pressure (kPa)", "simulated / measured - 1 (%)").zero_line();
    for (k, r) in runs.iter().enumerate() {
        let line: Vec<(f64, f64)> = r
            .points
            .iter()
            .filter_map(|p| p.height_m.map(|h| (p.pressure_pa * 1e-3, h * 1e3)))
            .collect();
        // the exact reference dashed, the spring models solid
        let series = |points| {
            let s = Series::line(r.model.to_string(), points).color(k + 1);
            if r.model == HeightModel::Axisym {
                s.dashed()
            } else {
                s
            }
        };
        top = top.with(series(line));
        let e: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|row| row.rel_errors()[k].map(|e| (row.pressure_pa * 1e-3, e * 100.0)))
            .collect();
        bottom = bottom.with(series(e));
    }
    if let Some(b) = band {
        let z = crate::fit::uncertainty::normal_quantile(0.975);
        let b: Vec<BandPoint> = b.iter().flatten().copied().collect();
        let k = runs.len() + 1;
        for (sign, name) in [(1.0, "95 % band of the law"), (-1.0, "")] {
            let h: Vec<(f64, f64)> = b
                .iter()
                .map(|q| {
                    (
                        q.pressure_pa * 1e-3,
                        (q.height_m + sign * z * q.std_m) * 1e3,
                    )
                })
                .collect();
            let rel: Vec<(f64, f64)> = b
                .iter()
                .map(|q| {
                    (
                        q.pressure_pa * 1e-3,
                        sign * 100.0 * z * q.std_m / q.height_m,
                    )
                })
                .collect();
            top = top.with(Series::line(name, h).color(k).dashed());
            bottom = bottom.with(Series::line("", rel).color(k).dashed());
        }
    }
    Figure::new(
        "Apex height against pressure: measured and simulated",
        vec![top, bottom],
    )
    .size(900, 800)
}

fn strain_of(m: StrainMeasure, l: f64) -> f64 {
    m.of_stretch(l)
}

/// The secant modulus `E(eps)` that a material implies under equibiaxial
/// stretch, in the fit's convention `E = k S / eps` (S nominal).
fn implied_modulus(model: &Model, k: f64, m: StrainMeasure, eps: f64) -> Option<f64> {
    match model {
        Model::Quartic {
            coefficients_pa, ..
        } => Some(quartic::eval(coefficients_pa, eps)),
        Model::Linear { young_pa } => Some(*young_pa),
        other => {
            let h = other.hyperelastic()?;
            let l = match m {
                StrainMeasure::Engineering => 1.0 + eps,
                StrainMeasure::Log => eps.exp(),
            };
            (eps != 0.0).then(|| k * h.equibiaxial_nominal(l) / eps)
        }
    }
}

/// Stress-strain with the law, `E(eps)` with the law, residuals.
pub fn fit(f: &FitOut) -> Figure {
    let k = f.modulus_factor;
    let sm = f.strain_measure;
    let sname = match sm {
        StrainMeasure::Engineering => "engineering",
        StrainMeasure::Log => "log",
    };
    let xlabel = format!("{sname} strain (-)");
    let (lo, hi) = match &f.detail {
        FitDetail::Quartic(q) => (q.strain_range[0].min(0.0), q.strain_range[1]),
        FitDetail::Hyper { .. } => {
            let hi = f
                .stress_points
                .last()
                .map(|p| strain_of(sm, p.0))
                .unwrap_or(0.1);
            (0.0, hi)
        }
    };
    let grid: Vec<f64> = (0..=200)
        .map(|i| lo + (hi - lo) * i as f64 / 200.0)
        .filter(|&e| e > 0.0)
        .collect();
    // kPa for everything: membrane moduli of rubber are 0.1-10 MPa.
    let kpa = 1e-3;
    // The law's modulus and stress curves over the grid.
    type Curve = Vec<(f64, f64)>;
    let curve = |model: &Model| -> (Curve, Curve) {
        let e: Vec<(f64, f64)> = grid
            .iter()
            .filter_map(|&e| implied_modulus(model, k, sm, e).map(|m| (e, m * kpa)))
            .collect();
        let s = e.iter().map(|&(e, m)| (e, m * e / k)).collect();
        (e, s)
    };
    let (law_e, law_s) = curve(&f.material.model);
    // With the correction to the heights: the cap-method law dashed, the
    // corrected one solid.
    let cap = f.refined.as_ref().map(|_| curve(&f.cap_material.model));
    let name = f.material.model.name();
    let (law_name, cap_name) = match cap {
        Some(_) => (
            format!("{name} corrected to the heights"),
            format!("{name} fitted to these points"),
        ),
        None => (format!("fitted {name}"), String::new()),
    };
    let data_e: Vec<(f64, f64)> = f.modulus_points.iter().map(|p| (p.0, p.1 * kpa)).collect();
    let data_e_err: Vec<f64> = f
        .modulus_points
        .iter()
        .map(|p| p.2.unwrap_or(0.0) * kpa)
        .collect();
    let data_s: Vec<(f64, f64)> = f
        .modulus_points
        .iter()
        .map(|p| (p.0, p.1 * p.0 / k * kpa))
        .collect();
    let kname = if k == 1.0 {
        "E eps".to_string()
    } else {
        format!("E eps / {k:.3}")
    };
    let mut p1 = Panel::new(&xlabel, format!("stress S = {kname} (kPa)"))
        .titled("stress against strain")
        .with(Series::scatter("measured (stress stage)", data_s).color(0));
    let mut p2 = Panel::new(&xlabel, "secant modulus E (kPa)")
        .titled("secant modulus E(eps)")
        .with(
            Series::scatter("measured", data_e)
                .with_errors(data_e_err)
                .color(0),
        );
    if let Some((cap_e, cap_s)) = cap {
        p1 = p1.with(Series::line(cap_name.clone(), cap_s).color(1).dashed());
        p2 = p2.with(Series::line(cap_name, cap_e).color(1).dashed());
    }
    let p1 = p1
        .with(Series::line(law_name.clone(), law_s).color(3))
        .weight(1.6);
    let p2 = p2
        .with(Series::line(law_name, law_e).color(3))
        .legend(LegendPosition::UpperRight)
        .weight(1.6);
    let p3 = match &f.detail {
        FitDetail::Quartic(q) => {
            let res: Vec<(f64, f64)> = f
                .modulus_points
                .iter()
                .zip(&q.residuals_pa)
                .map(|(p, r)| (p.0, r * kpa))
                .collect();
            Panel::new(&xlabel, "E residual, data - fit to the points (kPa)")
                .with(Series::scatter("", res).color(2))
                .zero_line()
        }
        FitDetail::Hyper { fits, best } => {
            let h = &fits[*best];
            let res: Vec<(f64, f64)> = f
                .stress_points
                .iter()
                .zip(&h.residuals_pa)
                .map(|(p, r)| (strain_of(sm, p.0), r * kpa))
                .collect();
            Panel::new(&xlabel, "Cauchy stress residual (kPa)")
                .with(Series::scatter("", res).color(2))
                .zero_line()
        }
    };
    Figure::new(
        format!("Material fit: {}", f.material.model.name()),
        vec![p1, p2, p3.weight(1.0)],
    )
    .size(900, 1100)
}
