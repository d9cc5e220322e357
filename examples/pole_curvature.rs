//! The pole's curvature of an inflated flat clamped disc against the
//! spherical cap through its rim with the same height, over the laws bulge
//! knows and heights from small up to 0.97 of the limit pressure (or a pole
//! stretch of 3 where the law has no limit point): the invariant the
//! tracker's curvature guards rest on (`src/track/guards.rs`,
//! docs/track.md, *Plausibility guards*).
//!
//! For every exact axisymmetric solution (`bulge::axisym`) it prints the
//! apex height `h/a`, the ratio `R = kappa_pole / (2 h / (a^2 + h^2))`, the
//! same ratio for a parabola fitted by least squares to the meridian over
//! the columns within 0.15 a and 0.3 a of the axis (what the tracker's edge
//! fit measures over its span), and per law the range of `R` and the
//! largest `|dR / d(h/a)|` between neighbouring rows.
//!
//! Run: `cargo run --release --example pole_curvature` (add `--rows` for
//! every solution, not only the per-law summary).

use bulge::axisym::{Options, Solution, limit_point, solve_pole_stretch, solve_pressure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model, StrainMeasure};

const A: f64 = 0.0375;

/// Curvature times `a` of the parabola `z = c0 - k x^2 / 2` fitted by least
/// squares to the meridian at 201 evenly spaced columns `x` within `w a` of
/// the axis (both sides; the profile interpolated linearly in `rho`).
fn fitted_curvature(s: &Solution, w: f64) -> f64 {
    let p = &s.profile;
    let rho: Vec<f64> = p.rho_m.iter().map(|r| r / A).collect();
    let z: Vec<f64> = p.z_m.iter().map(|r| r / A).collect();
    let at = |x: f64| -> f64 {
        let i = rho.partition_point(|&r| r < x).clamp(1, rho.len() - 1);
        let t = (x - rho[i - 1]) / (rho[i] - rho[i - 1]);
        z[i - 1] + t * (z[i] - z[i - 1])
    };
    let n = 201;
    let (mut sx, mut sxx, mut sy, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for j in 0..n {
        let x = w * (2.0 * j as f64 / (n - 1) as f64 - 1.0);
        let u = x * x;
        let y = at(x.abs());
        sx += u;
        sxx += u * u;
        sy += y;
        sxy += u * y;
    }
    let nn = n as f64;
    let slope = (nn * sxy - sx * sy) / (nn * sxx - sx * sx);
    -2.0 * slope
}

fn cap(h: f64) -> f64 {
    2.0 * h / (1.0 + h * h)
}

fn mat(model: Model, poisson: f64) -> Material {
    Material {
        model,
        poisson,
        fit: None,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rows = std::env::args().any(|a| a == "--rows");
    let specimen = Specimen {
        radius_m: A,
        thickness_m: 3.5e-4,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let opts = Options {
        n_profile: 4001,
        max_pole_stretch: 3.2,
        ..Options::default()
    };
    let c1 = 2.0e5;
    let mut laws: Vec<(String, Material, Option<f64>)> = vec![(
        "neo-Hookean".into(),
        mat(Model::NeoHookean { c1_pa: c1 }, 0.5),
        None,
    )];
    for r in [0.05, 0.1, 0.136, 0.2, 0.3, 0.5, 1.0] {
        laws.push((
            format!("Mooney-Rivlin C2/C1 {r}"),
            mat(
                Model::MooneyRivlin {
                    c1_pa: c1,
                    c2_pa: r * c1,
                },
                0.5,
            ),
            None,
        ));
    }
    laws.push((
        "Yeoh 0.2 MPa, -2 kPa, 50 Pa".into(),
        mat(
            Model::Yeoh {
                c1_pa: c1,
                c2_pa: -2.0e3,
                c3_pa: 50.0,
            },
            0.5,
        ),
        None,
    ));
    laws.push((
        "Ogden-3 (Treloar, Ogden 1972)".into(),
        mat(
            Model::Ogden {
                mu_pa: vec![6.3e5, 1.2e3, -1.0e4],
                alpha: vec![1.3, 5.0, -2.0],
            },
            0.5,
        ),
        None,
    ));
    for jm in [10.0, 30.0, 100.0] {
        laws.push((
            format!("Gent Jm {jm}"),
            mat(
                Model::Gent {
                    mu_pa: 2.0 * c1,
                    jm,
                },
                0.5,
            ),
            None,
        ));
    }
    laws.push((
        "linear E 1 MPa, nu 0.45 (to pole stretch 1.1)".into(),
        mat(Model::Linear { young_pa: 1.0e6 }, 0.45),
        Some(1.1),
    ));
    laws.push((
        "quartic latex (to pole stretch 1.8)".into(),
        mat(
            Model::Quartic {
                coefficients_pa: vec![1.6e6, -2.4e6, 2.0e6, -0.6e6, 0.0],
                strain_range: [0.0, 1.0],
                strain_measure: StrainMeasure::Engineering,
            },
            0.45,
        ),
        Some(1.8),
    ));
    println!(
        "| law | limit pressure / (C1 t / a) | h/a range | R pole | R fit 0.15 a | R fit 0.3 a | max abs dR/d(h/a) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut all = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    let mut cases: Vec<(String, Material, Option<f64>, f64)> =
        laws.into_iter().map(|(n, m, c)| (n, m, c, 0.0)).collect();
    for pre in [0.1, 0.3] {
        cases.push((
            format!("neo-Hookean, slack: stress-free cap {pre} a high"),
            mat(Model::NeoHookean { c1_pa: c1 }, 0.5),
            None,
            pre,
        ));
        cases.push((
            format!("Mooney-Rivlin C2/C1 0.136, slack: cap {pre} a high"),
            mat(
                Model::MooneyRivlin {
                    c1_pa: c1,
                    c2_pa: 0.136 * c1,
                },
                0.5,
            ),
            None,
            pre,
        ));
    }
    for (name, m, stretch_cap, pre) in &cases {
        let specimen = Specimen {
            prebulge_height_m: pre * A,
            ..specimen
        };
        let limit = match stretch_cap {
            Some(_) => None,
            None => limit_point(m, &specimen, &opts)?,
        };
        let mut sols = Vec::new();
        match &limit {
            Some(top) => {
                for k in 1..=40 {
                    let f = 0.97 * k as f64 / 40.0;
                    sols.push(solve_pressure(m, &specimen, f * top.pressure_pa, &opts)?);
                }
            }
            None => {
                let top = stretch_cap.unwrap_or(3.0);
                for k in 1..=40 {
                    let l0 = 1.0 + (top - 1.0) * (k as f64 / 40.0).powi(2);
                    match solve_pole_stretch(m, &specimen, l0, &opts) {
                        Ok(s) => sols.push(s),
                        Err(_) => break,
                    }
                }
            }
        }
        let mut stats = (f64::INFINITY, f64::NEG_INFINITY);
        let mut fit15 = (f64::INFINITY, f64::NEG_INFINITY);
        let mut fit30 = (f64::INFINITY, f64::NEG_INFINITY);
        let mut slope = 0.0f64;
        let mut last: Option<(f64, f64)> = None;
        let mut hr = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &sols {
            let h = s.height_m / A;
            let r = s.pole_curvature_per_m() * A / cap(h);
            let r15 = fitted_curvature(s, 0.15) / cap(h);
            let r30 = fitted_curvature(s, 0.3) / cap(h);
            if rows {
                println!(
                    "  {name}: p {:.1} Pa, l0 {:.4}, h/a {h:.4}, R {r:.4}, fit 0.15a {r15:.4}, fit 0.3a {r30:.4}",
                    s.pressure_pa, s.pole_stretch
                );
            }
            stats = (stats.0.min(r), stats.1.max(r));
            fit15 = (fit15.0.min(r15), fit15.1.max(r15));
            fit30 = (fit30.0.min(r30), fit30.1.max(r30));
            hr = (hr.0.min(h), hr.1.max(h));
            if let Some((h0, r0)) = last {
                slope = slope.max(((r - r0) / (h - h0)).abs());
            }
            last = Some((h, r));
        }
        all = (all.0.min(stats.0), all.1.max(stats.1), all.2.max(slope));
        let c1_of = match &m.model {
            Model::NeoHookean { c1_pa } | Model::MooneyRivlin { c1_pa, .. } => Some(*c1_pa),
            _ => None,
        };
        let lim = match (&limit, c1_of) {
            (Some(t), Some(c)) => format!("{:.4}", t.pressure_pa * A / (c * specimen.thickness_m)),
            (Some(t), None) => format!("{:.1} Pa", t.pressure_pa),
            (None, _) => "none".into(),
        };
        println!(
            "| {name} | {lim} | {:.3}-{:.3} | {:.3}-{:.3} | {:.3}-{:.3} | {:.3}-{:.3} | {:.3} |",
            hr.0, hr.1, stats.0, stats.1, fit15.0, fit15.1, fit30.0, fit30.1, slope
        );
    }
    println!(
        "all laws: R pole {:.3}-{:.3}, max abs dR/d(h/a) {:.3}",
        all.0, all.1, all.2
    );
    Ok(())
}
